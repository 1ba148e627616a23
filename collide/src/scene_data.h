// What a prepared Scene keeps between queries (SceneData) and what one check() builds as it runs
// through its stages (QueryState). Internal to cadclash::collide; the stages are in stage_*.cpp and
// declared in scene_stages.h.
#pragma once

#include "budget.h"
#include "cadclash/collide.h"
#include "decide.h"
#include "narrow_phase.h"
#include "refine.h"
#include "instance_tree.h"
#include "surface_bvh.h"
#include "task_costs.h"

#include <array>
#include <chrono>
#include <cstdint>
#include <set>
#include <span>
#include <string>
#include <unordered_map>
#include <map>
#include <set>
#include <vector>

namespace cadclash::detail {

// Per part, the largest reach share (SceneData::reach_share) of its surfaces, for fast decisions
// ([0]) and for the others ([1]), and the largest of all parts. Kept between checks rather than
// walked by each: a scene of distinct parts has a surface per CAD face (290 distinct copies of as1:
// 15,370), and walking them made a path step there half again as long as its own work.
struct ReachShares {
  std::vector<double> part[2];
  double largest[2] = {0.0, 0.0};
  std::vector<PartId> dirty;      // parts with surfaces this scene changed since they were worked out
  std::vector<char> is_dirty;     // per part
  std::uint64_t revision = 0;     // the model.revision they reflect
  bool valid = false;             // worked out at all
};

// Per surface, the first instance pair of the running query that needs it, or kInvalidId. Entries
// carry the query's serial, so a query writes only the surfaces it needs instead of clearing one
// entry per surface of the model (64 bits: no scene lives to see the serial wrap).
class FirstNeed {
 public:
  void resize(std::size_t surfaces) { stamp_.assign(surfaces, 0), pair_.assign(surfaces, kInvalidId); }
  // A new query: every entry reads kInvalidId again.
  void start() { ++serial_; }
  std::uint32_t operator[](SurfaceId s) const { return stamp_[s] == serial_ ? pair_[s] : kInvalidId; }
  void set(SurfaceId s, std::uint32_t pair) { stamp_[s] = serial_, pair_[s] = pair; }

 private:
  std::vector<std::uint64_t> stamp_;
  std::vector<std::uint32_t> pair_;
  std::uint64_t serial_ = 0;
};

struct SceneData {
  Model& model;
  SceneSelection selection;
  std::vector<Pose> poses;
  std::vector<Aabb> part_box;       // part-local union of its surfaces' boxes
  std::vector<double> part_norm;    // largest norm of a point of part_box (round-off bounds)
  std::vector<double> part_length;  // largest |coordinate| of part_box, deflection or uncertainty (range check)
  std::vector<double> eps;          // per surface: effective_uncertainty (decide.h)
  std::vector<double> slack;        // per surface: face_slack (decide.h)
  std::vector<Aabb> world_box;      // per instance
  std::vector<char> dirty;
  std::vector<InstanceId> dirty_list;  // the instances with dirty set, in the order they were moved
  std::set<InstanceId> outside_range;  // instances outside the supported range (query_range.cpp), as of their last move
  InstanceTree instance_tree;          // built by the first broad phase with a small selection side
  std::vector<SurfaceBvh> bvh;
  std::vector<char> bvh_ready;
  RefineCache refined;  // finer faces and parts of faces made for refinement, kept for later queries
  OutlineCache outlines;                // surfaces' outlines made by the decision stage, likewise
  std::vector<char> in_a, in_b;
  // Per surface: the deflection another process tessellated it at (Scene::note_deflection); < 0: none.
  std::vector<double> noted_deflection;
  std::vector<std::uint64_t> noted_triangles;  // ... and into how many triangles (plan costs)
  std::set<std::pair<InstanceId, InstanceId>> excluded;
  std::unordered_map<std::string, InstanceId> by_path;
  ReachShares shares;   // see refresh_reach_shares
  // What the surfaces with a hierarchy hold (triangles, vertices, hierarchy heap bytes, triangle
  // count): kept as trees are built and released, so Scene::memory() does not walk every surface.
  SceneMemory held;
  FirstNeed first_need;  // of the running query (QueryState)
  TaskCosts task_costs;  // what the last check's triangle-level tasks took (stage_triangles.cpp)

  SceneData(Model& m, SceneSelection sel);

  SurfaceId first(PartId p) const { return model.parts[p].first_surface; }
  SurfaceId end(PartId p) const { return model.parts[p].first_surface + model.parts[p].surface_count; }
  Aabb surface_box(SurfaceId s) const;
  // Deflection a surface's triangles have, or will have when tessellated on demand.
  double deflection(SurfaceId s) const;
  // What a surface adds to the search reach: its deflection, plus its uncertainty unless fast.
  double reach_share(SurfaceId s, const CollideOptions& o) const;
  // Brings `shares` up to date: the parts this scene changed, or every part when the model's
  // revision moved otherwise (require_triangles, another scene's lazy tessellation).
  void refresh_reach_shares();
  // Per part: the largest reach share of its surfaces; and the largest of those. Precondition:
  // refresh_reach_shares() since the last change to the model's surfaces.
  const std::vector<double>& part_reach_shares(const CollideOptions& o) const { return shares.part[certified(o)]; }
  double largest_reach_share(const CollideOptions& o) const { return shares.largest[certified(o)]; }
  // This scene changed `changed` surfaces' triangles or deflections (it read `revision_before` as the
  // model's revision just before, and added to it since when it changed the model).
  void surfaces_changed(std::uint64_t revision_before, std::span<const SurfaceId> changed);
  // A surface's hierarchy was built (+1) or released (-1): `held` follows.
  void hold(SurfaceId s, int sign);
  bool selected(InstanceId i, InstanceId j) const;

