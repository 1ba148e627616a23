// Stage 4: the triangle level, Version 1 (one item per surface pair) or 2 (surface pair × block of
// A's triangles), over the tasks of the pairs within the memory budget. With the time budget out,
// remaining items are skipped and marked cut (an OpenMP loop cannot break).
#include "decide.h"
#include "scene_stages.h"
#include "task_costs.h"
#include "team_loop.h"

#include "cadclash/internal/progress_meter.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <functional>

namespace cadclash::detail {
namespace {

// Work blocks of Version 2: this many of A's surviving triangles per item.
constexpr std::size_t kV2Block = 64;
constexpr std::ptrdiff_t kMinParallel = 4;
constexpr std::ptrdiff_t kFewItems = 64;

bool usable(const Model& m, const Task& t) {
  return m.surfaces[t.sa].has_triangles && m.surfaces[t.sb].has_triangles;
}

// The search reach of a task: the fast band, or everything a certified decision needs to see.
double task_tau(const SceneData& s, const QueryState& q, const Task& t) {
  const Surface& a = s.model.surfaces[t.sa];
  const Surface& b = s.model.surfaces[t.sb];
  if (q.o.decision == DecisionMode::Fast) return band_threshold(a, b, q.o.tolerance);
  return certified_reach(a, s.eps[t.sa], b, s.eps[t.sb], q.o.tolerance, q.pairs[t.pair].roundoff);
}

// The triangle level's progress in instance pairs (CheckPairs, "triangle level"): a pair is through
// when the last of its work items is; pairs without items are through at once. Without a progress
// callback it does nothing.
class PairsThrough {
 public:
  // pair_of(i): the instance pair of work item i < n.
  template <class PairOf>
  PairsThrough(const QueryState& q, std::size_t n, PairOf pair_of)
      : meter_(q.progress, ProgressStage::CheckPairs, q.pairs.size(), "triangle level") {
    if (!meter_.active()) return;
    left_ = std::vector<std::atomic<std::uint32_t>>(q.pairs.size());
    for (std::size_t i = 0; i < n; ++i) left_[pair_of(i)].fetch_add(1, std::memory_order_relaxed);
    std::size_t idle = 0;
    for (const auto& l : left_) idle += l.load(std::memory_order_relaxed) == 0;
    meter_.add(idle);
  }
  // One work item of instance pair `pair` finished (or was skipped); any thread.
  void item_done(std::uint32_t pair) {
    if (meter_.active() && left_[pair].fetch_sub(1, std::memory_order_relaxed) == 1) meter_.add();
  }
  void finish() { meter_.finish(); }

