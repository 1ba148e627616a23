// Motion between two poses of a path (trajectory.h, "Motion between steps"): the interpolated pose
// and a bound on how far a part's points travel over a stretch of it.
#include "cadclash/trajectory.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace cadclash {
namespace {

constexpr double kUnit = std::numeric_limits<double>::epsilon() / 2.0;  // 2^-53

Eigen::Quaterniond rotation_of(const Pose& p) { return Eigen::Quaterniond(p.linear()).normalized(); }

// The rotation from a to b as an angle and a unit axis (in a's frame): r = q_a^-1 q_b with w >= 0,
// half the angle atan2(|v|, w) and the axis v / |v|, both accurate to a few ulps whatever the angle
// (acos(w), as a textbook slerp takes it, loses half the digits of a small angle).
struct Turn {
  double angle = 0.0;
  Vec3 axis = Vec3::UnitX();
};
Turn turn(const Eigen::Quaterniond& qa, const Eigen::Quaterniond& qb) {
  Eigen::Quaterniond r = qa.conjugate() * qb;
  if (r.w() < 0.0) r.coeffs() = -r.coeffs();
  const double v = r.vec().norm();
  Turn t;
  t.angle = 2.0 * std::atan2(v, r.w());
  if (v > 0.0) t.axis = r.vec() / v;
  return t;
}

}  // namespace

Pose interpolate_pose(const Pose& a, const Pose& b, double s) {
  assert(s >= 0.0 && s <= 1.0);
  const Eigen::Quaterniond qa = rotation_of(a);
  const Turn t = turn(qa, rotation_of(b));
  const Eigen::Quaterniond step(Eigen::AngleAxisd(s * t.angle, t.axis));  // constant angular speed
  Pose out = Pose::Identity();
  out.linear() = (qa * step).normalized().toRotationMatrix();
  // Exact at both ends: (1 - s) t_a + s t_b is t_a at s = 0 and t_b at s = 1.
  out.translation() = (1.0 - s) * a.translation() + s * b.translation();
  return out;
}

double motion_angle(const Pose& a, const Pose& b) { return turn(rotation_of(a), rotation_of(b)).angle; }

double travel_bound(const Pose& a, const Pose& b, const Aabb& box, double s0, double s1) {
  assert(s0 >= 0.0 && s0 <= s1 && s1 <= 1.0 && !box.isEmpty());
  double reach = 0.0;  // the largest |p| over the box: at a corner
  for (int k = 0; k < 8; ++k) reach = std::max(reach, box.corner(static_cast<Aabb::CornerType>(k)).norm());
  const double shift = (b.translation() - a.translation()).norm();
  // The angle within a few ulps, and an absolute 1e-15 for the quaternions' own rounding.
  const double angle = motion_angle(a, b) * (1.0 + 16.0 * kUnit) + 64.0 * kUnit;
  const double speed = shift + angle * reach;
  // What the computed poses may be off the exact motion (their quaternions and rotation matrices,
  // the blend of the translations): far above it, for both ends.
  const double t = std::max(a.translation().norm(), b.translation().norm());
  const double poses = 2.0 * 64.0 * kUnit * (reach + t);
  return (s1 - s0) * speed * (1.0 + 16.0 * kUnit) + poses;
}

}  // namespace cadclash
