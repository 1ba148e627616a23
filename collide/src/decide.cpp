#include "decide.h"

#include "box_util.h"
#include "triangle_predicates.h"

#include <algorithm>
#include <cmath>

namespace cadclash::detail {
namespace {

constexpr double kUnit = 0x1p-53;  // unit round-off of double

// γ_n = n·u / (1 - n·u): the relative error bound of n successive roundings (Higham, §3.1).
constexpr double gamma(int n) { return n * kUnit / (1.0 - n * kUnit); }

// Largest entry of R^T·R - I: how far a stored rotation is from orthonormal, so R^T is not exactly
// its inverse. Computed, not assumed: a pose from a quaternion or a STEP placement is a few ulps off.
double orthonormal_defect(const Pose& p) {
  const Eigen::Matrix3d r = p.linear();
  const Eigen::Matrix3d e = r.transpose() * r - Eigen::Matrix3d::Identity();
  // The product above is itself rounded (3 products and 2 sums per entry of magnitude <= 1).
  return e.cwiseAbs().maxCoeff() + gamma(3);
}

}  // namespace

double pair_roundoff(const Pose& pose_a, const Pose& pose_b, double mag_a, double mag_b) {
  const double ta = pose_a.translation().norm(), tb = pose_b.translation().norm();
  // t_ab = pose_a⁻¹·pose_b = (R_aᵀR_b, R_aᵀ(t_b - t_a)) in doubles: each rotation entry is a 3-term
  // dot product of unit rows (error <= γ3), the translation two 3-term products and a sum
  // (error <= γ5·(|t_a| + |t_b|) per component).
  const double t_ab = (pose_a.inverse(Eigen::Isometry) * pose_b).translation().norm() + gamma(5) * (ta + tb);
  // Mapping a vertex v (|v| <= mag_b): R v + t, 3 products and 3 sums per component (γ4 of
  // |v| + |t_ab|), plus the rotation entries' own error times |v|_1 <= √3|v|.
  double comp = gamma(4) * (mag_b + t_ab) + gamma(3) * std::sqrt(3.0) * mag_b + gamma(5) * (ta + tb);
  // R_aᵀ stands for R_a⁻¹: off by the defect, applied to B's points near A (within mag_a + mag_b of
  // A's origin wherever the faces can be close); likewise R_b's defect on |v|.
  comp += orthonormal_defect(pose_a) * (mag_a + mag_b) + orthonormal_defect(pose_b) * mag_b;
  const double map = std::sqrt(3.0) * comp;
  // Vertices of either side are evaluated on their surfaces by the mesher with a few roundings
  // (γ8 of their magnitude), and triangle_distance is within 64·2^-53 of the pair's extent
  // (triangle_predicates.h), the extent being at most twice the largest coordinate in A's frame.
  const double frame = std::max(mag_a, mag_b + t_ab);
  return map + gamma(8) * (mag_a + mag_b) + 128.0 * kUnit * frame;
}

double touch_threshold(const Surface& a, const Surface& b, double tolerance) {
  return tolerance + a.uncertainty + b.uncertainty;
}

double certified_reach(const Surface& a, const Surface& b, double tolerance, double roundoff) {
  return touch_threshold(a, b, tolerance) + a.deflection + b.deflection + roundoff;
}

Interval mesh_interval(const PairOutcome& o, double band, double reach) {
  if (o.intersecting) return {0.0, band};
  if (!std::isfinite(o.distance)) return {reach, std::numeric_limits<double>::infinity()};
  return {std::max(0.0, o.distance - band), o.distance + band};
}

Verdict verdict(const Interval& d, double threshold) {
  if (d.hi <= threshold) return Verdict::Contact;
  if (d.lo > threshold) return Verdict::Apart;
  return Verdict::Ambiguous;
}

bool certainly_penetrating(const PairOutcome& o, double threshold, double band) {
  return o.intersecting && o.penetration > threshold + band;
}

AnalyticSurface transform_analytic(const AnalyticSurface& an, const Pose& t) {
  AnalyticSurface out = an;
  out.origin = t * an.origin;
  out.axis = (t.linear() * an.axis).normalized();
  return out;
}

std::optional<double> analytic_gap(const AnalyticSurface& an, const TriangleMesh& mesh, const Pose& to_f,
                                   const Aabb& region, double reach) {
  if (an.shape != SurfaceShape::Plane && an.shape != SurfaceShape::Cylinder && an.shape != SurfaceShape::Sphere)
    return std::nullopt;
  const Vec3 axis = an.axis.normalized();
  double gap = reach;
  for (const auto& t : mesh.triangles) {
    const Vec3 v[3] = {to_f * mesh.vertices[t[0]], to_f * mesh.vertices[t[1]], to_f * mesh.vertices[t[2]]};
    Aabb box;
    for (const Vec3& p : v) box.extend(p);
    if (box_distance(box, region) > reach) continue;  // every point of it is farther than reach
    double g = 0.0;
    switch (an.shape) {
      case SurfaceShape::Plane: {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const Vec3& p : v) {
          const double h = axis.dot(p - an.origin);
          lo = std::min(lo, h);
          hi = std::max(hi, h);
        }
        g = lo > 0.0 ? lo : hi < 0.0 ? -hi : 0.0;
        break;
      }
      case SurfaceShape::Cylinder: {
        double rmax = 0.0, smin = std::numeric_limits<double>::infinity(), smax = -smin;
        for (const Vec3& p : v) {
          const Vec3 w = p - an.origin;
          const double s = w.dot(axis);
          smin = std::min(smin, s);
          smax = std::max(smax, s);
          rmax = std::max(rmax, (w - s * axis).norm());
        }
        if (rmax < an.radius) {
          g = an.radius - rmax;
        } else {
          // The axis's nearest points to the triangle project within [smin, smax]: a segment a
          // little longer than that measures the distance to the whole line.
          const Vec3 p0 = an.origin + (smin - 1.0) * axis, p1 = an.origin + (smax + 1.0) * axis;
          const double rmin = triangle_distance(v[0], v[1], v[2], p0, p1, p1);
          g = std::max(0.0, rmin - an.radius);
        }
        break;
      }
      case SurfaceShape::Sphere: {
        double rmax = 0.0;
        for (const Vec3& p : v) rmax = std::max(rmax, (p - an.origin).norm());
        if (rmax < an.radius) {
          g = an.radius - rmax;
        } else {
          const double rmin = triangle_distance(v[0], v[1], v[2], an.origin, an.origin, an.origin);
          g = std::max(0.0, rmin - an.radius);
        }
        break;
      }
      default: return std::nullopt;
    }
    gap = std::min(gap, g);
    if (gap <= 0.0) break;
  }
  return gap;
}

}  // namespace cadclash::detail
