// patch_gap (collide/src/patch_gap.h): a lower bound on the distance between two faces' rational
// Bézier patches. On patches whose distance is known in closed form (quarter cylinders as rational
// quadratics, coaxial or shifted; parallel planes), placed directly or through a rigid motion:
// the bound never exceeds the true distance, it proves every threshold below that distance by a
// margin, and surfaces that cross are never proved apart.
#include "patch_gap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace cadclash::detail {
namespace {

using Patches = SurfaceSource::BezierPatches;
using Patch = SurfaceSource::BezierPatch;

// A quarter of the cylinder of radius r about the z axis (angles [a0, a0 + 90°], z in [z0, z1]):
// rational quadratic in u (the exact circle), linear in v.
Patch quarter_cylinder(double r, double a0, double z0, double z1, const Vec3& centre = Vec3::Zero()) {
  Patch p;
  p.degree_u = 2;
  p.degree_v = 1;
  const Vec3 e0(std::cos(a0), std::sin(a0), 0.0);
  const Vec3 e1(-std::sin(a0), std::cos(a0), 0.0);
  const Vec3 ring[3] = {r * e0, r * (e0 + e1), r * e1};
  const double w[3] = {1.0, std::numbers::sqrt2 / 2.0, 1.0};
  for (int i = 0; i < 3; ++i)
    for (double z : {z0, z1}) {
      p.points.push_back(centre + ring[i] + Vec3(0.0, 0.0, z));
      p.weights.push_back(w[i]);
    }
  return p;
}

// The rectangle [0, sx] x [0, sy] at height z, bilinear.
Patch rectangle(double sx, double sy, double z) {
  Patch p;
  p.degree_u = 1;
  p.degree_v = 1;
  for (double x : {0.0, sx})
    for (double y : {0.0, sy}) {
      p.points.emplace_back(x, y, z);
      p.weights.push_back(1.0);
    }
  return p;
}

Patches of(std::initializer_list<Patch> ps) {
  Patches out;
  out.patches = ps;
  return out;
}

// A rigid motion that is not a permutation of axes.
Pose skew_motion() {
  return Pose(Eigen::Translation3d(12.5, -40.25, 7.0) * Eigen::AngleAxisd(0.7, Vec3(1.0, 2.0, -0.5).normalized()));
}

Patches moved(const Patches& in, const Pose& by) {
  Patches out = in;
  for (Patch& p : out.patches)
    for (Vec3& q : p.points) q = by * q;
  return out;
}

TEST(PatchGap, CoaxialQuarterCylindersAreProvedApartUpToTheirGap) {
  for (double gap : {1e-2, 1e-4, 2.4e-6}) {
    const Patches inner = of({quarter_cylinder(5.0, 0.0, 0.0, 30.0)});
    const Patches outer = of({quarter_cylinder(5.0 + gap, 0.0, 10.0, 40.0)});
    for (double share : {0.5, 0.9}) {
      // The pieces must be thinner than gap - threshold: 10 % of a 2.4e-6 gap asks more pieces of a
      // radius-5 quarter than the default budget looks at.
      if (share > 0.5 && gap < 1e-5) continue;
      PatchGapOptions o;
      o.threshold = share * gap;
      const auto g = patch_gap(inner, outer, Pose::Identity(), o);
      ASSERT_TRUE(g.gap.has_value()) << "gap " << gap << ", threshold " << o.threshold;
      EXPECT_GT(*g.gap, o.threshold);
      EXPECT_LE(*g.gap, gap) << "a lower bound above the true distance";
    }
    PatchGapOptions o;
    o.threshold = 1.01 * gap;  // above the true distance: never proved
    EXPECT_FALSE(patch_gap(inner, outer, Pose::Identity(), o).gap.has_value()) << "gap " << gap;
  }
}

TEST(PatchGap, ABoltShiftedInItsHoleCrossesItOnOneSideAndLeavesAGapOnTheOther) {
  // Equal radii, B's axis shifted by d along x. The two circles cross where the angle from either
  // centre is ~90°: the quarters [45°, 135°] of both hold that line, so the faces meet (distance 0)
  // and are never proved apart. The quarters [-45°, 45°] with B shifted by -d (away from them) are
  // apart by d·cos(45°) (to first order in d/r): the radial gap d·cos(angle), least at their ends.
  const double d = 1e-5;
  const double q = std::numbers::pi / 4.0;
  PatchGapOptions o;
  o.threshold = 1e-9;
  const PatchGap crossing = patch_gap(of({quarter_cylinder(5.0, q, 0.0, 30.0)}),
                                      of({quarter_cylinder(5.0, q, 0.0, 30.0, Vec3(d, 0.0, 0.0))}), Pose::Identity(), o);
  EXPECT_FALSE(crossing.gap.has_value());
  // Where it stopped: a point of A's cylinder where B's comes within far less than d.
  ASSERT_TRUE(crossing.near.has_value());
  const Vec3 x = *crossing.near;
  EXPECT_NEAR(std::hypot(x.x(), x.y()), 5.0, 1e-12);
  EXPECT_LT(std::abs(std::hypot(x.x() - d, x.y()) - 5.0), 1e-3 * d);
  EXPECT_TRUE(x.z() >= 0.0 && x.z() <= 30.0);
  const double apart = d * std::cos(q);
  o.threshold = 0.5 * apart;
  const auto g = patch_gap(of({quarter_cylinder(5.0, -q, 0.0, 30.0)}),
                           of({quarter_cylinder(5.0, -q, 0.0, 30.0, Vec3(-d, 0.0, 0.0))}), Pose::Identity(), o);
  ASSERT_TRUE(g.gap.has_value());
  EXPECT_GT(*g.gap, o.threshold);
  EXPECT_LE(*g.gap, 1.0001 * apart);
}

TEST(PatchGap, TheSameUnderARigidMotionOfB) {
  const double gap = 1e-4;
  const Patches inner = of({quarter_cylinder(5.0, 0.3, 0.0, 30.0)});
  const Patches outer = of({quarter_cylinder(5.0 + gap, 0.3, 0.0, 30.0)});
  const Pose motion = skew_motion();
  // B stored in its own frame (moved by the inverse) and placed back by `motion`.
  const Patches outer_local = moved(outer, motion.inverse());
  PatchGapOptions o;
  o.threshold = 0.9 * gap;
  o.pose_magnitude = motion.translation().norm();
  const auto g = patch_gap(inner, outer_local, motion, o);
  ASSERT_TRUE(g.gap.has_value());
  EXPECT_GT(*g.gap, o.threshold);
  EXPECT_LE(*g.gap, gap);
  o.threshold = 1.01 * gap;
  EXPECT_FALSE(patch_gap(inner, outer_local, motion, o).gap.has_value());
}

TEST(PatchGap, ParallelAndTouchingRectangles) {
  const Patches a = of({rectangle(10.0, 5.0, 0.0)});
  PatchGapOptions o;
  o.threshold = 0.5e-3;
  const auto g = patch_gap(a, of({rectangle(10.0, 5.0, 1e-3)}), Pose::Identity(), o);
  ASSERT_TRUE(g.gap.has_value());
  EXPECT_GT(*g.gap, o.threshold);
  EXPECT_LE(*g.gap, 1e-3);
  // Coplanar and overlapping: distance 0, never proved apart at any positive threshold.
  o.threshold = 1e-12;
  EXPECT_FALSE(patch_gap(a, of({rectangle(3.0, 3.0, 0.0)}), Pose::Identity(), o).gap.has_value());
  // Side by side in one plane, 1e-3 apart edge to edge.
  Patch right = rectangle(10.0, 5.0, 0.0);
  for (Vec3& q : right.points) q.x() += 10.0 + 1e-3;
  o.threshold = 0.5e-3;
  const auto side = patch_gap(a, of({right}), Pose::Identity(), o);
  ASSERT_TRUE(side.gap.has_value());
  EXPECT_LE(*side.gap, 1e-3);
}

TEST(PatchGap, TheBudgetEndsTheSearchWithoutAnAnswer) {
  // Coaxial cylinders 1e-6 apart need fine pieces: four looks are not enough.
  const Patches inner = of({quarter_cylinder(5.0, 0.0, 0.0, 30.0)});
  const Patches outer = of({quarter_cylinder(5.0 + 1e-6, 0.0, 0.0, 30.0)});
  PatchGapOptions o;
  o.threshold = 0.5e-6;
  o.budget = 4;
  EXPECT_FALSE(patch_gap(inner, outer, Pose::Identity(), o).gap.has_value());
  o.budget = PatchGapOptions{}.budget;
  EXPECT_TRUE(patch_gap(inner, outer, Pose::Identity(), o).gap.has_value());
}

}  // namespace
}  // namespace cadclash::detail
