// Penetration proved on the exact surfaces where the triangles' band hides it (decide_steps.h,
// depth_step): a planar face against a planar or cylindrical one. A plane's triangles lie on it, so
// its band is in its outline (chords of curved edges, a board's holes), which inside_face accounts
// for; a cylinder's points are taken on the exact cylinder (its generators are lines on it). Heights
// are measured over the exact surfaces: over a plane the signed distance to it, over a cylinder the
// distance to its axis minus its radius.
#include "decide_steps.h"

#include "cadclash/geometry.h"

#include <algorithm>
#include <cmath>

namespace cadclash::detail {
namespace {

constexpr std::size_t kMaxCrossingTrials = 8;  // crossing points tried, spread over the crossing
constexpr int kBisections = 8;                 // steps from the smallest depth that proves it toward the band's top
constexpr int kStepTrials = 4;                 // tries to reach a height over a cylinder (not linear in the step)
// sin 0.5°: a direction closer than this to a surface's tangent plane does not rise over it.
constexpr double kMinSine = 0.0087;

// A plane or a cylinder, in A's frame.
struct Shape {
  bool plane = true;
  Vec3 o;     // plane: a point on it; cylinder: a point on its axis
  Vec3 n;     // plane: unit normal; cylinder: unit axis
  double radius = 0.0;

