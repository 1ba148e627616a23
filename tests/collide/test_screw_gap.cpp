// What a screw motion keeps (screw.h): a face's coordinate along the screw's axis shifts by s d and
// its distance from the axis line stays, so screw_gap bounds the distance of a moving face and one
// that stays over a whole stretch. Checked against the distance of sampled points of the exact
// surfaces along the motion: a bound above it would clear a stretch that touches.
#include "screw.h"

#include "cadclash/trajectory.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

namespace cadclash::detail {
namespace {

constexpr double kPi = std::numbers::pi;

Pose pose(const Vec3& axis, double angle, const Vec3& t) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  p.translation() = t;
  return p;
}

// A face on the cylinder of radius r about the local z axis, for z in [z0, z1], whole turn.
Surface cylinder(double r, double z0, double z1) {
  Surface s;
  s.aabb = Aabb(Vec3(-r, -r, z0), Vec3(r, r, z1));
  s.analytic.shape = SurfaceShape::Cylinder;
  s.analytic.origin = Vec3::Zero();
  s.analytic.axis = Vec3::UnitZ();
  s.analytic.radius = r;
  s.uncertainty = s.tolerance = 1e-7;
  return s;
}
// A face on the plane z = z, the square [-h, h]^2.
Surface square(double h, double z) {
  Surface s;
  s.aabb = Aabb(Vec3(-h, -h, z), Vec3(h, h, z));
  s.analytic.shape = SurfaceShape::Plane;
  s.analytic.origin = Vec3(0, 0, z);
  s.analytic.axis = Vec3::UnitZ();
  s.uncertainty = s.tolerance = 1e-7;
  return s;
}

// Points of a face (part-local), on its exact surface.
std::vector<Vec3> samples(const Surface& s) {
  std::vector<Vec3> out;
  const Aabb& b = s.aabb;
  for (int i = 0; i <= 16; ++i)
    for (int j = 0; j <= 16; ++j) {
      const double u = i / 16.0, v = j / 16.0;
      if (s.analytic.shape == SurfaceShape::Cylinder) {
        const double phi = 2.0 * kPi * u;
        out.push_back(s.analytic.radius * Vec3(std::cos(phi), std::sin(phi), 0.0) +
                      Vec3(0, 0, b.min().z() + v * (b.max().z() - b.min().z())));
      } else {
        out.push_back(b.min() + Vec3(u, v, 0.0).cwiseProduct(b.max() - b.min()));
      }
    }
  return out;
}

// The least distance of the sampled points over the motion's sampled poses in [s0, s1]: at least
// the exact distance, so a sound bound is never above it.
double sampled_distance(const Surface& moving, const Pose& from, const Pose& to, const Surface& still,
                        const Pose& still_pose, double s0, double s1) {
  const std::vector<Vec3> pm = samples(moving), ps = samples(still);
  std::vector<Vec3> fixed;
  for (const Vec3& p : ps) fixed.push_back(still_pose * p);
  double least = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= 24; ++k) {
    const Pose at = interpolate_pose(from, to, s0 + (s1 - s0) * k / 24.0);
    for (const Vec3& p : pm) {
      const Vec3 x = at * p;
      for (const Vec3& y : fixed) least = std::min(least, (x - y).norm());
    }
  }
  return least;
}

struct Scene2 {
  Model model;
  SurfaceId moving = 0, still = 1;
};
Scene2 two(const Surface& moving, const Surface& still) {
  Scene2 s;
  s.model.surfaces = {moving, still};
  return s;
}

// A ring turned about its own axis and shifted along it around a rod: the turn cannot bring them
// closer than the two radii's difference, however far it carries the ring.
TEST(ScrewGap, ARingTurnedAboutItsRodKeepsTheRadialGap) {
  const Scene2 s = two(cylinder(5.2, 0.0, 4.0), cylinder(5.0, -20.0, 20.0));
  const Pose from = pose(Vec3::UnitZ(), 0.3, Vec3(7, -3, 2)), to = pose(Vec3::UnitZ(), 0.3 + 1.9, Vec3(7, -3, 3));
  const Pose still = pose(Vec3::UnitZ(), 0.0, Vec3(7, -3, 0));
  const double g = screw_gap(s.model, s.moving, from, screw_of(from, to), s.still, still, 0.0, 1.0);
  EXPECT_GT(g, 0.2 - 1e-6);
  EXPECT_LE(g, 0.2);
  // Its travel over the stretch is ~10 mm: the isotropic bound proves nothing here.
  EXPECT_GT(travel_bound(from, to, s.model.surfaces[0].aabb, 0.0, 1.0), 9.0);
  EXPECT_LE(g, sampled_distance(s.model.surfaces[0], from, to, s.model.surfaces[1], still, 0.0, 1.0));
}

