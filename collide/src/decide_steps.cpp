// The steps of the certified decision (decide_steps.h): cheapest evidence first; each proves a
// bound on the exact faces' distance, and only what it leaves open goes to the next.
#include "decide_steps.h"
#include "patch_gap.h"

#include "cadclash/geometry.h"

#include <algorithm>
#include <cmath>

namespace cadclash::detail {
namespace {

// The class of a pair proved apart: clearance when its distance (the exact one when known, else the
// mesh's) is within the clearance, else not reported.
std::optional<ContactClass> apart_class(double distance, double clearance) {
  if (clearance > 0.0 && distance <= clearance) return ContactClass::Clearance;
  return std::nullopt;
}

}  // namespace

void settle(Pending& p, Verdict v, DecidedBy by, const PairOutcome* o, double clearance) {
  if (v == Verdict::Ambiguous) return;
  p.settled = true;
  p.by = by;
  if (v == Verdict::Contact) {
    p.cls = o != nullptr && certainly_penetrating(*o, p.threshold, p.mesh_band) ? ContactClass::Penetrating
                                                                                : ContactClass::Touching;
  } else {
    // Intersecting triangles measure no distance (narrow_phase.h): the proven lower bound stands in.
    p.cls = apart_class(p.exact ? *p.exact : o != nullptr && !o->intersecting ? o->distance : p.d.lo, clearance);
    p.dropped = !p.cls;
  }
}

Pending from_mesh(const Model& m, std::span<const double> eps, const DecideTask& t, const CollideOptions& o) {
  const Surface& a = m.surfaces[t.sa];
  const Surface& b = m.surfaces[t.sb];
  Pending p;
  p.threshold = touch_threshold(eps[t.sa], eps[t.sb], o.tolerance);
  p.band = p.mesh_band = a.deflection + b.deflection + t.roundoff;
  const double reach = p.threshold + p.band;
  if (t.outcome == nullptr) {  // no triangles on one side: only the boxes are known
    p.d = {box_distance(own_box(a), transform_box(own_box(b), t.t_ab())), std::numeric_limits<double>::infinity()};
    return p;
  }
  p.d = mesh_interval(*t.outcome, p.band, reach);
  const DecidedBy by =
      triangles_are_exact(m, t.sa) && triangles_are_exact(m, t.sb) ? DecidedBy::MeshExact : DecidedBy::Mesh;
  const Verdict v = verdict(p.d, p.threshold);
  if (o.decision == DecisionMode::Exact && !(v == Verdict::Apart && p.d.lo > std::max(p.threshold, o.clearance)))
    return p;  // the exact step decides (faces without exact geometry fall back to this verdict there)
  settle(p, v, by, t.outcome, o.clearance);
  return p;
}

// A lower bound on the exact faces' distance from their planes, cylinders and spheres: the two
// surfaces' parameters, and each one's triangles kept off the other's surface (0 when none helps).
// `a`, `b` are the model's faces or finer copies of them (same analytic surface and box).
double analytic_bound(const Surface& a, const Surface& b, double slack_a, double slack_b, const DecideTask& t,
                      double threshold) {
  const double r = t.roundoff;
  double lb = 0.0;
  // The two surfaces' parameters: where the faces can come within T of each other, both lie in A's
  // face box and in B's grown by T.
  const Aabb box_b = transform_box(own_box(b), t.t_ab());
  const Aabb region = own_box(a).intersection(pad_box(box_b, threshold));
  if (region.isEmpty()) {
    lb = box_distance(own_box(a), box_b);  // the boxes enclose the exact faces
  } else if (auto g = analytic_pair_gap(a.analytic, transform_analytic(b.analytic, t.t_ab()), region)) {
    lb = std::max(lb, *g - slack_a - slack_b - r);
  }
  // The triangles' gap is searched up to twice what proving "apart" needs (farther triangles are
  // skipped and count as that reach), so a gap that proves it is never cut short.
  if (b.has_triangles) {
    const double reach = 2.0 * (threshold + b.deflection + r + slack_a);
    if (auto g = analytic_gap(a.analytic, b.mesh, t.t_ab(), own_box(a), reach))
      lb = std::max(lb, std::min(*g, reach) - b.deflection - r - slack_a);
  }
  if (a.has_triangles) {
    const double reach = 2.0 * (threshold + a.deflection + r + slack_b);
    if (auto g = analytic_gap(b.analytic, a.mesh, t.t_ba(), own_box(b), reach))
      lb = std::max(lb, std::min(*g, reach) - a.deflection - r - slack_b);
  }
  return lb;
}

namespace {

// A plane against a face whose surface has a hull (SurfaceSource::height_range: a B-spline's control
// points): the hull's height over the plane bounds the face's distance to the plane, whatever the
// face's triangles, with no band at all. A part standing off a flat face by less than its triangles'
// deflection is proved apart without refining it.
double hull_bound(const Model& m, std::span<const double> slack, const DecideTask& t) {
  double lb = 0.0;
  for (int side = 0; side < 2; ++side) {
    const SurfaceId sp = side == 0 ? t.sa : t.sb, sq = side == 0 ? t.sb : t.sa;
    const Surface& plane_face = m.surfaces[sp];
    const Part& part_q = m.parts[m.surfaces[sq].part];
    if (plane_face.analytic.shape != SurfaceShape::Plane || !part_q.source) continue;
    const AnalyticSurface plane = transform_analytic(plane_face.analytic, side == 0 ? t.t_ba() : t.t_ab());
    const auto range = part_q.source->height_range(sq - part_q.first_surface, plane.origin, plane.axis.normalized());
    if (!range) continue;
    const double gap = (*range)[0] > 0.0 ? (*range)[0] : (*range)[1] < 0.0 ? -(*range)[1] : 0.0;
    lb = std::max(lb, gap - slack[t.sa] - slack[t.sb] - t.roundoff);
  }
  return lb;
}

}  // namespace

namespace {

// The holes of face `s` when it is a plane with round holes, else null.
std::shared_ptr<const std::vector<SurfaceSource::CircularHole>> plane_holes(const Model& m, SurfaceId s) {
  const Surface& f = m.surfaces[s];
  if (f.analytic.shape != SurfaceShape::Plane) return nullptr;
  const Part& part = m.parts[f.part];
  if (!part.source) return nullptr;
  auto holes = part.source->circular_holes(s - part.first_surface);
  return holes && !holes->empty() ? holes : nullptr;
}

}  // namespace

double hole_bound(const Model& m, const DecideTask& t, const Surface& a, const Surface& b, std::span<const double> slack,
                  double threshold) {
  const double r = t.roundoff;
  double lb = 0.0;
  for (int side = 0; side < 2; ++side) {
    const SurfaceId sp = side == 0 ? t.sa : t.sb;
    const Surface& plane_face = side == 0 ? a : b;
    const Surface& q = side == 0 ? b : a;
    if (!q.has_triangles) continue;
    const auto holes = plane_holes(m, sp);
    if (!holes) continue;
    // Searched up to twice what proving "apart" needs, as in analytic_bound.
    const double reach = 2.0 * (threshold + q.deflection + r + slack[sp]);
    const Pose& to_plane = side == 0 ? t.t_ab() : t.t_ba();
    if (auto g = hole_gap(plane_face.analytic, *holes, q.mesh, to_plane, own_box(plane_face), reach))
      lb = std::max(lb, std::min(*g, reach) - q.deflection - r - slack[sp]);
  }
  return lb;
}

bool at_hole(const Model& m, const DecideTask& t, bool of_a) {
  const auto holes = plane_holes(m, of_a ? t.sa : t.sb);
  if (!holes) return false;
  const Surface& plane_face = m.surfaces[of_a ? t.sa : t.sb];
  const Aabb other = transform_box(own_box(m.surfaces[of_a ? t.sb : t.sa]), of_a ? t.t_ab() : t.t_ba());
  const Vec3 n = plane_face.analytic.axis.normalized();
  return std::any_of(holes->begin(), holes->end(), [&](const SurfaceSource::CircularHole& h) {
    const Vec3 w = other.center() - h.centre;
    return (w - n.dot(w) * n).norm() < h.radius + 0.5 * other.diagonal().norm();
  });
}

// Step 2: a plane, cylinder or sphere that the other face's triangles provably keep off.
void analytic(const Model& m, std::span<const double> slack, const DecideTask& t, Pending& p, const CollideOptions& o) {
  double lb = analytic_bound(m.surfaces[t.sa], m.surfaces[t.sb], slack[t.sa], slack[t.sb], t, p.threshold);
  if (!(lb > p.threshold)) lb = std::max(lb, hull_bound(m, slack, t));
  if (!(lb > p.threshold)) lb = std::max(lb, hole_bound(m, t, m.surfaces[t.sa], m.surfaces[t.sb], slack, p.threshold));
  if (!(lb > p.threshold)) return;
  p.d.lo = std::max(p.d.lo, lb);
  settle(p, Verdict::Apart, DecidedBy::Analytic, t.outcome, o.clearance);
}

// A vertex's foot point on the other face's plane, cylinder or sphere proves contact when it lies
// inside that face: the witness is checked against B's triangles through their tree.
void analytic_contact(std::span<const double> slack, const DecideTask& t, FaceView fa, FaceView fb, Pending& p,
                      const CollideOptions& o) {
  const Surface& a = fa.surface;
  const Surface& b = fb.surface;
  if (!a.has_triangles || !b.has_triangles) return;
  const double r = t.roundoff;
  const Aabb box_a = own_box(a), box_b = own_box(b);
  // A's vertices on B's surface, in B's frame; then B's on A's, in A's frame.
  const Aabb region_b = box_b.intersection(pad_box(transform_box(box_a, t.t_ba()), p.threshold));
  // A vertex of one face (within its slack of that face) whose foot on the other surface is within
  // T - slack - r proves contact.
  std::optional<double> g = analytic_witness(b.analytic, b.mesh, fb.bvh, *fb.outline, b.deflection, a.mesh, t.t_ba(),
                                             region_b, p.threshold - slack[t.sa] - r, r);
  double own = slack[t.sa];
  if (!g) {
    const Aabb region_a = box_a.intersection(pad_box(transform_box(box_b, t.t_ab()), p.threshold));
    g = analytic_witness(a.analytic, a.mesh, fa.bvh, *fa.outline, a.deflection, b.mesh, t.t_ab(), region_a,
                         p.threshold - slack[t.sb] - r, r);
    own = slack[t.sb];
  }
  if (!g || !(own + *g + r <= p.threshold)) return;
  p.d.hi = std::min(p.d.hi, own + *g + r);
  settle(p, Verdict::Contact, DecidedBy::Analytic, t.outcome, o.clearance);
}

namespace {

// A vertex that could be a witness: its distance to the other face's triangles orders the trials.
struct Candidate {
  double near;  // distance to the other face's triangles (A's frame)
  bool of_a;    // a vertex of A, asked of B's face
  Vec3 point;   // in the part frame of the face it is asked of
};

// The vertices of `from` (mapped into the other face's frame by `to_other`, inside `region` there)
// within `limit` of the other face's triangles, found through its tree: a vertex farther from them
// is farther than `limit` minus the other face's deflection from its exact face, no witness.
void near_vertices(const Surface& from, const Pose& to_other, FaceView other, const Aabb& region, double limit,
                   bool of_a, std::vector<Candidate>& out) {
  for (const Vec3& v : from.mesh.vertices) {
    const Vec3 w = to_other * v;
    if (!region.contains(w)) continue;
    const double d = point_mesh_distance(other.bvh, other.surface.mesh, w, limit);
    if (d <= limit) out.push_back({d, of_a, w});
  }
}

// At most this many exact point queries per pair and level: nearest first, the rest seldom help.
constexpr std::size_t kMaxWitnessTrials = 8;


// Trial order: nearest first, but among the nearest a vertex whose foot lies well inside the other
// face's outline first. A foot near the outline is the exact face classifier's slow case, and the
// contact there is often along the edge, where the edge's own curve answers anyway. At most
// kMaxWitnessTrials of the 4·kMaxWitnessTrials nearest. The outline is asked in that nearest-first
// order only until the trials are found: the vertices inside come first, so each can be tried as
// it is met; the first success (the common case) ends the search. True when `prove` succeeded.
template <class Prove>
bool try_in_order(std::vector<Candidate>& cs, FaceView a, FaceView b, Prove prove) {
  const std::size_t keep = std::min<std::size_t>(cs.size(), 4 * kMaxWitnessTrials);
  auto nearer = [](const Candidate& x, const Candidate& y) { return x.near < y.near; };
  std::partial_sort(cs.begin(), cs.begin() + static_cast<std::ptrdiff_t>(keep), cs.end(), nearer);
  cs.resize(keep);
  auto inside = [&](const Candidate& c) {
    const FaceView& other = c.of_a ? b : a;
    return other.outline != nullptr && !near_outline(*other.outline, c.point, 2.0 * other.surface.deflection + c.near);
  };
  std::size_t trials = 0;
  std::vector<std::size_t> outside;  // by the outline: tried after every inside one, nearest first
  for (std::size_t k = 0; k < cs.size() && trials < kMaxWitnessTrials; ++k) {
    if (!inside(cs[k])) {
      outside.push_back(k);
      continue;
    }
    ++trials;
    if (prove(cs[k])) return true;
  }
  for (std::size_t k : outside) {
    if (trials++ >= kMaxWitnessTrials) break;
    if (prove(cs[k])) return true;
  }
  return false;
}

}  // namespace

// Inside-ness by the triangles (decide_steps.h). A point of a face's exact surface lies inside the face when the face's triangles come within its
// deflection (they stand for the face) and it is clear of their outline by twice that (the outline is
// within a deflection of the face's boundary): analytic_witness's test. Faces without an outline
// (not made, or closed) are not judged here.
bool inside_face(FaceView f, const Vec3& x, double slack, bool on_triangles) {
  if (f.outline == nullptr || f.outline->empty()) return false;
  const double delta = f.surface.deflection;
  return !near_outline(*f.outline, x, 2.0 * delta + slack) &&
         (on_triangles || point_near_mesh(f.bvh, f.surface.mesh, x, delta + slack));
}

// A vertex of a face lies on its own exact face (within that face's ε: the mesher puts nodes on the
// surface and its edges); when its exact distance to the other face is within tolerance + that
// face's ε (after the mapping's round-off), the faces are within T. Candidates are the vertices of
// either face near the other's triangles, nearest first; one success settles it.
void witness_step(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView fa, FaceView fb,
                  const PairOutcome* out, double band, Pending& p, const CollideOptions& o, CollideCounters& c) {
  if (out == nullptr) return;
  const Surface& a = fa.surface;
  const Surface& b = fb.surface;
  const Part& pa = m.parts[a.part];
  const Part& pb = m.parts[b.part];
  if (!pa.source || !pb.source || !a.has_triangles || !b.has_triangles) return;
  // A vertex farther than this from the other face's triangles is beyond reach of its exact face.
  const double limit_a = p.threshold - slack[t.sa] + band;  // A's vertices, asked of B
  const double limit_b = p.threshold - slack[t.sb] + band;
  std::vector<Candidate> tried;
  // One trial: the candidate's distance to the other exact face, bounded by a point of that face.
  auto proves = [&](const Candidate& cand) {
    for (const Candidate& x : tried)
      if (x.of_a == cand.of_a && x.point == cand.point) return false;
    tried.push_back(cand);
    const Part& asked = cand.of_a ? pb : pa;
    const FaceView& face = cand.of_a ? fb : fa;
    const std::uint32_t local = (cand.of_a ? t.sb : t.sa) - asked.first_surface;
    const double own = (cand.of_a ? slack[t.sa] : slack[t.sb]) + t.roundoff;
    // The foot point on the other face's surface, kept when that face's triangles put it inside; a
    // foot outside is mostly on the face's boundary (faces meeting along an edge), where a point of
    // its edge curves answers; last, the source's exact classifier decides (ten times the cost).
    ++c.witness_queries;
    const auto sp = asked.source->surface_point(local, cand.point);
    std::optional<double> d;
    if (sp && inside_face(face, sp->point, sp->rounding + t.roundoff)) {
      d = (sp->point - cand.point).norm() + sp->rounding;
    } else {
      ++c.witness_queries;
      d = asked.source->boundary_distance(local, cand.point);
      if (!d || !(own + *d <= p.threshold)) {
        ++c.witness_queries;
        d = asked.source->point_distance(local, cand.point);
      }
    }
    if (!d || !(own + *d <= p.threshold)) return false;
    p.d.hi = std::min(p.d.hi, own + *d);
    settle(p, Verdict::Contact, DecidedBy::Exact, t.outcome, o.clearance);
    return true;
  };
  // First the vertices of the triangle pair that decided the triangles' outcome (found already: six
  // tree queries), then every vertex near the other face.
  std::vector<Candidate> cs;
  if (out->witness[0] != kInvalidId && out->witness[1] != kInvalidId) {
    for (std::uint32_t v : a.mesh.triangles[out->witness[0]]) {
      const Vec3 w = t.t_ba() * a.mesh.vertices[v];
      if (const double d = point_mesh_distance(fb.bvh, b.mesh, w, limit_a); d <= limit_a) cs.push_back({d, true, w});
    }
    for (std::uint32_t v : b.mesh.triangles[out->witness[1]]) {
      const Vec3 w = t.t_ab() * b.mesh.vertices[v];
      if (const double d = point_mesh_distance(fa.bvh, a.mesh, w, limit_b); d <= limit_b) cs.push_back({d, false, w});
    }
    if (try_in_order(cs, fa, fb, proves)) return;
    cs.clear();
  }
  near_vertices(a, t.t_ba(), fb, pad_box(own_box(b), limit_a), limit_a, true, cs);
  near_vertices(b, t.t_ab(), fa, pad_box(own_box(a), limit_b), limit_b, false, cs);
  try_in_order(cs, fa, fb, proves);
}

namespace {

// Where two outlines (segments, both in one frame) come closest, by their vertices against the
// other's segments (a tangent point lies inside a segment, seldom at a vertex): the two points.
struct Closest {
  double d2 = std::numeric_limits<double>::infinity();
  Vec3 a, b;
};

void vertices_against_segments(const std::vector<std::array<Vec3, 2>>& from, const std::vector<std::array<Vec3, 2>>& to,
                               bool from_is_a, Closest& best) {
  for (const auto& e : from)
    for (const auto& f : to) {
      const Vec3& v = e[0];
      const Vec3 q = closest_on_segment(v, f[0], f[1]);
      if (const double d2 = (q - v).squaredNorm(); d2 < best.d2) best = {d2, from_is_a ? v : q, from_is_a ? q : v};
    }
}

// The segments of `outline` mapped by `to` whose boxes meet `region`.
std::vector<std::array<Vec3, 2>> outline_near(const Outline& outline, const Pose& to,
                                              const Aabb& region) {
  std::vector<std::array<Vec3, 2>> out;
  for (const auto& e : outline.segments) {
    const std::array<Vec3, 2> m{to * e[0], to * e[1]};
    Aabb box;
    box.extend(m[0]);
    box.extend(m[1]);
    if (box.intersects(region)) out.push_back(m);
  }
  return out;
}

// Outline segments compared pairwise at most: beyond this the pair is left to the next steps.
constexpr std::size_t kMaxOutlinePairs = 1u << 16;

}  // namespace

void edge_witness_step(const Model& m, std::span<const Pose> poses, const DecideTask& t, FaceView fa, FaceView fb,
                       Pending& p, const CollideOptions& o, CollideCounters& c) {
  const Part& pa = m.parts[fa.surface.part];
  const Part& pb = m.parts[fb.surface.part];
  if (!pa.source || !pb.source || fa.outline == nullptr || fb.outline == nullptr) return;  // closed faces: no outline
  // Both in A's frame: A's outline near B, and B's near A.
  const double reach = p.threshold + p.band;
  const auto sa = outline_near(*fa.outline, Pose::Identity(), pad_box(transform_box(own_box(fb.surface), t.t_ab()), reach));
  const auto sb = outline_near(*fb.outline, t.t_ab(), pad_box(own_box(fa.surface), reach));
  if (sa.empty() || sb.empty() || sa.size() * sb.size() > kMaxOutlinePairs) return;
  Closest best;
  vertices_against_segments(sa, sb, true, best);
  vertices_against_segments(sb, sa, false, best);
  ++c.witness_queries;
  const std::optional<double> d = pa.source->edge_distance(t.sa - pa.first_surface, poses[t.ia], *pb.source,
                                                           t.sb - pb.first_surface, poses[t.ib], best.a, t.t_ba() * best.b);
  if (!d || !(*d + t.roundoff <= p.threshold)) return;
  p.d.hi = std::min(p.d.hi, *d + t.roundoff);
  settle(p, Verdict::Contact, DecidedBy::Exact, t.outcome, o.clearance);
}

// The exact faces' distance by BRepExtrema (SurfaceSource::exact_distance). Its value is the
// distance of two points it found on the faces: an upper bound on d*, and OCCT 7.6 can miss the
// minimum of two B-spline faces (tests/collide/test_certified_truth.cpp has such a pair). So a value
// <= T proves contact; a larger one only lowers the interval's top, and "apart" needs a lower bound
// from finer triangles (corroborate). Returns false when the faces have no exact geometry.
bool exact_step(const Model& m, std::span<const Pose> poses, const DecideTask& t, Pending& p,
                const CollideOptions& o, CollideCounters& c) {
  const Surface& a = m.surfaces[t.sa];
  const Surface& b = m.surfaces[t.sb];
  const Part& pa = m.parts[a.part];
  const Part& pb = m.parts[b.part];
  if (!pa.source || !pb.source) return false;
  ++c.exact_queries;
  const double search = std::max(p.threshold, o.clearance);
  // Certified: any two points within T prove contact, so the search may stop there (vertex and edge
  // levels before the face–face one). Exact mode measures the minimum.
  const double enough = o.decision == DecisionMode::Certified ? p.threshold : 0.0;
  const std::optional<double> d = pa.source->exact_distance(t.sa - pa.first_surface, poses[t.ia], *pb.source,
                                                            t.sb - pb.first_surface, poses[t.ib], search, enough);
  if (!d) return false;
  p.exact = *d;
  // p.band stays the triangles' band: the exact distance says nothing about how deep faces cross,
  // so penetration is still judged on the triangles' crossing depth beyond T + band.
  if (*d <= p.threshold) {
    p.d.hi = std::min(p.d.hi, *d);
    p.d.lo = std::min(p.d.lo, p.d.hi);
    settle(p, Verdict::Contact, DecidedBy::Exact, t.outcome, o.clearance);
  } else {
    if (*d <= search) p.d.hi = std::max(p.d.lo, std::min(p.d.hi, *d));
    // Apart needs a lower bound: one already known (the boxes of a face without triangles, say) or
    // the finer triangles' (corroborate).
    if (p.d.lo > p.threshold) settle(p, Verdict::Apart, DecidedBy::Exact, t.outcome, o.clearance);
    else p.needs_lower = true;
  }
  return true;
}

void count(CollideCounters& c, DecidedBy by) {
  switch (by) {
    case DecidedBy::Mesh: ++c.decided_mesh; break;
    case DecidedBy::MeshExact: ++c.decided_mesh_exact; break;
    case DecidedBy::Analytic: ++c.decided_analytic; break;
    case DecidedBy::Refined: ++c.decided_refined; break;
    case DecidedBy::Exact: ++c.decided_exact; break;
    case DecidedBy::Undecided: ++c.undecided; break;
  }
}

SurfacePairResult make_result(const DecideTask& t, const PairOutcome* out, ContactClass cls) {
  SurfacePairResult r;
  r.instance_a = t.ia;
  r.instance_b = t.ib;
  r.surface_a = t.sa;
  r.surface_b = t.sb;
  r.contact = cls;
  if (out != nullptr) {
    r.intersecting = out->intersecting;
    r.distance = out->intersecting ? 0.0 : out->distance;
    r.penetration = out->penetration;
    r.triangle_pairs = out->triangle_pairs;
  } else {
    r.distance = std::numeric_limits<double>::infinity();
  }
  return r;
}

// Fast mode: the band of the triangles alone, as before certification.
std::optional<SurfacePairResult> fast(const Model& m, const DecideTask& t, const CollideOptions& o) {
  if (t.outcome == nullptr) return std::nullopt;
  const double band = m.surfaces[t.sa].deflection + m.surfaces[t.sb].deflection;
  const double tau = band_threshold(m.surfaces[t.sa], m.surfaces[t.sb], o.tolerance);  // tolerance + band
  const auto cls = classify(*t.outcome, tau, o.clearance);
  if (!cls) return std::nullopt;
  SurfacePairResult r = make_result(t, t.outcome, *cls);
  const Interval d = mesh_interval(*t.outcome, band, tau);
  r.distance_lo = d.lo;
  r.distance_hi = d.hi;
  return r;
}

}  // namespace cadclash::detail
