// Issue 16 items 4-6: one part moving through a large instanced scene, and the scene's one-shot cost.
//   bench_scale_path [--data DIR] [--out FILE.json] [--copies N] [--deflection D] [--steps N]
// The scene: N copies of as1-tu-203.stp (default 290: 5,220 instances, ~10 M instance triangles at
// 0.001 mm) on a grid, sharing the parts (bench_compare's instanced scene). Copy 0's NUT::3 is
// unscrewed off its bolt (bench_compare's "unscrew" path) while every other instance stays.
// Measured, with the certified default, on 1 and 2 threads:
// - build: Scene::build_hierarchies on one thread, model triangles per second;
// - one-shot: one check of every instance pair of the scene;
// - path: per step set_pose + check of the pairs with the nut (SceneSelection set_a = {nut}): median,
//   90th percentile and largest step time; the reports must not depend on the thread count (the
//   pairs and counters of every step are compared, and a difference is an error, exit 1);
// - Table 2 (Figueiredo & Fernando): OAABB vs brute force counters (AABB tests, updates, triangle
//   tests) on the path in the as1 assembly alone (brute force over 5,220 instances would take days).
// Prints a markdown summary; timings are printed, never judged.
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
};

void add(CollideCounters& into, const CollideCounters& c) {
  for (const CounterField& f : kCounterFields) into.*f.member += c.*f.member;
}

