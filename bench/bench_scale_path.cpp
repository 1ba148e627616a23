// Issue 16 items 4-6: one part moving through a large instanced scene, and the scene's one-shot cost.
//   bench_scale_path [--data DIR] [--out FILE.json] [--series FILE.dat] [--copies N] [--deflection D] [--steps N]
// The scene: N copies of as1-tu-203.stp (default 290: 5,220 instances, ~10 M instance triangles at
// 0.001 mm) on a grid, sharing the parts (bench_compare's instanced scene). Copy 0's NUT::3 is
// unscrewed off its bolt (bench_compare's "unscrew" path) while every other instance stays.
// Measured, with the certified default, on 1 and 2 threads:
// - build: Scene::build_hierarchies on one thread, model triangles per second;
// - one-shot: one check of every instance pair, for 1, 3, 10, 30, 100 copies and the whole scene
//   (--series writes "copies instance_triangles seconds_1 seconds_2" rows for the log-log plot);
// - path: per step set_pose + check of the pairs with the nut (SceneSelection set_a = {nut}): median,
//   90th percentile and largest step time; the reports must not depend on the thread count (the
//   pairs and counters of every step are compared, and a difference is an error, exit 1); the same
//   path in the same grid with distinct parts (every copy its own parts and surfaces), whose steps
//   must cost and report the same;
// - Table 2 (Figueiredo & Fernando): OAABB vs brute force counters (AABB tests, updates, triangle
//   tests) on the path in the as1 assembly alone (brute force over 5,220 instances would take days).
// Prints a markdown summary on stdout (scripts/results.sh puts it in docs/results.md), progress on
// stderr; timings are printed, never judged.
#include "compare_workload.h"

#include "cadclash/import.h"
#include "cadclash/report.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace {

using namespace cadclash;
namespace cb = cadclash::bench;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct PathRun {
  std::vector<double> step_seconds;
  CollideCounters counters;  // summed over the steps
  std::vector<std::vector<SurfacePairResult>> pairs;  // per step
  std::vector<CollideCounters> step_counters;
  std::vector<CollideTimings> step_timings;  // the report's stage times, per step
};

void add(CollideCounters& into, const CollideCounters& c) {
  for (const CounterField& f : kCounterFields) into.*f.member += c.*f.member;
}

// One scene following the path with the nut selected: steps can be run a block at a time.
struct PathRunner {
  static SceneSelection with(InstanceId nut) {
    SceneSelection sel;
    sel.set_a = {nut};
    return sel;
  }
  PathRunner(Model& model, InstanceId nut, const CollideOptions& options) : scene(model, with(nut)), o(options) {
    scene.build_hierarchies(o.threads);
    scene.check(o);  // the first check builds the instance tree and the world boxes
  }
  // Steps [from, to) of the path, every `stride`-th one checked and timed.
  void steps(const cb::GeneratedPath& path, std::size_t from, std::size_t to, std::size_t stride) {
    for (std::size_t k = from; k < to; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      for (const cb::PoseUpdate& u : path.steps[k]) scene.set_pose(u.instance, u.pose);
      if (k % stride != 0) continue;
      Report r = scene.check(o);
      run.step_seconds.push_back(seconds_since(t0));
      add(run.counters, r.counters);
      run.step_counters.push_back(r.counters);
      run.step_timings.push_back(r.timings);
      run.pairs.push_back(std::move(r.pairs));
    }
  }
  Scene scene;
  CollideOptions o;
  PathRun run;
};

PathRun run_path(Model& model, InstanceId nut, const cb::GeneratedPath& path, CollideOptions o, std::size_t stride) {
  PathRunner runner(model, nut, o);
  runner.steps(path, 0, path.steps.size(), stride);
  return std::move(runner.run);
}

// Steps per block when 1 and 2 threads follow the path in turns: each sees the machine of the same
// minutes, so a disturbance (the VM's second core taken for a while) does not fall on one side only.
constexpr std::size_t kPathBlock = 50;

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5))];
}

