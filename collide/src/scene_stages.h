// The stages of Scene::check, in the order it runs them. Each reads the scene and writes the query
// state (scene_data.h); the OpenMP loops inside merge in a fixed order, so what a stage leaves does
// not depend on the thread count. Internal to cadclash::collide.
#pragma once

#include "scene_data.h"

#include <span>
#include <vector>

namespace cadclash::detail {

// 1. World boxes of the instances moved since the last check, then sweep-and-prune over them (brute
//    force: every selected pair) → q.pairs.
void broad_phase_stage(SceneData& s, QueryState& q);

// 2. Object and surface levels of every instance pair (OAABB, surviving surfaces, candidate surface
//    pairs), then the task list, the surfaces needed in order of first need, and their ledger.
void surface_level_stage(const SceneData& s, QueryState& q);

// 3. Lazy tessellation of the needed surfaces and their BVHs, in rounds under a memory budget.
void tessellation_stage(SceneData& s, QueryState& q);

// The trees of those `wave` surfaces that have triangles and no tree yet, built on `threads` threads
// (marked ready); past the deadline the rest are skipped. Returns the surfaces built, in wave order.
std::vector<SurfaceId> build_trees(SceneData& s, std::span<const SurfaceId> wave, int threads, const Deadline& deadline);

// 4. Triangle level of every task within the budget: Version 1 or 2 (collide.h).
void triangle_level_stage(SceneData& s, QueryState& q);

// 5. The certified (or fast, or exact) decision of every finished task → q.pair_results.
void decision_stage(SceneData& s, QueryState& q);

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
