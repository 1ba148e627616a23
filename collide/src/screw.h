// The screw of a rigid displacement (trajectory.h, "Motion between steps") and what stays the same
// along it: the bound check_motion uses to clear a pair of surfaces for a whole stretch of a turn
// when the turn cannot bring them closer. Internal to cadclash::collide.
#pragma once

#include "cadclash/model.h"

namespace cadclash::detail {

inline Eigen::Quaterniond rotation_of(const Pose& p) { return Eigen::Quaterniond(p.linear()).normalized(); }

// The rotation from a to b as an angle and a unit axis (in a's frame): r = q_a^-1 q_b with w >= 0,
// half the angle atan2(|v|, w) and the axis v / |v|, both accurate to a few ulps whatever the angle
// (acos(w), as a textbook slerp takes it, loses half the digits of a small angle).
struct Turn {
  double angle = 0.0;
  Vec3 axis = Vec3::UnitX();
};
Turn turn(const Eigen::Quaterniond& qa, const Eigen::Quaterniond& qb);

// The screw of the displacement from a to b (Chasles): b = M a with M the turn by `angle` about a
// world line along `axis`, then the shift `along` along it. Computed once from a and b, and used as
// it is by interpolate_pose and travel_bound, so that the bound is about the motion the poses follow.
// `drift` is the velocity (per unit of s) of the point of a's origin across the axis at s = 0,
// angle * (P t_a - c) for the axis through c (P: across the axis); it stays finite as the angle
// goes to 0 (the axis then lies far off and the motion becomes the shift t_b - t_a).
struct Screw {
  Eigen::Quaterniond qa;
  Turn local;          // the turn in a's frame (slerp's)
  Vec3 axis;           // the same axis in the world: q_a * local.axis
  double along = 0.0;  // d: M's shift along the axis
  Vec3 drift = Vec3::Zero();
  Vec3 across = Vec3::Zero();  // M's translation across the axis: (I - R) c for the axis through c
};
Screw screw_of(const Pose& a, const Pose& b);

// A lower bound on the distance between surface `moving` of a part placed at `from` and moved by the
// screw `w` (from its s = 0) and surface `still` of a part that stays at `still_pose`, over every s
// in [s0, s1]: along the screw a point's coordinate on the axis shifts by s d and its distance from
// the axis line stays (|x - y|^2 >= dz^2 + (rho_x - rho_y)^2 in cylindrical coordinates about it),
// so two surfaces whose ranges of those are apart stay apart however far the turn carries them.
// The ranges come from the surfaces' boxes (which enclose the exact faces) and, for a cylinder,
// cone or torus about the axis, from their exact surfaces (AnalyticSurface, widened by the faces'
// own tolerance). The distance from the axis is used only for a turn of at least 1e-3 radians about
// a well-placed axis, or a pure shift (any line along it then: the still surface's axis, else the
// moving one's). Computed with its rounding; 0 when nothing is known. Precondition: s0 <= s1.
double screw_gap(const Model& model, SurfaceId moving, const Pose& from, const Screw& w, SurfaceId still,
                 const Pose& still_pose, double s0, double s1);

// screw_gap in two steps, for many stretches of one motion: what does not depend on the stretch,
// then the bound over [s0, s1] from it (a few operations).
struct ScrewKeep {
  double moving_lo = 0.0, moving_hi = 0.0;  // the moving face's coordinate along the axis at s = 0
  double still_lo = 0.0, still_hi = 0.0;    // the still face's
  double shift = 0.0, shift_pad = 0.0;      // per unit of s, and its rounding
  double radial_gap = 0.0;                  // between their distances from the axis
  bool known = false;                       // false: nothing is known (screw_gap 0)
};
ScrewKeep screw_keep(const Model& model, SurfaceId moving, const Pose& from, const Screw& w, SurfaceId still,
                     const Pose& still_pose);
double screw_gap(const ScrewKeep& keep, double s0, double s1);

}  // namespace cadclash::detail
