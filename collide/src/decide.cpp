#include "decide.h"

#include "cadclash/geometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

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

Pose relative_pose(const Pose& pose_a, const Pose& pose_b) {
  Pose t = Pose::Identity();
  const Eigen::Matrix3d ra_t = pose_a.linear().transpose();
  t.linear() = ra_t * pose_b.linear();
  const Vec3 d = pose_b.translation() - pose_a.translation();
  t.translation() = ra_t * d;
  return t;
}

double pair_roundoff(const Pose& pose_a, const Pose& pose_b, double mag_a, double mag_b) {
  // t_ab = relative_pose(pose_a, pose_b) = (R_aᵀR_b, R_aᵀ(t_b - t_a)) in doubles: each rotation entry
  // is a 3-term dot product of unit rows (error <= γ3); each translation component one rounded
  // difference and a 3-term dot product with a unit row, error <= γ4·|t_b - t_a|_1 <= γ4·√3·|t_b -
  // t_a|, which 2·γ6 of the computed difference's norm covers with its own roundings. Where the pair
  // is placed does not enter, only where B lies relative to A: the same verdicts wherever the
  // assembly is moved.
  const double t_err = 2.0 * gamma(6) * (pose_b.translation() - pose_a.translation()).norm();
  const double t_ab = relative_pose(pose_a, pose_b).translation().norm() + t_err;
  // Mapping a vertex v (|v| <= mag_b): R v + t, 3 products and 3 sums per component (γ4 of
  // |v| + |t_ab|), plus the rotation entries' own error times |v|_1 <= √3|v|.
  double comp = gamma(4) * (mag_b + t_ab) + gamma(3) * std::sqrt(3.0) * mag_b + t_err;
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

double effective_uncertainty(const Surface& s, double part_magnitude) {
  return std::max(kMinUncertainty, s.uncertainty > 0.0 ? s.uncertainty : 0x1p-24 * part_magnitude);
}

bool triangles_are_exact(const Model& model, SurfaceId s) {
  const Surface& surf = model.surfaces[s];
  return surf.exact_triangles || (!model.parts[surf.part].source && surf.deflection == 0.0);
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

std::optional<double> hole_gap(const AnalyticSurface& plane, std::span<const SurfaceSource::CircularHole> holes,
                               const TriangleMesh& mesh, const Pose& to_f, const Aabb& region, double reach) {
  if (plane.shape != SurfaceShape::Plane || holes.empty() || mesh.triangles.empty()) return std::nullopt;
  const Vec3 n = plane.axis.normalized();
  // The holes whose cylinder (grown by reach) meets the mesh's box: a pin's triangles are inside one.
  Aabb box;
  for (const Vec3& v : mesh.vertices) box.extend(to_f * v);
  std::vector<const SurfaceSource::CircularHole*> near;
  for (const auto& h : holes) {
    const Vec3 w = box.center() - h.centre;
    if ((w - n.dot(w) * n).norm() <= h.radius + 0.5 * box.diagonal().norm() + reach) near.push_back(&h);
  }
  if (near.empty()) return std::nullopt;
  double gap = reach;
  for (const auto& t : mesh.triangles) {
    const Vec3 v[3] = {to_f * mesh.vertices[t[0]], to_f * mesh.vertices[t[1]], to_f * mesh.vertices[t[2]]};
    Aabb tri;
    for (const Vec3& p : v) tri.extend(p);
    if (box_distance(tri, region) > reach) continue;  // every point of it is farther than reach
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Vec3& p : v) {
      const double h = n.dot(p - plane.origin);
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
    double g = lo > 0.0 ? lo : hi < 0.0 ? -hi : 0.0;  // off the plane
    for (const auto* h : near) {  // inside a hole: the face is at least its radius from the axis
      double rmax = 0.0;
      for (const Vec3& p : v) {
        const Vec3 w = p - h->centre;
        rmax = std::max(rmax, (w - n.dot(w) * n).norm());
      }
      g = std::max(g, h->radius - rmax);
    }
    gap = std::min(gap, g);
    if (gap <= 0.0) break;
  }
  return gap;
}

namespace {

// Bounds of the distance to a cylinder's axis (or a sphere's centre) over the points of another
// surface within the region, then the gap to that surface's radius.
double radial_gap(double radius, double rho_lo, double rho_hi) {
  return std::max({0.0, radius - rho_hi, rho_lo - radius});
}

// Plane `p` against cylinder or sphere `q`: heights of q's points over p's plane.
std::optional<double> plane_against(const AnalyticSurface& p, const AnalyticSurface& q, const Vec3& centre,
                                    double half) {
  const Vec3 n = p.axis.normalized();
  if (q.shape == SurfaceShape::Sphere) return std::max(0.0, std::abs(n.dot(q.origin - p.origin)) - q.radius);
  if (q.shape != SurfaceShape::Cylinder) return std::nullopt;
  // q's points are p0 + s·a + r·w with |w| = 1; over the region |s| <= half + r + |c - p0|.
  const Vec3 a = q.axis.normalized();
  const Vec3 p0 = q.origin + (centre - q.origin).dot(a) * a;
  const double span = half + q.radius + (centre - p0).norm();
  const double h0 = std::abs(n.dot(p0 - p.origin));
  return std::max(0.0, h0 - std::abs(n.dot(a)) * span - q.radius);
}

}  // namespace

std::optional<double> analytic_pair_gap(const AnalyticSurface& a, const AnalyticSurface& b, const Aabb& region) {
  if (region.isEmpty()) return std::nullopt;
  const Vec3 centre = region.center();
  const double half = 0.5 * region.diagonal().norm();
  using S = SurfaceShape;
  if (a.shape == S::Plane && b.shape == S::Plane) {
    // b's points within the region: their heights over a's plane vary by at most sinθ times their
    // distance from the foot of the centre on b's plane.
    const Vec3 n1 = a.axis.normalized(), n2 = b.axis.normalized();
    const double hc2 = n2.dot(centre - b.origin);
    const Vec3 c2 = centre - hc2 * n2;
    const double sin_t = n1.cross(n2).norm();
    return std::max(0.0, std::abs(n1.dot(c2 - a.origin)) - sin_t * (half + std::abs(hc2)));
  }
  if (a.shape == S::Plane) return plane_against(a, b, centre, half);
  if (b.shape == S::Plane) return plane_against(b, a, centre, half);
  if (a.shape == S::Sphere && b.shape == S::Sphere) {
    const double e = (a.origin - b.origin).norm();
    return radial_gap(a.radius, std::abs(e - b.radius), e + b.radius);
  }
  if (a.shape == S::Cylinder && b.shape == S::Cylinder) {
    // b's points p + r2·w (p on b's axis, w ⊥ b's axis): their distance to a's axis lies within
    // [r2·cosθ - E, r2 + E], E bounding p's distance to a's axis over the region.
    const Vec3 a1 = a.axis.normalized(), a2 = b.axis.normalized();
    const Vec3 p0 = b.origin + (centre - b.origin).dot(a2) * a2;
    const Vec3 w0 = p0 - a.origin;
    const double e0 = (w0 - w0.dot(a1) * a1).norm();
    const double sin_t = a1.cross(a2).norm();
    const double cos_t = std::sqrt(std::max(0.0, 1.0 - sin_t * sin_t));
    const double E = e0 + sin_t * (half + b.radius + (centre - p0).norm());
    return radial_gap(a.radius, b.radius * cos_t - E, b.radius + E);
  }
  return std::nullopt;
}

std::vector<std::array<Vec3, 2>> boundary_edges(const TriangleMesh& mesh) {
  std::vector<std::array<std::uint32_t, 3>> edges;  // (lo, hi, count) after merging
  std::vector<std::array<std::uint32_t, 2>> all;
  all.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      all.push_back({std::min(a, b), std::max(a, b)});
    }
  std::sort(all.begin(), all.end());
  std::vector<std::array<Vec3, 2>> out;
  for (std::size_t i = 0; i < all.size();) {
    std::size_t j = i + 1;
    while (j < all.size() && all[j] == all[i]) ++j;
    if (j - i == 1) out.push_back({mesh.vertices[all[i][0]], mesh.vertices[all[i][1]]});
    i = j;
  }
  return out;
}

Outline make_outline(const TriangleMesh& mesh) {
  Outline out;
  out.segments = boundary_edges(mesh);
  std::vector<Aabb> boxes(out.segments.size());
  for (std::size_t k = 0; k < boxes.size(); ++k) boxes[k].extend(out.segments[k][0]).extend(out.segments[k][1]);
  out.tree = build_box_bvh(boxes);
  return out;
}

bool near_outline(const Outline& outline, const Vec3& p, double margin) {
  const SurfaceBvh& tree = outline.tree;
  if (tree.empty() || !(margin >= 0.0)) return false;
  // Both distances are a few roundings of the coordinates' magnitude M off (well within the slack
  // the callers add to their margins); 2^-40 M covers them, so pruning never changes the answer
  // (the nodes' grid boxes, rounded outward, only prune less; squaring rounds far below that).
  const Aabb& root = tree.root;
  const double mag = std::max({p.cwiseAbs().maxCoeff(), root.min().cwiseAbs().maxCoeff(), root.max().cwiseAbs().maxCoeff()});
  const double prune = margin + 0x1p-40 * mag;
  const double prune2 = prune * prune;
  const double m2 = margin * margin;
  auto near_segment = [&](std::uint32_t i) {
    const auto& [a, b] = outline.segments[i];
    return (closest_on_segment(p, a, b) - p).squaredNorm() <= m2;
  };
  if (tree.node_count == 0) {
    for (std::uint32_t i = 0; i < tree.items; ++i)
      if (near_segment(i)) return true;
    return false;
  }
  // Points asked one after another often lie along one stretch of one outline (the crossings of a
  // pin with a plate, round the hole): the segments next to the last one found near, in outline
  // order (mostly along the boundary), are tried first. Any near segment gives the answer; a hint
  // that misses (or is stale: only its index is kept) costs five tests.
  thread_local const Outline* hint_outline = nullptr;
  thread_local std::uint32_t hint_segment = 0;
  const auto n = static_cast<std::uint32_t>(outline.segments.size());
  if (hint_outline == &outline && hint_segment < n) {
    const std::uint32_t lo = hint_segment >= 2 ? hint_segment - 2 : 0, hi = std::min(n, hint_segment + 3);
    for (std::uint32_t i = lo; i < hi; ++i)
      if (near_segment(i)) {
        hint_segment = i;
        return true;
      }
  }
  auto found = [&](std::uint32_t i) {
    hint_outline = &outline;
    hint_segment = i;
    return true;
  };
  // Nearer child first: most points asked lie by the outline (a foot on a face's edge), and the
  // first near segment answers; any order gives the same answer.
  std::uint32_t stack[64];
  int top = 0;
  if (tree.node_box(tree.nodes[0]).squaredExteriorDistance(p) > prune2) return false;
  stack[top++] = 0;
  while (top > 0) {
    const SurfaceBvh::Node& node = tree.nodes[stack[--top]];
    if (const std::uint32_t count = node.count(); count > 0) {
      for (std::uint32_t i = node.first(); i < node.first() + count; ++i)
        if (near_segment(tree.item(i))) return found(tree.item(i));
      continue;
    }
    const double dl = tree.node_box(tree.nodes[node.first()]).squaredExteriorDistance(p);
    const double dr = tree.node_box(tree.nodes[node.first() + 1]).squaredExteriorDistance(p);
    const bool left_nearer = dl <= dr;
    const double d_far = left_nearer ? dr : dl, d_near = left_nearer ? dl : dr;
    if (d_far <= prune2) stack[top++] = left_nearer ? node.first() + 1 : node.first();
    if (d_near <= prune2) stack[top++] = left_nearer ? node.first() : node.first() + 1;
  }
  return false;
}

namespace {

// The foot of p on the full surface (nullopt where it is not unique: on an axis or at a centre).
std::optional<Vec3> foot_point(const AnalyticSurface& an, const Vec3& p) {
  const Vec3 axis = an.axis.normalized();
  switch (an.shape) {
    case SurfaceShape::Plane: return p - axis.dot(p - an.origin) * axis;
    case SurfaceShape::Cylinder: {
      const Vec3 w = p - an.origin;
      const Vec3 on_axis = an.origin + w.dot(axis) * axis;
      const Vec3 radial = p - on_axis;
      if (!(radial.norm() > 0.0)) return std::nullopt;
      return on_axis + an.radius * radial.normalized();
    }
    case SurfaceShape::Sphere: {
      const Vec3 radial = p - an.origin;
      if (!(radial.norm() > 0.0)) return std::nullopt;
      return an.origin + an.radius * radial.normalized();
    }
    default: return std::nullopt;
  }
}

}  // namespace

// Candidates tried per side, nearest to the surface first: on as1 and the board no pair needed more
// than the second, and each costs two tree queries; the witness steps take the rest.
constexpr std::size_t kMaxAnalyticTrials = 4;

std::optional<double> analytic_witness(const AnalyticSurface& an_b, const TriangleMesh& mesh_b,
                                       const SurfaceBvh& bvh_b, const Outline& outline_b,
                                       double delta_b,
                                       const TriangleMesh& mesh_a, const Pose& to_b, const Aabb& region,
                                       double limit, double slack) {
  if (an_b.shape != SurfaceShape::Plane && an_b.shape != SurfaceShape::Cylinder &&
      an_b.shape != SurfaceShape::Sphere)
    return std::nullopt;
  struct Candidate {
    double g;
    Vec3 foot;
  };
  if (region.isEmpty()) return std::nullopt;
  // The nearest kMaxAnalyticTrials, in vertex order among equals (a stable sort's first ones). A
  // vertex is mapped only when it lies in the region taken back to A's frame, padded far beyond the
  // rounding of either mapping: those outside map outside `region` too.
  const Aabb region_a = pad_box(transform_box(region, to_b.inverse()),
                                kRelativePad * (box_magnitude(region) + to_b.translation().cwiseAbs().maxCoeff()));
  std::array<Candidate, kMaxAnalyticTrials> best;
  std::size_t kept = 0;
  for (const Vec3& va : mesh_a.vertices) {
    if (!region_a.contains(va)) continue;
    const Vec3 v = to_b * va;
    if (!region.contains(v)) continue;
    const std::optional<Vec3> f = foot_point(an_b, v);
    if (!f) continue;
    const double g = (v - *f).norm();
    if (!(g <= limit) || (kept == best.size() && !(g < best[kept - 1].g))) continue;
    std::size_t i = kept < best.size() ? kept++ : kept - 1;
    for (; i > 0 && g < best[i - 1].g; --i) best[i] = best[i - 1];
    best[i] = {g, *f};
  }
  for (std::size_t k = 0; k < kept; ++k) {
    const Candidate& c = best[k];
    // Both must hold; the outline (a few segment tests when the last answer's neighbours hold) first.
    if (near_outline(outline_b, c.foot, 2.0 * delta_b + slack)) continue;
    if (point_near_mesh(bvh_b, mesh_b, c.foot, delta_b + slack)) return c.g;
  }
  return std::nullopt;
}

}  // namespace cadclash::detail
