// The screw of a rigid displacement and the distance bound its invariants give (screw.h).
#include "screw.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace cadclash::detail {

Turn turn(const Eigen::Quaterniond& qa, const Eigen::Quaterniond& qb) {
  Eigen::Quaterniond r = qa.conjugate() * qb;
  if (r.w() < 0.0) r.coeffs() = -r.coeffs();
  const double v = r.vec().norm();
  Turn t;
  t.angle = 2.0 * std::atan2(v, r.w());
  if (v > 0.0) t.axis = r.vec() / v;
  return t;
}

Screw screw_of(const Pose& a, const Pose& b) {
  Screw w;
  w.qa = rotation_of(a);
  w.local = turn(w.qa, rotation_of(b));
  w.axis = w.qa * w.local.axis;
  const double angle = w.local.angle;
  // M = b a^-1: its rotation turns by angle about axis, its translation is t = t_b - R t_a.
  const Vec3 t = b.translation() - Eigen::AngleAxisd(angle, w.axis) * a.translation();
  w.along = w.axis.dot(t);
  w.across = t - w.along * w.axis;
  // The axis point c (across the axis) solves (I - R) c = across: c = across / 2 + cot(angle / 2)
  // axis x across / 2; angle * c, with g = angle cot(angle / 2) (2 at angle 0).
  const double half = 0.5 * angle;
  const double g = half == 0.0 ? 2.0 : angle * std::cos(half) / std::sin(half);
  const Vec3 ta = a.translation() - w.axis.dot(a.translation()) * w.axis;
  w.drift = angle * ta - 0.5 * angle * w.across - 0.5 * g * w.axis.cross(w.across);
  return w;
}