bool same_pairs(const std::vector<SurfacePairResult>& x, const std::vector<SurfacePairResult>& y) {
  if (x.size() != y.size()) return false;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const SurfacePairResult &a = x[k], &b = y[k];
    if (a.instance_a != b.instance_a || a.instance_b != b.instance_b || a.surface_a != b.surface_a ||
        a.surface_b != b.surface_b || a.contact != b.contact || a.distance != b.distance ||
        a.penetration != b.penetration || a.decided_by != b.decided_by)
      return false;
  }
  return true;
}

bool same_counters(const CollideCounters& a, const CollideCounters& b) {
  for (const CounterField& f : kCounterFields)
    if (a.*f.member != b.*f.member) return false;
  return true;
}

int usage() {
  std::fprintf(stderr,
               "usage: bench_scale_path [--data DIR] [--out FILE.json] [--series FILE.dat] [--copies N] [--deflection D] "
               "[--steps N]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data = CADCLASH_DATA_DIR "/external", out, series_out;
  std::uint32_t copies = 290;
  double deflection = 0.001;
  int steps = 500;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) return usage();
    const std::string v = argv[++i];
    if (a == "--data") data = v;
    else if (a == "--out") out = v;
    else if (a == "--series") series_out = v;
    else if (a == "--copies") copies = static_cast<std::uint32_t>(std::stoul(v));
    else if (a == "--deflection") deflection = std::stod(v);
    else if (a == "--steps") steps = std::stoi(v);
    else return usage();
  }
  const std::string file = data + "/as1-tu-203.stp";
  if (!std::ifstream(file)) {
    std::fprintf(stderr, "bench_scale_path: %s not found (run scripts/setup.sh)\n", file.c_str());
    return 77;
  }
  ImportOptions io;
  io.tessellation.linear_deflection = deflection;
  ImportResult imported = import_file(file, io);
  Model& base = imported.model;
  Model scene_model = cb::instanced_grid(base, copies);
  const std::size_t model_triangles = triangle_count(base);
  const std::size_t instance_triangles = cb::instance_triangle_count(scene_model);
  nlohmann::json j = {{"file", file},
                      {"deflection", deflection},
                      {"copies", copies},
                      {"instances", scene_model.instances.size()},
                      {"instance_triangles", instance_triangles},
                      {"model_triangles", model_triangles}};
  std::string md;  // the summary, printed at the end (scripts/results.sh embeds it in docs/results.md)
  auto line = [&](const std::string& text) { md += text + "\n"; };
  line("Scene: " + std::to_string(copies) + " copies of as1-tu-203.stp at deflection " + fmt("%g", deflection) +
       " mm on a grid (bench_compare's instanced scene): " + std::to_string(scene_model.instances.size()) +
       " instances, " + std::to_string(instance_triangles) + " instance triangles, " + std::to_string(model_triangles) +
       " triangles in the model (the copies share the parts). Certified default; 2 cores.");
  line("");

  // Bytes of the collision model, per component: as1 alone and the whole scene.
  line("| collision model | triangles | vertices | hierarchies | instances | total | bytes per model triangle | "
       "bytes per instance triangle |");
  line("|---|---:|---:|---:|---:|---:|---:|---:|");
  // The build takes about a millisecond: its rate is the median of kBuilds fresh scenes' builds (one
  // such measurement read anywhere from 3 to 12 M triangles per second).
  constexpr int kBuilds = 21;
  std::vector<double> builds;
  for (int k = 0; k < kBuilds; ++k) {
    Scene fresh(scene_model);
    const auto t0 = std::chrono::steady_clock::now();
    fresh.build_hierarchies(1);
    builds.push_back(seconds_since(t0));
  }
  std::sort(builds.begin(), builds.end());
  const double build_seconds = builds[kBuilds / 2];
  for (Model* m : {&base, &scene_model}) {
    Scene scene(*m);
    scene.build_hierarchies(1);
    const SceneMemory mem = scene.memory();
    const double per_instance = static_cast<double>(cb::instance_triangle_count(*m));
    line(std::string(m == &base ? "| as1 alone" : "| the whole scene") + " | " + std::to_string(mem.triangles) + " | " +
         std::to_string(mem.vertices) + " | " + std::to_string(mem.hierarchies) + " | " + std::to_string(mem.instances) +
         " | " + std::to_string(mem.total()) + " | " +
         fmt("%.1f", static_cast<double>(mem.total()) / static_cast<double>(mem.triangle_count)) + " | " +
         fmt("%.2f", static_cast<double>(mem.total()) / per_instance) + " |");
    j[m == &base ? "bytes_as1" : "bytes_scene"] = {{"triangles", mem.triangles}, {"vertices", mem.vertices},
                                                   {"hierarchies", mem.hierarchies}, {"instances", mem.instances},
                                                   {"total", mem.total()}, {"model_triangles", mem.triangle_count}};
  }
  j["build"] = {{"seconds", build_seconds},
                {"seconds_fastest", builds.front()},
                {"seconds_slowest", builds.back()},
                {"runs", kBuilds},
                {"triangles_per_second", static_cast<double>(model_triangles) / build_seconds}};
  line("");
  line("Build: every surface's hierarchy on one thread in " + fmt("%.2f", 1e3 * build_seconds) + " ms, " +
       fmt("%.1f", 1e-6 * static_cast<double>(model_triangles) / build_seconds) +
       " M model triangles per second (median of " + std::to_string(kBuilds) + " builds of fresh scenes; " +
       fmt("%.1f", 1e-6 * static_cast<double>(model_triangles) / builds.back()) + " to " +
       fmt("%.1f", 1e-6 * static_cast<double>(model_triangles) / builds.front()) + " M/s).");
  line("");

  // One-shot: every instance pair, for a series of scene sizes up to the whole scene (the time vs
  // triangles plot and the parallel efficiency of issue 16 item 5).
  struct OneShot {
    std::uint32_t copies = 0;
    std::size_t instance_triangles = 0, pairs = 0;
    double seconds[2] = {0.0, 0.0};
    cb::HostCheck host;  // around the two checks (compare_workload.h, until_host_gave_both)
  };
  std::vector<OneShot> series;
  for (std::uint32_t c : {1u, 3u, 10u, 30u, 100u, copies}) {
    if (c > copies || (!series.empty() && series.back().copies >= c)) continue;
    Model m = cb::instanced_grid(base, c);
    OneShot row;
    row.copies = c;
    row.instance_triangles = cb::instance_triangle_count(m);
    row.host = cb::until_host_gave_both(
        [&] {
          for (int threads : {1, 2}) {
            Scene scene(m);
            scene.build_hierarchies(threads);
            CollideOptions o;
            o.threads = threads;
            const auto t0 = std::chrono::steady_clock::now();
            const Report r = scene.check(o);
            row.seconds[threads - 1] = seconds_since(t0);
            row.pairs = r.pairs.size();
            j["one_shot"][std::to_string(c)][std::to_string(threads)] = {
                {"seconds", row.seconds[threads - 1]}, {"pairs", r.pairs.size()}, {"counters", counters_json(r.counters)}};
            std::fprintf(stderr, "one-shot, %u copies, %d thread(s): %.3f s\n", c, threads, row.seconds[threads - 1]);
          }
        },
        [&](const cb::HostCheck& h) {
          std::fprintf(stderr, "one-shot, %u copies: the host took a vCPU (second CPU share %.2f / %.2f): again\n", c,
                       h.before, h.after);
        });
    j["one_shot"][std::to_string(c)]["second_cpu_share"] = {row.host.before, row.host.after};
    j["one_shot"][std::to_string(c)]["attempt"] = row.host.attempt;
    series.push_back(row);
  }
  if (!series_out.empty()) {
    std::ofstream dat(series_out);
    dat << "# copies instance_triangles seconds_1_thread seconds_2_threads\n";
    for (const OneShot& r : series)
      dat << r.copies << ' ' << r.instance_triangles << ' ' << r.seconds[0] << ' ' << r.seconds[1] << '\n';
  }
  const double one_shot[2] = {series.back().seconds[0], series.back().seconds[1]};
  const std::size_t one_shot_pairs = series.back().pairs;

  // The path through the big scene.
  const std::string nut_path = "/copy0/as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::1/NUT::3";
  const std::string bolt_path = "/copy0/as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::1/BOLT";
  cb::GeneratedPath path;
  std::string error;
  if (!cb::unscrew_path(scene_model, nut_path, bolt_path, steps, 5.0, path, error)) {
    std::fprintf(stderr, "bench_scale_path: %s\n", error.c_str());
    return 1;
  }
  const InstanceId nut = path.moving.at(0);
  // The same scene with distinct parts: every copy its own (copy 0 keeps the ids of the shared one's
  // parts and surfaces, so its steps' reports must be the same), as in a plant where few parts repeat.
  // What a step costs must not grow with the model's surfaces any more than with its instances.
  Model distinct_model = cb::distinct_grid(base, copies);
  std::vector<PathRun> runs, distinct_runs;
  std::vector<double> turn_round_trip;  // ns, measured before each turn of kPathBlock steps
  {
    CollideOptions o1, o2;
    o1.threads = 1;
    o2.threads = 2;
    PathRunner one(scene_model, nut, o1), two(scene_model, nut, o2);
    PathRunner distinct_one(distinct_model, nut, o1), distinct_two(distinct_model, nut, o2);
    for (std::size_t b = 0; b < path.steps.size(); b += kPathBlock) {
      const std::size_t e = std::min(path.steps.size(), b + kPathBlock);
      turn_round_trip.push_back(cb::core_round_trip_ns(2000));
      one.steps(path, b, e, 1);
      two.steps(path, b, e, 1);
      distinct_one.steps(path, b, e, 1);
      distinct_two.steps(path, b, e, 1);
    }
    runs.push_back(std::move(one.run));
    runs.push_back(std::move(two.run));
    distinct_runs.push_back(std::move(distinct_one.run));
    distinct_runs.push_back(std::move(distinct_two.run));
  }
  // The path's medians by where the host had put the two vCPUs during each turn (near: cores sharing
  // a cache; far: across the package, every exchange between the threads ~6x dearer).
  struct Placement {
    const char* name;
    std::vector<double> seconds[2], round_trip;
  } placements[2] = {{"near", {}, {}}, {"far", {}, {}}};
  for (std::size_t t = 0; t < turn_round_trip.size(); ++t) {
    Placement& p = placements[turn_round_trip[t] >= cb::kFarCoresNs ? 1 : 0];
    p.round_trip.push_back(turn_round_trip[t]);
    for (int th = 0; th < 2; ++th) {
      const auto& v = runs[static_cast<std::size_t>(th)].step_seconds;
      const std::size_t b = t * kPathBlock, e = std::min(v.size(), b + kPathBlock);
      p.seconds[th].insert(p.seconds[th].end(), v.begin() + static_cast<std::ptrdiff_t>(b),
                           v.begin() + static_cast<std::ptrdiff_t>(e));
    }
  }
  for (int threads : {1, 2}) {
    const PathRun& r = runs[static_cast<std::size_t>(threads - 1)];
    double sum = 0.0;
    for (double s : r.step_seconds) sum += s;
    j["path"][std::to_string(threads)] = {{"steps", r.step_seconds.size()},
                                          {"median_ms", 1e3 * percentile(r.step_seconds, 0.5)},
                                          {"p90_ms", 1e3 * percentile(r.step_seconds, 0.9)},
                                          {"max_ms", 1e3 * percentile(r.step_seconds, 1.0)},
                                          {"total_s", sum},
                                          {"counters", counters_json(r.counters)}};
    std::fprintf(stderr, "path, %d thread(s): median %.3f ms\n", threads, 1e3 * percentile(r.step_seconds, 0.5));
  }
  int status = 0;
  for (std::size_t k = 0; k < runs[0].pairs.size(); ++k)
    for (const PathRun* other : {&runs[1], &distinct_runs[0], &distinct_runs[1]})
      if (!same_pairs(runs[0].pairs[k], other->pairs[k]) ||
          !same_counters(runs[0].step_counters[k], other->step_counters[k])) {
        std::fprintf(stderr, "bench_scale_path: step %zu differs between 1 and 2 threads or shared and distinct parts\n", k);
        status = 1;
      }
  for (int threads : {1, 2})
    j["path_distinct_parts"][std::to_string(threads)] = {
        {"median_ms", 1e3 * percentile(distinct_runs[static_cast<std::size_t>(threads - 1)].step_seconds, 0.5)},
        {"parts", distinct_model.parts.size()},
        {"surfaces", distinct_model.surfaces.size()}};
  line("The path: " + path.description + "; each step moves the nut (set_pose) and checks the pairs with it (SceneSelection set_a = {nut}). "
       "One scene per thread count follows it, in turns of " + std::to_string(kPathBlock) +
       " steps (both see the machine of the same minutes). Reports and counters of every step " +
       std::string(status == 0 ? "are identical" : "DIFFER") +
       " on 1 and 2 threads, and in the same scene with distinct parts (every copy its own parts: " +
       std::to_string(distinct_model.parts.size()) + " parts, " + std::to_string(distinct_model.surfaces.size()) +
       " surfaces, followed in the same turns).");
  line("");
  line("| measure | 1 thread | 2 threads |");
  line("|---|---:|---:|");
  line("| one-shot query of every instance pair (" + std::to_string(one_shot_pairs) + " reported pairs) | " +
       fmt("%.2f s", one_shot[0]) + " | " + fmt("%.2f s", one_shot[1]) + " |");
  for (const auto& [label, q] : {std::pair<const char*, double>{"median", 0.5}, {"90th percentile", 0.9},
                                 {"largest", 1.0}})
    line(std::string("| path step, ") + label + " | " + fmt("%.3f ms", 1e3 * percentile(runs[0].step_seconds, q)) +
         " | " + fmt("%.3f ms", 1e3 * percentile(runs[1].step_seconds, q)) + " |");
  for (const Placement& p : placements) {
    if (p.round_trip.empty()) continue;
    const double m1 = percentile(p.seconds[0], 0.5), m2 = percentile(p.seconds[1], 0.5);
    line(std::string("| path step, median in the turns with the vCPUs ") + p.name + " (" +
         std::to_string(p.round_trip.size()) + " of " + std::to_string(turn_round_trip.size()) +
         " turns, core-to-core round trip " + fmt("%.0f ns", percentile(p.round_trip, 0.5)) +
         "; parallel efficiency " + fmt("%.0f %%", 100.0 * m1 / (2.0 * m2)) + ") | " + fmt("%.3f ms", 1e3 * m1) +
         " | " + fmt("%.3f ms", 1e3 * m2) + " |");
    j["path"]["placement"][p.name] = {{"turns", p.round_trip.size()},
                                      {"round_trip_ns", percentile(p.round_trip, 0.5)},
                                      {"median_ms_1", 1e3 * m1},
                                      {"median_ms_2", 1e3 * m2}};
  }
  {
    const double m1 = percentile(distinct_runs[0].step_seconds, 0.5), m2 = percentile(distinct_runs[1].step_seconds, 0.5);
    line("| path step, median, distinct parts (parallel efficiency " + fmt("%.0f %%", 100.0 * m1 / (2.0 * m2)) + ") | " +
         fmt("%.3f ms", 1e3 * m1) + " | " + fmt("%.3f ms", 1e3 * m2) + " |");
  }
  {
    // Where a step's time goes (the report's stage timings; a step also holds set_pose and handing
    // the report over): what a second thread shortens, and what it cannot.
    struct Stage {
      const char* name;
      double (*of)(const CollideTimings&);
    };
    const Stage stages[] = {
        {"broad phase", [](const CollideTimings& t) { return t.broad; }},
        {"surface level", [](const CollideTimings& t) { return t.surface_level; }},
        {"tessellation", [](const CollideTimings& t) { return t.tessellation; }},
        {"triangles and decisions", [](const CollideTimings& t) { return t.triangle_level; }},
        {"results and report",
         [](const CollideTimings& t) { return t.total - t.broad - t.surface_level - t.tessellation - t.triangle_level; }}};
    for (const Stage& st : stages) {
      double m[2];
      for (int th = 0; th < 2; ++th) {
        std::vector<double> v;
        for (const CollideTimings& t : runs[static_cast<std::size_t>(th)].step_timings) v.push_back(st.of(t));
        m[th] = percentile(v, 0.5);
        j["path"][std::to_string(th + 1)]["stage_median_ms"][st.name] = 1e3 * m[th];
      }
      line(std::string("| path step, median of its ") + st.name + " | " + fmt("%.4f ms", 1e3 * m[0]) + " | " +
           fmt("%.4f ms", 1e3 * m[1]) + " |");
    }
  }
  line("| path: instance pairs / triangle tests over all steps | " + std::to_string(runs[0].counters.instance_pairs) +
       " / " + std::to_string(runs[0].counters.triangle_tests) + " | " + std::to_string(runs[1].counters.instance_pairs) +
       " / " + std::to_string(runs[1].counters.triangle_tests) + " |");
  line("");

  line("One-shot query time by scene size (the same grid with fewer copies; parallel efficiency = "
       "time on 1 thread / (2 x time on 2 threads); second CPU share = the lower of second_cpu_share() before and "
       "after the size's two checks, which are timed again, up to " + std::to_string(cb::kHostAttempts) +
       " times, while it is below " + fmt("%.1f", cb::kFullSecondCpu) + "):");
  line("");
  line("| copies | instance triangles | reported pairs | 1 thread | 2 threads | parallel efficiency | second CPU share (run) |");
  line("|---:|---:|---:|---:|---:|---:|---:|");
  for (const OneShot& r : series)
    line("| " + std::to_string(r.copies) + " | " + std::to_string(r.instance_triangles) + " | " +
         std::to_string(r.pairs) + " | " + fmt("%.3f s", r.seconds[0]) + " | " + fmt("%.3f s", r.seconds[1]) + " | " +
         fmt("%.0f %%", 100.0 * r.seconds[0] / (2.0 * r.seconds[1])) + " | " + fmt("%.2f", std::min(r.host.before, r.host.after)) + " (" +
         std::to_string(r.host.attempt) + ") |");
  line("");

  // Table 2 on the as1 assembly alone: the same path, OAABB vs brute force, every 10th step.
  {
    cb::GeneratedPath small;
    if (!cb::unscrew_path(base, nut_path.substr(6), bolt_path.substr(6), steps, 5.0, small, error)) {
      std::fprintf(stderr, "bench_scale_path: %s\n", error.c_str());
      return 1;
    }
    line("Table 2 of the paper on the same path in as1 alone (18 instances; brute force over the whole scene "
         "would take days), every 10th step (" + std::to_string((small.steps.size() + 9) / 10) +
         " checks), 2 threads. Brute force tests every triangle pair of every pair with the nut and no box; "
         "OAABB spends box tests and box updates to skip almost all of them.");
    line("");
    line("| method | AABB tests | AABB updates | triangle tests |");
    line("|---|---:|---:|---:|");
    CollideCounters with_oaabb, brute;
    for (bool oaabb : {true, false}) {
      CollideOptions o;
      o.use_oaabb = oaabb;
      o.threads = 2;
      const PathRun r = run_path(base, small.moving.at(0), small, o, 10);
      (oaabb ? with_oaabb : brute) = r.counters;
      line(std::string("| ") + (oaabb ? "OAABB" : "brute force") + " | " + std::to_string(r.counters.aabb_tests) +
           " | " + std::to_string(r.counters.aabb_updates) + " | " + std::to_string(r.counters.triangle_tests) + " |");
      j["table2"][oaabb ? "oaabb" : "brute_force"] = counters_json(r.counters);
    }
    line("| brute force / OAABB | — | " +
         fmt("%.3f", static_cast<double>(brute.aabb_updates) / std::max(1.0, static_cast<double>(with_oaabb.aabb_updates))) +
         " | " +
         fmt("%.0f", static_cast<double>(brute.triangle_tests) / std::max(1.0, static_cast<double>(with_oaabb.triangle_tests))) +
         " |");
  }
  std::fputs(md.c_str(), stdout);
  if (!out.empty()) std::ofstream(out) << j.dump(2) << '\n';
  return status;
}
