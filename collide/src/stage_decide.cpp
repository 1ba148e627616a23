// The decision stage: each candidate surface pair's class, certified on the exact faces (collide.h,
// "Certified decisions"). Cheapest evidence first; only what it leaves open goes to the next step.
#include "box_util.h"
#include "decide.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

namespace cadclash::detail {
namespace {

// Where one pair's decision stands between the steps.
struct Pending {
  Interval d;
  double threshold = 0.0;  // T
  double band = 0.0;       // δa + δb + r of the model's triangles
  bool settled = false;
  bool dropped = false;    // settled apart and not reported
  std::optional<ContactClass> cls;
  DecidedBy by = DecidedBy::Mesh;
  std::optional<double> exact;
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
    p.cls = o != nullptr && certainly_penetrating(*o, p.threshold, p.band) ? ContactClass::Penetrating
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
  p.band = a.deflection + b.deflection + t.roundoff;
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

// Step 3: the same interval on finer triangles of both faces.
void refined_step(const DecideTask& t, const std::vector<RefinedSurface>& cache, Pending& p,
                  const CollideOptions& o, CollideCounters& c) {
  const RefinedSurface& ra = cache[t.sa];
  const RefinedSurface& rb = cache[t.sb];
  if (!ra.ok || !rb.ok) return;
  const double band = ra.surface.deflection + rb.surface.deflection + t.roundoff;
  const double reach = p.threshold + band;
  const PairOutcome out = pair_outcome(ra.surface, ra.bvh, rb.surface, rb.bvh, t.t_ab, t.t_ba, reach, o.clearance, c);
  const Interval d = mesh_interval(out, band, reach);
  p.d = {std::max(p.d.lo, d.lo), std::min(p.d.hi, d.hi)};
  p.band = band;
  settle(p, verdict(p.d, p.threshold), DecidedBy::Refined, &out, o.clearance);
  // A contact proved on finer triangles is penetrating only when they prove it.
  if (p.settled && p.cls == ContactClass::Touching && certainly_penetrating(out, p.threshold, band))
    p.cls = ContactClass::Penetrating;
}

// Step 4: the exact faces' distance. Returns false when the faces have no exact geometry.
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
  p.d = *d <= search ? Interval{*d, *d} : Interval{*d, std::numeric_limits<double>::infinity()};
  p.band = 0.0;
  settle(p, verdict(p.d, p.threshold), DecidedBy::Exact, t.outcome, o.clearance);
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

std::vector<DecideResult> decide_pairs(const Model& model, std::span<const Pose> poses, std::span<const double> eps,
                                       std::span<const DecideTask> tasks, std::vector<RefinedSurface>& refined,
                                       const CollideOptions& o, int threads, const Deadline& deadline,
                                       CollideCounters& counters) {
  std::vector<DecideResult> results(tasks.size());
  if (o.decision == DecisionMode::Fast) {
    for (std::size_t k = 0; k < tasks.size(); ++k) results[k].result = fast(model, tasks[k], o);
    return results;
  }
  const auto n = static_cast<std::ptrdiff_t>(tasks.size());
  std::vector<Pending> pending(tasks.size());
  std::vector<CollideCounters> task_counters(tasks.size());
  // Steps 1 and 2: microseconds per pair.
#pragma omp parallel for num_threads(threads) schedule(guided) if (n >= 64)
  for (std::ptrdiff_t k = 0; k < n; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    pending[ku] = from_mesh(model, eps, tasks[ku], o);
    if (!pending[ku].settled && o.decision == DecisionMode::Certified && tasks[ku].outcome != nullptr)
      analytic(model, eps, tasks[ku], pending[ku], o);
  }
  for (const Pending& p : pending) counters.ambiguous_pairs += !p.settled;

  // Step 3: finer triangles for the faces of the pairs still open (certified mode; exact mode asks
  // the exact faces directly).
  std::vector<std::size_t> open;
  for (std::size_t k = 0; k < tasks.size(); ++k)
    if (!pending[k].settled && tasks[k].outcome != nullptr && o.decision == DecisionMode::Certified &&
        (can_refine(model, tasks[k].sa) || can_refine(model, tasks[k].sb)))
      open.push_back(k);
  if (!open.empty() && !deadline.expired()) {
    std::vector<SurfaceId> faces;
    for (std::size_t k : open) faces.insert(faces.end(), {tasks[k].sa, tasks[k].sb});
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    counters.refined_surfaces += refine_surfaces(model, faces, refined, threads);
    const auto nopen = static_cast<std::ptrdiff_t>(open.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) if (nopen >= 2)
    for (std::ptrdiff_t i = 0; i < nopen; ++i) {
      const std::size_t k = open[static_cast<std::size_t>(i)];
      if (deadline.expired()) pending[k].cut = true;
      else refined_step(tasks[k], refined, pending[k], o, task_counters[k]);
    }
  }

  // Step 4: the exact faces, for what is still open.
  std::vector<std::size_t> rest;
  for (std::size_t k = 0; k < tasks.size(); ++k)
    if (!pending[k].settled && !pending[k].cut) rest.push_back(k);
  const auto nrest = static_cast<std::ptrdiff_t>(rest.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) if (nrest >= 2)
  for (std::ptrdiff_t i = 0; i < nrest; ++i) {
    const std::size_t k = rest[static_cast<std::size_t>(i)];
    Pending& p = pending[k];
    if (deadline.expired()) {
      p.cut = true;
      continue;
    }
    if (exact_step(model, poses, tasks[k], p, o, task_counters[k])) continue;
    // No exact geometry. Exact mode on triangles that are the surfaces: their verdict stands.
    if (tasks[k].outcome != nullptr)
      settle(p, verdict(p.d, p.threshold),
             triangles_are_exact(model, tasks[k].sa) && triangles_are_exact(model, tasks[k].sb) ? DecidedBy::MeshExact
                                                                                               : DecidedBy::Mesh,
             tasks[k].outcome, o.clearance);
  }

  for (std::size_t k = 0; k < tasks.size(); ++k) {
    const DecideTask& t = tasks[k];
    Pending& p = pending[k];
    counters.exact_queries += task_counters[k].exact_queries;
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