namespace {

constexpr double kUnit = std::numeric_limits<double>::epsilon() / 2.0;  // 2^-53
// Below this angle the screw's axis lies far off and is computed from a small rotation's few
// digits: its distance from the axis is not used (its shift along the axis still is).
constexpr double kLeastTurn = 1e-3;

struct Range {
  double lo = 0.0, hi = 0.0;
};

// The gap between two ranges (0 when they meet).
double gap(const Range& x, const Range& y) { return std::max({0.0, y.lo - x.hi, x.lo - y.hi}); }

// The line the distances from an axis are measured from: through `point`, along unit `u`; `pad`
// covers how far the computed line may be off the true one near the origin, `tilt` how far its
// direction may be off (per unit of distance from `point`).
struct Line {
  Vec3 point = Vec3::Zero(), u = Vec3::UnitZ();
  double pad = 0.0, tilt = 0.0;
  double rho(const Vec3& x) const {
    const Vec3 v = x - point;
    return (v - u.dot(v) * u).norm();
  }
  // How far rho(x), computed, may be off the distance of x from the true line.
  double error(const Vec3& x) const { return pad + (tilt + 16.0 * kUnit) * ((x - point).norm() + 1.0); }
};

// The coordinate along u of the box (part-local) placed by `pose`.
Range along(const Aabb& box, const Pose& pose, const Vec3& u, double tilt) {
  const Vec3 c = pose * box.center();
  const Vec3 h = 0.5 * box.sizes();
  const double mid = u.dot(c), half = (pose.linear().transpose() * u).cwiseAbs().dot(h);
  const double pad = (tilt + 64.0 * kUnit) * (c.norm() + h.norm() + 1.0);
  return {mid - half - pad, mid + half + pad};
}

// The least distance from `line` of the placed box's points: across the line the box is the zonotope
// y0 + sum t_i g_i (|t_i| <= 1) in the plane normal to it, and for any unit n of that plane
// n.y0 - sum |n.g_i| is at most its distance from the line (the least of n.y over the zonotope).
// The distance itself is that at the normal of an edge (a g_i turned a quarter) or at the direction
// of a corner, whichever is nearest: the largest over those candidates is exact.
double least_from_axis(const Aabb& box, const Pose& pose, const Line& line) {
  const Vec3 e1 = line.u.unitOrthogonal(), e2 = line.u.cross(e1);
  const Vec3 c = pose * box.center(), h = 0.5 * box.sizes();
  const Eigen::Vector2d y0(e1.dot(c - line.point), e2.dot(c - line.point));
  Eigen::Vector2d g[3];
  double spread = 0.0;
  for (int i = 0; i < 3; ++i) {
    const Vec3 col = h[i] * pose.linear().col(i);
    g[i] = Eigen::Vector2d(e1.dot(col), e2.dot(col));
    spread += g[i].norm();
  }
  auto below = [&](const Eigen::Vector2d& n) {
    return n.dot(y0) - std::abs(n.dot(g[0])) - std::abs(n.dot(g[1])) - std::abs(n.dot(g[2]));
  };
  double best = 0.0;
  auto try_direction = [&](const Eigen::Vector2d& v) {
    if (const double n = v.norm(); n > 0.0) best = std::max(best, below(v / n));
  };
  for (const Eigen::Vector2d& gi : g) try_direction(Eigen::Vector2d(-gi.y(), gi.x())), try_direction(Eigen::Vector2d(gi.y(), -gi.x()));
  for (int k = 0; k < 8; ++k)
    try_direction(y0 + (k & 1 ? 1.0 : -1.0) * g[0] + (k & 2 ? 1.0 : -1.0) * g[1] + (k & 4 ? 1.0 : -1.0) * g[2]);
  // The line's own error over the box, and the rounding of the placed centre, the projections and
  // the sums (a few ulps of their magnitudes).
  const double round = 64.0 * kUnit * (c.norm() + line.point.norm() + y0.norm() + spread + h.norm() + 1.0);
  return std::max(0.0, best - line.error(c) - (line.tilt + 16.0 * kUnit) * h.norm() - round);
}

// The distance from `line` of the points of the box (part-local) placed by `pose`: its largest at a
// corner (convex), its least least_from_axis.
Range from_axis(const Aabb& box, const Pose& pose, const Line& line) {
  Range r{least_from_axis(box, pose, line), 0.0};
  for (int k = 0; k < 8; ++k) {
    const Vec3 x = pose * box.corner(static_cast<Aabb::CornerType>(k));
    r.hi = std::max(r.hi, line.rho(x) + line.error(x));
  }
  return r;
}

// The same from the face's exact surface when it turns about its own axis (a cylinder, cone or
// torus): a point x = f + v with f on the surface's axis and v across it, |v| in [m_lo, m_hi], is
// within [m_lo cos(a) - rho(f), m_hi + rho(f)] of the line (a: the angle between the two axes),
// rho(f) largest at an end of the axis segment the face spans.
std::optional<Range> exact_from_axis(const Surface& s, const Aabb& box, const Pose& pose, const Line& line) {
  const AnalyticSurface& f = s.analytic;
  if (f.shape != SurfaceShape::Cylinder && f.shape != SurfaceShape::Cone && f.shape != SurfaceShape::Torus) return std::nullopt;
  const Vec3 a = f.axis.normalized();
  // The face's extent along its axis, from the origin: the box's.
  const double hc = a.dot(box.center() - f.origin), hh = a.cwiseAbs().dot(0.5 * box.sizes());
  double h0 = hc - hh, h1 = hc + hh, m_lo = 0.0, m_hi = 0.0;
  switch (f.shape) {
    case SurfaceShape::Cylinder:
      m_lo = m_hi = f.radius;
      break;
    case SurfaceShape::Cone: {
      const double slope = std::tan(f.radius2);
      const double least = h0 <= 0.0 && h1 >= 0.0 ? 0.0 : std::min(std::abs(h0), std::abs(h1));
      m_lo = least * slope;
      m_hi = std::max(std::abs(h0), std::abs(h1)) * slope;
      break;
    }
    default:  // torus: the tube's centre circle, then the tube
      m_lo = std::max(0.0, f.radius - f.radius2);
      m_hi = f.radius + f.radius2;
      h0 = -f.radius2;
      h1 = f.radius2;
      break;
  }
  const Vec3 e0 = pose * (f.origin + h0 * a), e1 = pose * (f.origin + h1 * a);
  const double off = std::max(line.rho(e0) + line.error(e0), line.rho(e1) + line.error(e1));
  const double cos_a = std::min(1.0, std::abs(line.u.dot(pose.linear() * a)));
  // The face's points may lie off its exact surface by its tolerance; the products' rounding.
  const double tol = (s.tolerance > 0.0 ? s.tolerance : s.uncertainty) +
                     64.0 * kUnit * (m_hi + std::abs(h0) + std::abs(h1) + f.origin.norm() + 1.0);
  return Range{std::max(0.0, m_lo * cos_a * (1.0 - 4.0 * kUnit) - off - tol), m_hi + off + tol};
}

Range surface_from_axis(const Surface& s, const Aabb& box, const Pose& pose, const Line& line) {
  Range r = from_axis(box, pose, line);
  if (const std::optional<Range> e = exact_from_axis(s, box, pose, line)) r = {std::max(r.lo, e->lo), std::min(r.hi, e->hi)};
  return r;
}

Aabb box_of(const Surface& s) { return s.aabb.isEmpty() ? mesh_aabb(s.mesh) : s.aabb; }

// The axis of a cylinder, cone or torus face placed by `pose`, when it runs along u.
std::optional<Vec3> axis_point_along(const Surface& s, const Pose& pose, const Vec3& u) {
  const AnalyticSurface& f = s.analytic;
  if (f.shape != SurfaceShape::Cylinder && f.shape != SurfaceShape::Cone && f.shape != SurfaceShape::Torus) return std::nullopt;
  if ((pose.linear() * f.axis.normalized()).cross(u).norm() > 1e-9) return std::nullopt;
  return pose * f.origin;
}

}  // namespace

