// Penetration proved on two planar faces where the triangles' band hides it (decide_steps.h,
// depth_step). Planar faces' triangles lie on their planes; what the band covers is their outline
// (chords of curved edges, a board's holes). So heights over a plane are measured on the exact
// planes, and the points that realise them are checked inside the exact faces (inside_face).
#include "decide_steps.h"

#include "cadclash/geometry.h"

#include <algorithm>
#include <cmath>

namespace cadclash::detail {
namespace {

constexpr std::size_t kMaxCrossingTrials = 8;  // crossing points tried, spread over the crossing
constexpr int kBisections = 8;                 // steps from the smallest depth that proves it toward the band's top
// sin 0.5°: planes closer to parallel have no crossing line to step across.
constexpr double kMinSine = 0.0087;

struct Plane {
  Vec3 n;  // unit normal
  Vec3 o;  // a point on it
};

// Everything in A's frame: A's plane, B's plane, and the maps into B's frame for B's membership.
struct Setup {
  FaceView fa, fb;
  Plane pa, pb;
  Vec3 u_a, u_b;  // in A's (B's) plane, across the crossing line, rising over the other plane
  const Pose* to_b;
  double r;
};

bool in_a(const Setup& s, const Vec3& x) { return inside_face(s.fa, x, s.r); }
bool in_b(const Setup& s, const Vec3& x) { return inside_face(s.fb, *s.to_b * x, s.r); }

// The points of the crossing through c at height ±h: along u in the plane of `own` over `other`,
// each inside its own face, its foot on `other` inside the other face. Returns the smaller of the
// two heights reached (computed after the points are made), or nothing.
std::optional<double> straddle(const Setup& s, const Vec3& c, double h, bool of_a) {
  const Plane& other = of_a ? s.pb : s.pa;
  const Vec3& u = of_a ? s.u_a : s.u_b;
  const double rate = other.n.dot(u);  // > kMinSine by construction
  const double h0 = other.n.dot(c - other.o);
  double reached = std::numeric_limits<double>::infinity();
  for (const double sign : {1.0, -1.0}) {
    const Vec3 x = c + ((sign * h - h0) / rate) * u;
    const double hx = other.n.dot(x - other.o);
    const Vec3 foot = x - hx * other.n;
    const bool own_in = of_a ? in_a(s, x) : in_b(s, x);
    const bool foot_in = of_a ? in_b(s, foot) : in_a(s, foot);
    if (!own_in || !foot_in || !(sign * hx > 0.0)) return std::nullopt;
    reached = std::min(reached, sign * hx);
  }
  return reached;
}

// The depth both faces reach through each other at c, at least h (their heights minus rounding).
std::optional<double> crossing_at(const Setup& s, const Vec3& c, double h) {
  const auto da = straddle(s, c, h, true);
  if (!da) return std::nullopt;
  const auto db = straddle(s, c, h, false);
  if (!db) return std::nullopt;
  return std::min(*da, *db) - 2.0 * s.r;
}

// The part of segment [e0, e1] inside `box` (slab clipping), or nothing.
std::optional<std::pair<Vec3, Vec3>> clip(const Vec3& e0, const Vec3& e1, const Aabb& box) {
  double s0 = 0.0, s1 = 1.0;
  const Vec3 d = e1 - e0;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0) {
      if (e0[k] < box.min()[k] || e0[k] > box.max()[k]) return std::nullopt;
      continue;
    }
    double a = (box.min()[k] - e0[k]) / d[k], b = (box.max()[k] - e0[k]) / d[k];
    if (a > b) std::swap(a, b);
    s0 = std::max(s0, a);
    s1 = std::min(s1, b);
    if (s0 > s1) return std::nullopt;
  }
  return std::pair{e0 + s0 * d, e0 + s1 * d};
}

