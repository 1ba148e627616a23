// The stages of Scene::check, in the order it runs them. Each reads the scene and writes the query
// state (scene_data.h); the OpenMP loops inside merge in a fixed order, so what a stage leaves does
// not depend on the thread count. Internal to cadclash::collide.
#pragma once

#include "scene_data.h"

#include <functional>
#include <span>
#include <vector>

namespace cadclash::detail {

// 0. Why the query is outside the supported range (model.h), if it is: the options, then each
//    selected instance whose part (box, deflections, uncertainties) or pose is; at most 16 listed.
std::vector<Diagnostic> range_errors(SceneData& s, const CollideOptions& o);
// A refused query's report: nothing examined, complete false, stopped_by "out of range".
void refuse(Report& r, std::vector<Diagnostic> errors);

// 1. World boxes of the instances moved since the last check, then sweep-and-prune over them (brute
//    force: every selected pair) → q.pairs.
void broad_phase_stage(SceneData& s, QueryState& q);

// 2. Object and surface levels of every instance pair (OAABB, surviving surfaces, candidate surface
//    pairs), then the task list, the surfaces needed in order of first need, and their ledger.
void surface_level_stage(SceneData& s, QueryState& q);

// 3. Lazy tessellation of the needed surfaces and their BVHs, in rounds under a memory budget.
void tessellation_stage(SceneData& s, QueryState& q);

// The trees of those `wave` surfaces that have triangles and no tree yet, built on `threads` threads
// (marked ready); past the deadline the rest are skipped. Returns the surfaces built, in wave order.
std::vector<SurfaceId> build_trees(SceneData& s, std::span<const SurfaceId> wave, int threads, const Deadline& deadline);

// 4. Triangle level of every task within the budget: Version 1 or 2 (collide.h). Version 1 only:
//    `after(k)`, when given, runs on the thread that finished task k, once its outcome is final
//    (also for a task the deadline cut).
void triangle_level_stage(SceneData& s, QueryState& q, const std::function<void(std::size_t)>& after = {});

// 5. The certified (or fast, or exact) decision of every finished task → q.results.
void decision_stage(SceneData& s, QueryState& q);

// Stages 4 and 5 as one pass when decide_with_triangles(q) (Version 1, a certified or exact decision,
// no memory budget, more than one thread): each task's decision steps up to the witnesses run right
// after its triangle level, on the same thread, and the rest of stage 5 after the loop. The same
// answers and counters as stage 4 then stage 5, since each task's steps depend on it alone; it saves
// the barrier between the stages and the threads' idle time at the end of each loop. One thread has
// neither to save, and the stages in turn keep each one's data in cache (as1 at 0.001 mm: 3 % faster).
bool decide_with_triangles(const QueryState& q);
void triangle_and_decision_stage(SceneData& s, QueryState& q);

// 6. Containment of instance pairs whose boxes nest and whose surfaces do not cross.
void containment_stage(const SceneData& s, QueryState& q);

// 7. The kept prefix of instance pairs into q.report (results, counters, unexamined pairs, the
//    partial marker), and what was built past the memory budget released again.
void results_stage(SceneData& s, QueryState& q);

// Stages 2-7 in order, with their timings and the model memory after them: check() after its broad
// phase, check_part() after taking its pairs from the plan.
void narrow_stages(SceneData& s, QueryState& q);
void set_schedule(Schedule s);
SceneMemory scene_memory(const SceneData& s);

}  // namespace cadclash::detail

namespace cadclash {
struct Scene::Impl : detail::SceneData {
  using SceneData::SceneData;
};
}  // namespace cadclash
