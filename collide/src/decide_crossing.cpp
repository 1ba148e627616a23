// Steps 2c and 2d of the certified decision (decide_steps.h): contacts with a face's plane that no
// vertex witnesses. A part sunk into a flat face or pressed through it has faces whose vertices all
// lie a crossing depth away from the flat face; a point of the crossing proves the contact. A
// cylinder, cone or sphere tangent to a flat face touches it along a line or at a point where no
// vertex need lie; its support point toward the plane proves it.
#include "decide_steps.h"

#include "cadclash/geometry.h"

#include <algorithm>
#include <cmath>

namespace cadclash::detail {
namespace {

// At most this many crossing points are tried per side; Newton ones cost a few point queries each.
constexpr std::size_t kMaxPlanarTrials = 8;
constexpr std::size_t kMaxNewtonTrials = 4;
constexpr std::size_t kMaxClassifierTrials = 2;
constexpr std::size_t kMaxCrossingStarts = 32;  // crossings of a curved face whose foot is tried
constexpr std::size_t kMaxEdgeTrials = 4;  // outline vertices (each shared by two segments: two points)
constexpr int kMaxNewtonSteps = 6;
// cos 0.5°: triangles closer to parallel than this do not start a crossing.
constexpr double kParallel = 0.99996;

// The midpoints of the segments where the triangles of `mesh` inside `region` cross the plane
// (unit normal n through o), in triangle order: each is a point of a triangle on the plane.
std::vector<Vec3> plane_crossings(const TriangleMesh& mesh, const Vec3& n, const Vec3& o, const Aabb& region) {
  std::vector<Vec3> out;
  for (const auto& tri : mesh.triangles) {
    const Vec3* const v[3] = {&mesh.vertices[tri[0]], &mesh.vertices[tri[1]], &mesh.vertices[tri[2]]};
    Aabb box;
    for (const Vec3* p : v) box.extend(*p);
    if (!box.intersects(region)) continue;
    double h[3];
    for (int k = 0; k < 3; ++k) h[k] = n.dot(*v[k] - o);
    const auto ends = plane_cut(v, h);
    if (!ends) continue;
    // A triangle (nearly) parallel to the plane crosses it by round-off or by its chord's sag: faces
    // lying on the plane or tangent to it, which the witness steps prove; no crossing curve to follow.
    const Vec3 normal = (*v[1] - *v[0]).cross(*v[2] - *v[0]);
    if (!(std::abs(normal.dot(n)) < kParallel * normal.norm())) continue;
    out.push_back(0.5 * ((*ends)[0] + (*ends)[1]));
  }
  return out;
}

// One side: P's face lies on a plane, Q's face crosses it. `to_q` maps P's frame into Q's,
// `to_p` back. Returns the bound on d* it proved (<= T), or nothing.
struct Proof {
  double hi;
  DecidedBy by;
};

std::optional<Proof> cross_plane(const Part&, SurfaceId, const Part& part_q, SurfaceId sq, FaceView fp, FaceView fq,
                                 double slack_q, const Pose& to_q, const Pose& to_p, double r, double threshold,
                                 CollideCounters& c) {
  const Surface& P = fp.surface;
  const Surface& Q = fq.surface;
  const AnalyticSurface plane = transform_analytic(P.analytic, to_q);
  const Vec3 n = plane.axis.normalized();
  const Aabb region =
      pad_box(Q.aabb.isEmpty() ? mesh_aabb(Q.mesh) : Q.aabb, Q.deflection)
          .intersection(pad_box(transform_box(P.aabb.isEmpty() ? mesh_aabb(P.mesh) : P.aabb, to_q), threshold));
  if (region.isEmpty()) return std::nullopt;
  const std::vector<Vec3> xs = plane_crossings(Q.mesh, n, plane.origin, region);
  // The plane's foot of a point of Q, inside P's face: then |height| bounds the point's distance to it.
  auto on_p = [&](const Vec3& y, double h) { return inside_face(fp, to_p * (y - h * n), r); };
  const double headroom = threshold - slack_q - r;
  if (!(headroom > 0.0)) return std::nullopt;
  const std::uint32_t local = part_q.source ? sq - part_q.first_surface : 0;
  // A point y of Q's surface (within `rounding`) whose foot on P's plane is inside P: its distance to
  // face Q is 0 when Q's triangles put it inside, else what Q's exact classifier measures (a point
  // near Q's boundary, as where a sunk part's side meets its seat: one query).
  std::size_t asked = 0;
  auto bound = [&](const Vec3& y, double h, double rounding, bool on_triangles) -> std::optional<double> {
    if (!(std::abs(h) + rounding <= headroom) || !on_p(y, h)) return std::nullopt;
    if (inside_face(fq, y, rounding + r, on_triangles)) return slack_q + std::abs(h) + rounding + r;
    if (!part_q.source || ++asked > kMaxClassifierTrials) return std::nullopt;
    ++c.witness_queries;
    const std::optional<double> d = part_q.source->point_distance(local, y);
    if (!d) return std::nullopt;
    return slack_q + *d + std::abs(h) + rounding + r;
  };
  // A planar face's triangles lie on its plane: a crossing point is a point of that face's surface.
  if (Q.analytic.shape == SurfaceShape::Plane || Q.exact_triangles) {
    std::size_t trials = 0;
    for (const Vec3& x : xs) {
      if (++trials > kMaxPlanarTrials) break;
      if (auto hi = bound(x, n.dot(x - plane.origin), 0.0, true); hi && *hi <= threshold)
        return Proof{*hi, asked > 0 ? DecidedBy::Exact : DecidedBy::Analytic};
    }
    return std::nullopt;
  }
  if (!part_q.source) return std::nullopt;
  std::size_t trials = 0;
  // At most kMaxCrossingStarts crossings looked at, every stride-th in triangle order (spread over
  // the face rather than the first few triangles').
  const std::size_t stride = (xs.size() + kMaxCrossingStarts - 1) / kMaxCrossingStarts;
  for (std::size_t k = 0; k < xs.size(); k += stride) {
    const Vec3& x = xs[k];
    // Only crossings whose foot lies well inside P start a Newton run (one on P's boundary is an edge
    // contact, the witness steps' case).
    if (!on_p(x, n.dot(x - plane.origin))) continue;
    if (++trials > kMaxNewtonTrials) break;
    // Newton on the curve where Q's surface meets the plane: from each foot point, to the point of
    // the line (plane ∩ tangent plane there) nearest it, and its foot again.
    Vec3 y = x;
    for (int step = 0; step < kMaxNewtonSteps; ++step) {
      ++c.witness_queries;
      const auto sp = part_q.source->surface_point(local, y);
      if (!sp) break;
      const double h = n.dot(sp->point - plane.origin);
      if (std::abs(h) + sp->rounding <= 0.5 * headroom) {
        if (auto hi = bound(sp->point, h, sp->rounding, false); hi && *hi <= threshold) return Proof{*hi, DecidedBy::Exact};
        break;
      }
      const double cn = n.dot(sp->normal);
      const double den = 1.0 - cn * cn;
      if (!(den > 1e-6)) break;  // the surfaces are tangent there: no crossing curve to follow
      const double alpha = -h / den;
      y = sp->point + alpha * n - alpha * cn * sp->normal;
    }
  }
  return std::nullopt;
}

// The point of Q's cylinder, cone or sphere farthest along `d` (a unit vector) near the point `v`
// (for a cylinder on v's cross-section, for a cone on v's distance along the generatrix): where a
// surface tangent to a plane touches it. nullopt where that is not unique (axis along d).
std::optional<Vec3> support_point(const AnalyticSurface& q, const Vec3& d, const Vec3& v) {
  const Vec3 a = q.axis.normalized();
  switch (q.shape) {
    case SurfaceShape::Sphere: return q.origin + q.radius * d;
    case SurfaceShape::Cylinder: {
      const Vec3 w = d - d.dot(a) * a;
      if (!(w.norm() > 1e-9)) return std::nullopt;
      return q.origin + (v - q.origin).dot(a) * a + q.radius * w.normalized();
    }
    case SurfaceShape::Cone: {
      const Vec3 w = d - d.dot(a) * a;
      if (!(w.norm() > 1e-9)) return std::nullopt;
      const double side = (v - q.origin).dot(a) < 0.0 ? -1.0 : 1.0;  // the nappe v lies on
      const Vec3 g = std::cos(q.radius2) * side * a + std::sin(q.radius2) * w.normalized();
      const double s = (v - q.origin).dot(g);
      if (!(s > 0.0)) return std::nullopt;
      return q.origin + s * g;
    }
    default: return std::nullopt;
  }
}

// P's face lies on a plane, Q's on a cylinder, cone or sphere that may touch it (tangent). The
// support point toward the plane near Q's lowest vertices, inside both faces, bounds d*.
std::optional<Proof> touch_plane(const Part& part_p, SurfaceId sp, const Part& part_q, SurfaceId sq, FaceView fp,
                                 FaceView fq, double slack_q, const Pose& to_q, const Pose& to_p, double r, double threshold,
                                 CollideCounters& c) {
  const Surface& Q = fq.surface;
  const AnalyticSurface plane = transform_analytic(fp.surface.analytic, to_q);
  const Vec3 n = plane.axis.normalized();
  const double headroom = threshold - slack_q - r;
  if (!(headroom > 0.0) || Q.mesh.vertices.empty()) return std::nullopt;
  // Q's vertices nearest the plane (by |height|), a few.
  std::vector<std::pair<double, std::uint32_t>> low;
  for (std::uint32_t i = 0; i < Q.mesh.vertices.size(); ++i)
    low.emplace_back(std::abs(n.dot(Q.mesh.vertices[i] - plane.origin)), i);
  const std::size_t keep = std::min<std::size_t>(low.size(), kMaxNewtonTrials);
  std::partial_sort(low.begin(), low.begin() + static_cast<std::ptrdiff_t>(keep), low.end());
  std::size_t asked = 0;
  for (std::size_t k = 0; k < keep; ++k) {
    const Vec3& v = Q.mesh.vertices[low[k].second];
    const Vec3 d = n.dot(v - plane.origin) > 0.0 ? Vec3(-n) : n;  // toward the plane
    const std::optional<Vec3> x = support_point(Q.analytic, d, v);
    if (!x) continue;
    const double h = n.dot(*x - plane.origin);
    if (!(std::abs(h) <= headroom)) continue;
    // x's distance to face Q (0 inside it) and to face P (|h| when its foot is inside P); a point on
    // either face's boundary (a shaft lying across the board's edge) is asked of the source.
    bool exact = false;
    auto ask = [&](const Part& part, SurfaceId s, const Vec3& y) -> std::optional<double> {
      if (!part.source || ++asked > kMaxClassifierTrials) return std::nullopt;
      ++c.witness_queries;
      exact = true;
      return part.source->point_distance(s - part.first_surface, y);
    };
    std::optional<double> off_q = 0.0, to_face_p = std::abs(h);
    if (!inside_face(fq, *x, r)) off_q = ask(part_q, sq, *x);
    if (!off_q) continue;
    if (!inside_face(fp, to_p * (*x - h * n), r)) to_face_p = ask(part_p, sp, to_p * *x);
    if (!to_face_p) continue;
    const double hi = slack_q + *off_q + *to_face_p + r;
    if (hi <= threshold) return Proof{hi, exact ? DecidedBy::Exact : DecidedBy::Analytic};
  }
  return std::nullopt;
}

// P's face lies on a plane; Q's face may touch it at one point of a curved edge (a disk or a bolt's
// flat lying on its rim). The extremum toward the plane of Q's edge near its lowest outline points,
// whose foot lies inside P, bounds d*.
std::optional<Proof> edge_on_plane(const Part& part_p, SurfaceId sp, const Part& part_q, SurfaceId sq, FaceView fp,
                                   FaceView fq, double slack_q, const Pose& to_q, const Pose& to_p, double r,
                                   double threshold, CollideCounters& c) {
  if (!part_q.source || fq.outline == nullptr || fq.outline->empty()) return std::nullopt;
  const AnalyticSurface plane = transform_analytic(fp.surface.analytic, to_q);
  const Vec3 n = plane.axis.normalized();
  const double headroom = threshold - slack_q - r;
  if (!(headroom > 0.0)) return std::nullopt;
  std::vector<std::pair<double, Vec3>> low;
  for (const auto& e : fq.outline->segments)
    for (const Vec3& v : e) low.emplace_back(std::abs(n.dot(v - plane.origin)), v);
  const std::size_t keep = std::min<std::size_t>(low.size(), kMaxEdgeTrials);
  std::partial_sort(low.begin(), low.begin() + static_cast<std::ptrdiff_t>(keep), low.end(),
                    [](const auto& x, const auto& y) { return x.first < y.first; });
  for (std::size_t k = 0; k < keep; ++k) {
    if (k > 0 && low[k].second == low[k - 1].second) continue;  // an outline vertex ends two segments
    const Vec3& v = low[k].second;
    const Vec3 d = n.dot(v - plane.origin) > 0.0 ? Vec3(-n) : n;  // toward the plane
    ++c.witness_queries;
    const auto x = part_q.source->edge_support(sq - part_q.first_surface, d, v);
    if (!x) continue;
    const double h = n.dot(x->point - plane.origin);
    if (!(std::abs(h) + x->rounding <= headroom)) continue;
    // x is a point of face Q (on its edge); its distance to face P is |h| when its foot is inside P.
    std::optional<double> to_face_p = std::abs(h);
    if (!inside_face(fp, to_p * (x->point - h * n), r)) {
      if (!part_p.source) continue;
      ++c.witness_queries;
      to_face_p = part_p.source->point_distance(sp - part_p.first_surface, to_p * x->point);
      if (!to_face_p) continue;
    }
    const double hi = slack_q + *to_face_p + x->rounding + r;
    if (hi <= threshold) return Proof{hi, DecidedBy::Exact};
  }
  return std::nullopt;
}

bool touches_plane(const Surface& s) {
  return s.analytic.shape == SurfaceShape::Cylinder || s.analytic.shape == SurfaceShape::Cone ||
         s.analytic.shape == SurfaceShape::Sphere;
}

// Runs `side` (one of the functions above) with A's face as the plane, then with B's, for the faces
// `other_ok` accepts on the other side, and settles the pair in contact on the first proof.
template <class Side>
void prove_against_plane(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView fa, FaceView fb,
                         Pending& p, const CollideOptions& o, CollideCounters& c, bool (*other_ok)(const Surface&),
                         Side side) {
  if (t.outcome == nullptr || !fa.surface.has_triangles || !fb.surface.has_triangles) return;
  const Part& pa = m.parts[fa.surface.part];
  const Part& pb = m.parts[fb.surface.part];
  std::optional<Proof> proof;
  if (fa.surface.analytic.shape == SurfaceShape::Plane && other_ok(fb.surface))
    proof = side(pa, t.sa, pb, t.sb, fa, fb, slack[t.sb], t.t_ba(), t.t_ab(), t.roundoff, p.threshold, c);
  if (!proof && fb.surface.analytic.shape == SurfaceShape::Plane && other_ok(fa.surface))
    proof = side(pb, t.sb, pa, t.sa, fb, fa, slack[t.sa], t.t_ab(), t.t_ba(), t.roundoff, p.threshold, c);
  if (!proof || !(proof->hi <= p.threshold)) return;
  p.d.hi = std::min(p.d.hi, proof->hi);
  settle(p, Verdict::Contact, proof->by, t.outcome, o.clearance);
}

bool any_face(const Surface&) { return true; }

}  // namespace

void tangent_step(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView fa, FaceView fb,
                  Pending& p, const CollideOptions& o, CollideCounters& c) {
  prove_against_plane(m, slack, t, fa, fb, p, o, c, touches_plane, touch_plane);
}

void edge_support_step(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView fa, FaceView fb,
                       Pending& p, const CollideOptions& o, CollideCounters& c) {
  prove_against_plane(m, slack, t, fa, fb, p, o, c, any_face, edge_on_plane);
}

void crossing_step(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView fa, FaceView fb,
                   Pending& p, const CollideOptions& o, CollideCounters& c) {
  if (t.outcome == nullptr || !t.outcome->intersecting) return;
  prove_against_plane(m, slack, t, fa, fb, p, o, c, any_face, cross_plane);
}

}  // namespace cadclash::detail
