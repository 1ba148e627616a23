// Motion between the steps of a path (trajectory.h): the interpolated poses and the bound on how far
// a part's points travel over a stretch of the motion.
#include "cadclash/trajectory.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace cadclash {
namespace {

Pose pose(const Vec3& axis, double angle, const Vec3& t) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  p.translation() = t;
  return p;
}

double rotation_between(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

// s = 0 and s = 1 give the two poses (translations exactly, rotations to a few ulps); in between
// the rotation turns at constant speed along the shorter arc: 350 degrees about z is -10 degrees.
TEST(Motion, EndsShorterArcAndConstantSpeed) {
  const Pose a = pose(Vec3(1, 2, 3), 0.7, Vec3(10, -20, 5e5)), b = pose(Vec3(-2, 1, 0.5), 2.1, Vec3(12, -19, 5e5 + 3));
  EXPECT_EQ(interpolate_pose(a, b, 0.0).translation(), a.translation());
  EXPECT_EQ(interpolate_pose(a, b, 1.0).translation(), b.translation());
  EXPECT_LT((interpolate_pose(a, b, 0.0).linear() - a.linear()).norm(), 1e-14);
  EXPECT_LT((interpolate_pose(a, b, 1.0).linear() - b.linear()).norm(), 1e-14);
  const double total = motion_angle(a, b);
  EXPECT_NEAR(total, rotation_between(a, b), 1e-12);
  for (double s : {0.1, 0.25, 0.5, 0.9})
    EXPECT_NEAR(rotation_between(a, interpolate_pose(a, b, s)), s * total, 1e-12) << s;
  const Pose id = Pose::Identity(), turned = pose(Vec3::UnitZ(), 350.0 * std::numbers::pi / 180.0, Vec3::Zero());
  EXPECT_NEAR(motion_angle(id, turned), 10.0 * std::numbers::pi / 180.0, 1e-14);
  const Pose mid = interpolate_pose(id, turned, 0.5);
  EXPECT_NEAR(std::atan2(mid.linear()(1, 0), mid.linear()(0, 0)), -5.0 * std::numbers::pi / 180.0, 1e-14);
  // A tiny turn keeps its digits (acos of the quaternion's w would not).
  const Pose tiny = pose(Vec3(0, 1, 1), 3e-9, Vec3::Zero());
  EXPECT_NEAR(motion_angle(id, tiny), 3e-9, 1e-22);
}

// The motion is the screw of the displacement from a to b (Chasles): a point's path does not depend
// on where the part's own frame has its origin, nor on where the world's has; parts moved by one
// displacement move together all the way; a turn about a fixed axis with a shift along it (a nut
// unscrewed) keeps each point at its distance from that axis.
TEST(Motion, TheScrewFollowsThePointsNotTheFrames) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  auto random_pose = [&](double spread) {
    return pose(Vec3(u(rng), u(rng), u(rng)), 3.0 * u(rng), spread * Vec3(u(rng), u(rng), u(rng)));
  };
  for (int k = 0; k < 200; ++k) {
    const Pose a = random_pose(100.0), b = random_pose(100.0);
    const Pose frame = random_pose(50.0), world = random_pose(1e3);  // a part frame moved; the world moved
    const Vec3 p(10.0 * u(rng), 10.0 * u(rng), 10.0 * u(rng));
    for (double s : {0.1, 0.37, 0.5, 0.93}) {
      const Vec3 x = interpolate_pose(a, b, s) * p;
      // The same part described in another frame: its points p' = frame^-1 p, its poses a frame.
      EXPECT_LT((interpolate_pose(a * frame, b * frame, s) * (frame.inverse() * p) - x).norm(), 1e-9) << k << ' ' << s;
      EXPECT_LT((interpolate_pose(world * a, world * b, s) * p - world * x).norm(), 1e-9) << k << ' ' << s;
      // Another part moved by the same displacement b a^-1 moves with it.
      const Pose c = random_pose(100.0), d = b * a.inverse() * c;
      const Pose together = interpolate_pose(c, d, s) * c.inverse();
      EXPECT_LT((together * (a * p) - x).norm(), 1e-9) << k << ' ' << s;
    }
  }
  // Turned 108 degrees about the line x = 20, y = -5 (along z) and shifted 0.45 mm along it: every
  // point keeps its distance from the line and rises by s 0.45, turning by s 108 degrees.
  const Vec3 c(20, -5, 0);
  Pose a = pose(Vec3(1, 1, 0), 0.3, Vec3(3, 4, 5));
  Pose screw = Pose::Identity();
  screw.translate(c + Vec3(0, 0, 0.45));
  screw.rotate(Eigen::AngleAxisd(0.6 * std::numbers::pi, Vec3::UnitZ()));
  screw.translate(-c);
  const Pose b = screw * a;
  const Vec3 p(1, 2, 3), x0 = a * p;
  for (double s : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    Pose part = Pose::Identity();
    part.translate(c + Vec3(0, 0, s * 0.45));
    part.rotate(Eigen::AngleAxisd(s * 0.6 * std::numbers::pi, Vec3::UnitZ()));
    part.translate(-c);
    EXPECT_LT((interpolate_pose(a, b, s) * p - part * x0).norm(), 1e-12) << s;
  }
}

