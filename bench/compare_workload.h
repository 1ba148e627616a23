// What bench_compare measures: a scene (model + which instances move) and the steps it is queried
// at, plus the pieces every method shares (surface-pair keys, the world-box broad phase) and the
// generators of the workloads (as1 trajectories, the instanced large scene). Bench-only code.
#pragma once

#include "cadclash/collide.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace cadclash::bench {

// (step, instance a, instance b, surface a, surface b) with instance a < instance b: one surface pair
// found at one step of a workload. Surfaces are model surface ids (shared by a part's instances).
using PairKey = std::array<std::uint32_t, 5>;
using PairSet = std::set<PairKey>;

struct PoseUpdate {
  InstanceId instance = kInvalidId;
  Pose pose = Pose::Identity();
};

struct Workload {
  std::string name;         // row group title in the report
  Model* model = nullptr;   // not owned
  double deflection = 0.0;  // the tessellation deflection (mm); also the peers' "tolerance t"
  // Instances that move; empty: every instance pair is checked (a static scene). Otherwise only pairs
  // with at least one moving instance, as a maintenance-path query does.
  std::vector<InstanceId> moving;
  // Per step, the poses that change before that step is checked. A static scene has one empty step.
  std::vector<std::vector<PoseUpdate>> steps;
};

// The part of a workload a method too slow for all of it runs on: pairs of instances with ids below
// `instances` (0 = all), checked at every `stride`-th step (the poses still follow every step).
struct Subset {
  std::uint32_t instances = 0;
  std::uint32_t stride = 1;
  bool whole() const { return instances == 0 && stride <= 1; }
  bool has_step(std::uint32_t step) const { return stride <= 1 || step % stride == 0; }
  bool contains(const PairKey& k) const {
    return has_step(k[0]) && (instances == 0 || (k[1] < instances && k[2] < instances));
  }
};

// Current world pose of every instance while a workload is replayed from its start.
struct PoseState {
  std::vector<Pose> poses;
  explicit PoseState(const Model& model);
  void apply(const std::vector<PoseUpdate>& updates);
};

// The surfaces' triangles' box per part (part-local), from the triangles themselves.
std::vector<Aabb> part_triangle_boxes(const Model& model);

// Instance pairs (a < b) whose world triangle boxes overlap (touching counts), optionally only pairs
// with a moving instance and only pairs of instances below `instance_limit` (0 = all). Sorted.
std::vector<std::array<InstanceId, 2>> overlapping_instance_pairs(const Model& model,
                                                                   const std::vector<Aabb>& part_boxes,
                                                                   const std::vector<Pose>& poses,
                                                                   const std::vector<char>& moving,
                                                                   std::uint32_t instance_limit);

// Replays `w` from its start: at every step of `subset`, after the step's pose updates, calls
// f(step, a, b, pose_a, pose_b) for each broad-phase pair (overlapping_instance_pairs with the
// workload's moving set and the subset's instance limit), in ascending (a, b) order.
void for_each_step_pair(const Workload& w, const Subset& subset,
                        const std::function<void(std::uint32_t, InstanceId, InstanceId, const Pose&, const Pose&)>& f);

// A trajectory of one or more instances through the scene, generated from the model's geometry.
struct GeneratedPath {
  std::string name;
  std::string description;            // what moves and how, for the report
  std::vector<InstanceId> moving;
  std::vector<std::vector<PoseUpdate>> steps;
};

// A nut of a bolted joint unscrewed off its bolt: the bolt axis from the bolt's principal axis
// (area-weighted), the nut turned `turns` times while it travels off the bolt's end in `steps` steps.
// `nut_path` and `bolt_path` are instance paths. Returns false with `error` set if either is missing.
bool unscrew_path(const Model& model, const std::string& nut_path, const std::string& bolt_path, int steps,
                  double turns, GeneratedPath& out, std::string& error);

// The instances under `subassembly` (a path prefix) withdrawn from `plate` along the plate's normal
// (its thinnest principal axis, pointing to the subassembly) until they clear it, in `steps` steps.
bool withdraw_path(const Model& model, const std::string& subassembly, const std::string& plate_path, int steps,
                   GeneratedPath& out, std::string& error);

// Writes a path as CSV in the format parse_trajectory reads (absolute poses of the moving instances
// at every step). Returns false if the file cannot be written.
bool write_path_csv(const Model& model, const GeneratedPath& path, const std::string& file);

// A model made of `copies` copies of `base`'s instances laid out on a grid (spaced by the base's
// world box plus a gap so copies never touch), sharing base's parts. Copy k's instances are
// "/copyK" + the base path and have ids [k * n, (k + 1) * n) for n base instances.
Model instanced_grid(const Model& base, std::uint32_t copies);

// instanced_grid, but every copy has parts of its own (copies of base's parts and surfaces, sharing
// their SurfaceSource): a plant of distinct parts, where a model's surfaces grow with the scene.
Model distinct_grid(const Model& base, std::uint32_t copies);

// Triangles over all instances (a part's triangles counted once per instance).
std::size_t instance_triangle_count(const Model& model);

// Nanoseconds for one cache line to go from one thread to another and back (two threads taking
// turns on one atomic; mean of `trips` round trips). On a VM the host may put the two vCPUs on
// cores that share a cache or on cores far apart in the package: every exchange between threads
// (a team's start and end, a dynamic loop's next item, results one thread wrote and another
// reads) costs accordingly, so benchmarks report it beside parallel timings.
double core_round_trip_ns(int trips = 20000);

// Round trips above this are "far" cores: this 2-vCPU machine reads 50-140 ns or 330-500 ns.
constexpr double kFarCoresNs = 200.0;

// How much of a second CPU the host gives the process now: one thread's time for a fixed compute
// loop (~20 ms, registers only) over the slower thread's time when the OpenMP team's two threads run
// it at once; the median of three. ~1.0 when both vCPUs are ours; the host running other work on
// one of them reads well below. It sees only that, not other tenants' load on the shared caches and
// memory (which slowed 1- and 2-thread rows here while this read 0.97-1.01). It measures the host,
// not cadclash: benchmarks use it to run a table again when the host took a vCPU, never to choose
// between their own timings.
double second_cpu_share();

// second_cpu_share() at or above this: the host gave both vCPUs.
constexpr double kFullSecondCpu = 0.9;

// What second_cpu_share() read before and after something timed, and in which run of it.
struct HostCheck {
  double before = 0.0, after = 0.0;  // 0: not measured
  int attempt = 0;
  bool gave_both() const { return std::min(before, after) >= kFullSecondCpu; }
};
// Runs of a timing the host disturbed by taking a vCPU, at most.
constexpr int kHostAttempts = 3;
// Runs timed() between two second_cpu_share() readings until they say the host gave both vCPUs,
// at most kHostAttempts times; again(check) is told of each run that is thrown away.
template <class Timed, class Again>
HostCheck until_host_gave_both(Timed&& timed, Again&& again) {
  HostCheck h;
  for (h.attempt = 1;; ++h.attempt) {
    h.before = second_cpu_share();
    timed();
    h.after = second_cpu_share();
    if (h.gave_both() || h.attempt == kHostAttempts) return h;
    again(h);
  }
}

}  // namespace cadclash::bench
