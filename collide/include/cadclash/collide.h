// cadclash/collide.h — the OAABB collision queries over the surface-tagged model (cadclash/model.h).
//
// This is the public header of cadclash::collide (with cadclash/model.h, which it includes). It
// depends on Eigen and the standard library only: a design-review tool can link cadclash::collide
// without OpenCASCADE or assimp. Conventions are model.h's: ids index the Model's flat arrays,
// millimetres, caller mistakes are assertions, untrusted input gives Diagnostic values, library
// code never prints.
#pragma once

#include "cadclash/contact_classes.h"
#include "cadclash/model.h"

#include <Eigen/Geometry>

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace cadclash {

// =============================================================================================
// Collision queries: the OAABB narrow phase, contact classes, prepared scenes, trajectories
// =============================================================================================
//
// The query, level by level (Figueiredo & Fernando's OAABB scheme, extended with distances):
// 1. Broad phase: sweep-and-prune over instance world AABBs (inflated by the margin) → instance pairs.
// 2. Object level: OAABB(A,B) = A's local box ∩ B's local box mapped into A's frame; mapped once
//    more into B's frame (the paper's single update). Surfaces meeting it survive (msA, msB).
// 3. Surface level: surviving pairs whose boxes (in A's frame) overlap → surface-pair OAABB.
// 4. Triangle level: each surface's BVH (built once) is queried under the surface-pair OAABB on both
//    sides (mpSk, mpSl); candidate triangle pairs come from a tree over Sl's survivors queried by
//    each survivor of Sk in turn (so a surface pair whose outcome is settled stops making them), or from the
//    paper's flat double loop for small lists.
// 5. Exact test (triangles_intersect; float filter + exact fallback) and, while no intersection is
//    found, triangle–triangle distance.
//
// Frames: every triangle test happens in instance A's part frame. B's vertices are mapped by
// T = pose_a⁻¹·pose_b (computed once per instance pair) and the answer is exact arithmetic on those
// mapped doubles. Instance A is always the one with the smaller id. All culling boxes are padded by a
// relative epsilon, so culling never drops a pair the unculled (brute-force) query would report.
//
// Contact classes and what the certified decision proves: cadclash/contact_classes.h.

enum class CollideMode : std::uint8_t {
  EarlyExit,          // per surface pair, stop at the first triangle pair that decides the class
  AllTrianglePairs,   // visit every candidate triangle pair and list all intersecting ones
};
// Returns "early-exit" or "all-triangle-pairs".
const char* collide_mode_name(CollideMode m);

// How the candidate surface pairs are spread over threads.
enum class ParallelVersion : std::uint8_t {
  V1,  // one work item per candidate surface pair (the paper's Version 1)
  V2,  // one work item per (surface pair, block of A's surviving triangles): the flattened index
};
// Returns "v1" or "v2".
const char* parallel_version_name(ParallelVersion v);
// The OpenMP schedule of the candidate-pair loop. Guided (the paper's) hands a thread half of the
// items left at its first request; for a loop of fewer than 64 candidate pairs, where a few items
// may hold most of the work (a part moving through a scene), Guided runs as Dynamic with chunks of
// one instead, the pairs a Scene's previous check took longest first (by their measured times).
// The report is the same for every schedule and order.
enum class Schedule : std::uint8_t { Guided, Dynamic, Static };
// Returns "guided", "dynamic" or "static".
const char* schedule_name(Schedule s);

// How candidate triangle pairs are formed under the surface-pair OAABB.
enum class TriangleLevel : std::uint8_t {
  Auto,  // flat loops when |survivors of Sk| * |survivors of Sl| <= flat_limit, else the BVH + tree
  Flat,  // the paper's loops: every triangle of Sk against every triangle of Sl, box test first
  Bvh,   // per-surface BVH queried under the OAABB, candidate pairs from a tree over Sl's survivors
};
// Returns "auto", "flat" or "bvh".
const char* triangle_level_name(TriangleLevel t);

// ---------------------------------------------------------------------------------------------
// Progress of long work
// ---------------------------------------------------------------------------------------------
// An import (import.h), the eager tessellation of B-rep parts (tessellate.h), a check and a
// trajectory replay tell an optional callback how far they are, for a progress display such as the
// command line's status line. Library code never prints. An empty callback (the default) costs one
// test per work item and nothing else; a callback never changes a result (reports are byte-identical
// with and without one).
//
// Each run of a stage makes calls with done rising from 0 to total: a first call with done = 0 as
// it starts, calls as items finish (at most one per whole percent of total, so a callback is cheap
// whatever the number of items), and a last call with done == total when it ends (also when a
// budget cut it short: skipped items count as finished); the first call with done == total is the
// run's last (so a run of total 0 is one call). Calls never overlap. The callback must not
// throw and must not use the object that is reporting (the Scene, the Model being imported).
enum class ProgressStage : std::uint8_t {
  ReadFile,        // import: files finished of the files given; label: the file (as given) that
                   // started or finished last. One run per import_file / import_files call.
  TessellatePart,  // eager B-rep tessellation: parts meshed of one file's (one add_brep_parts call's)
                   // parts; label: the name of a part meshed last. None when lazy or read from the cache.
  CheckPairs,      // Scene::check: instance pairs (of the broad phase's) through one step of the query;
                   // label: the step, "surface level", then "triangle level", then "decisions" (a run
                   // each, done starting at 0 again; the decisions count the pairs with nothing to
                   // decide at once and the rest when every decision step is done).
  TrajectoryStep,  // replay_trajectory: steps checked of the trajectory's steps; label: the number of
                   // the step checked last (the first step's as it starts). The checks of the steps
                   // do not report CheckPairs.
  CheckPart,       // B-rep import: parts of one file's (one add_brep_parts call's) whose faces were
                   // checked (BRepCheck), healed where invalid, and boxed; label: the name of a part
                   // checked last. Lazy or eager; none when read from the cache.
};
// Returns "read file", "tessellate part", "check instance pairs", "trajectory step" or "check part".
const char* progress_stage_name(ProgressStage s);

struct Progress {
  ProgressStage stage = ProgressStage::ReadFile;
  std::size_t done = 0;   // items finished, 0 <= done <= total, never falling within a run
  std::size_t total = 0;  // items of this run of the stage
  std::string label;      // what it is working on (see ProgressStage)
};

// Called by a long operation as it goes (see above). Threads: collide (check, replay) calls it only
// on the thread that called the query; tessellation on the thread that called add_brep_parts; an
// import on the threads reading files (import_files with parallel_files > 1: several, one at a time).
using ProgressCallback = std::function<void(const Progress&)>;

struct CollideOptions {
  double tolerance = 0.0;         // contact tolerance t, mm (>= 0)
  double clearance = 0.0;         // report non-touching pairs closer than this, mm (0 = never)
  CollideMode mode = CollideMode::EarlyExit;
  int threads = 0;                // <= 0: OpenMP's default
  ParallelVersion version = ParallelVersion::V1;
  Schedule schedule = Schedule::Guided;
  bool use_oaabb = true;          // false: brute force — every surface pair, every triangle pair, no culling
  TriangleLevel triangle_level = TriangleLevel::Auto;
  std::size_t flat_limit = 4096;  // Auto switches to the BVH above this many candidate pairs
  bool detect_containment = true;
  // Examine only the instance pairs with at least one instance in this list (and that the scene's
  // selection allows); empty: every pair. What a continuous check asks of the motion between steps,
  // whose pairs of parts that stay need no search (trajectory.h). Ids < model.instances.size().
  std::vector<InstanceId> involving;
  // Surface pairs the caller has proved apart already, farther than tolerance + `uncertainty` (the
  // two surfaces' model uncertainties, as the report gives them): left out as if their boxes were
  // apart, so a pair it names is neither meshed nor decided. What a continuous check knows of the
  // pairs a turn cannot bring together (trajectory.h). Called from the check's threads with the
  // pair as the report orders it: thread-safe, and the same answer for the same arguments. Empty:
  // none.
  std::function<bool(InstanceId a, InstanceId b, SurfaceId sa, SurfaceId sb, double uncertainty)> proved_apart;
  DecisionMode decision = DecisionMode::Certified;  // see "Certified decisions"
  // Budgets; 0 = none. When one runs out the query ends early and returns a partial report: the
  // results of the instance pairs it finished, with Report::complete false (see Report).
  // - time_budget_seconds: wall clock from the start of check(). Checked cooperatively between work
  //   items of every parallel loop (surface level, lazy tessellation, BVH builds, triangle level —
  //   every 256 triangle tests inside a surface pair — and containment). Which pairs finish depends
  //   on the machine and the thread count. A surface being tessellated is not interrupted.
  // - memory_budget_bytes: bytes of what the query builds — candidate surface-pair lists, triangles
  //   tessellated on demand, per-surface BVHs, the triangle level's survivor lists and the results —
  //   summed per instance pair in instance-pair order (a sum of allocations, not a peak). The query
  //   keeps the longest prefix of instance pairs whose sum fits, so the partial report is the same
  //   for any thread count. Triangles and BVHs built for pairs past that prefix are released again.
  //   Structures a previous check() of the same Scene built are not counted again.
  double time_budget_seconds = 0.0;
  std::size_t memory_budget_bytes = 0;
  // Told how far check() (CheckPairs) and replay_trajectory() (TrajectoryStep) are; empty = nothing.
  // The split forms (Scene::plan, check_part, cadclash/distributed.h) do not call it.
  ProgressCallback progress;
};

// Counters of one query, summed over instance pairs (the paper's Table 2). They depend on the options
// (including the parallel version) but never on the number of threads.
struct CollideCounters {
  std::uint64_t instance_pairs = 0;       // instance pairs whose world boxes overlap (broad phase output)
  std::uint64_t aabb_tests = 0;           // box-box overlap tests at every level
  std::uint64_t aabb_updates = 0;         // boxes transformed into another frame
  std::uint64_t surfaces_a = 0;           // msA: surfaces of A surviving the object OAABB
  std::uint64_t surfaces_b = 0;           // msB
  std::uint64_t surface_pairs = 0;        // candidate surface pairs (boxes overlap)
  std::uint64_t triangles_a = 0;          // mpSk: triangles of Sk surviving the surface-pair OAABB
  std::uint64_t triangles_b = 0;          // mpSl
  std::uint64_t triangle_tests = 0;       // exact triangle intersection tests (EarlyExit: after a surface
                                          // pair's first intersecting triangle pair, only pairs whose
                                          // crossing depth could exceed T or τ are tested)
  std::uint64_t exact_fallbacks = 0;      // tests the float filter could not decide
  std::uint64_t distance_tests = 0;       // triangle distance computations
  std::uint64_t intersecting_pairs = 0;   // surface pairs with at least one intersecting triangle pair
  std::uint64_t tessellated_surfaces = 0; // surfaces this query asked require_triangles for
  // Decisions (Certified and Exact modes): reported or dismissed surface pairs by what settled them,
  // and the work the refinements did.
  std::uint64_t decided_mesh = 0, decided_mesh_exact = 0, decided_analytic = 0, decided_refined = 0,
                decided_exact = 0, undecided = 0;
  std::uint64_t ambiguous_pairs = 0;    // pairs the triangles' interval could not decide
  std::uint64_t refined_surfaces = 0;   // faces re-tessellated finer (whole, or near a pair) by this query
  std::uint64_t exact_queries = 0;      // SurfaceSource::exact_distance calls
  std::uint64_t witness_queries = 0;    // SurfaceSource surface_point, boundary_distance, point_distance,
                                        // edge_distance and edge_support calls (witnesses, crossings)
  std::uint64_t dismissed_pairs = 0;    // candidate pairs the triangles' band would call touching
                                        // (fast mode's answer) that a certificate proved apart
};

struct CollideTimings {  // seconds; never part of a determinism comparison
  double broad = 0.0, surface_level = 0.0, tessellation = 0.0, triangle_level = 0.0, total = 0.0;
  // Where the certified (or exact) decision spent its time, per step ("Certified decisions"),
  // summed over the pairs and faces each worked on, on every thread (so together they may exceed
  // the wall time of triangle_level, which includes them): the triangles' interval, the analytic
  // bounds and the contact witnesses (steps 1 to 3c); the depth step; refinement (re-meshing
  // faces finer and their triangles' intervals); the control hulls; OCCT's face distance and its
  // corroboration by finer triangles. 0 in the fast mode.
  double decide_witness = 0.0, decide_depth = 0.0, decide_refine = 0.0, decide_hull = 0.0, decide_exact = 0.0;
};

struct SurfacePairResult {
  InstanceId instance_a = kInvalidId;  // instance_a < instance_b
  InstanceId instance_b = kInvalidId;
  SurfaceId surface_a = kInvalidId;    // model surface ids; kInvalidId for Containment
  SurfaceId surface_b = kInvalidId;
  ContactClass contact = ContactClass::Touching;
  bool intersecting = false;  // some triangle pair intersects exactly
  double distance = 0.0;      // min triangle distance; 0 when intersecting; for Containment, the min
                              // distance when within the search margin, else +infinity
  // Crossing depth (see above) of a triangle pair crossing deeper than τ (certified: T + δa + δb + r),
  // the depth that makes the pair penetrating: in EarlyExit mode the first such pair in visiting
  // order (a lower bound of the deepest), in AllTrianglePairs mode the deepest. 0 when no triangle
  // pair crosses deeper: shallower crossings are within the tessellation bands and say nothing about
  // the exact faces, so they are neither reported nor, past the first one, measured.
  double penetration = 0.0;
  DecidedBy decided_by = DecidedBy::Mesh;
  // Bounds on the exact face distance d* from the evidence that decided the pair (see "Certified
  // decisions"); [d*, d*] when the exact distance was computed. Containment: [distance, distance].
  double distance_lo = 0.0, distance_hi = 0.0;
  // ε of each surface as the decision used it (Surface::uncertainty, or 2^-24 of its part's largest
  // coordinate when that is 0, never below kMinUncertainty); 0 for Containment.
  double uncertainty_a = 0.0, uncertainty_b = 0.0;
  ContactWithin within = ContactWithin::Unknown;  // see ContactWithin
  // SurfaceSource::exact_distance when the decision asked for it (exact step; DecisionMode::Exact asks
  // for every pair with exact geometry); a value > max(T, clearance) means "farther than that". In
  // the certified mode the search stops at the first two points within T: a value <= T there is an
  // upper bound (contact either way), not necessarily the minimum.
  std::optional<double> exact_distance;
  // AllTrianglePairs only: intersecting (triangle index in Sk, triangle index in Sl), sorted.
  std::vector<std::array<std::uint32_t, 2>> triangle_pairs;
};

// What a Scene's collision model holds, in bytes per component: the triangles and vertices of the
// surfaces that have a hierarchy (the Model's arrays, counted once per surface), the hierarchies
// built so far plus every surface's slot (exact root box, sizes; built or not), and the per-instance
// data (poses, world boxes, flags, and the instance tree when a broad phase built one).
struct SceneMemory {
  std::uint64_t triangles = 0;
  std::uint64_t vertices = 0;
  std::uint64_t hierarchies = 0;
  std::uint64_t instances = 0;
  std::uint64_t triangle_count = 0;  // triangles of the surfaces counted above
  std::uint64_t total() const { return triangles + vertices + hierarchies + instances; }
};

struct Report {
  std::vector<SurfacePairResult> pairs;  // sorted by (instance_a, instance_b, surface_a, surface_b)
  CollideCounters counters;
  CollideTimings timings;
  std::vector<Diagnostic> diagnostics;   // surfaces that could not be tessellated (skipped)
  // False when a budget (CollideOptions) ran out before every instance pair was examined. `pairs`
  // then holds what was found: every result of the examined instance pairs and, under a time budget,
  // the surface pairs finished within the others. Counters count the work whose results are kept.
  bool complete = true;
  // "time budget" or "memory budget" when !complete; empty otherwise. "out of range" when the query
  // was refused because a selected instance or an option is outside the supported range (model.h):
  // nothing was examined, no pairs, and `diagnostics` has an error for each cause.
  std::string stopped_by;
  // Broad-phase instance pairs (of counters.instance_pairs) not fully examined, sorted; (a < b).
  std::vector<std::array<InstanceId, 2>> unexamined_pairs;
  // Bytes charged against memory_budget_bytes (computed whether or not a budget is set); the same
  // for any thread count.
  std::uint64_t memory_charged = 0;
  // What the scene's collision model held after this query (Scene::memory()); the same for any
  // thread count.
  SceneMemory model_memory;
};

// One-off query of two instances. Tessellates (require_triangles) exactly the surfaces it needs.
// Refuses a query outside the supported range (model.h; Report::stopped_by "out of range").
// Preconditions: a < model.instances.size(); b < model.instances.size(); a != b.
Report collide(Model& model, InstanceId a, InstanceId b, const CollideOptions& options = {});

// Which instance pairs a Scene checks.
struct SceneSelection {
  std::vector<InstanceId> set_a;  // empty: every instance
  std::vector<InstanceId> set_b;  // empty: every instance; a pair is checked if one side is in A, the other in B
  std::vector<std::array<std::string, 2>> excluded_pairs;  // instance paths, either order
  std::vector<std::string> excluded_subassemblies;  // pairs with both paths under one of these prefixes ("/root/sub")
};


// ---------------------------------------------------------------------------------------------
// One check split over processes (cadclash/distributed.h runs it under MPI)
// ---------------------------------------------------------------------------------------------
// check(o) = plan(o), check_part(o, plan, part) for parts covering the plan's pairs (each on its own
// replica of the scene: same model, same poses), and a merge (cadclash/distributed.h) that adds the
// parts' per-instance-pair results and counters and counts per-surface work (tessellation, BVHs,
// refinement) once, as one process would have. Each part tessellates only the surfaces its pairs
// reach.

// One broad-phase instance pair of a plan and its estimated cost.
struct PlannedPair {
  InstanceId a = kInvalidId, b = kInvalidId;  // a < b
  // Triangles under the pair's OAABB: summed over its candidate surface pairs, both surfaces'
  // triangles (all surfaces of both parts when their boxes nest: containment), a surface not
  // tessellated yet counted as kUntessellatedCost triangles. An estimate for splitting work only.
  std::uint64_t cost = 0;
};
inline constexpr std::uint64_t kUntessellatedCost = 64;

struct CheckPlan {
  std::vector<PlannedPair> pairs;  // the broad phase's instance pairs, sorted (check()'s order)
  CollideCounters broad;           // the broad phase's own work (world-box updates, sweep tests); instance_pairs 0
  std::vector<SurfaceId> needed;   // surfaces the pairs reach, in order of first need (as check() tessellates them)
  double seconds = 0.0;            // time plan() took
  // Not empty when the query is outside the supported range (model.h): why, as check() would list
  // it; then pairs is empty and each check_part() returns a refused report (stopped_by "out of range").
  std::vector<Diagnostic> refused;
};

// What a check_part() did to one surface, for a merge to count it once over all parts.
struct SurfaceWork {
  SurfaceId surface = kInvalidId;
  bool asked = false;        // it had no triangles and was given to its source (tessellated_surfaces)
  bool tessellated = false;  // ... and got them, at `deflection`; mesh_bytes charged
  bool built = false;        // its hierarchy was built by this query; bvh_bytes charged
  bool refined = false;      // meshed finer for refinement by this query (refined_surfaces)
  double deflection = 0.0;
  std::uint64_t mesh_bytes = 0, bvh_bytes = 0;
  SceneMemory held;          // when built: what it adds to Scene::memory() (triangles, vertices, hierarchy)
  std::optional<Diagnostic> error;  // asked and not tessellated: why
};

struct PartialCheck {
  // check()'s report restricted to the part's instance pairs: results, unexamined pairs, stopped_by,
  // complete, timings, and counters summed over those pairs (instance_pairs = their number) without
  // the plan's broad phase and without tessellated_surfaces and refined_surfaces (see `surfaces`);
  // memory_charged without the surfaces' mesh and BVH bytes; diagnostics empty (in `surfaces`);
  // model_memory this process's.
  Report report;
  std::vector<SurfaceWork> surfaces;  // ascending surface id
};

namespace detail {
struct SceneAccess;  // the library's own restricted checks (continuous motion)
}

// A prepared scene: per-surface BVHs and instance world boxes are built once; each check() updates
// only the instances moved by set_pose since the last check.
// The model must outlive the scene; the scene writes only surfaces' triangles (lazy tessellation).
class Scene {
 public:
  explicit Scene(Model& model, SceneSelection selection = {});
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // Moves an instance (part-local → world). Precondition: instance < model.instances.size().
  void set_pose(InstanceId instance, const Pose& pose);
  const Pose& pose(InstanceId instance) const;

  // Returns the instance id with this path, or kInvalidId.
  InstanceId find_instance(const std::string& path) const;

  // Refused (Report::stopped_by "out of range") when a selected instance or an option is outside the
  // supported range (model.h).
  Report check(const CollideOptions& options = {});

  // Builds now the hierarchy of every surface that has triangles and none yet (check() builds them
  // on demand, for the surfaces its pairs reach). threads <= 0: all available. Returns how many.
  std::size_t build_hierarchies(int threads = 0);

  // The bytes held now (see SceneMemory).
  SceneMemory memory() const;

  // The broad phase and the object and surface levels of check(options), nothing tessellated or
  // tested: the instance pairs check() would examine, with cost estimates. Updates the world boxes of
  // the instances moved since the last check, as check() does. Ignores the budgets.
  CheckPlan plan(const CollideOptions& options);

  // check(options) restricted to plan.pairs[k] for k in `part` (see PartialCheck).
  // Preconditions: `plan` is this scene's last plan(options) and no set_pose since; `part` ascending,
  // each k < plan.pairs.size(); options.memory_budget_bytes == 0 (a budget over a prefix of all pairs
  // cannot be split).
  PartialCheck check_part(const CollideOptions& options, const CheckPlan& plan, std::span<const std::uint32_t> part);

  // Surface `s`, which has no triangles here, was tessellated by another process at `deflection`
  // (into `triangles` triangles): search reaches use it, as they would in the process that holds its
  // triangles, and plan() costs it at `triangles`. Precondition: s < model.surfaces.size().
  void note_deflection(SurfaceId s, double deflection, std::uint64_t triangles = kUntessellatedCost);

 private:
  friend struct detail::SceneAccess;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cadclash

// Paths of poses replayed on a Scene (part of this header's API).
#include "cadclash/trajectory.h"