  Vec3 radial(const Vec3& x) const { return (x - o) - (x - o).dot(n) * n; }
  double height(const Vec3& x) const { return plane ? n.dot(x - o) : radial(x).norm() - radius; }
  // The direction in which height grows at x (the normal of the surface through x parallel to this one).
  std::optional<Vec3> rise(const Vec3& x) const {
    if (plane) return n;
    const Vec3 r = radial(x);
    if (!(r.norm() > 0.0)) return std::nullopt;
    return Vec3(r.normalized());
  }
  // x's foot on the surface.
  std::optional<Vec3> foot(const Vec3& x) const {
    if (plane) return Vec3(x - height(x) * n);
    const Vec3 r = radial(x);
    if (!(r.norm() > 0.0)) return std::nullopt;
    return Vec3(x - r + radius * r.normalized());
  }
};

struct Side {
  FaceView f;
  Shape s;
  const Pose* to_own;  // A's frame → this face's part frame
  const SurfaceSource* source;  // the face's exact geometry (null: none)
  std::uint32_t local;          // the face's index in its source
};

// The classifier's answers one pair may ask for (each an OCCT projection and face classification).
struct Asked {
  int left = 16;
  CollideCounters& c;
};

// Whether x (a point of the side's exact surface, within r) lies inside the face: by its triangles
// (clear of their outline by twice the deflection: 0 returned), else by the exact face classifier
// (a point near a curved edge, where the triangles cannot tell), which returns how far x may be from
// the face (its projection's rounding; a depth proved with x gives that much away). Nothing when x
// is outside, or when the classifier puts it farther than `within` from the face.
std::optional<double> inside(const Side& side, const Vec3& x, double r, double within, Asked& asked) {
  const Vec3 own = *side.to_own * x;
  if (inside_face(side.f, own, r)) return 0.0;
  if (side.source == nullptr || asked.left <= 0) return std::nullopt;
  --asked.left;
  ++asked.c.witness_queries;
  const std::optional<double> d = side.source->point_distance(side.local, own);
  if (!d || !(*d <= within)) return std::nullopt;
  return *d;
}

std::optional<Shape> shape_of(const Surface& s, const Pose& to_a) {
  const AnalyticSurface an = transform_analytic(s.analytic, to_a);
  if (an.shape == SurfaceShape::Plane) return Shape{true, an.origin, an.axis.normalized(), 0.0};
  if (an.shape == SurfaceShape::Cylinder) return Shape{false, an.origin, an.axis.normalized(), an.radius};
  return std::nullopt;
}

// A direction from c that stays on `own`'s surface (a line in a plane, a cylinder's generator) along
// which the height over `other` grows; nothing where it would barely grow.
std::optional<Vec3> walk(const Shape& own, const Shape& other, const Vec3& c) {
  const std::optional<Vec3> g = other.rise(c);
  if (!g) return std::nullopt;
  Vec3 d = own.plane ? Vec3(*g - g->dot(own.n) * own.n) : own.n;
  if (!(d.norm() > 0.0)) return std::nullopt;
  d.normalize();
  if (d.dot(*g) < 0.0) d = -d;
  if (!(d.dot(*g) > kMinSine)) return std::nullopt;
  return d;
}

// The points of `own` through c at height +-h over `other`, each inside its face, its foot on
// `other` inside that face. Returns the smaller of the two heights reached, or nothing.
std::optional<double> straddle(const Side& own, const Side& other, const Vec3& c, double h, double r, double within,
                               Asked& asked) {
  const std::optional<Vec3> d = walk(own.s, other.s, c);
  if (!d) return std::nullopt;
  double reached = std::numeric_limits<double>::infinity();
  for (const double sign : {1.0, -1.0}) {
    // Linear in the step over a plane; over a cylinder a few corrections from the height reached.
    double step = sign * h / d->dot(*other.s.rise(c));
    double hx = 0.0;
    Vec3 x = c;
    for (int k = 0; k < kStepTrials; ++k) {
      x = c + step * *d;
      hx = other.s.height(x);
      if (sign * hx >= h) break;
      if (!(sign * hx > 0.0)) return std::nullopt;
      step *= 1.25 * h / (sign * hx);
    }
    if (!(sign * hx >= h)) return std::nullopt;
    const std::optional<Vec3> f = other.s.foot(x);
    if (!f) return std::nullopt;
    const std::optional<double> off_own = inside(own, x, r, within, asked);
    if (!off_own) return std::nullopt;
    const std::optional<double> off_other = inside(other, *f, r, within, asked);
    if (!off_other) return std::nullopt;
    reached = std::min(reached, sign * hx - *off_own - *off_other);
  }
  return reached;
}

// The depth both faces reach through each other at c (on both surfaces), at least h: their heights
// minus the rounding of points and heights.
std::optional<double> crossing_at(const Side& a, const Side& b, const Vec3& c, double h, double r, double within,
                                  Asked& asked) {
  const auto da = straddle(a, b, c, h, r, within, asked);
  if (!da) return std::nullopt;
  const auto db = straddle(b, a, c, h, r, within, asked);
  if (!db) return std::nullopt;
  return std::min(*da, *db) - 2.0 * r;
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
    double lo = (box.min()[k] - e0[k]) / d[k], hi = (box.max()[k] - e0[k]) / d[k];
    if (lo > hi) std::swap(lo, hi);
    s0 = std::max(s0, lo);
    s1 = std::min(s1, hi);
    if (s0 > s1) return std::nullopt;
  }
  return std::pair{e0 + s0 * d, e0 + s1 * d};
}

// Where the triangles of `q`'s face (mapped into A's frame by `to_a`) cross plane `p`, within
// `region`: the midpoint of each crossing segment's part there, moved onto q's exact surface and
// back onto the plane along a line of q's surface (a cylinder's generator): points of both surfaces.
void crossings(const Side& q, const Pose& to_a, const Shape& p, const Aabb& region, std::vector<Vec3>& out) {
  const TriangleMesh& mesh = q.f.surface.mesh;
  for (const auto& tri : mesh.triangles) {
    const Vec3 v[3] = {to_a * mesh.vertices[tri[0]], to_a * mesh.vertices[tri[1]], to_a * mesh.vertices[tri[2]]};
    double h[3];
    for (int k = 0; k < 3; ++k) h[k] = p.height(v[k]);
    if (!(std::min({h[0], h[1], h[2]}) < 0.0 && std::max({h[0], h[1], h[2]}) > 0.0)) continue;
    Vec3 ends[2];
    int found = 0;
    for (int k = 0; k < 3 && found < 2; ++k) {
      const int l = (k + 1) % 3;
      if ((h[k] < 0.0) == (h[l] < 0.0)) continue;
      ends[found++] = v[k] + (h[k] / (h[k] - h[l])) * (v[l] - v[k]);
    }
    if (found < 2) continue;
    const auto part = clip(ends[0], ends[1], region);
    if (!part) continue;
    Vec3 c = 0.5 * (part->first + part->second);
    if (!q.s.plane) {
      const std::optional<Vec3> on_q = q.s.foot(c);
      const double rate = p.n.dot(q.s.n);
      if (!on_q || !(std::abs(rate) > kMinSine)) continue;
      c = *on_q - (p.height(*on_q) / rate) * q.s.n;
    }
    out.push_back(c);
  }
}

}  // namespace

