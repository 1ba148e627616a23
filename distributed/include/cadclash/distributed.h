// cadclash/distributed.h — one check (or trajectory) split over MPI processes, merged on rank 0 into
// the report one process gives.
//
// How (collide.h, "One check split over processes"): every rank holds the same model and builds
// the same Scene (replicated: assembly, poses, surface boxes; the B-rep where its files were read,
// below); every rank computes the plan
// (broad phase and surface level: boxes only; the same pairs everywhere); rank 0 splits its pairs
// into contiguous runs of equal estimated cost; each rank checks its run (check_part), tessellating
// only what its pairs reach: with lazy tessellation the surfaces, face by face; with part meshing
// (below: the import read no triangles, and whole parts are meshed as an eager import meshes them)
// the parts. Rank 0 gathers the parts and merges them in a fixed order. The merged Report equals Scene::check()'s in every
// field a `--no-timings` report holds, for any number of ranks and threads (pairs, counters,
// diagnostics, unexamined pairs, memory_charged, model_memory); timings are the slowest rank's.
//
// The splitting, merging and (de)serialising below use no MPI and are usable (and tested) in one
// process; check_distributed and replay_distributed exist when built with CADCLASH_WITH_MPI
// (CADCLASH_HAS_MPI is then 1). Library code never prints: per-rank statistics are returned.
#pragma once

#include "cadclash/collide.h"

#include <cstdint>
#include <functional>
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

// ---------------------------------------------------------------------------------------------
// Whole parts meshed where they are needed (no MPI)
// ---------------------------------------------------------------------------------------------
// A replica may hold the B-rep without triangles (a lazy import) and mesh a part only when its share
// of the work reaches it, exactly as one process's eager import meshes it (tessellate_parts in
// cadclash/tessellate.h; this module does not link OCCT, so the meshing comes as a PartMesher). The
// plan needs, of every surface, what the eager import gives it: its box (extended by its
// triangles'), its achieved deflection and (for the cost estimates) its triangle count. So each part
// is meshed first on one rank, its owner (mesh_owners), which sends these facts to every rank
// (share_part_facts under MPI); a rank keeps the triangles of its owned parts only when its share
// reaches them (share_parts). Per rank, meshing = its owned parts + the other parts its shares reach.

// Meshes whole parts as the eager import does, and drops them again (tessellate_parts,
// release_part_triangles). mesh returns false when a face could not be meshed.
struct PartMesher {
  std::function<bool(std::span<const PartId>)> mesh;
  std::function<void(std::span<const PartId>)> release;
};

// What the plan needs of a surface whose part may be meshed on another rank.
struct SurfaceFacts {
  Aabb box;                     // Surface::aabb after meshing
  double deflection = 0.0;      // Surface::deflection after meshing
  std::uint64_t triangles = 0;  // its triangles
  bool has_triangles = false;   // meshing gave it triangles
};

// One replica's part meshing: what it holds and what the whole model's surfaces are.
struct PartMeshing {
  PartMesher mesher;
  std::vector<SurfaceFacts> facts;  // per surface of the model, once share_part_facts ran
  std::vector<char> held;           // per part: its triangles are here
  std::vector<char> facts_only;     // per part: meshed here for its facts, not reached by a share yet
  std::uint64_t meshed_triangles = 0;  // triangles this replica meshed so far (released ones included)
  std::uint64_t model_triangles = 0;   // triangles of every B-rep surface of the model (from the facts)
  // Per part, the rank that meshes it when no pair reaches it (the rank that read its file, which
  // holds its exact faces); empty: the rank with the fewest surfaces owned (mesh_owners).
  std::vector<int> home;
};

// The parts of the instances of plan.pairs[k], k in `pairs`: ascending, each once.
std::vector<PartId> parts_of_pairs(const Model& model, const CheckPlan& plan, std::span<const std::uint32_t> pairs);

// Per part, the rank that meshes it first: the first rank, in split_by_cost(plan, ranks), whose run
// reaches the part; a part no pair reaches goes to home[part] when `home` is given, else to the rank
// with the fewest surfaces owned so far (lowest rank on ties). The same on every replica of the same
// plan. Preconditions: ranks >= 1; `home` empty or one rank in [0, ranks) per part.
std::vector<int> mesh_owners(const Model& model, const CheckPlan& plan, int ranks, std::span<const int> home = {});

// ---------------------------------------------------------------------------------------------
// Files read where they are needed (no MPI)
// ---------------------------------------------------------------------------------------------
// Under mpirun each input file is read by one rank, its reader, which shares what it read without
// the exact faces (import.h, import_description); a rank reads another file only when its share of
// the work reaches a part of it. The readers are chosen by file size, the work of reading.

// Per file, its reader: the files in the order given split into contiguous runs of about equal
// bytes, as split_by_cost splits pairs (file f goes to the rank r with r·B/ranks <= bytes before f +
// half of f's < (r+1)·B/ranks, B the total; an empty file counts 1 byte). Instances, and so the
// plan's sorted pairs and their runs, come in file order: when most pairs lie within a file, a
// rank's run falls mostly in the files it reads. Precondition: ranks >= 1.
std::vector<int> assign_readers(std::span<const std::uint64_t> file_bytes, int ranks);

