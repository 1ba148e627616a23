// The decision stage: each candidate surface pair's class, certified on the exact faces (collide.h,
// "Certified decisions"). The steps (decide_steps.h) run over the pairs each leaves open, cheapest
// first, in parallel, each answer depending on its pair alone.
#include "decide_steps.h"
#include "scene_data.h"  // add(CollideCounters)
#include "team_loop.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <limits>
#include <memory>
#include <thread>

namespace cadclash::detail {
namespace {

// What early() left of a task, one byte per task (written once by the thread that ran it).
enum EarlyState : char { kAmbiguous = 1, kAnswered = 2 };

// The tasks still open (not answered by early(), nor settled or cut since) whose pending state
// satisfies `keep`, in task order. An answered task's pending state is never read: the thread that
// answered it may hold its cache line.
template <class Keep>
std::vector<std::size_t> select(const std::vector<char>& state, const std::vector<Pending>& pending, Keep keep) {
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < pending.size(); ++k)
    if (!(state[k] & kAnswered) && !pending[k].settled && !pending[k].cut && keep(k)) out.push_back(k);
  return out;
}

// The faces refinement helps for the listed tasks (faces_to_refine), each once, ascending, but
// those `regional` says a task refines near the other face only.
template <class Regional>
std::vector<SurfaceId> refinable_faces(const Model& model, std::span<const DecideTask> tasks,
                                       const std::vector<std::size_t>& ks, Regional regional) {
  std::vector<SurfaceId> faces;
  for (std::size_t k : ks)
    for (SurfaceId s : faces_to_refine(model, tasks[k]))
      if (!regional(k, s)) faces.push_back(s);
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
  dynamic_loop(n, threads, true, [&](std::ptrdiff_t i) {
    const std::size_t k = ks[static_cast<std::size_t>(i)];
    if (deadline.expired()) pending[k].cut = true;
    else step(k);
  });
}

}  // namespace

// Seconds one task's steps took (CollideTimings' decide_* fields).
struct StepSeconds {
  double witness = 0.0, depth = 0.0, refine = 0.0, hull = 0.0, exact = 0.0;
};