 private:
  ProgressMeter meter_;
  std::vector<std::atomic<std::uint32_t>> left_;
};

// `one_run`: one run_pair covers the whole pair (Version 1), so it may make its own candidates.
// Into `out` (q.prepared[k], or Version 1's per-thread scratch), counting into `counters`, the
// survivor lists' bytes into `bytes`; false when the task is not usable.
bool prepare(const SceneData& s, QueryState& q, std::size_t k, std::uint64_t& bytes, bool one_run, PreparedPair& out,
             CollideCounters& counters) {
  const Task& t = q.tasks[k];
  if (!usable(s.model, t)) return false;
  const InstancePair& ip = q.pairs[t.pair];
  prepare_pair_reach(s.model.surfaces[t.sa], s.bvh[t.sa], s.model.surfaces[t.sb], s.bvh[t.sb], ip.t_ab, ip.t_ba, q.o,
                     task_tau(s, q, t), out, counters, one_run);
  // Certified: the decision's crossing step asks whether the triangles cross deeper than T, and
  // only where one face is a plane (decide_crossing.cpp); elsewhere the run need not find out.
  const Surface& a = s.model.surfaces[t.sa];
  const Surface& b = s.model.surfaces[t.sb];
  // The depth step asks whether the exact faces may cross deeper than T: triangles crossing deeper
  // than T less their band (tau - T), and deeper than the rounding (faces lying on each other or
  // meeting at an edge cross by round-off only).
  if (q.o.decision != DecisionMode::Fast &&
      (a.analytic.shape == SurfaceShape::Plane || b.analytic.shape == SurfaceShape::Plane)) {
    out.threshold = touch_threshold(s.eps[t.sa], s.eps[t.sb], q.o.tolerance);
    out.low = std::min(out.threshold, std::max(out.threshold - (out.tau - out.threshold), out.slack));
  }
  bytes = prepared_bytes(out);
  return true;
}

void run_v1(SceneData& s, QueryState& q, std::size_t ntasks, std::vector<std::uint64_t>& bytes,
            const std::function<void(std::size_t)>& after) {
  const auto n = static_cast<std::ptrdiff_t>(ntasks);
  PairsThrough through(q, ntasks, [&](std::size_t k) { return q.tasks[k].pair; });
  const bool team = use_team(n, q.threads, n >= kMinParallel);
  // Guided gives a thread half of the items at its first request: with a handful of items that is
  // half the work on one thread (collide.h, Schedule), so a short loop on a team takes them one at a
  // time, the tasks the last check found longest first (task_costs.h), each timed for the next
  // check. The loop's answers do not depend on the order.
  const bool few = team && n < kFewItems && q.o.schedule == Schedule::Guided;
  std::vector<TaskCosts::Key> keys;
  std::vector<std::uint32_t> order;
  std::vector<float> took;
  if (few) {
    keys.resize(ntasks);
    for (std::size_t k = 0; k < ntasks; ++k) {
      const Task& t = q.tasks[k];
      keys[k] = TaskCosts::key(q.pairs[t.pair].a, q.pairs[t.pair].b, t.sa, t.sb);
    }
    order = s.task_costs.longest_first(keys);
    took.assign(ntasks, 0.0F);
  }
  // The region's body: for a team, or for the calling thread alone (team_loop.h: a region with a
  // false if clause still starts a team of one).
  // Its loops end `nowait`: the region's end is the one barrier the stage needs (nothing a thread
  // does after the loop reads another's work), and the loop's own barrier cost every path step of
  // bench_scale_path on 2 threads 0.6-1.4 us of idle time (8 same-steps A/B runs, vCPUs near).
  auto run = [&] {
    // One pair at a time per thread: its survivor lists reuse the thread's buffers, freed with them
    // when the stage ends.
    PreparedPair scratch;
    auto one = [&](std::size_t ku) {
      if (q.deadline.expired()) {
        q.task_cut[ku] = 1;
      } else {
        // The task's outcome and counters stay on this thread's stack until it ends, then are
        // written once: neighbouring tasks' entries share cache lines, and another thread writing
        // its task's entry meanwhile took the line back and forth at every update (a path step on
        // 2 threads with the vCPUs on different core complexes: the second thread's triangle level
        // took 1.34x one thread's time, 1.01x with the entries written once).
        PairOutcome outcome;
        CollideCounters counters;
        if (prepare(s, q, ku, bytes[ku], /*one_run=*/true, scratch, counters))
          run_pair(s.model.surfaces[q.tasks[ku].sa], scratch, 0, scratch.la.size(), q.o, outcome, counters,
                   &q.deadline);
        q.outcomes[ku] = std::move(outcome);
        q.task_counters[ku] = counters;
      }
      if (after) after(ku);
      through.item_done(q.tasks[ku].pair);
    };
    if (!team) {
      for (std::ptrdiff_t k = 0; k < n; ++k) one(static_cast<std::size_t>(k));
    } else if (few) {
#pragma omp for schedule(dynamic, 1) nowait
      for (std::ptrdiff_t i = 0; i < n; ++i) {
        const std::size_t k = order[static_cast<std::size_t>(i)];
        const auto t0 = std::chrono::steady_clock::now();
        one(k);
        took[k] = std::chrono::duration<float>(std::chrono::steady_clock::now() - t0).count();
      }
    } else {
#pragma omp for schedule(runtime) nowait
      for (std::ptrdiff_t k = 0; k < n; ++k) one(static_cast<std::size_t>(k));
    }
  };
  if (team) {
#pragma omp parallel num_threads(q.threads)
    run();
  } else {
    run();
  }
  if (few) s.task_costs.remember(keys, took);
  through.finish();
}

// Version 2 holds every survivor list at once: they are charged, and the budget applied, before the
// blocks run, so pairs past the new cutoff are released unrun.
void run_v2(const SceneData& s, QueryState& q, std::size_t ntasks, std::vector<std::uint64_t>& bytes) {
  const auto n = static_cast<std::ptrdiff_t>(ntasks);
  runtime_loop(n, q.threads, n >= kMinParallel, [&](std::ptrdiff_t k) {
    if (q.deadline.expired()) q.task_cut[static_cast<std::size_t>(k)] = 1;
    else {
      const auto ku = static_cast<std::size_t>(k);
      prepare(s, q, ku, bytes[ku], /*one_run=*/false, q.prepared[ku], q.task_counters[ku]);
    }
  });
  for (std::size_t k = 0; k < ntasks; ++k) q.charge[q.tasks[k].pair] += bytes[k];
  q.apply_memory_budget();
  for (std::size_t k = q.first_task[q.cutoff]; k < ntasks; ++k) q.prepared[k] = PreparedPair{};
  ntasks = q.first_task[q.cutoff];
  struct Item {
    std::size_t task, begin, end;
  };
  std::vector<Item> items;
  for (std::size_t k = 0; k < ntasks; ++k)
    for (std::size_t b = 0; b < q.prepared[k].la.size(); b += kV2Block)
      items.push_back({k, b, std::min(q.prepared[k].la.size(), b + kV2Block)});
  std::vector<PairOutcome> item_out(items.size());
  std::vector<CollideCounters> item_counters(items.size());
  const auto nitems = static_cast<std::ptrdiff_t>(items.size());
  PairsThrough through(q, items.size(), [&](std::size_t i) { return q.tasks[items[i].task].pair; });
  runtime_loop(nitems, q.threads, nitems >= kMinParallel, [&](std::ptrdiff_t i) {
    const auto iu = static_cast<std::size_t>(i);
    const Item& it = items[iu];
    if (q.deadline.expired()) item_out[iu].cut = true;
    else run_pair(s.model.surfaces[q.tasks[it.task].sa], q.prepared[it.task], it.begin, it.end, q.o, item_out[iu],
                  item_counters[iu], &q.deadline);
    through.item_done(q.tasks[it.task].pair);
  });
  through.finish();
  for (std::size_t i = 0; i < items.size(); ++i) {  // fixed order: independent of the thread count
    merge_outcome(q.outcomes[items[i].task], std::move(item_out[i]));
    add(q.task_counters[items[i].task], item_counters[i]);
  }
  for (std::size_t k = 0; k < ntasks; ++k) q.prepared[k] = PreparedPair{};
}

}  // namespace

void triangle_level_stage(SceneData& s, QueryState& q, const std::function<void(std::size_t)>& after) {
  assert(!after || q.o.version == ParallelVersion::V1);
  const std::size_t ntasks = q.first_task[q.cutoff];
  q.prepared.assign(q.o.version == ParallelVersion::V1 ? 0 : q.tasks.size(), PreparedPair{});  // V1: per thread
  q.outcomes.assign(q.tasks.size(), PairOutcome{});
  q.task_counters.assign(q.tasks.size(), CollideCounters{});
  q.task_cut.assign(q.tasks.size(), 0);
  std::vector<std::uint64_t> bytes(q.tasks.size(), 0);
  if (q.o.version == ParallelVersion::V1) {
    run_v1(s, q, ntasks, bytes, after);
    for (std::size_t k = 0; k < ntasks; ++k) q.charge[q.tasks[k].pair] += bytes[k];
    q.apply_memory_budget();
  } else {
    run_v2(s, q, ntasks, bytes);
  }
  for (std::size_t k = 0; k < q.first_task[q.cutoff]; ++k)
    if (q.outcomes[k].cut) q.task_cut[k] = 1;
}

}  // namespace cadclash::detail