// The bound holds for every point of the box over every stretch, with random motions near the
// origin and a million millimetres out, rotations about far axes included; and it is not loose: a
// pure translation travels it all, a pure turn its arc.
TEST(Motion, TravelBoundHoldsAndIsTight) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  int checked = 0;
  for (double offset : {0.0, 1e3, 1e6})
    for (int k = 0; k < 200; ++k) {
      const Vec3 c(offset * u(rng), offset * u(rng), offset * u(rng));
      const Pose a = pose(Vec3(u(rng), u(rng), u(rng)), 3.0 * u(rng), c + Vec3(u(rng), u(rng), u(rng)));
      // b: a turn of up to a half turn about an axis up to 50 mm off the part, then a small shift.
      const Vec3 pivot = c + 50.0 * Vec3(u(rng), u(rng), u(rng));
      const Eigen::AngleAxisd spin(std::numbers::pi * unit(rng), Vec3(u(rng), u(rng), u(rng)).normalized());
      Pose b = a;
      b.linear() = spin.toRotationMatrix() * a.linear();
      b.translation() = pivot + spin.toRotationMatrix() * (a.translation() - pivot) + Vec3(u(rng), u(rng), u(rng));
      const Aabb box(Vec3(-5, -3, -1) + Vec3(u(rng), u(rng), u(rng)), Vec3(4, 6, 2) + Vec3(u(rng), u(rng), u(rng)));
      double s0 = unit(rng), s1 = unit(rng);
      if (s0 > s1) std::swap(s0, s1);
      const double bound = travel_bound(a, b, box, s0, s1);
      const Pose p0 = interpolate_pose(a, b, s0);
      for (int i = 0; i < 20; ++i) {
        const double s = s0 + (s1 - s0) * unit(rng);
        const Pose ps = interpolate_pose(a, b, s);
        for (int j = 0; j < 9; ++j) {
          const Vec3 p = j < 8 ? box.corner(static_cast<Aabb::CornerType>(j))
                               : Vec3(box.min() + (box.max() - box.min()).cwiseProduct(Vec3(unit(rng), unit(rng), unit(rng))));
          EXPECT_LE((ps * p - p0 * p).norm(), bound) << offset << ' ' << k;
          ++checked;
        }
      }
    }
  EXPECT_GT(checked, 100000);
  // Stretches far shorter than a step a million millimetres out: the motion itself moves the points
  // by less than the computed poses' rounding, which the bound covers too.
  for (int k = 0; k < 2000; ++k) {
    const Vec3 c = 1e6 * Vec3(u(rng), u(rng), u(rng));
    const Pose a = pose(Vec3(u(rng), u(rng), u(rng)), 3.0 * u(rng), c);
    const Pose b = pose(Vec3(u(rng), u(rng), u(rng)), 3.0 * u(rng), c + Vec3(u(rng), u(rng), u(rng)));
    const Aabb box(Vec3(-100, -100, -100), Vec3(100, 100, 100));
    const double s0 = unit(rng), s1 = std::min(1.0, s0 + 1e-15 * unit(rng));
    const double bound = travel_bound(a, b, box, s0, s1);
    const Vec3 p = box.corner(static_cast<Aabb::CornerType>(k % 8));
    EXPECT_LE((interpolate_pose(a, b, s1) * p - interpolate_pose(a, b, s0) * p).norm(), bound) << k;
  }
  // Tight: a translation by (3, 4, 0) travels 5 over the whole motion; a turn by 90 degrees about z
  // moves the corner (4, 4, 0) along an arc of length pi/2 * |corner| = the bound.
  const Aabb box(Vec3(-4, -4, 0), Vec3(4, 4, 0));
  const Pose id = Pose::Identity();
  EXPECT_NEAR(travel_bound(id, pose(Vec3::UnitZ(), 0.0, Vec3(3, 4, 0)), box, 0.0, 1.0), 5.0, 1e-12);
  EXPECT_NEAR(travel_bound(id, pose(Vec3::UnitZ(), std::numbers::pi / 2, Vec3::Zero()), box, 0.25, 0.75),
              0.5 * std::numbers::pi / 2 * std::sqrt(32.0), 1e-12);
}