PathRun run_path(Model& model, InstanceId nut, const cb::GeneratedPath& path, CollideOptions o, std::size_t stride) {
  SceneSelection sel;
  sel.set_a = {nut};
  Scene scene(model, sel);
  scene.build_hierarchies(o.threads);
  scene.check(o);  // the first check builds the instance tree and the world boxes
  PathRun run;
  for (std::size_t k = 0; k < path.steps.size(); ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const cb::PoseUpdate& u : path.steps[k]) scene.set_pose(u.instance, u.pose);
    if (k % stride != 0) continue;
    Report r = scene.check(o);
    run.step_seconds.push_back(seconds_since(t0));
    add(run.counters, r.counters);
    run.step_counters.push_back(r.counters);
    run.pairs.push_back(std::move(r.pairs));
  }
  return run;
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
               "usage: bench_scale_path [--data DIR] [--out FILE.json] [--copies N] [--deflection D] [--steps N]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data = CADCLASH_DATA_DIR "/external", out;
  std::uint32_t copies = 290;
  double deflection = 0.001;
  int steps = 500;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) return usage();
    const std::string v = argv[++i];
    if (a == "--data") data = v;
    else if (a == "--out") out = v;
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
  std::printf("scene: %u copies of as1 at %g mm: %zu instances, %zu instance triangles (%zu in the model)\n\n",
              copies, deflection, scene_model.instances.size(), instance_triangles, model_triangles);

  // Build: every surface's hierarchy on one thread.
  {
    Scene scene(scene_model);
    const auto t0 = std::chrono::steady_clock::now();
    scene.build_hierarchies(1);
    const double s = seconds_since(t0);
    const SceneMemory m = scene.memory();
    j["build"] = {{"seconds", s},
                  {"triangles_per_second", static_cast<double>(model_triangles) / s},
                  {"bytes", {{"triangles", m.triangles}, {"vertices", m.vertices}, {"hierarchies", m.hierarchies},
                             {"instances", m.instances}, {"total", m.total()}}},
                  {"bytes_per_model_triangle", static_cast<double>(m.total()) / static_cast<double>(m.triangle_count)}};
    std::printf("build (1 thread): %.3f ms, %.2f M model triangles/s; model %.1f bytes/triangle "
                "(triangles %llu, vertices %llu, hierarchies %llu, instances %llu)\n",
                1e3 * s, 1e-6 * static_cast<double>(model_triangles) / s,
                static_cast<double>(m.total()) / static_cast<double>(m.triangle_count),
                static_cast<unsigned long long>(m.triangles), static_cast<unsigned long long>(m.vertices),
                static_cast<unsigned long long>(m.hierarchies), static_cast<unsigned long long>(m.instances));
  }

  // One-shot: every instance pair of the scene.
  for (int threads : {1, 2}) {
    Scene scene(scene_model);
    scene.build_hierarchies(threads);
    CollideOptions o;
    o.threads = threads;
    const auto t0 = std::chrono::steady_clock::now();
    const Report r = scene.check(o);
    const double s = seconds_since(t0);
    j["one_shot"][std::to_string(threads)] = {{"seconds", s}, {"pairs", r.pairs.size()}, {"counters", counters_json(r.counters)}};
    std::printf("one-shot, %d thread(s): %.3f s, %zu reported pairs, %llu triangle tests\n", threads, s, r.pairs.size(),
                static_cast<unsigned long long>(r.counters.triangle_tests));
  }

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
  std::vector<PathRun> runs;
  for (int threads : {1, 2}) {
    CollideOptions o;
    o.threads = threads;
    runs.push_back(run_path(scene_model, nut, path, o, 1));
    const PathRun& r = runs.back();
    double sum = 0.0;
    for (double s : r.step_seconds) sum += s;
    j["path"][std::to_string(threads)] = {{"steps", r.step_seconds.size()},
                                          {"median_ms", 1e3 * percentile(r.step_seconds, 0.5)},
                                          {"p90_ms", 1e3 * percentile(r.step_seconds, 0.9)},
                                          {"max_ms", 1e3 * percentile(r.step_seconds, 1.0)},
                                          {"total_s", sum},
                                          {"counters", counters_json(r.counters)}};
    std::printf("path (%s), %d thread(s): %zu steps, median %.3f ms, p90 %.3f ms, max %.3f ms, total %.3f s; "
                "%llu instance pairs, %llu triangle tests\n",
                path.name.c_str(), threads, r.step_seconds.size(), 1e3 * percentile(r.step_seconds, 0.5),
                1e3 * percentile(r.step_seconds, 0.9), 1e3 * percentile(r.step_seconds, 1.0), sum,
                static_cast<unsigned long long>(r.counters.instance_pairs),
                static_cast<unsigned long long>(r.counters.triangle_tests));
  }
  int status = 0;
  for (std::size_t k = 0; k < runs[0].pairs.size(); ++k)
    if (!same_pairs(runs[0].pairs[k], runs[1].pairs[k]) ||
        !same_counters(runs[0].step_counters[k], runs[1].step_counters[k])) {
      std::fprintf(stderr, "bench_scale_path: step %zu differs between 1 and 2 threads\n", k);
      status = 1;
    }

  // Table 2 on the as1 assembly alone: the same path, OAABB vs brute force, every 10th step.
  {
    cb::GeneratedPath small;
    if (!cb::unscrew_path(base, nut_path.substr(6), bolt_path.substr(6), steps, 5.0, small, error)) {
      std::fprintf(stderr, "bench_scale_path: %s\n", error.c_str());
      return 1;
    }
    std::printf("\nTable 2 on as1 alone, path %s, every 10th step (%zu steps):\n\n", small.name.c_str(),
                (small.steps.size() + 9) / 10);
    std::printf("| method | AABB tests | AABB updates | triangle tests |\n|---|---:|---:|---:|\n");
    CollideCounters with_oaabb, brute;
    for (bool oaabb : {true, false}) {
      CollideOptions o;
      o.use_oaabb = oaabb;
      o.threads = 2;
      const PathRun r = run_path(base, small.moving.at(0), small, o, 10);
      (oaabb ? with_oaabb : brute) = r.counters;
      std::printf("| %s | %llu | %llu | %llu |\n", oaabb ? "OAABB" : "brute force",
                  static_cast<unsigned long long>(r.counters.aabb_tests),
                  static_cast<unsigned long long>(r.counters.aabb_updates),
                  static_cast<unsigned long long>(r.counters.triangle_tests));
      j["table2"][oaabb ? "oaabb" : "brute_force"] = counters_json(r.counters);
    }
    // Brute force makes no box tests and one update per step (the moving instance's world box): the
    // OAABB spends box tests and updates to save triangle tests.
    std::printf("| ratio OAABB/brute force | %s | %.1f | 1/%.0f |\n",
                brute.aabb_tests == 0 ? "n/a (brute force: none)" : std::to_string(static_cast<double>(with_oaabb.aabb_tests) / static_cast<double>(brute.aabb_tests)).c_str(),
                static_cast<double>(with_oaabb.aabb_updates) / std::max<double>(1.0, static_cast<double>(brute.aabb_updates)),
                static_cast<double>(brute.triangle_tests) /
                    std::max<double>(1.0, static_cast<double>(with_oaabb.triangle_tests)));
  }
  if (!out.empty()) std::ofstream(out) << j.dump(2) << '\n';
  return status;
}
