// Penetration proved on the exact surfaces where the triangles' band hides it (decide_steps.h,
// depth_step): a planar face against a planar, cylindrical or any other face with exact geometry.
// A plane's triangles lie on it, so its band is in its outline (chords of curved edges, a board's
// holes), which the "inside" tests account for; a cylinder's points are taken on the exact cylinder
// (its generators are lines on it), any other surface's by the source's foot points
// (SurfaceSource::surface_point). Heights are signed distances to the exact surfaces: over a plane
// along its normal, over a cylinder from its axis minus the radius, over another surface along its
// normal at the foot point (oriented as at the crossing).
#include "decide_steps.h"

#include "cadclash/geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cadclash::detail {
namespace {

constexpr std::size_t kMaxCrossingTrials = 8;  // crossing points tried, spread over the crossing
constexpr int kBisections = 8;                 // steps from the smallest depth that proves it toward the band's top
constexpr int kStepTrials = 4;                 // tries to reach a height over a curved surface (not linear in the step)
constexpr int kNewtonSteps = 6;                // onto the curve where a surface meets a plane
constexpr std::size_t kVertexTrials = 4;       // a general face's vertices tried per side of the other surface
// sin 0.5°: a direction closer than this to a surface's tangent plane does not rise over it.
constexpr double kMinSine = 0.0087;

enum class Kind { Plane, Cylinder, General };

// The exact surface of one face, and the face, seen from A's frame.
struct Side {
  FaceView f;
  Kind kind = Kind::General;
  Vec3 o = Vec3::Zero();  // plane: a point on it; cylinder: a point on its axis
  Vec3 n = Vec3::UnitZ();  // plane: unit normal; cylinder: unit axis
  double radius = 0.0;
  const Pose* to_own = nullptr;  // A's frame → the face's part frame
  const Pose* to_a = nullptr;    // back
  const SurfaceSource* source = nullptr;  // the face's exact geometry (null: none)
  std::uint32_t local = 0;                // the face's index in its source
};

// What one pair may ask its sources (OCCT projections and face classifications).
struct Asked {
  int classify = 16;
  int feet = 96;
  CollideCounters& c;
};

// A point of a surface, its unit normal there (a cylinder's: outward; a general one's: either way)
// and how far the point may be from the exact surface.
struct Foot {
  Vec3 point;
  Vec3 normal;
  double rounding = 0.0;
};

std::optional<Foot> foot(const Side& s, const Vec3& x, Asked& asked) {
  switch (s.kind) {
    case Kind::Plane: return Foot{x - s.n.dot(x - s.o) * s.n, s.n, 0.0};
    case Kind::Cylinder: {
      const Vec3 radial = (x - s.o) - (x - s.o).dot(s.n) * s.n;
      if (!(radial.norm() > 0.0)) return std::nullopt;
      const Vec3 u = radial.normalized();
      return Foot{x - radial + s.radius * u, u, 0.0};
    }
    case Kind::General: {
      if (s.source == nullptr || asked.feet <= 0) return std::nullopt;
      --asked.feet;
      ++asked.c.witness_queries;
      const auto sp = s.source->surface_point(s.local, *s.to_own * x);
      if (!sp) return std::nullopt;
      return Foot{*s.to_a * sp->point, (s.to_a->linear() * sp->normal).normalized(), sp->rounding};
    }
  }
  return std::nullopt;
}

// x's signed height over s (its foot f given): along the normal, a general surface's oriented as `up`.
double height(const Side& s, const Vec3& x, const Foot& f, const Vec3& up) {
  if (s.kind == Kind::Plane) return s.n.dot(x - s.o);
  const Vec3 nu = s.kind == Kind::General && f.normal.dot(up) < 0.0 ? Vec3(-f.normal) : f.normal;
  return nu.dot(x - f.point);
}

// Whether x (a point of the side's exact surface, within r) lies inside the face: by its triangles
// (clear of their outline by twice the deflection: 0 returned), else by the exact face classifier
// (a point near a curved edge, where the triangles cannot tell), which returns how far x may be from
// the face (its projection's rounding; a depth proved with x gives that much away). Nothing when x
// is outside, or when the classifier puts it farther than `within` from the face.
std::optional<double> inside(const Side& side, const Vec3& x, double r, double within, Asked& asked) {
  const Vec3 own = *side.to_own * x;
  if (inside_face(side.f, own, r)) return 0.0;
  if (side.source == nullptr || asked.classify <= 0) return std::nullopt;
  --asked.classify;
  ++asked.c.witness_queries;
  const std::optional<double> d = side.source->point_distance(side.local, own);
  if (!d || !(*d <= within)) return std::nullopt;
  return *d;
}

struct Tolerances {
  double r;       // rounding of points and heights in A's frame
  double within;  // what a point may be off its face and still count, given away from the depth
};

// A point of `own` at height sign * >= h over `other` whose foot is inside `other`'s face: the
// height reached minus what it gives away, or nothing. x must be a point of own's exact surface
// (within `off`).
std::optional<double> witness(const Side& own, const Side& other, const Vec3& x, double off, double sign, double h,
                              const Vec3& up, const Tolerances& tol, Asked& asked) {
  const std::optional<Foot> f = foot(other, x, asked);
  if (!f) return std::nullopt;
  const double hx = sign * height(other, x, *f, up);
  if (!(hx - off - f->rounding >= h)) return std::nullopt;
  const std::optional<double> off_own = inside(own, x, tol.r, tol.within, asked);
  if (!off_own) return std::nullopt;
  const std::optional<double> off_other = inside(other, f->point, tol.r + f->rounding, tol.within, asked);
  if (!off_other) return std::nullopt;
  return hx - off - f->rounding - *off_own - *off_other;
}

// A general face: its vertices farthest on that side of `other` (by their heights), moved onto the
// exact surface (their foot points), tried until one witnesses. A foot not high enough (the chords
// of the face's triangles cut below a bulge of it, and no vertex lies at its top) climbs along the
// face a few times: a step along its tangent plane toward the height, moved onto the surface again.
// Only witness() proves anything: how the candidates are found cannot make an answer wrong.
std::optional<double> vertex_witness(const Side& own, const Side& other, double sign, double h, const Vec3& up,
                                     const Tolerances& tol, Asked& asked) {
  const TriangleMesh& mesh = own.f.surface.mesh;
  auto over = [&](const Vec3& x) { return sign * other.n.dot(x - other.o); };  // other is a plane here
  std::vector<std::pair<double, std::uint32_t>> far;
  for (std::uint32_t i = 0; i < mesh.vertices.size(); ++i) {
    const double hv = over(*own.to_a * mesh.vertices[i]);
    if (hv > 0.0) far.emplace_back(-hv, i);
  }
  const std::size_t keep = std::min(far.size(), kVertexTrials);
  std::partial_sort(far.begin(), far.begin() + static_cast<std::ptrdiff_t>(keep), far.end());
  for (std::size_t k = 0; k < keep; ++k) {
    std::optional<Foot> on_own = foot(own, *own.to_a * mesh.vertices[far[k].second], asked);
    for (int step = 0; on_own && step <= kStepTrials; ++step) {
      const double hx = over(on_own->point);
      if (hx - on_own->rounding >= h) {
        if (auto d = witness(own, other, on_own->point, on_own->rounding, sign, h, up, tol, asked)) return d;
        break;  // high enough, but not inside the faces
      }
      if (!(hx > 0.0) || step == kStepTrials) break;
      // Along the face toward the bulge's top: the rise per unit length there is the tangent part
      // of the plane's normal; a step that would rise to twice h if the face were flat.
      const Vec3 rise = sign * other.n - (sign * other.n).dot(on_own->normal) * on_own->normal;
      const double slope = rise.norm();
      if (!(slope > kMinSine)) break;
      on_own = foot(own, on_own->point + ((2.0 * h - hx) / (slope * slope)) * rise, asked);
    }
  }
  return std::nullopt;
}

// The points of `own` at height +-h over `other`, each inside its face, its foot on `other` inside
// that face: along own's surface from c (a line of a plane across the crossing, a cylinder's
// generator), or a general face's vertices. Returns the smaller of the two depths, or nothing.
std::optional<double> straddle(const Side& own, const Side& other, const Vec3& c, const Vec3& up, double h,
                               const Tolerances& tol, Asked& asked) {
  double reached = std::numeric_limits<double>::infinity();
  if (own.kind == Kind::General) {
    for (const double sign : {1.0, -1.0}) {
      const auto d = vertex_witness(own, other, sign, h, up, tol, asked);
      if (!d) return std::nullopt;
      reached = std::min(reached, *d);
    }
    return reached;
  }
  const std::optional<Foot> at_c = foot(other, c, asked);
  if (!at_c) return std::nullopt;
  const Vec3 g = other.kind == Kind::General && at_c->normal.dot(up) < 0.0 ? Vec3(-at_c->normal) : at_c->normal;
  Vec3 d = own.kind == Kind::Plane ? Vec3(g - g.dot(own.n) * own.n) : own.n;
  if (!(d.norm() > 0.0)) return std::nullopt;
  d.normalize();
  if (d.dot(g) < 0.0) d = -d;
  const double rate = d.dot(g);
  if (!(rate > kMinSine)) return std::nullopt;
  for (const double sign : {1.0, -1.0}) {
    // Linear in the step over a plane; over a curved surface a few corrections from the height reached.
    double step = sign * h / rate;
    std::optional<double> got;
    for (int k = 0; k < kStepTrials && !got; ++k) {
      const Vec3 x = c + step * d;
      const std::optional<Foot> f = foot(other, x, asked);
      if (!f) return std::nullopt;
      const double hx = sign * height(other, x, *f, up);
      if (!(hx > 0.0)) return std::nullopt;
      if (hx - f->rounding >= h) got = witness(own, other, x, 0.0, sign, h, up, tol, asked);
      if (!got && hx - f->rounding >= h) return std::nullopt;  // high enough, but not inside the faces
      step *= 1.25 * h / hx;
    }
    if (!got) return std::nullopt;
    reached = std::min(reached, *got);
  }
  return reached;
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

// Where the triangles of `q` cross plane `p`, within `region`: the midpoint of each crossing
// segment's part there (in triangle order).
std::vector<Vec3> crossings(const Side& q, const Side& p, const Aabb& region) {
  std::vector<Vec3> out;
  const TriangleMesh& mesh = q.f.surface.mesh;
  // Only triangles near the region: through q's tree, with the region mapped into q's frame (a box
  // enclosing it). Ascending, so the points come in triangle order as from a scan of all of them.
  std::vector<std::uint32_t> near;
  std::uint64_t tests = 0;
  query_surface_bvh(q.f.bvh, mesh, transform_box(region, *q.to_own), near, tests);
  for (const std::uint32_t k : near) {
    const auto& tri = mesh.triangles[k];
    const Vec3 w[3] = {*q.to_a * mesh.vertices[tri[0]], *q.to_a * mesh.vertices[tri[1]], *q.to_a * mesh.vertices[tri[2]]};
    const Vec3* const v[3] = {&w[0], &w[1], &w[2]};
    double h[3];
    for (int j = 0; j < 3; ++j) h[j] = p.n.dot(w[j] - p.o);
    const auto ends = plane_cut(v, h);
    if (!ends) continue;
    if (const auto part = clip((*ends)[0], (*ends)[1], region)) out.push_back(0.5 * (part->first + part->second));
  }
  return out;
}

// Whether face q can reach above +threshold and below -threshold over plane p anywhere a proof
// could look: the exact face lies within its deflection of its triangles (a plane: see below), whose
// heights over p are at most their vertices', and a point the proof uses (its height at most
// `reach` less q's deflection, its foot inside p's face) lies within `reach` of `region`. False: no
// crossing deeper than the threshold can be proved, and no exact query is made.
bool may_cross_deeper(const Side& q, const Side& p, const Aabb& region, double reach, double threshold, double r) {
  const TriangleMesh& mesh = q.f.surface.mesh;
  std::vector<std::uint32_t> near;
  std::uint64_t tests = 0;
  query_surface_bvh(q.f.bvh, mesh, transform_box(pad_box(region, reach), *q.to_own), near, tests);
  double up = 0.0, down = 0.0;
  for (const std::uint32_t k : near)
    for (const std::uint32_t v : mesh.triangles[k]) {
      const double h = p.n.dot(*q.to_a * mesh.vertices[v] - p.o);
      up = std::max(up, h);
      down = std::max(down, -h);
    }
  // A plane's interior is exact (its triangles lie on it); its deflection is its outline's, which
  // reaches past the triangles within the plane, rising over p by at most the planes' sine.
  const double off = q.kind == Kind::Plane ? q.n.cross(p.n).norm() * q.f.surface.deflection : q.f.surface.deflection;
  return std::min(up, down) + off + 4.0 * r > threshold;
}

// A crossing point x of q's triangles with plane p moved onto both exact surfaces: a plane's point
// is on it already; a cylinder's goes to the cylinder and back onto p along its generator; another
// surface's by Newton on the curve where it meets p. Returns the point and what it may be off q
// (its distance to p is within the rounding).
std::optional<std::pair<Vec3, double>> onto_both(const Side& q, const Side& p, const Vec3& x, double within, Asked& asked) {
  if (q.kind == Kind::Plane) return std::pair{x, 0.0};
  if (q.kind == Kind::Cylinder) {
    const std::optional<Foot> on_q = foot(q, x, asked);
    const double rate = p.n.dot(q.n);
    if (!on_q || !(std::abs(rate) > kMinSine)) return std::nullopt;
    return std::pair{Vec3(on_q->point - (p.n.dot(on_q->point - p.o) / rate) * q.n), 0.0};
  }
  Vec3 y = x;
  for (int step = 0; step < kNewtonSteps; ++step) {
    const std::optional<Foot> f = foot(q, y, asked);
    if (!f) return std::nullopt;
    const double h = p.n.dot(f->point - p.o);
    if (std::abs(h) + f->rounding <= within) return std::pair{Vec3(f->point - h * p.n), std::abs(h) + f->rounding};
    // To the point of the line (p ∩ q's tangent plane) nearest the foot, then its foot again.
    const double cn = p.n.dot(f->normal);
    const double den = 1.0 - cn * cn;
    if (!(den > 1e-6)) return std::nullopt;  // tangent there: no crossing curve to follow
    const double alpha = -h / den;
    y = f->point + alpha * p.n - alpha * cn * f->normal;
  }
  return std::nullopt;
}

Side side_of(const Model& m, FaceView f, SurfaceId s, const Pose& to_a, const Pose& to_own) {
  const Part& part = m.parts[f.surface.part];
  Side out{f};
  out.to_own = &to_own;
  out.to_a = &to_a;
  out.source = part.source.get();
  out.local = s - part.first_surface;
  const AnalyticSurface an = transform_analytic(f.surface.analytic, to_a);
  if (an.shape == SurfaceShape::Plane) out.kind = Kind::Plane;
  else if (an.shape == SurfaceShape::Cylinder) out.kind = Kind::Cylinder;
  out.o = an.origin;
  out.n = an.axis.normalized();
  out.radius = an.radius;
  return out;
}

}  // namespace

bool depth_step_applies(const Model& m, const DecideTask& t, const Pending& p) {
  if (!p.settled || p.cut || p.cls != ContactClass::Touching || t.outcome == nullptr) return false;
  if (!t.outcome->intersecting || !t.outcome->may_cross_threshold) return false;
  const Surface& a = m.surfaces[t.sa];
  const Surface& b = m.surfaces[t.sb];
  if (!a.has_triangles || !b.has_triangles) return false;
  auto plane = [](const Surface& s) { return s.analytic.shape == SurfaceShape::Plane; };
  auto exact = [&](const Surface& s) {  // a cylinder, or a face whose source gives its foot points
    return s.analytic.shape == SurfaceShape::Cylinder || m.parts[s.part].source != nullptr;
  };
  return (plane(a) && (plane(b) || exact(b))) || (plane(b) && exact(a));
}

bool depth_step(const Model& m, const DecideTask& t, FaceView fa, FaceView fb, Pending& p, CollideCounters& c) {
  if (fa.outline == nullptr || fb.outline == nullptr) return false;
  const Pose identity = Pose::Identity();
  const Side a = side_of(m, fa, t.sa, identity, identity);
  const Side b = side_of(m, fb, t.sb, t.t_ab(), t.t_ba());
  // Deeper than T past the rounding of the heights (each within r), and never deeper than the
  // triangles allow (T + their band). What the classifier and the feet may leave between a point
  // and its surface or face is a small part of the headroom, so the heights minus it exceed T.
  const double r = t.roundoff;
  const double low = p.threshold * (1.0 + 0x1p-20) + 4.0 * r;
  const double high = p.threshold + p.mesh_band;
  if (!(low < high)) return false;
  const Tolerances tol{r, (low - p.threshold) / 16.0};
  Asked asked{16, 96, c};
  // Crossing points near both faces: each face's triangles against the other's plane.
  const Aabb region = own_box(fa.surface).intersection(transform_box(own_box(fb.surface), t.t_ab()));
  if (region.isEmpty()) return false;
  struct Start {
    const Side* q;  // the face whose triangles crossed the plane of the other
    const Side* p;
    Vec3 x;
  };
  std::vector<Start> starts;
  const double reach = high + std::max(a.f.surface.deflection, b.f.surface.deflection);
  if (a.kind == Kind::Plane && may_cross_deeper(b, a, region, reach, p.threshold, r))
    for (const Vec3& x : crossings(b, a, region)) starts.push_back({&b, &a, x});
  if (b.kind == Kind::Plane && may_cross_deeper(a, b, region, reach, p.threshold, r))
    for (const Vec3& x : crossings(a, b, region)) starts.push_back({&a, &b, x});
  if (starts.empty()) return false;
  const std::size_t stride = (starts.size() + kMaxCrossingTrials - 1) / kMaxCrossingTrials;
  for (std::size_t k = 0; k < starts.size(); k += stride) {
    const Start& s = starts[k];
    const auto on = onto_both(*s.q, *s.p, s.x, tol.within, asked);
    if (!on) continue;
    const Vec3& x = on->first;
    // The crossing point itself, inside both faces.
    const auto in_a = inside(a, x, r + on->second, tol.within, asked);
    const auto in_b = in_a ? inside(b, x, r + on->second, tol.within, asked) : std::nullopt;
    if (!in_b) continue;
    // A general surface's normal at the crossing orients its heights on both sides.
    const std::optional<Foot> fa_x = foot(a, x, asked);
    const std::optional<Foot> fb_x = foot(b, x, asked);
    if (!fa_x || !fb_x) continue;
    const Vec3 up_a = fa_x->normal, up_b = fb_x->normal;
    const double first = low + 8.0 * tol.within + on->second;
    // The depth both faces reach through each other at x, at least h: each side's straddle made only
    // when h is above what its points already reached (they witness every lower height too).
    double reached_a = -std::numeric_limits<double>::infinity(), reached_b = reached_a;
    auto crossing_here = [&](double h) -> std::optional<double> {
      if (!(reached_a >= h)) {
        const auto d = straddle(a, b, x, up_b, h, tol, asked);
        if (!d) return std::nullopt;
        reached_a = *d;
      }
      if (!(reached_b >= h)) {
        const auto d = straddle(b, a, x, up_a, h, tol, asked);
        if (!d) return std::nullopt;
        reached_b = *d;
      }
      return std::min(reached_a, reached_b) - 2.0 * tol.r;
    };
    std::optional<double> proved = crossing_here(first);
    if (!proved || !(*proved > p.threshold)) continue;
    // The deepest height this crossing holds, up to the band's top (what a depth estimate says).
    double lo = first, hi = high;
    for (int i = 0; i < kBisections; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (const auto d = crossing_here(mid); d && *d > p.threshold) {
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