// The relative bound holds for every pair of points of the two boxes over every stretch: random
// motions of both parts, and the same displacement applied to both (then slightly perturbed), near
// the origin and a million millimetres out; and it is tight where it should be: two parts moved by
// one displacement get the rounding only, a part against a still one its own travel or less.
TEST(Motion, RelativeTravelBoundHolds) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  auto random_pose = [&](const Vec3& c, double spread) {
    return pose(Vec3(u(rng), u(rng), u(rng)), 3.0 * u(rng), c + spread * Vec3(u(rng), u(rng), u(rng)));
  };
  int checked = 0;
  for (double offset : {0.0, 1e3, 1e6})
    for (int k = 0; k < 300; ++k) {
      const Vec3 c(offset * u(rng), offset * u(rng), offset * u(rng));
      const Pose a0 = random_pose(c, 20.0), b0 = random_pose(c, 20.0);
      Pose a1, b1;
      if (k % 3 == 0) {  // independent motions
        a1 = random_pose(c, 20.0);
        b1 = random_pose(c, 20.0);
      } else {  // one displacement (a turn about an axis up to 50 mm off), b's perturbed on every third
        Pose m = Pose::Identity();
        const Vec3 pivot = c + 50.0 * Vec3(u(rng), u(rng), u(rng));
        m.translate(pivot);
        m.rotate(Eigen::AngleAxisd(std::numbers::pi * unit(rng), Vec3(u(rng), u(rng), u(rng)).normalized()));
        m.translate(-pivot + Vec3(u(rng), u(rng), u(rng)));
        a1 = m * a0;
        b1 = m * b0;
        if (k % 3 == 2) b1 = Pose(b1 * pose(Vec3(u(rng), u(rng), u(rng)), 1e-3 * u(rng), 1e-3 * Vec3(u(rng), u(rng), u(rng))));
      }
      const Aabb box_a(Vec3(-5, -3, -1), Vec3(4, 6, 2) + Vec3(unit(rng), unit(rng), unit(rng)));
      const Aabb box_b(Vec3(-2, -2, -2) + Vec3(u(rng), u(rng), u(rng)), Vec3(3, 1, 5));
      double s0 = unit(rng), s1 = unit(rng);
      if (s0 > s1) std::swap(s0, s1);
      const double bound = relative_travel_bound(a0, a1, box_a, b0, b1, box_b, s0, s1);
      if (k % 3 == 1) {
        EXPECT_LT(bound, 1e-9 * (1.0 + offset)) << offset << ' ' << k;
      }
      const Pose pa0 = interpolate_pose(a0, a1, s0), pb0 = interpolate_pose(b0, b1, s0);
      for (int i = 0; i < 10; ++i) {
        const double s = s0 + (s1 - s0) * unit(rng);
        const Pose pa = interpolate_pose(a0, a1, s), pb = interpolate_pose(b0, b1, s);
        for (int j = 0; j < 16; ++j) {
          const Vec3 p = j < 8 ? box_a.corner(static_cast<Aabb::CornerType>(j))
                               : Vec3(box_a.min() + box_a.sizes().cwiseProduct(Vec3(unit(rng), unit(rng), unit(rng))));
          const Vec3 q = j < 8 ? box_b.corner(static_cast<Aabb::CornerType>((j + 3) % 8))
                               : Vec3(box_b.min() + box_b.sizes().cwiseProduct(Vec3(unit(rng), unit(rng), unit(rng))));
          const double now = (pb * q - pa * p).norm(), then = (pb0 * q - pa0 * p).norm();
          EXPECT_LE(std::abs(now - then), bound) << offset << ' ' << k;
          ++checked;
        }
      }
    }
  EXPECT_GT(checked, 100000);
  // A part moving against a still one: no more than its own travel (plus the still side's rounding).
  const Pose id = Pose::Identity(), moved = pose(Vec3::UnitZ(), 0.0, Vec3(3, 4, 0));
  const Aabb box(Vec3(-1, -1, -1), Vec3(1, 1, 1));
  EXPECT_NEAR(relative_travel_bound(id, id, box, id, moved, box, 0.0, 1.0), 5.0, 1e-12);
}

}  // namespace
}  // namespace cadclash