ScrewKeep screw_keep(const Model& model, SurfaceId moving, const Pose& from, const Screw& w, SurfaceId still,
                     const Pose& still_pose) {
  ScrewKeep keep;
  const Surface& sm = model.surfaces[moving];
  const Surface& ss = model.surfaces[still];
  const Aabb bm = box_of(sm), bs = box_of(ss);
  if (bm.isEmpty() || bs.isEmpty()) return keep;
  const double angle = w.local.angle;
  // The direction the points shift along, and how far (per unit of s): the screw's axis, or for a
  // pure shift its own direction.
  Vec3 u = w.axis;
  double d = w.along;
  const double reach = from.translation().norm() + w.across.norm() + std::abs(w.along);
  std::optional<Line> line;
  if (angle == 0.0) {
    const Vec3 t = w.across + w.along * w.axis;  // the shift t_b - t_a
    const double n = t.norm();
    if (!(n > 0.0)) return keep;
    u = t / n;
    d = n;
    // Any line along the shift keeps every point's distance: the still face's axis, else the moving one's.
    std::optional<Vec3> p = axis_point_along(ss, still_pose, u);
    if (!p) p = axis_point_along(sm, from, u);
    if (p) line = Line{*p, u, 64.0 * kUnit * (n + reach), 16.0 * kUnit};
  } else if (angle >= kLeastTurn && angle <= M_PI) {
    // The axis point c = across / 2 + cot(angle / 2) axis x across / 2, off by the rounding of
    // across and of the angle (whose cotangent's error grows as 1 / sin^2(angle / 2)).
    const double half = 0.5 * angle, cot = std::cos(half) / std::sin(half);
    const Vec3 c = 0.5 * w.across + (0.5 * cot) * w.axis.cross(w.across);
    const double pad = 256.0 * kUnit * (reach * (1.0 + cot) + w.across.norm() / (std::sin(half) * std::sin(half)));
    line = Line{c, u, pad, 256.0 * kUnit};
  } else {
    return keep;  // a turn too small to place its axis
  }
  const double tilt = 256.0 * kUnit;
  const Range zm = along(bm, from, u, tilt), zs = along(bs, still_pose, u, tilt);
  keep.moving_lo = zm.lo;
  keep.moving_hi = zm.hi;
  keep.still_lo = zs.lo;
  keep.still_hi = zs.hi;
  keep.shift = d;
  keep.shift_pad = 64.0 * kUnit * (std::abs(d) + reach);
  keep.radial_gap = line ? gap(surface_from_axis(sm, bm, from, *line), surface_from_axis(ss, bs, still_pose, *line)) : 0.0;
  keep.known = true;
  return keep;
}

double screw_gap(const ScrewKeep& keep, double s0, double s1) {
  if (!keep.known) return 0.0;
  // Along the axis: the moving face's range at s = 0 shifted by s d over [s0, s1].
  const double d = keep.shift;
  const Range zm{keep.moving_lo + std::min(s0 * d, s1 * d) - keep.shift_pad, keep.moving_hi + std::max(s0 * d, s1 * d) + keep.shift_pad};
  const double gz = gap(zm, Range{keep.still_lo, keep.still_hi});
  return std::sqrt(gz * gz + keep.radial_gap * keep.radial_gap) * (1.0 - 8.0 * kUnit);
}

double screw_gap(const Model& model, SurfaceId moving, const Pose& from, const Screw& w, SurfaceId still,
                 const Pose& still_pose, double s0, double s1) {
  return screw_gap(screw_keep(model, moving, from, w, still, still_pose), s0, s1);
}

}  // namespace cadclash::detail