// The same turn about a line 1 mm off the rod's axis swings the ring into the rod: no gap.
TEST(ScrewGap, ATurnAboutAnotherLineKeepsNothing) {
  const Scene2 s = two(cylinder(5.2, 0.0, 4.0), cylinder(5.0, -20.0, 20.0));
  const Vec3 c(1.0, 0.0, 0.0);  // the turn's axis: through c, along z
  const Pose from = pose(Vec3::UnitZ(), 0.0, Vec3::Zero());
  Pose to = pose(Vec3::UnitZ(), 2.0, Vec3::Zero());
  to.translation() = c - to.linear() * c;  // turn about the line through c
  const Pose still = Pose::Identity();
  const double g = screw_gap(s.model, s.moving, from, screw_of(from, to), s.still, still, 0.0, 1.0);
  EXPECT_LE(g, sampled_distance(s.model.surfaces[0], from, to, s.model.surfaces[1], still, 0.0, 1.0));
  EXPECT_EQ(g, 0.0);
}

// A nut's face lifting off a plate while it turns: apart by how far it has risen, over the part of
// the motion after it left; a face coming down is apart until it arrives.
TEST(ScrewGap, AFaceAlongTheAxisMovesOnlyByTheShift) {
  const Scene2 s = two(square(4.0, 0.0), square(30.0, 0.0));
  const Pose from = pose(Vec3::UnitZ(), 0.0, Vec3(0, 0, 0.5)), up = pose(Vec3::UnitZ(), 1.8, Vec3(0, 0, 1.5));
  const Pose down = pose(Vec3::UnitZ(), 1.8, Vec3(0, 0, -0.5));
  const Pose still = Pose::Identity();
  EXPECT_NEAR(screw_gap(s.model, s.moving, from, screw_of(from, up), s.still, still, 0.0, 1.0), 0.5, 1e-9);
  EXPECT_NEAR(screw_gap(s.model, s.moving, from, screw_of(from, up), s.still, still, 0.5, 1.0), 1.0, 1e-9);
  EXPECT_NEAR(screw_gap(s.model, s.moving, from, screw_of(from, down), s.still, still, 0.0, 0.25), 0.25, 1e-9);
  EXPECT_EQ(screw_gap(s.model, s.moving, from, screw_of(from, down), s.still, still, 0.0, 1.0), 0.0);
  for (const Pose& to : {up, down})
    for (const auto& [s0, s1] : {std::pair{0.0, 1.0}, {0.5, 1.0}, {0.0, 0.25}})
      EXPECT_LE(screw_gap(s.model, s.moving, from, screw_of(from, to), s.still, still, s0, s1),
                sampled_distance(s.model.surfaces[0], from, to, s.model.surfaces[1], still, s0, s1));
}

// A square turning about its centre beside a wall parallel to the axis (a nut turned beside its
// neighbour's flank): its corners reach 4 sqrt(2) from the axis and the wall is 8 from it, however
// tall and wide, so the turn keeps them 8 - 4 sqrt(2) apart. (The wall's box centre is 8 from the
// axis but its half diagonal is 3.4: the wall's least distance is its box's own, not the centre's
// less the half diagonal.)
TEST(ScrewGap, AWallBesideTheTurnKeepsItsDistanceFromTheAxis) {
  Surface wall;
  wall.aabb = Aabb(Vec3(8, -3, -1), Vec3(8, 3, 3));
  wall.analytic.shape = SurfaceShape::Plane;
  wall.analytic.origin = Vec3(8, 0, 0);
  wall.analytic.axis = Vec3::UnitX();
  wall.uncertainty = wall.tolerance = 1e-7;
  const Scene2 s = two(square(4.0, 0.0), wall);
  // The wall as built, turned about the axis (its box's edges then run across it), and leaning
  // 0.3 radians about its own foot line, which brings its lower edge sin(0.3) nearer the axis.
  Pose lean = pose(Vec3::UnitY(), 0.3, Vec3::Zero());
  lean.translation() = Vec3(8, 0, 0) - lean.linear() * Vec3(8, 0, 0);
  const double reach = 4.0 * std::sqrt(2.0);
  for (const Vec3& where : {Vec3(0, 0, 0), Vec3(1.2e4, -2e4, 5e3)})
    for (const auto& [placed, gap] : {std::pair{pose(Vec3::UnitZ(), 0.0, Vec3::Zero()), 8.0 - reach},
                                      std::pair{pose(Vec3::UnitZ(), 0.5, Vec3::Zero()), 8.0 - reach},
                                      std::pair{lean, 8.0 - std::sin(0.3) - reach}}) {
      const Pose from = pose(Vec3::UnitZ(), 0.2, where), to = pose(Vec3::UnitZ(), 2.9, where + Vec3(0, 0, 1));
      const Pose still = pose(Vec3::UnitZ(), 0.0, where) * placed;
      const double g = screw_gap(s.model, s.moving, from, screw_of(from, to), s.still, still, 0.0, 1.0);
      EXPECT_GT(g, gap - 1e-6);
      EXPECT_LE(g, gap);
      EXPECT_LE(g, sampled_distance(s.model.surfaces[0], from, to, s.model.surfaces[1], still, 0.0, 1.0));
    }
}