bool depth_step_applies(const Model& m, const DecideTask& t, const Pending& p) {
  if (!p.settled || p.cut || p.cls != ContactClass::Touching || t.outcome == nullptr) return false;
  if (!t.outcome->intersecting || !t.outcome->crosses_threshold) return false;
  const Surface& a = m.surfaces[t.sa];
  const Surface& b = m.surfaces[t.sb];
  auto plane = [](const Surface& s) { return s.analytic.shape == SurfaceShape::Plane; };
  auto cylinder = [](const Surface& s) { return s.analytic.shape == SurfaceShape::Cylinder; };
  return a.has_triangles && b.has_triangles &&
         ((plane(a) && (plane(b) || cylinder(b))) || (cylinder(a) && plane(b)));
}

bool depth_step(const Model& m, const DecideTask& t, FaceView fa, FaceView fb, Pending& p, CollideCounters& c) {
  if (fa.outline == nullptr || fb.outline == nullptr) return false;
  const std::optional<Shape> sa = shape_of(fa.surface, Pose::Identity());
  const std::optional<Shape> sb = shape_of(fb.surface, t.t_ab());
  if (!sa || !sb) return false;
  const Pose identity = Pose::Identity();
  const Part& pa = m.parts[fa.surface.part];
  const Part& pb = m.parts[fb.surface.part];
  const Side a{fa, *sa, &identity, pa.source.get(), t.sa - pa.first_surface};
  const Side b{fb, *sb, &t.t_ba(), pb.source.get(), t.sb - pb.first_surface};
  Asked asked{16, c};
  const double r = t.roundoff;
  // Crossing points near both faces: each face's triangles against the other's plane.
  const Aabb region = own_box(fa.surface).intersection(transform_box(own_box(fb.surface), t.t_ab()));
  if (region.isEmpty()) return false;
  std::vector<Vec3> xs;
  if (a.s.plane) crossings(b, t.t_ab(), a.s, region, xs);
  if (b.s.plane) crossings(a, identity, b.s, region, xs);
  if (xs.empty()) return false;
  // Deeper than T past the rounding of the heights (each within r), and never deeper than the
  // triangles allow (T + their band).
  const double low = p.threshold * (1.0 + 0x1p-20) + 4.0 * r;
  const double high = p.threshold + p.mesh_band;
  if (!(low < high)) return false;
  // What the classifier may leave between a point and its face: a small part of the headroom, so
  // that the heights minus it still exceed T.
  const double within = (low - p.threshold) / 8.0;
  const std::size_t stride = (xs.size() + kMaxCrossingTrials - 1) / kMaxCrossingTrials;
  for (std::size_t k = 0; k < xs.size(); k += stride) {
    const Vec3& x = xs[k];
    // The crossing point itself, inside both faces.
    if (!inside(a, x, r, within, asked) || !inside(b, x, r, within, asked)) continue;
    std::optional<double> proved = crossing_at(a, b, x, low + 4.0 * within, r, within, asked);
    if (!proved || !(*proved > p.threshold)) continue;
    // The deepest height this crossing holds, up to the band's top (what a depth estimate says).
    double lo = low, hi = high;
    for (int i = 0; i < kBisections; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (const auto d = crossing_at(a, b, x, mid, r, within, asked); d && *d > p.threshold) {
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