// The facts of every surface of `parts` as `model` holds them now, in part then surface order.
std::vector<SurfaceFacts> surface_facts(const Model& model, std::span<const PartId> parts);

// `facts` (surface_facts of `parts`, from whichever replica meshed them) into pm.facts; for parts
// whose triangles are not here, into the model's surfaces too (box and deflection). Precondition:
// pm.facts sized for model.surfaces.
void apply_surface_facts(Model& model, std::span<const PartId> parts, std::span<const SurfaceFacts> facts,
                         PartMeshing& pm);

// Tells `scene` (built on the model after apply_surface_facts) the deflection and triangle count of
// every surface that has triangles on some replica, for when it has none here (Scene::note_deflection).
void note_surface_facts(Scene& scene, const PartMeshing& pm);

// Before a replica checks `pairs` of `plan`: the parts they reach are meshed here (those not held),
// and the parts meshed for their facts only that they do not reach are released. Returns false when
// a face failed to mesh.
bool share_parts(Model& model, const CheckPlan& plan, std::span<const std::uint32_t> pairs, PartMeshing& pm);

// Triangles of the surfaces that have them in `model`.
std::uint64_t held_triangles(const Model& model);

// Gives a replica the exact faces of `parts` before it checks pairs that reach them: reads the files
// holding them when the import left those parts with stand-in sources (import.h,
// import_from_description), which mesh nothing. A lazy check tessellates faces, and a certified one
// asks them for exact distances, inside Scene::check_part, so they must be read before it starts.
// Returns false when they could not be read as the plan's replica describes them.
using PartReader = std::function<bool(std::span<const PartId>)>;

// One rank's share of a query (or of a whole trajectory: summed over its steps).
struct RankStats {
  int rank = 0;
  std::uint64_t instance_pairs = 0;  // assigned to it
  std::uint64_t cost = 0;            // their estimated cost (PlannedPair::cost)
  std::uint64_t triangles = 0;       // triangles its scene holds afterwards (model_memory.triangle_count)
  double seconds = 0.0;              // wall time of its check_part() calls and what precedes them
                                     // (reading files, share_parts())
  double cpu_seconds = 0.0;          // CPU time of the process (all its threads) during them
  double plan_seconds = 0.0;         // wall time of its plan() calls (every rank plans every pair)
  std::uint64_t result_bytes = 0;    // bytes of its results sent to rank 0
  std::uint64_t peak_memory_bytes = 0;  // the process's peak resident set (getrusage)
  // Triangles its model holds after its part (every surface with triangles; B-rep ones meshed here
  // and those of mesh files, which every rank reads); with part meshing, the triangles it meshed so
  // far (released ones included) and the model's (every B-rep surface, once); else 0.
  std::uint64_t held_triangles = 0;
  std::uint64_t meshed_triangles = 0;
  std::uint64_t model_triangles = 0;
};

// `s` added to `into`: sums, except triangles, held, meshed and model triangles (the latest) and
// peak memory (the larger).
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

// Every rank's bytes on every rank, in rank order (MPI_Allgatherv). Collective. A rank's bytes
// beyond one MPI message (2^31 - 1) end the job (MPI_Abort) with a message naming it.
std::vector<std::string> allgather_bytes(const std::string& mine, MPI_Comm comm);

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
// With `parts` (part meshing: `model` imported without triangles, share_part_facts done, `scene`
// built afterwards and told note_surface_facts), each rank first meshes the parts its run reaches
// (share_parts); the merged report is then the one of one process that imported eagerly.
// With `read`, each rank first reads what its run reaches (parts_of_pairs); when it fails the job
// ends (MPI_Abort) with a message naming the rank.
DistributedCheck check_distributed(Scene& scene, Model& model, const CollideOptions& options,
                                   MergeHistory& history, MPI_Comm comm, PartMeshing* parts = nullptr,
                                   const PartReader& read = {});

// Part meshing's first step, collective: every rank plans `boxes_scene` (a Scene over `model`, a
// lazy import: nothing meshed; the selection of the real check), meshes the parts mesh_owners gives
// it (pm.mesher) and receives the facts of every other part (MPI_Allgatherv), which
// apply_surface_facts writes into pm and `model`. Afterwards build the checking Scene on `model` and
// call note_surface_facts. Returns false on every rank when a face failed to mesh on some rank or
// two B-rep parts share an edge (`share_edges`, the same on every rank): the eager import's
// diagnostics cannot then be rebuilt, import eagerly instead. Precondition: pm.mesher set.
bool share_part_facts(Scene& boxes_scene, Model& model, const CollideOptions& options, bool share_edges,
                      PartMeshing& pm, MPI_Comm comm);

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
                                     const std::string& file, MPI_Comm comm, PartMeshing* parts = nullptr,
                                     const PartReader& read = {});
#endif

}  // namespace cadclash