 private:
  static int certified(const CollideOptions& o) { return o.decision == DecisionMode::Fast ? 0 : 1; }
  void work_out_shares(PartId p);
};

// One overlapping instance pair: what the object and surface levels found.
struct InstancePair {
  InstanceId a = kInvalidId, b = kInvalidId;
  Pose t_ab = Pose::Identity(), t_ba = Pose::Identity();  // B → A and A → B
  double roundoff = 0.0;  // pair_roundoff (decide.h); 0 in fast mode
  std::vector<std::array<SurfaceId, 2>> candidates;
  int containment = 0;  // 1: B's box inside A's (test B inside A); 2: the reverse; 0: neither
  CollideCounters counters;
  bool cut = false;  // the time budget ran out before its surface level
};

struct Task {
  std::uint32_t pair = 0;  // index into the instance pairs
  SurfaceId sa = kInvalidId, sb = kInvalidId;
};

// A check of some instance pairs only and, of each, some surface pairs (restricted_check.h).
struct CheckRestriction {
  // Per instance pair (a < b): the surface pairs (of a's part, of b's) examined; its containment is
  // tested as check() tests it.
  std::map<std::pair<InstanceId, InstanceId>, std::set<std::pair<SurfaceId, SurfaceId>>> pairs;
};

struct QueryState {
  const CollideOptions& o;
  const CheckRestriction* only = nullptr;  // null: every pair the broad phase finds
  bool depth = true;  // false: contacts are not told penetrating by the depth step (decide_pairs)
  std::chrono::steady_clock::time_point t0;
  Deadline deadline;
  int threads = 1;
  // The check's progress callback (CheckPairs); null for check_part, which reports nothing.
  const ProgressCallback* progress = nullptr;
  Report report;

  std::vector<InstancePair> pairs;
  std::vector<Task> tasks;
  std::vector<std::size_t> first_task;  // tasks of pair k: [first_task[k], first_task[k+1])
  // The memory budget's ledger: per instance pair, the bytes it makes this query build. Each surface
  // is charged to the first pair (in pair order) that needs it, so the prefix of pairs that fits the
  // budget does not depend on how the work was spread over threads.
  std::vector<std::uint64_t> charge;
  std::vector<SurfaceId> needed;           // in order of first need (SceneData::first_need)
  // check_part: per surface of `needed`, whether SceneData::refined had it attempted before this
  // query's decisions (only those surfaces can be refined by them). Filled when `note_refined`.
  bool note_refined = false;
  std::vector<char> refined_before;
  std::vector<std::uint32_t> regions_before;  // per needed surface: RefineCache::regions_made before the query
  std::uint32_t cutoff = 0;                // pairs from here on do not fit the memory budget

  // Lazy tessellation: what this query asked for, made, and built (released past the cutoff).
  std::vector<SurfaceId> asked, tessellated, built;
  std::vector<SurfaceId> failed;  // the surface of each tessellation diagnostic in report.diagnostics
  std::vector<double> old_deflection;  // parallel to `tessellated`

  // Triangle level, per task.
  std::vector<PreparedPair> prepared;  // Version 2 only (Version 1 prepares into per-thread buffers)
  std::vector<PairOutcome> outcomes;
  std::vector<CollideCounters> task_counters;
  std::vector<char> task_cut;

  // Per instance pair.
  std::vector<char> pair_cut, pair_intersects, contained;
  std::vector<double> pair_distance;
  // The reported pairs of the decisions and the containment test (in no particular order: the
  // report sorts them), each with its instance pair; those past the final cutoff are dropped.
  std::vector<SurfacePairResult> results;
  std::vector<std::uint32_t> result_pair;

  QueryState(const CollideOptions& options, std::chrono::steady_clock::time_point start);
  // Moves the cutoff to the first pair whose running charge exceeds the budget. Charges only grow,
  // so the cutoff can only move earlier as more is charged.
  void apply_memory_budget();
};

double seconds_since(std::chrono::steady_clock::time_point t0);

// Bytes a reported pair holds (charged against the memory budget).
inline std::uint64_t result_bytes(const SurfacePairResult& r) {
  return sizeof(r) + r.triangle_pairs.size() * sizeof(r.triangle_pairs[0]);
}
void add(CollideCounters& into, const CollideCounters& c);
inline std::uint64_t mesh_bytes(const TriangleMesh& m) {
  return m.vertices.size() * sizeof(m.vertices[0]) + m.triangles.size() * sizeof(m.triangles[0]);
}

}  // namespace cadclash::detail
