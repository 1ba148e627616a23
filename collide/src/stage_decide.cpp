// The decision stage: each candidate surface pair's class, certified on the exact faces (collide.h,
// "Certified decisions"). Cheapest evidence first; only what it leaves open goes to the next step.
#include "box_util.h"
#include "decide.h"
#include "triangle_predicates.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

namespace cadclash::detail {
namespace {

// Per surface: the outline of its triangles (boundary_edges), made for the surfaces that need it.
using Outlines = std::vector<std::vector<std::array<Vec3, 2>>>;

// Where one pair's decision stands between the steps.
struct Pending {
  Interval d;
  double threshold = 0.0;  // T
  double band = 0.0;       // δa + δb + r of the triangles the interval came from
  double mesh_band = 0.0;  // the same for the model's triangles: penetration is judged on them
  bool settled = false;
  bool dropped = false;    // settled apart and not reported
  std::optional<ContactClass> cls;
  DecidedBy by = DecidedBy::Mesh;
  std::optional<double> exact;  // BRepExtrema's value: realised by two points, so an upper bound only
  bool needs_lower = false;      // the exact value is above T: "apart" still needs a lower bound
  std::optional<PairOutcome> fine;  // the finer triangles' outcome, once refined
  bool cut = false;
};

// A box enclosing the exact face: Surface::aabb does for B-rep faces, but for a mesh it encloses the
// triangles, which may lie up to the deflection inside the surface they stand for.
Aabb own_box(const Surface& s) { return pad_box(s.aabb.isEmpty() ? mesh_aabb(s.mesh) : s.aabb, s.deflection); }

// The class of a pair proved apart: clearance when its distance (the exact one when known, else the
// mesh's) is within the clearance, else not reported.
std::optional<ContactClass> apart_class(double distance, double clearance) {
  if (clearance > 0.0 && distance <= clearance) return ContactClass::Clearance;
  return std::nullopt;
}

void settle(Pending& p, Verdict v, DecidedBy by, const PairOutcome* o, double clearance) {
  if (v == Verdict::Ambiguous) return;
  p.settled = true;
  p.by = by;
  if (v == Verdict::Contact) {
    p.cls = o != nullptr && certainly_penetrating(*o, p.threshold, p.mesh_band) ? ContactClass::Penetrating
                                                                                : ContactClass::Touching;
  } else {
    p.cls = apart_class(p.exact ? *p.exact : o != nullptr ? o->distance : p.d.lo, clearance);
    p.dropped = !p.cls;
  }
}

// Step 1: the interval of the model's triangles.
Pending from_mesh(const Model& m, std::span<const double> eps, const DecideTask& t, const CollideOptions& o) {
  const Surface& a = m.surfaces[t.sa];
  const Surface& b = m.surfaces[t.sb];
  Pending p;
  p.threshold = touch_threshold(eps[t.sa], eps[t.sb], o.tolerance);
  p.band = p.mesh_band = a.deflection + b.deflection + t.roundoff;
  const double reach = p.threshold + p.band;
  if (t.outcome == nullptr) {  // no triangles on one side: only the boxes are known
    p.d = {box_distance(own_box(a), transform_box(own_box(b), t.t_ab)), std::numeric_limits<double>::infinity()};
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

// Step 2: a plane, cylinder or sphere that the other face's triangles provably keep off.
void analytic(const Model& m, std::span<const double> eps, const DecideTask& t, Pending& p, const CollideOptions& o) {
  const Surface& a = m.surfaces[t.sa];
  const Surface& b = m.surfaces[t.sb];
  const double r = t.roundoff;
  double lb = 0.0;
  // The two surfaces' parameters: where the faces can come within T of each other, both lie in A's
  // face box and in B's grown by T.
  const Aabb box_b = transform_box(own_box(b), t.t_ab);
  const Aabb region = own_box(a).intersection(pad_box(box_b, p.threshold));
  if (region.isEmpty()) {
    lb = box_distance(own_box(a), box_b);  // the boxes enclose the exact faces
  } else if (auto g = analytic_pair_gap(a.analytic, transform_analytic(b.analytic, t.t_ab), region)) {
    lb = std::max(lb, *g - eps[t.sa] - eps[t.sb] - r);
  }
  if (b.has_triangles) {
    const double reach = p.threshold + b.deflection + r;
    if (auto g = analytic_gap(a.analytic, b.mesh, t.t_ab, own_box(a), reach))
      lb = std::max(lb, std::min(*g, reach) - b.deflection - r - eps[t.sa]);
  }
  if (a.has_triangles) {
    const double reach = p.threshold + a.deflection + r;
    if (auto g = analytic_gap(b.analytic, a.mesh, t.t_ba, own_box(b), reach))
      lb = std::max(lb, std::min(*g, reach) - a.deflection - r - eps[t.sb]);
  }
  if (!(lb > p.threshold)) return;
  p.d.lo = std::max(p.d.lo, lb);
  settle(p, Verdict::Apart, DecidedBy::Analytic, t.outcome, o.clearance);
}

// Step 2b: a vertex of one face on the other face's plane, cylinder or sphere, its foot point
// provably inside that face (analytic_witness): the faces are within εA + g + r.
void analytic_contact(const Model& m, std::span<const double> eps, const Outlines& outlines, const DecideTask& t,
                      Pending& p, const CollideOptions& o) {
  const Surface& a = m.surfaces[t.sa];
  const Surface& b = m.surfaces[t.sb];
  if (!a.has_triangles || !b.has_triangles) return;
  const double r = t.roundoff;
  const Aabb box_a = own_box(a), box_b = own_box(b);
  // A's vertices on B's surface, in B's frame; then B's on A's, in A's frame.
  const Aabb region_b = box_b.intersection(pad_box(transform_box(box_a, t.t_ba), p.threshold));
  std::optional<double> g = analytic_witness(b.analytic, b.mesh, outlines[t.sb], b.deflection, a.mesh, t.t_ba,
                                             region_b, o.tolerance + eps[t.sb] - r, r);
  double own = eps[t.sa];
  if (!g) {
    const Aabb region_a = box_a.intersection(pad_box(transform_box(box_b, t.t_ab), p.threshold));
    g = analytic_witness(a.analytic, a.mesh, outlines[t.sa], a.deflection, b.mesh, t.t_ab, region_a,
                         o.tolerance + eps[t.sa] - r, r);
    own = eps[t.sb];
  }
  if (!g || !(own + *g + r <= p.threshold)) return;
  p.d.hi = std::min(p.d.hi, own + *g + r);
  settle(p, Verdict::Contact, DecidedBy::Analytic, t.outcome, o.clearance);
}

// Witness vertices. A vertex of the deciding triangle pair lies on its own exact face (within that
// face's ε: the mesher puts nodes on the surface and its edges); when its exact distance to the
// other face is within tolerance + that face's ε (after the mapping's round-off), the faces are within
// T. Nearest vertices first; one success settles it. `a` and `b` are the model's surfaces or finer
// ones (same part and index); `out` their outcome, `band` its band.
void witness_step(const Model& m, std::span<const double> eps, const DecideTask& t, const Surface& a,
                  const Surface& b, const PairOutcome* out, double band, Pending& p, const CollideOptions& o,
                  CollideCounters& c) {
  if (out == nullptr || out->witness[0] == kInvalidId) return;
  const Part& pa = m.parts[a.part];
  const Part& pb = m.parts[b.part];
  if (!pa.source || !pb.source) return;
  const auto& ta = a.mesh.triangles[out->witness[0]];
  const auto& tb = b.mesh.triangles[out->witness[1]];
  const Vec3 va[3] = {a.mesh.vertices[ta[0]], a.mesh.vertices[ta[1]], a.mesh.vertices[ta[2]]};
  const Vec3 vb[3] = {t.t_ab * b.mesh.vertices[tb[0]], t.t_ab * b.mesh.vertices[tb[1]], t.t_ab * b.mesh.vertices[tb[2]]};
  struct Candidate {
    double near;   // its distance to the other triangle (A's frame): the order of trial
    bool of_a;     // a vertex of A's triangle, asked of B's face
    Vec3 point;    // in the part frame of the face it is asked of
  };
  std::vector<Candidate> cs;
  for (const Vec3& v : va) cs.push_back({triangle_distance(v, v, v, vb[0], vb[1], vb[2]), true, t.t_ba * v});
  for (const Vec3& v : vb) cs.push_back({triangle_distance(v, v, v, va[0], va[1], va[2]), false, v});
  std::stable_sort(cs.begin(), cs.end(), [](const Candidate& x, const Candidate& y) { return x.near < y.near; });
  for (const Candidate& cand : cs) {
    const double own_eps = cand.of_a ? eps[t.sa] : eps[t.sb];
    const double other_eps = cand.of_a ? eps[t.sb] : eps[t.sa];
    if (cand.near > o.tolerance + other_eps + band) break;  // farther ones cannot be within reach
    ++c.witness_queries;
    const std::optional<double> d =
        cand.of_a ? pb.source->point_distance(t.sb - pb.first_surface, cand.point)
                  : pa.source->point_distance(t.sa - pa.first_surface, cand.point);
    if (!d) continue;
    const double hi = own_eps + *d + t.roundoff;
    if (hi <= p.threshold) {
      p.d.hi = std::min(p.d.hi, hi);
      settle(p, Verdict::Contact, DecidedBy::Exact, t.outcome, o.clearance);
      return;
    }
  }
}

// Step 4: the same interval on finer triangles of both faces.
void refined_step(const DecideTask& t, const std::vector<RefinedSurface>& cache, Pending& p,
                  const CollideOptions& o, CollideCounters& c) {
  const RefinedSurface& ra = cache[t.sa];
  const RefinedSurface& rb = cache[t.sb];
  if (!ra.ok || !rb.ok) return;
  const double band = ra.surface.deflection + rb.surface.deflection + t.roundoff;
  const double reach = p.threshold + band;
  p.fine = pair_outcome(ra.surface, ra.bvh, rb.surface, rb.bvh, t.t_ab, t.t_ba, reach, o.clearance, c);
  const PairOutcome& out = *p.fine;
  const Interval d = mesh_interval(out, band, reach);
  p.d = {std::max(p.d.lo, d.lo), std::min(p.d.hi, d.hi)};
  p.band = band;
  if (p.d.lo > p.d.hi) p.d.lo = p.d.hi;  // cannot happen for sound bounds; keep the interval ordered
  settle(p, verdict(p.d, p.threshold), DecidedBy::Refined, &out, o.clearance);
  // A contact proved on finer triangles is penetrating only when they prove it.
  if (p.settled && p.cls == ContactClass::Touching && certainly_penetrating(out, p.threshold, band))
    p.cls = ContactClass::Penetrating;
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
  const std::optional<double> d = pa.source->exact_distance(t.sa - pa.first_surface, poses[t.ia], *pb.source,
                                                            t.sb - pb.first_surface, poses[t.ib], search);
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

// Corroborates an exact value above T: the finer triangles' lower bound proves the pair apart, their
// upper bound or a witness on them proves it in contact (BRepExtrema missed), else it stays open.
void corroborate(const Model& m, std::span<const double> eps, const DecideTask& t,
                 const std::vector<RefinedSurface>& cache, Pending& p, const CollideOptions& o, CollideCounters& c) {
  // The surfaces' parameters first (exact mode has not asked them yet): a lower bound for free.
  if (t.outcome != nullptr) analytic(m, eps, t, p, o);
  if (!p.settled && !p.fine) refined_step(t, cache, p, o, c);
  // Settled apart here: the exact value is the measured distance, the finer triangles' lower bound
  // its corroboration; it is reported as decided by the exact faces.
  if (p.settled && p.exact) p.by = DecidedBy::Exact;
  if (p.settled || !p.fine) return;
  const RefinedSurface& ra = cache[t.sa];
  const RefinedSurface& rb = cache[t.sb];
  witness_step(m, eps, t, ra.surface, rb.surface, &*p.fine, p.band, p, o, c);
  if (p.settled || !p.exact) return;
  // Deeper, for this pair alone: a band below half the exact value's margin over T proves it apart
  // if OCCT's value is right (and shows the contact if OCCT missed it). Not below a hundredth of the
  // model's deflection: the triangles grow with the inverse deflection, and past that a pair would
  // cost seconds; such knife-edge pairs are reported undecided with their interval.
  const double margin = *p.exact - p.threshold - t.roundoff;
  const double target = 0.25 * margin;
  const double floor = 1e-2 * std::max(m.surfaces[t.sa].deflection, m.surfaces[t.sb].deflection);
  if (!(target > floor) || !(target < std::max(ra.surface.deflection, rb.surface.deflection))) return;
  const RefinedSurface fa = refine_to(m, t.sa, target), fb = refine_to(m, t.sb, target);
  if (!fa.ok || !fb.ok) return;
  const double band = fa.surface.deflection + fb.surface.deflection + t.roundoff;
  const double reach = p.threshold + band;
  const PairOutcome out = pair_outcome(fa.surface, fa.bvh, fb.surface, fb.bvh, t.t_ab, t.t_ba, reach, o.clearance, c);
  const Interval d = mesh_interval(out, band, reach);
  p.d = {std::max(p.d.lo, d.lo), std::min(p.d.hi, d.hi)};
  if (p.d.lo > p.d.hi) p.d.lo = p.d.hi;
  settle(p, verdict(p.d, p.threshold), DecidedBy::Exact, t.outcome, o.clearance);
  if (!p.settled) witness_step(m, eps, t, fa.surface, fb.surface, &out, band, p, o, c);
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
  const double tau = o.tolerance + band;
  const auto cls = classify(*t.outcome, tau, o.clearance);
  if (!cls) return std::nullopt;
  SurfacePairResult r = make_result(t, t.outcome, *cls);
  const Interval d = mesh_interval(*t.outcome, band, tau);
  r.distance_lo = d.lo;
  r.distance_hi = d.hi;
  return r;
}

}  // namespace

namespace {

// The tasks whose pending state satisfies `keep`, in task order.
template <class Keep>
std::vector<std::size_t> select(const std::vector<Pending>& pending, Keep keep) {
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < pending.size(); ++k)
    if (!pending[k].settled && !pending[k].cut && keep(k)) out.push_back(k);
  return out;
}

// The surfaces of the listed tasks, each once, ascending.
std::vector<SurfaceId> faces_of(std::span<const DecideTask> tasks, const std::vector<std::size_t>& ks) {
  std::vector<SurfaceId> faces;
  for (std::size_t k : ks) faces.insert(faces.end(), {tasks[k].sa, tasks[k].sb});
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

// Runs step(k) for the listed tasks on the threads, one task at a time (a step may cost OCCT work);
// each answer depends on its task alone. Past the deadline the rest are marked cut.
template <class Step>
void run_step(const std::vector<std::size_t>& ks, std::vector<Pending>& pending, int threads,
              const Deadline& deadline, Step step) {
  const auto n = static_cast<std::ptrdiff_t>(ks.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) if (n >= 2)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const std::size_t k = ks[static_cast<std::size_t>(i)];
    if (deadline.expired()) pending[k].cut = true;
    else step(k);
  }
}

}  // namespace

std::vector<DecideResult> decide_pairs(const Model& model, std::span<const Pose> poses, std::span<const double> eps,
                                       std::span<const DecideTask> tasks, std::vector<RefinedSurface>& refined,
                                       const CollideOptions& o, int threads, const Deadline& deadline,
                                       CollideCounters& counters) {
  std::vector<DecideResult> results(tasks.size());
  if (o.decision == DecisionMode::Fast) {
    for (std::size_t k = 0; k < tasks.size(); ++k) results[k].result = fast(model, tasks[k], o);
    return results;
  }
  const bool certified = o.decision == DecisionMode::Certified;
  const auto n = static_cast<std::ptrdiff_t>(tasks.size());
  std::vector<Pending> pending(tasks.size());
  std::vector<CollideCounters> task_counters(tasks.size());
  auto meshed = [&](std::size_t k) { return tasks[k].outcome != nullptr; };
  // Steps 1 and 2: the triangles' interval and the surfaces' parameters, microseconds per pair.
#pragma omp parallel for num_threads(threads) schedule(guided) if (n >= 64)
  for (std::ptrdiff_t k = 0; k < n; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    pending[ku] = from_mesh(model, eps, tasks[ku], o);
    if (!pending[ku].settled && certified && meshed(ku)) analytic(model, eps, tasks[ku], pending[ku], o);
  }
  for (const Pending& p : pending) counters.ambiguous_pairs += !p.settled;

  if (certified) {
    // Step 2b: analytic contact witnesses, on the outlines of the open pairs' surfaces.
    const std::vector<std::size_t> open = select(pending, meshed);
    const std::vector<SurfaceId> faces = faces_of(tasks, open);
    Outlines outlines(model.surfaces.size());
    const auto nfaces = static_cast<std::ptrdiff_t>(faces.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 4) if (nfaces >= 8)
    for (std::ptrdiff_t i = 0; i < nfaces; ++i) {
      const SurfaceId f = faces[static_cast<std::size_t>(i)];
      outlines[f] = boundary_edges(model.surfaces[f].mesh);
    }
    run_step(open, pending, threads, deadline,
             [&](std::size_t k) { analytic_contact(model, eps, outlines, tasks[k], pending[k], o); });
    // Step 3: witness vertices of the deciding triangle pair (a few OCCT point distances each).
    run_step(select(pending, meshed), pending, threads, deadline, [&](std::size_t k) {
      witness_step(model, eps, tasks[k], model.surfaces[tasks[k].sa], model.surfaces[tasks[k].sb], tasks[k].outcome,
                   pending[k].band, pending[k], o, task_counters[k]);
    });
    // Step 4: finer triangles shrink the band tenfold: they can prove a gap the triangles see
    // (apart), not a contact within T (far below any band): crossing or touching triangles go on.
    const std::vector<std::size_t> gaps = select(pending, [&](std::size_t k) {
      return meshed(k) && !tasks[k].outcome->intersecting && tasks[k].outcome->distance > pending[k].threshold &&
             (can_refine(model, tasks[k].sa) || can_refine(model, tasks[k].sb));
    });
    if (!gaps.empty() && !deadline.expired())
      counters.refined_surfaces += refine_surfaces(model, faces_of(tasks, gaps), refined, threads);
    run_step(gaps, pending, threads, deadline,
             [&](std::size_t k) { refined_step(tasks[k], refined, pending[k], o, task_counters[k]); });
  }

  // Step 5: the exact faces, for what is still open.
  run_step(select(pending, [](std::size_t) { return true; }), pending, threads, deadline, [&](std::size_t k) {
    Pending& p = pending[k];
    if (exact_step(model, poses, tasks[k], p, o, task_counters[k]) || !meshed(k)) return;
    // No exact geometry. Exact mode on triangles that are the surfaces: their verdict stands.
    const bool exact = triangles_are_exact(model, tasks[k].sa) && triangles_are_exact(model, tasks[k].sb);
    settle(p, verdict(p.d, p.threshold), exact ? DecidedBy::MeshExact : DecidedBy::Mesh, tasks[k].outcome, o.clearance);
  });

  // Step 6: exact values above T, corroborated (or contradicted) by finer triangles.
  const std::vector<std::size_t> check =
      select(pending, [&](std::size_t k) { return pending[k].needs_lower && meshed(k); });
  if (!check.empty() && !deadline.expired())
    counters.refined_surfaces += refine_surfaces(model, faces_of(tasks, check), refined, threads);
  run_step(check, pending, threads, deadline,
           [&](std::size_t k) { corroborate(model, eps, tasks[k], refined, pending[k], o, task_counters[k]); });

  for (std::size_t k = 0; k < tasks.size(); ++k) {
    const DecideTask& t = tasks[k];
    Pending& p = pending[k];
    counters.exact_queries += task_counters[k].exact_queries;
    counters.witness_queries += task_counters[k].witness_queries;
    counters.distance_tests += task_counters[k].distance_tests;
    if (p.cut) {
      results[k].cut = true;
      continue;
    }
    if (!p.settled) {  // nothing could decide it: say so, with what is known
      if (!(p.d.lo <= std::max(p.threshold, o.clearance))) continue;
      p.cls = ContactClass::Undecided;
      p.by = DecidedBy::Undecided;
    }
    if (p.dropped) {
      // Counted (with what proved it) when the triangles' band alone, fast mode, would have called it
      // in contact; the many pairs every mode leaves out are not.
      if (t.outcome != nullptr) {
        const double tau = o.tolerance + model.surfaces[t.sa].deflection + model.surfaces[t.sb].deflection;
        if (classify(*t.outcome, tau, 0.0)) {
          ++counters.dismissed_pairs;
          count(counters, p.by);
        }
      }
      continue;
    }
    if (!p.cls) continue;
    count(counters, p.by);
    SurfacePairResult r = make_result(t, t.outcome, *p.cls);
    r.decided_by = p.by;
    r.distance_lo = p.d.lo;
    r.distance_hi = p.d.hi;
    r.exact_distance = p.exact;
    results[k].result = std::move(r);
  }
  return results;
}

}  // namespace cadclash::detail

// ---------------------------------------------------------------------------------------------
// Stage 5 of Scene::check: the decision of every finished task, into the per-instance-pair results.
// ---------------------------------------------------------------------------------------------
#include "scene_stages.h"

namespace cadclash::detail {

void decision_stage(SceneData& s, QueryState& q) {
  const Model& model = s.model;
  const std::size_t npairs = q.pairs.size();
  q.pair_cut.assign(npairs, 0);
  for (std::size_t k = 0; k < npairs; ++k) q.pair_cut[k] = q.pairs[k].cut;
  q.pair_intersects.assign(npairs, 0);
  q.pair_distance.assign(npairs, std::numeric_limits<double>::infinity());
  q.pair_results.assign(npairs, {});
  std::vector<DecideTask> decide;
  std::vector<std::size_t> task_of;  // decide[i] is task task_of[i]
  for (std::size_t k = 0; k < q.first_task[q.cutoff]; ++k) {
    const Task& t = q.tasks[k];
    if (q.task_cut[k]) {
      q.pair_cut[t.pair] = 1;
      continue;
    }
    const InstancePair& ip = q.pairs[t.pair];
    const bool usable = model.surfaces[t.sa].has_triangles && model.surfaces[t.sb].has_triangles;
    if (usable && q.outcomes[k].intersecting) q.pair_intersects[t.pair] = 1;
    decide.push_back({ip.a, ip.b, t.sa, t.sb, usable ? &q.outcomes[k] : nullptr, ip.t_ab, ip.t_ba, ip.roundoff});
    task_of.push_back(k);
  }
  std::vector<DecideResult> results =
      decide_pairs(model, s.poses, s.eps, decide, s.refined, q.o, q.threads, q.deadline, q.report.counters);
  for (std::size_t i = 0; i < results.size(); ++i) {
    const std::size_t k = task_of[i];
    const std::size_t pair = q.tasks[k].pair;
    if (results[i].cut) {
      q.task_cut[k] = 1;
      q.pair_cut[pair] = 1;
      continue;
    }
    if (!results[i].result) continue;
    SurfacePairResult& r = *results[i].result;
    q.pair_distance[pair] = std::min(q.pair_distance[pair], r.distance);
    q.charge[pair] += result_bytes(r);
    q.pair_results[pair].push_back(std::move(r));
  }
}

}  // namespace cadclash::detail