// Midpoints of the parts inside `region` of the segments where the triangles of `mesh` (mapped by
// `to_a`) cross the plane: points of the mesh's triangles on the plane, near the other face.
void crossings(const TriangleMesh& mesh, const Pose& to_a, const Plane& plane, const Aabb& region,
               std::vector<Vec3>& out) {
  for (const auto& tri : mesh.triangles) {
    const Vec3 v[3] = {to_a * mesh.vertices[tri[0]], to_a * mesh.vertices[tri[1]], to_a * mesh.vertices[tri[2]]};
    double h[3];
    for (int k = 0; k < 3; ++k) h[k] = plane.n.dot(v[k] - plane.o);
    if (!(std::min({h[0], h[1], h[2]}) < 0.0 && std::max({h[0], h[1], h[2]}) > 0.0)) continue;
    Vec3 ends[2];
    int found = 0;
    for (int k = 0; k < 3 && found < 2; ++k) {
      const int l = (k + 1) % 3;
      if ((h[k] < 0.0) == (h[l] < 0.0)) continue;
      ends[found++] = v[k] + (h[k] / (h[k] - h[l])) * (v[l] - v[k]);
    }
    if (found < 2) continue;
    if (const auto part = clip(ends[0], ends[1], region)) out.push_back(0.5 * (part->first + part->second));
  }
}

}  // namespace

bool depth_step_applies(const Model& m, const DecideTask& t, const Pending& p) {
  if (!p.settled || p.cut || p.cls != ContactClass::Touching || t.outcome == nullptr) return false;
  if (!t.outcome->intersecting || !t.outcome->crosses_threshold) return false;
  const Surface& a = m.surfaces[t.sa];
  const Surface& b = m.surfaces[t.sb];
  return a.analytic.shape == SurfaceShape::Plane && b.analytic.shape == SurfaceShape::Plane && a.has_triangles &&
         b.has_triangles;
}

bool depth_step(const DecideTask& t, FaceView fa, FaceView fb, Pending& p, CollideCounters& c) {
  if (fa.outline == nullptr || fb.outline == nullptr) return false;
  const AnalyticSurface b_plane = transform_analytic(fb.surface.analytic, t.t_ab());
  Setup s{fa, fb, {fa.surface.analytic.axis.normalized(), fa.surface.analytic.origin},
          {b_plane.axis.normalized(), b_plane.origin}, Vec3::Zero(), Vec3::Zero(), &t.t_ba(), t.roundoff};
  const Vec3 line = s.pa.n.cross(s.pb.n);
  if (!(line.norm() > kMinSine)) return false;  // (nearly) parallel planes: no crossing to step across
  s.u_a = s.pa.n.cross(line).normalized();
  if (s.pb.n.dot(s.u_a) < 0.0) s.u_a = -s.u_a;
  s.u_b = s.pb.n.cross(line).normalized();
  if (s.pa.n.dot(s.u_b) < 0.0) s.u_b = -s.u_b;
  // Where either face's triangles cross the other's plane, within both faces' boxes: B's first
  // (in A's frame), then A's.
  const Aabb region = own_box(fa.surface).intersection(transform_box(own_box(fb.surface), t.t_ab()));
  if (region.isEmpty()) return false;
  std::vector<Vec3> xs;
  crossings(fb.surface.mesh, t.t_ab(), s.pa, region, xs);
  crossings(fa.surface.mesh, Pose::Identity(), s.pb, region, xs);
  if (xs.empty()) return false;
  // Deeper than T past the rounding of the heights (each within r), and never deeper than the
  // triangles allow (T + their band).
  const double low = p.threshold * (1.0 + 0x1p-20) + 4.0 * t.roundoff;
  const double high = p.threshold + p.mesh_band;
  if (!(low < high)) return false;
  const std::size_t stride = (xs.size() + kMaxCrossingTrials - 1) / kMaxCrossingTrials;
  for (std::size_t k = 0; k < xs.size(); k += stride) {
    const Vec3& x = xs[k];
    // The crossing point itself: on A's plane (A's triangle) and on B's, inside both faces.
    ++c.witness_queries;
    if (!in_a(s, x) || !in_b(s, x)) continue;
    std::optional<double> proved = crossing_at(s, x, low);
    if (!proved || !(*proved > p.threshold)) continue;
    // The deepest height this crossing holds, up to the band's top (what a depth estimate says).
    double lo = low, hi = high;
    for (int i = 0; i < kBisections; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (const auto d = crossing_at(s, x, mid); d && *d > p.threshold) {
        lo = mid;
        proved = std::max(*proved, *d);
      } else {
        hi = mid;
      }
    }
    p.cls = ContactClass::Penetrating;
    p.by = DecidedBy::Analytic;
    p.depth = *proved;
    return true;
  }
  return false;
}

}  // namespace cadclash::detail