// Runs f, adding the seconds it took to `into`.
template <class F>
auto timed(double& into, F f) {
  const auto start = std::chrono::steady_clock::now();
  struct Add {
    double& into;
    std::chrono::steady_clock::time_point start;
    ~Add() { into += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
  } add{into, start};
  return f();
}

// One decision run: its inputs, and each pair's state between the steps.
struct DecisionRun::Impl {
  const Model& model;
  std::span<const Pose> poses;
  std::span<const double> eps;    // the contact band's ε (T = tolerance + εa + εb)
  std::span<const double> slack;  // how far a face's points may lie off it (face_slack)
  std::span<const SurfaceBvh> bvh;
  std::span<const DecideTask> tasks;
  RefineCache& refined;
  OutlineCache& outlines;
  const CollideOptions& o;
  int threads;
  const Deadline& deadline;
  bool depth;  // run the depth step (decide_pairs)
  std::vector<Pending> pending = std::vector<Pending>(tasks.size());
  std::vector<CollideCounters> task_counters = std::vector<CollideCounters>(tasks.size());
  std::vector<char> state = std::vector<char>(tasks.size(), 0);  // EarlyState bits
  std::vector<DecideResult> answers = std::vector<DecideResult>(tasks.size());
  std::vector<StepSeconds> seconds = std::vector<StepSeconds>(tasks.size());
  double meshing = 0.0;  // refine_surfaces' time, summed over its threads (written by one thread at a time)
  std::vector<SurfaceId> refined_faces{};  // faces this run meshed finer, whole or in part (each counted once)

  bool meshed(std::size_t k) const { return tasks[k].outcome != nullptr; }
  FaceView view(SurfaceId f) const {
    const Outline& outline = outlines.outline[f];
    return FaceView{model.surfaces[f], bvh[f], outline.empty() ? nullptr : &outline};
  }
  FaceView finer(SurfaceId f) const { return finer_view(model, bvh, refined.surfaces, f); }
  // The open pairs that satisfy `keep`.
  template <class Keep>
  std::vector<std::size_t> open(Keep keep) const { return select(state, pending, keep); }
  template <class Step>
  void step(const std::vector<std::size_t>& ks, Step s) { run_step(ks, pending, threads, deadline, s); }

  // Surface f's outline, made on its first need by the thread that meets it (the Scene keeps it);
  // a thread that needs it meanwhile waits. The outline depends on the triangles alone, so which
  // thread makes it changes nothing.
  void need_outline(SurfaceId f) {
    std::atomic_ref<char> ready(outlines.ready[f]);  // 0: not made, 1: made, 2: being made
    if (ready.load(std::memory_order_acquire) == 1) return;
    char expected = 0;
    if (ready.compare_exchange_strong(expected, 2, std::memory_order_acq_rel)) {
      outlines.outline[f] = make_outline(model.surfaces[f].mesh);
      ready.store(1, std::memory_order_release);
      return;
    }
    while (ready.load(std::memory_order_acquire) != 1) std::this_thread::yield();
  }

  // Steps 1 to 3c of task k, on the calling thread: each task's answer depends on it alone, so
  // the tasks may run in any order and on any threads. The task's state and counters stay on the
  // thread's stack until it ends (as the triangle level's, stage_triangles.cpp): written once.
  // A task these steps settle (or cut) is answered here too, with its counts: steps 4 to 6 take
  // open tasks only, and finish() then only adds the counts up (on 2 threads, reading back every
  // task's state and result after the loop missed the cache for each task the other thread ran).
  void early(std::size_t k) {
    Pending p;
    CollideCounters c;
    const bool ambiguous = timed(seconds[k].witness, [&] { return early(k, p, c); });
    timed(seconds[k].depth, [&] { deepen(k, p, c); });
    char st = ambiguous ? kAmbiguous : 0;
    if (p.settled || p.cut) {
      CollideCounters counts;
      answers[k] = answer(k, p, c, counts);
      task_counters[k] = counts;
      st |= kAnswered;
    } else {
      pending[k] = std::move(p);
      task_counters[k] = c;
    }
    state[k] = st;
  }
  // Steps 1 to 3c into p and c; whether steps 1 and 2 left the task open (ambiguous).
  bool early(std::size_t k, Pending& p, CollideCounters& c);
  // A contact of a planar face with another whose triangles cross it deeper than T: proved
  // penetrating on the exact surfaces where it can be (depth_step), whichever step proved the
  // contact. Past the deadline the pair is cut, as any unfinished step leaves it.
  void deepen(std::size_t k, Pending& p, CollideCounters& c) {
    if (!depth || !depth_step_applies(model, tasks[k], p)) return;
    if (deadline.expired()) {
      p.cut = true;
      return;
    }
    need_outline(tasks[k].sa);
    need_outline(tasks[k].sb);
    depth_step(model, tasks[k], view(tasks[k].sa), view(tasks[k].sb), p, c);
  }
  // Task k's answer from its final state p, adding to `counts` the work its steps counted (`steps`)
  // and what decided it.
  DecideResult answer(std::size_t k, Pending& p, const CollideCounters& steps, CollideCounters& counts) const;
};

bool DecisionRun::Impl::early(std::size_t k, Pending& p, CollideCounters& c) {
  const DecideTask& t = tasks[k];
  // Steps 1 and 2: the triangles' interval and the surfaces' parameters, microseconds per pair.
  p = from_mesh(model, eps, t, o);
  const bool certified = o.decision == DecisionMode::Certified;
  if (!p.settled && certified && meshed(k)) analytic(model, slack, t, p, o);
  const bool ambiguous = !p.settled;
  if (!certified || p.settled || !meshed(k)) return ambiguous;
  // Steps 2b to 3c: witnesses of contact, each a few point queries, in order until one settles it;
  // each only while the time lasts (a step past the deadline marks the pair cut).
  auto next = [&] {
    if (p.settled || p.cut) return false;
    if (deadline.expired()) p.cut = true;
    return !p.cut;
  };
  if (!next()) return ambiguous;
  need_outline(t.sa);  // step 2b asks the outlines of both surfaces
  need_outline(t.sb);
  const FaceView a = view(t.sa), b = view(t.sb);
  // Step 2b: analytic contact witnesses, on the outlines.
  analytic_contact(slack, t, a, b, p, o);
  // Step 2c: faces crossing a plane of the other (sunk, pressed in): a point of the crossing. Only
  // where the triangles cross deeper than T: faces lying on each other or meeting at an edge cross
  // by round-off only, and the vertex witnesses prove those.
  if (t.outcome->intersecting && t.outcome->crosses_threshold && next()) crossing_step(model, slack, t, a, b, p, o, c);
  // Step 2d: cylinders, cones and spheres tangent to a plane: their support point.
  if (next()) tangent_step(model, slack, t, a, b, p, o, c);
  // Step 3: witness vertices near the other face (a few exact point queries each).
  if (next()) witness_step(model, slack, t, a, b, t.outcome, p.band, p, o, c);
  // Step 3b: faces meeting edge to edge (a curved edge tangent to another): one Newton each.
  if (next()) edge_witness_step(model, poses, t, a, b, p, o, c);
  // Step 3c: faces touching a plane at one point of a curved edge: the edge's extremum.
  if (next()) edge_support_step(model, slack, t, a, b, p, o, c);
  return ambiguous;
}

DecideResult DecisionRun::Impl::answer(std::size_t k, Pending& p, const CollideCounters& steps,
                                       CollideCounters& counts) const {
  const DecideTask& t = tasks[k];
  counts.exact_queries += steps.exact_queries;
  counts.witness_queries += steps.witness_queries;
  counts.distance_tests += steps.distance_tests;
  DecideResult out;
  if (p.cut) {
    out.cut = true;
    return out;
  }
  if (!p.settled) {  // nothing could decide it: say so, with what is known
    if (!(p.d.lo <= std::max(p.threshold, o.clearance))) return out;
    p.cls = ContactClass::Undecided;
    p.by = DecidedBy::Undecided;
  }
  if (p.dropped) {
    // Counted (with what proved it) when the triangles' band alone, fast mode, would have called it
    // in contact; the many pairs every mode leaves out are not.
    if (t.outcome != nullptr) {
      const double band = band_threshold(model.surfaces[t.sa], model.surfaces[t.sb], o.tolerance);
      if (classify(*t.outcome, band, 0.0)) {
        ++counts.dismissed_pairs;
        count(counts, p.by);
      }
    }
    return out;
  }
  if (!p.cls) return out;
  count(counts, p.by);
  SurfacePairResult r = make_result(t, t.outcome, *p.cls);
  r.penetration = std::max(r.penetration, p.depth);
  r.decided_by = p.by;
  r.distance_lo = p.d.lo;
  r.distance_hi = p.d.hi;
  r.exact_distance = p.exact;
  out.result = std::move(r);
  return out;
}

namespace {

using Run = DecisionRun::Impl;

// A pair's finer parts of its large faces (refines_by_region), and how far the faces' points outside
// them are from the other face at least.
struct Regions {
  std::shared_ptr<const RefinedSurface> a, b;
  double outside = std::numeric_limits<double>::infinity();
};

// Step 4: finer triangles shrink the band tenfold: they can prove a gap the triangles see (apart),
// not a contact within T (far below any band): crossing or touching triangles go on. A large face
// of which the pair reaches a small part (a board's top face near one pin) is meshed finer only
// there, by the pair's thread; other faces whole, once for every pair that needs them.
void refinement_step(Run& run) {
  const Model& model = run.model;
  const auto& tasks = run.tasks;
  const std::vector<std::size_t> gaps = run.open([&](std::size_t k) {
    if (!run.meshed(k) || !refinement_can_separate(model, tasks[k], run.pending[k])) return false;
    const std::vector<SurfaceId> which = faces_to_refine(model, tasks[k]);
    return std::any_of(which.begin(), which.end(), [&](SurfaceId s) { return can_refine(model, s); });
  });
  if (gaps.empty()) return;
  // Where the faces can come within reach of each other: points of a face outside its region lie
  // farther than `outside` from the other face (the boxes enclose the exact faces; the mapping
  // rounds by at most the pair's round-off), far past T.
  std::vector<Regions> regions(tasks.size());
  std::vector<std::uint32_t> made_before(run.refined.regions_made);
  run.step(gaps, [&](std::size_t k) {
    const DecideTask& t = tasks[k];
    const Pending& p = run.pending[k];
    const Surface& a = model.surfaces[t.sa];
    const Surface& b = model.surfaces[t.sb];
    const double margin = 2.0 * (p.threshold + p.band) + 4.0 * t.roundoff;
    double took = 0.0;
    for (SurfaceId s : faces_to_refine(model, t)) {
      if (!can_refine(model, s)) continue;
      const Aabb region = reach_region(t, a, b, s == t.sa, margin);
      if (!refines_by_region(model.surfaces[s], region)) continue;
      (s == t.sa ? regions[k].a : regions[k].b) = refine_region(model, s, region, run.refined, took);
    }
    if (regions[k].a || regions[k].b) regions[k].outside = margin - 2.0 * t.roundoff;
    run.seconds[k].refine += took;
  });
  for (SurfaceId s = 0; s < made_before.size(); ++s)
    if (run.refined.regions_made[s] > made_before[s]) run.refined_faces.push_back(s);
  const auto by_region = [&](std::size_t k, SurfaceId s) {
    return static_cast<bool>(s == tasks[k].sa ? regions[k].a : regions[k].b);
  };
  if (!run.deadline.expired())
    refine_surfaces(model, refinable_faces(model, tasks, gaps, by_region), run.refined.surfaces, run.threads,
                    run.refined_faces, &run.meshing);
  run.step(gaps, [&](std::size_t k) {
    const Regions& r = regions[k];
    auto view = [&](SurfaceId s, const std::shared_ptr<const RefinedSurface>& part) {
      return part ? FaceView{part->surface, part->bvh} : run.finer(s);
    };
    timed(run.seconds[k].refine, [&] {
      refined_step(model, run.slack, tasks[k], view(tasks[k].sa, r.a), view(tasks[k].sb, r.b), run.pending[k], run.o,
                   run.task_counters[k], r.outside);
    });
  });
}

// Step 3d (certified): the faces' control hulls, before any face is meshed again. A bounded search
// of a few microseconds to milliseconds per pair, where refinement re-meshes a whole face (the board
// under a component, thousands of triangles, for each wall standing off it by less than its band).
void hull_pass(Run& run) {
  run.step(run.open([](std::size_t) { return true; }), [&](std::size_t k) {
    timed(run.seconds[k].hull, [&] {
      hull_step(run.model, run.poses, run.slack, run.tasks[k], run.pending[k], run.o, run.task_counters[k]);
    });
  });
}

// Steps 5 and 6: the exact faces for what is still open, and exact values above T corroborated (or
// contradicted) by finer triangles.
void exact_steps(Run& run) {
  const Model& model = run.model;
  const auto& tasks = run.tasks;
  run.step(run.open([](std::size_t) { return true; }), [&](std::size_t k) {
    Pending& p = run.pending[k];
    if (timed(run.seconds[k].exact, [&] { return exact_step(model, run.poses, tasks[k], p, run.o, run.task_counters[k]); }) ||
        !run.meshed(k))
      return;
    // No exact geometry. Exact mode on triangles that are the surfaces: their verdict stands.
    const bool exact = triangles_are_exact(model, tasks[k].sa) && triangles_are_exact(model, tasks[k].sb);
    settle(p, verdict(p.d, p.threshold), exact ? DecidedBy::MeshExact : DecidedBy::Mesh, tasks[k].outcome,
           run.o.clearance);
  });
  const std::vector<std::size_t> check =
      run.open([&](std::size_t k) { return run.pending[k].needs_lower && run.meshed(k); });
  if (!check.empty() && !run.deadline.expired())
    refine_surfaces(model, refinable_faces(model, tasks, check, [](std::size_t, SurfaceId) { return false; }),
                    run.refined.surfaces, run.threads, run.refined_faces, &run.meshing);
  run.step(check, [&](std::size_t k) {
    timed(run.seconds[k].exact, [&] {
      corroborate(model, run.slack, tasks[k], run.finer(tasks[k].sa), run.finer(tasks[k].sb), run.pending[k], run.o,
                  run.task_counters[k]);
    });
  });
}

// Each pair's answer in task order (early()'s, or from its final state), with the counters.
std::vector<DecideResult> collect(Run& run, CollideCounters& counters) {
  for (std::size_t k = 0; k < run.tasks.size(); ++k) {
    if (run.state[k] & kAnswered) add(counters, run.task_counters[k]);
    else run.answers[k] = run.answer(k, run.pending[k], run.task_counters[k], counters);
  }
  return std::move(run.answers);
}

}  // namespace

std::vector<DecideResult> decide_pairs(const Model& model, std::span<const Pose> poses, std::span<const double> eps,
                                       std::span<const double> slack,
                                       std::span<const SurfaceBvh> bvh, std::span<const DecideTask> tasks,
                                       RefineCache& refined, OutlineCache& outline_cache,
                                       const CollideOptions& o, int threads, const Deadline& deadline,
                                       CollideCounters& counters, CollideTimings& timings, bool depth) {
  if (o.decision == DecisionMode::Fast) {
    std::vector<DecideResult> results(tasks.size());
    for (std::size_t k = 0; k < tasks.size(); ++k) results[k].result = fast(model, tasks[k], o);
    return results;
  }
  DecisionRun run(model, poses, eps, slack, bvh, tasks, refined, outline_cache, o, threads, deadline, depth);
  const auto n = static_cast<std::ptrdiff_t>(tasks.size());
  dynamic_loop(n, threads, true, [&](std::ptrdiff_t k) { run.early(static_cast<std::size_t>(k)); });
  return run.finish(counters, timings);
}

DecisionRun::DecisionRun(const Model& model, std::span<const Pose> poses, std::span<const double> eps,
                         std::span<const double> slack,
                         std::span<const SurfaceBvh> bvh, std::span<const DecideTask> tasks,
                         RefineCache& refined, OutlineCache& outlines, const CollideOptions& o,
                         int threads, const Deadline& deadline, bool depth) {
  assert(o.decision != DecisionMode::Fast);
  // Outlines are made on first need (step 2b) unless the Scene has them already.
  outlines.outline.resize(model.surfaces.size());
  outlines.ready.resize(model.surfaces.size(), 0);
  impl_ = std::unique_ptr<Impl>(new Impl{model, poses, eps, slack, bvh, tasks, refined, outlines, o, threads, deadline, depth});
}

DecisionRun::~DecisionRun() = default;

void DecisionRun::early(std::size_t k) { impl_->early(k); }

void DecisionRun::skip(std::size_t k) { impl_->pending[k].cut = true; }

std::vector<DecideResult> DecisionRun::finish(CollideCounters& counters, CollideTimings& timings) {
  Run& run = *impl_;
  for (char st : run.state) counters.ambiguous_pairs += (st & kAmbiguous) != 0;
  if (run.o.decision == DecisionMode::Certified) {
    hull_pass(run);
    refinement_step(run);
  }
  exact_steps(run);
  // Faces meshed finer, whole or in part, by steps 4 and 6: each once.
  std::sort(run.refined_faces.begin(), run.refined_faces.end());
  counters.refined_surfaces += static_cast<std::uint64_t>(
      std::unique(run.refined_faces.begin(), run.refined_faces.end()) - run.refined_faces.begin());
  // The contacts steps 4 to 6 proved, as early() does for its own.
  std::vector<std::size_t> late;
  for (std::size_t k = 0; k < run.tasks.size(); ++k)
    if (!(run.state[k] & kAnswered) && run.depth && depth_step_applies(run.model, run.tasks[k], run.pending[k])) late.push_back(k);
  dynamic_loop(static_cast<std::ptrdiff_t>(late.size()), run.threads, true, [&](std::ptrdiff_t i) {
    const std::size_t k = late[static_cast<std::size_t>(i)];
    timed(run.seconds[k].depth, [&] { run.deepen(k, run.pending[k], run.task_counters[k]); });
  });
  timings.decide_refine += run.meshing;
  for (const StepSeconds& t : run.seconds) {
    timings.decide_witness += t.witness;
    timings.decide_depth += t.depth;
    timings.decide_refine += t.refine;
    timings.decide_hull += t.hull;
    timings.decide_exact += t.exact;
  }
  return collect(run, counters);
}

}  // namespace cadclash::detail

