// cadclash/distributed.h — one check (or trajectory) split over MPI processes, merged on rank 0 into
// the report one process gives.
//
// How (collide.h, "One check split over processes"): every rank imports the same files and builds
// the same Scene (replicated: assembly, B-rep, poses); every rank computes the plan (broad phase and
// surface level: boxes only; the same pairs everywhere); rank 0 splits its pairs into contiguous runs
// of equal estimated cost; each rank checks its run (check_part), tessellating only the surfaces its pairs
// reach (with lazy tessellation; otherwise the import already tessellated everything); rank 0 gathers
// the parts and merges them in a fixed order. The merged Report equals Scene::check()'s in every
// field a `--no-timings` report holds, for any number of ranks and threads (pairs, counters,
// diagnostics, unexamined pairs, memory_charged, model_memory); timings are the slowest rank's.
//
// The splitting, merging and (de)serialising below use no MPI and are usable (and tested) in one
// process; check_distributed and replay_distributed exist when built with CADCLASH_WITH_MPI
// (CADCLASH_HAS_MPI is then 1). Library code never prints: per-rank statistics are returned.
#pragma once

#include "cadclash/collide.h"

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#if CADCLASH_HAS_MPI
#include <mpi.h>
#endif

namespace cadclash {

// ---------------------------------------------------------------------------------------------
// Splitting and merging (no MPI)
// ---------------------------------------------------------------------------------------------

// Splits the plan's pairs into `parts` contiguous runs of about equal estimated cost: pair k goes to
// the part r with r·C/parts <= (cost before k + cost of k / 2) < (r+1)·C/parts, C the total cost.
// Contiguous runs keep pairs sharing an instance together (pairs are sorted), so parts tessellate
// fewer surfaces twice. Returns per part its ascending pair indices (a part may be empty).
// Precondition: parts >= 1.
std::vector<std::vector<std::uint32_t>> split_by_cost(const CheckPlan& plan, int parts);

// What a merge keeps between the queries of one scene (a trajectory's steps), so that work on a
// surface is counted once however many processes did it: as one process, which keeps its triangles,
// hierarchies and refined faces from one query to the next.
struct MergeHistory {
  std::vector<char> tessellated, built, refined;  // per surface: by some part of an earlier query
  SceneMemory held;  // the surfaces' part of Scene::memory() (instances excluded)

  MergeHistory() = default;
  // `start` is the scene's memory() before its first query (what it already held).
  MergeHistory(std::size_t surface_count, const SceneMemory& start);
};

struct MergedCheck {
  Report report;  // what Scene::check() gives (timings: see the header comment)
  // Surfaces first tessellated in this query, with their deflection: every process notes them
  // (Scene::note_deflection) so its next plan has the search reaches of one process.
  std::vector<std::pair<SurfaceId, double>> new_deflections;
};

// Merges the parts of one query: pairs sorted as check() sorts them; counters: the plan's broad
// phase plus the parts' sums, tessellated_surfaces and refined_surfaces counting each surface once
// and not again when an earlier query (history) did it; memory_charged: the parts' plus each newly
// tessellated or built surface's bytes once; diagnostics: the failed surfaces' once, ordered by part
// then first need (check()'s order); unexamined pairs: the union, sorted; complete and stopped_by.
// Updates `history`. Preconditions: the parts are check_part()s of `plan` on replicas of the scene
// whose model is `model`, covering every plan pair once; history sized for model.surfaces.
MergedCheck merge_parts(const CheckPlan& plan, std::span<const PartialCheck> parts, const Model& model,
                        MergeHistory& history);

// PartialCheck as bytes (CBOR, doubles exact) and back. from_bytes returns nullopt and says why in
// `error` for bytes this writer did not produce.
std::vector<std::uint8_t> partial_check_bytes(const PartialCheck& p);
std::optional<PartialCheck> partial_check_from_bytes(std::span<const std::uint8_t> bytes, std::string& error);

// One rank's share of a query (or of a whole trajectory: summed over its steps).
struct RankStats {
  int rank = 0;
  std::uint64_t instance_pairs = 0;  // assigned to it
  std::uint64_t cost = 0;            // their estimated cost (PlannedPair::cost)
  std::uint64_t triangles = 0;       // triangles its scene holds afterwards (model_memory.triangle_count)
  double seconds = 0.0;              // wall time of its check_part() calls
  double cpu_seconds = 0.0;          // CPU time of the process (all its threads) during them
  double plan_seconds = 0.0;         // wall time of its plan() calls (every rank plans every pair)
  std::uint64_t result_bytes = 0;    // bytes of its results sent to rank 0
  std::uint64_t peak_memory_bytes = 0;  // the process's peak resident set (getrusage)
};

// `s` added to `into`: sums, except triangles (the latest) and peak memory (the larger).
void add_stats(RankStats& into, const RankStats& s);

#if CADCLASH_HAS_MPI
// ---------------------------------------------------------------------------------------------
// Under MPI (collective over `comm`: every rank calls it with the same arguments on its replica)
// ---------------------------------------------------------------------------------------------

struct DistributedCheck {
  Report report;                // rank 0: the merged report; other ranks: empty
  std::vector<RankStats> ranks;  // rank 0: one per rank; other ranks: empty
  double merge_seconds = 0.0;    // rank 0: reading the parts and merging them
};

// Scene::check(options) over the ranks of `comm`: the plan on every rank, rank 0's split (its cost
// estimates count the triangles it holds) broadcast, a part per rank, the parts merged on rank 0. `history` (MergeHistory(surface count,
// scene.memory()) before the first query) is used on rank 0 only. Preconditions: every rank's
// scene is a replica (same model, selection and poses); options.memory_budget_bytes == 0.
// A rank that runs out of memory (std::bad_alloc) or receives a fatal signal while checking prints
// (the one place this library prints: the process is about to die) which rank it is and the first of
// its unfinished instance pairs, then the job is aborted (MPI_Abort): Open MPI 4.1 does not let the
// other ranks continue without it. Testing aid: with CADCLASH_TEST_CRASH_RANK=r in the environment,
// rank r raises SIGSEGV as its part starts.
// `model` is the scene's model (instance paths for that message, part ids for the merge). Surfaces
// tessellated by another rank get the achieved deflection on every rank: in `model` (the report's
// "deflection" of a surface) and in the scene (Scene::note_deflection: the next query's reaches).
DistributedCheck check_distributed(Scene& scene, Model& model, const CollideOptions& options,
                                   MergeHistory& history, MPI_Comm comm);

// replay_trajectory (collide.h) over the ranks: the same steps, diagnostics and time-budget
// behaviour; each step's check split and merged as check_distributed does. `ranks` (rank 0) sums the
// steps.
struct DistributedReplay {
  std::vector<StepResult> steps;  // rank 0
  std::vector<RankStats> ranks;   // rank 0
  double merge_seconds = 0.0;     // rank 0, summed over the steps
};
DistributedReplay replay_distributed(Scene& scene, Model& model, std::span<const TrajectoryRow> rows,
                                     const CollideOptions& options, std::vector<Diagnostic>& diagnostics,
                                     const std::string& file, MPI_Comm comm);
#endif

}  // namespace cadclash