// A pin pulled along a bore's axis (a shift, no turn) keeps the radial gap; pulled across, not.
TEST(ScrewGap, APinPulledAlongItsBoreKeepsTheGap) {
  const Scene2 s = two(cylinder(3.0, 0.0, 10.0), cylinder(3.1, 0.0, 10.0));
  const Pose from = pose(Vec3::UnitX(), 0.4, Vec3(1, 2, 3));
  const Vec3 axis = from.linear() * Vec3::UnitZ();
  Pose along = from, across = from;
  along.translation() += 25.0 * axis;
  across.translation() += 25.0 * axis.unitOrthogonal();
  const double g = screw_gap(s.model, s.moving, from, screw_of(from, along), s.still, from, 0.0, 1.0);
  EXPECT_GT(g, 0.1 - 1e-6);
  EXPECT_LE(g, 0.1);
  EXPECT_EQ(screw_gap(s.model, s.moving, from, screw_of(from, across), s.still, from, 0.0, 1.0), 0.0);
}

// Random screws about random lines, cylinders and planes about or near them: the bound is never
// above the sampled distance.
TEST(ScrewGap, NeverAboveTheSampledDistance) {
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), pos(0.0, 1.0);
  int positive = 0;
  for (int trial = 0; trial < 150; ++trial) {
    SCOPED_TRACE(trial);
    const Vec3 axis = Vec3(unit(rng), unit(rng), unit(rng)).normalized();
    const Vec3 c(5 * unit(rng), 5 * unit(rng), 5 * unit(rng));
    // The moving part's frame has its z along the axis, or nearly (a tilt), and its origin on the
    // axis or near it.
    const double tilt = trial % 3 == 0 ? 0.05 * pos(rng) : 0.0, off = trial % 4 == 0 ? 0.5 * pos(rng) : 0.0;
    Pose from = Pose::Identity();
    from.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis).toRotationMatrix() *
                    Eigen::AngleAxisd(tilt, Vec3::UnitX()).toRotationMatrix();
    from.translation() = c + off * axis.unitOrthogonal();
    const double angle = trial % 5 == 0 ? 0.0 : 3.0 * pos(rng), shift = 4.0 * unit(rng);
    Pose to = from;
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    to.linear() = turn * from.linear();
    to.translation() = c + turn * (from.translation() - c) + shift * axis;
    const Surface moving = trial % 2 == 0 ? cylinder(2.0 + pos(rng), -1.0, 1.0) : square(1.5, 0.0);
    const Surface still_face = trial % 3 == 1 ? square(6.0, 2.0 * unit(rng)) : cylinder(1.0 + 3.0 * pos(rng), -4.0, 4.0);
    Pose still = Pose::Identity();
    still.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis).toRotationMatrix();
    // Some still faces lie off the axis, across it, and turned about another line.
    still.translation() = c + (trial % 7 == 0 ? 6.0 * pos(rng) : 0.0) * axis.unitOrthogonal();
    if (trial % 7 == 0) still.linear() = Eigen::AngleAxisd(0.6 * unit(rng), axis.unitOrthogonal()).toRotationMatrix() * still.linear();
    const Scene2 s = two(moving, still_face);
    const double s0 = 0.5 * pos(rng), s1 = s0 + 0.5 * pos(rng);
    const double g = screw_gap(s.model, s.moving, from, screw_of(from, to), s.still, still, s0, s1);
    const double d = sampled_distance(moving, from, to, still_face, still, s0, s1);
    EXPECT_LE(g, d);
    if (g > 0.0) ++positive;
  }
  EXPECT_GT(positive, 60) << positive;  // it proves something in many of them
}

}  // namespace
}  // namespace cadclash::detail