// ---------------------------------------------------------------------------------------------
// Stage 5 of Scene::check: the decision of every finished task, into the per-instance-pair results.
// ---------------------------------------------------------------------------------------------
#include "scene_stages.h"

#include "cadclash/internal/progress_meter.h"

#include <cassert>
#include <functional>

namespace cadclash::detail {

namespace {

// The per-instance-pair state the decisions fill in.
void start_results(QueryState& q) {
  const std::size_t npairs = q.pairs.size();
  q.pair_cut.assign(npairs, 0);
  for (std::size_t k = 0; k < npairs; ++k) q.pair_cut[k] = q.pairs[k].cut;
  q.pair_intersects.assign(npairs, 0);
  q.pair_distance.assign(npairs, std::numeric_limits<double>::infinity());
  q.results.clear();
  q.result_pair.clear();
}

// Task k as the decision takes it (`outcome` null when a surface has no triangles).
DecideTask decide_task(const QueryState& q, std::size_t k, const PairOutcome* outcome) {
  const Task& t = q.tasks[k];
  const InstancePair& ip = q.pairs[t.pair];
  return {ip.a, ip.b, t.sa, t.sb, outcome, &ip.t_ab, &ip.t_ba, ip.roundoff};
}

bool usable(const Model& model, const Task& t) {
  return model.surfaces[t.sa].has_triangles && model.surfaces[t.sb].has_triangles;
}

// The decisions' answers into the query's results, after the decisions' progress: the pairs with
// nothing to decide are through at once, the rest now. The answer for task task_of[i] is results[i],
// or results[task_of[i]] when `by_task`.
void conclude(QueryState& q, std::vector<DecideResult>& results, const std::vector<std::size_t>& task_of,
              bool by_task, ProgressMeter& meter) {
  if (meter.active()) {
    std::vector<char> open(q.pairs.size(), 0);
    for (std::size_t k : task_of) open[q.tasks[k].pair] = 1;
    meter.add(static_cast<std::size_t>(std::count(open.begin(), open.end(), 0)));
  }
  meter.finish();
  q.results.reserve(task_of.size());
  q.result_pair.reserve(task_of.size());
  for (std::size_t i = 0; i < task_of.size(); ++i) {
    const std::size_t k = task_of[i];
    DecideResult& answer = results[by_task ? k : i];
    const std::uint32_t pair = q.tasks[k].pair;
    if (answer.cut) {
      q.task_cut[k] = 1;
      q.pair_cut[pair] = 1;
      continue;
    }
    if (!answer.result) continue;
    SurfacePairResult& r = *answer.result;
    q.pair_distance[pair] = std::min(q.pair_distance[pair], r.distance);
    q.charge[pair] += result_bytes(r);
    q.results.push_back(std::move(r));
    q.result_pair.push_back(pair);
  }
}

// The per-pair results' state for stage 5, with the pairs of tasks the deadline cut marked cut and
// those with intersecting triangles marked intersecting: the tasks to decide, ascending.
std::vector<std::size_t> tasks_to_decide(const Model& model, QueryState& q) {
  start_results(q);
  std::vector<std::size_t> task_of;
  task_of.reserve(q.first_task[q.cutoff]);
  for (std::size_t k = 0; k < q.first_task[q.cutoff]; ++k) {
    const Task& t = q.tasks[k];
    if (q.task_cut[k]) {
      q.pair_cut[t.pair] = 1;
      continue;
    }
    if (usable(model, t) && q.outcomes[k].intersecting) q.pair_intersects[t.pair] = 1;
    task_of.push_back(k);
  }
  return task_of;
}

}  // namespace

void decision_stage(SceneData& s, QueryState& q) {
  const Model& model = s.model;
  const std::vector<std::size_t> task_of = tasks_to_decide(model, q);  // decide[i] is task task_of[i]
  std::vector<DecideTask> decide;
  decide.reserve(task_of.size());
  for (std::size_t k : task_of) decide.push_back(decide_task(q, k, usable(model, q.tasks[k]) ? &q.outcomes[k] : nullptr));
  ProgressMeter meter(q.progress, ProgressStage::CheckPairs, q.pairs.size(), "decisions");
  std::vector<DecideResult> results =
      decide_pairs(model, s.poses, s.eps, s.slack, s.bvh, decide, s.refined, s.outlines, q.o, q.threads, q.deadline,
                   q.report.counters, q.report.timings, q.depth);
  conclude(q, results, task_of, /*by_task=*/false, meter);
}

bool decide_with_triangles(const QueryState& q) {
  return q.o.version == ParallelVersion::V1 && q.o.decision != DecisionMode::Fast && q.o.memory_budget_bytes == 0 &&
         q.threads > 1;
}

void triangle_and_decision_stage(SceneData& s, QueryState& q) {
  assert(decide_with_triangles(q));
  const Model& model = s.model;
  // Without a memory budget every task is kept (the cutoff stays past the last pair), so each task
  // is decided: its outcome pointer is set by the thread that finished its triangles, before early().
  const std::size_t ntasks = q.first_task[q.cutoff];
  std::vector<DecideTask> decide;
  decide.reserve(ntasks);
  for (std::size_t k = 0; k < ntasks; ++k) decide.push_back(decide_task(q, k, nullptr));
  DecisionRun run(model, s.poses, s.eps, s.slack, s.bvh, decide, s.refined, s.outlines, q.o, q.threads, q.deadline, q.depth);
  triangle_level_stage(s, q, [&](std::size_t k) {
    if (q.task_cut[k] || q.outcomes[k].cut) {
      run.skip(k);  // cut by the deadline: no answer, as decision_stage leaves it
      return;
    }
    if (usable(model, q.tasks[k])) decide[k].outcome = &q.outcomes[k];
    run.early(k);
  });
  assert(q.first_task[q.cutoff] == ntasks);
  const std::vector<std::size_t> task_of = tasks_to_decide(model, q);  // what decide_pairs would be given
  ProgressMeter meter(q.progress, ProgressStage::CheckPairs, q.pairs.size(), "decisions");
  std::vector<DecideResult> all = run.finish(q.report.counters, q.report.timings);  // every task's, task_of's among them
  conclude(q, all, task_of, /*by_task=*/true, meter);
}

}  // namespace cadclash::detail
