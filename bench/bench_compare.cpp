// Side-by-side benchmark (issue 6): cadclash's variants, brute force, FCL, OCCT and CGAL on the same
// scenes and the same triangles in one process, with the surface pairs each finds checked against
// cadclash's. Writes OUT/compare.md, OUT/compare.json and the generated trajectories
// (OUT/unscrew.csv, OUT/withdraw.csv, for `cadclash check --path`).
//   bench_compare [--data DIR] [--out DIR] [--quick] [--threads N] [--scale-triangles N]
// Workloads: as1-tu-203.stp at deflection 0.1, 0.01, 0.001; two 500-step paths through it at 0.1;
// copies of it to >= 1000 instances and >= 10 M triangles at 0.001. --quick: 0.1 only, 20-step paths,
// 4 copies. Timings are printed, never judged; bench_compare_check (CTest) checks completeness and
// agreement of the quick run.
#include "compare_peers.h"
#include "compare_workload.h"
#include "cadclash/testing/benchmark_switches.h"

#include "cadclash/import.h"

#include <nlohmann/json.hpp>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace cb = cadclash::bench;
using cadclash::CollideOptions;
using cadclash::InstanceId;
using cadclash::Model;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Settings {
  std::string data = CADCLASH_DATA_DIR "/external";
  std::string out = "out/results";
  bool quick = false;
  int threads = 0;
  double scale_triangles = 10e6;
  std::uint32_t scale_min_instances = 1000;
  int reps = 15;          // timed repetitions per row at most...
  double rep_cap = 3.0;   // ...and no new one once a row has used this many seconds
};

// Which cadclash pairs a peer is compared with.
enum class Reference { Intersecting, WithinT };

struct Method {
  std::string name;
  bool is_cadclash = true;
  CollideOptions options;   // cadclash rows
  bool float_only = false;  // cadclash rows: float filter alone
  std::function<std::unique_ptr<cb::Peer>()> peer;  // peer rows
  cb::Subset subset;        // the part of the workload it runs on
  Reference reference = Reference::Intersecting;
  bool is_default = false;  // the row ratios are taken against (per subset)
  bool is_reference_t = false;
  // The mesh answer (DecisionMode::Fast) the peers' pair sets are compared with: they decide on the
  // same triangles, not on the exact faces as the certified default does.
  bool is_mesh_reference = false, is_mesh_reference_t = false;
};

struct Row {
  Method method;
  std::vector<double> times;
  cb::PairSet found;
  // cadclash rows: the contact class of every reported pair (containment: surfaces kInvalidId).
  std::map<cb::PairKey, cadclash::ContactClass> classes;
  std::optional<std::uint64_t> triangle_tests, exact_fallbacks;
  double build_seconds = -1.0, bytes_per_triangle = -1.0;
  int threads = 1;
  std::string error;
  // Filled after all rows ran.
  double ratio = 0.0;
  std::size_t both = 0, only_reference = 0, only_method = 0;
  std::string reference_name;
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Runs `once` until `reps` timings or `cap` seconds are used (at least one run).
template <class F>
std::vector<double> repeat(const Settings& s, F&& once) {
  std::vector<double> times;
  double used = 0.0;
  while (static_cast<int>(times.size()) < s.reps && (times.empty() || used + median(times) <= s.rep_cap)) {
    const auto t0 = std::chrono::steady_clock::now();
    once(times.empty());
    times.push_back(seconds_since(t0));
    used += times.back();
  }
  return times;
}

// The cadclash structures' build time and size: the per-surface hierarchies (what a Scene builds
// once, here all at once on one thread) plus the triangles and vertices they index.
void cadclash_build_cost(Model& model, double& seconds, double& bytes_per_triangle) {
  cadclash::Scene scene(model);
  const auto t0 = std::chrono::steady_clock::now();
  scene.build_hierarchies(1);
  seconds = seconds_since(t0);
  const cadclash::SceneMemory m = scene.memory();
  bytes_per_triangle = m.triangle_count ? static_cast<double>(m.triangles + m.vertices + m.hierarchies) /
                                              static_cast<double>(m.triangle_count)
                                        : 0.0;
}

void run_cadclash(const Settings& s, const cb::Workload& w, Row& row) {
  Model& model = *w.model;
  const cb::Subset& sub = row.method.subset;
  cadclash::SceneSelection selection;
  if (sub.instances > 0) {
    for (InstanceId i = 0; i < sub.instances; ++i) selection.set_a.push_back(i);
    selection.set_b = selection.set_a;
    if (!w.moving.empty()) selection.set_a.clear();
  }
  if (!w.moving.empty()) {
    for (InstanceId i : w.moving)
      if (sub.instances == 0 || i < sub.instances) selection.set_a.push_back(i);
  }
  cadclash::Scene scene(model, selection);
  const CollideOptions& o = row.method.options;
  row.threads = o.threads > 0 ? o.threads : omp_get_max_threads();
  cadclash::CollideCounters total;
  cadclash::testing::set_float_only_for_benchmark(row.method.float_only);
  row.times = repeat(s, [&](bool first) {
    cb::PoseState state(model);
    for (InstanceId i : w.moving) scene.set_pose(i, state.poses[i]);
    for (std::uint32_t k = 0; k < w.steps.size(); ++k) {
      for (const cb::PoseUpdate& u : w.steps[k]) scene.set_pose(u.instance, u.pose);
      if (!sub.has_step(k)) continue;
      const cadclash::Report r = scene.check(o);
      if (!first) continue;
      const auto& c = r.counters;
      total.triangle_tests += c.triangle_tests;
      total.exact_fallbacks += c.exact_fallbacks;
      for (const cadclash::SurfacePairResult& p : r.pairs) {
        row.classes[{k, p.instance_a, p.instance_b, p.surface_a, p.surface_b}] = p.contact;
        if (p.surface_a == cadclash::kInvalidId) continue;  // containment: whole instances
        const bool hit = row.method.reference == Reference::WithinT ? (p.intersecting || p.distance <= o.tolerance)
                                                                     : p.intersecting;
        if (hit) row.found.insert({k, p.instance_a, p.instance_b, p.surface_a, p.surface_b});
      }
    }
  });
  cadclash::testing::set_float_only_for_benchmark(false);
  row.triangle_tests = total.triangle_tests;
  row.exact_fallbacks = total.exact_fallbacks;
  cadclash_build_cost(model, row.build_seconds, row.bytes_per_triangle);
}

void run_peer(const Settings& s, const cb::Workload& w, Row& row) {
  std::unique_ptr<cb::Peer> peer = row.method.peer();
  const auto t0 = std::chrono::steady_clock::now();
  if (!peer->build(*w.model, row.error)) return;
  row.build_seconds = seconds_since(t0);
  row.bytes_per_triangle = peer->bytes_per_triangle();
  row.threads = 1;
  row.times = repeat(s, [&](bool first) {
    cb::PeerRun r = peer->run(w, row.method.subset);
    if (!first) return;
    row.found = std::move(r.found);
    if (r.has_tests) row.triangle_tests = r.triangle_tests;
  });
}

cb::PairSet restricted(const cb::PairSet& set, const cb::Subset& subset) {
  if (subset.whole()) return set;
  cb::PairSet out;
  for (const cb::PairKey& k : set)
    if (subset.contains(k)) out.insert(k);
  return out;
}

bool same_subset(const cb::Subset& a, const cb::Subset& b) { return a.instances == b.instances && a.stride == b.stride; }

// The rows of a workload. Rows named in `slow` run on the workload's slow subset, and then a
// cadclash default row on that subset is added so that their ratio compares equal work.
std::vector<Method> methods_for(const cb::Workload& w, int threads, const cb::Subset& subset,
                                const std::set<std::string>& slow) {
  std::vector<Method> m;
  CollideOptions base;
  base.threads = threads;
  bool any_subset = false;
  auto place = [&](Method& x, const std::string& key) {
    if (slow.count(key) && !subset.whole()) {
      x.subset = subset;
      x.name += " [subset]";
      any_subset = true;
    }
  };
  auto cad = [&](std::string key, std::string name, auto&& tweak) {
    Method x;
    x.name = std::move(name);
    x.options = base;
    tweak(x);
    place(x, key);
    m.push_back(std::move(x));
  };
  auto peer = [&](std::string key, std::function<std::unique_ptr<cb::Peer>()> make, Reference ref) {
    Method x;
    x.is_cadclash = false;
    x.peer = std::move(make);
    x.name = x.peer()->name();
    x.reference = ref;
    place(x, key);
    m.push_back(std::move(x));
  };
  cad("default", "cadclash default (OAABB, auto triangle level, early exit, V1 guided)", [](Method& x) { x.is_default = true; });
  cad("flat", "cadclash flat OAABB loops (paper)", [](Method& x) { x.options.triangle_level = cadclash::TriangleLevel::Flat; });
  cad("bvh", "cadclash OAABB + per-surface BVH", [](Method& x) { x.options.triangle_level = cadclash::TriangleLevel::Bvh; });
  cad("all", "cadclash all triangle pairs", [](Method& x) { x.options.mode = cadclash::CollideMode::AllTrianglePairs; });
  cad("float", "cadclash float filter only (no exact fallback)", [](Method& x) { x.float_only = true; });
  cad("1thread", "cadclash 1 thread", [](Method& x) { x.options.threads = 1; });
  cad("v2", "cadclash Version 2 (flattened blocks)", [](Method& x) { x.options.version = cadclash::ParallelVersion::V2; });
  cad("v2dynamic", "cadclash Version 2, dynamic schedule", [](Method& x) {
    x.options.version = cadclash::ParallelVersion::V2;
    x.options.schedule = cadclash::Schedule::Dynamic;
  });
  cad("brute", "brute force (no OAABB)", [](Method& x) { x.options.use_oaabb = false; });
  cad("fast", "cadclash --fast (the triangles' band, not certified)", [](Method& x) {
    x.options.decision = cadclash::DecisionMode::Fast;
    x.is_mesh_reference = true;
  });
  peer("fcl-obbrss", cb::make_fcl_obbrss_peer, Reference::Intersecting);
  peer("fcl-aabb", cb::make_fcl_aabb_peer, Reference::Intersecting);
  peer("cgal", cb::make_cgal_peer, Reference::Intersecting);
  peer("occt", [] { return cb::make_occt_peer(0.0); }, Reference::Intersecting);
  cad("t", "cadclash default, tolerance t", [&](Method& x) {
    x.options.tolerance = w.deflection;
    x.reference = Reference::WithinT;
    x.is_reference_t = true;
  });
  cad("t-fast", "cadclash --fast, tolerance t", [&](Method& x) {
    x.options.tolerance = w.deflection;
    x.options.decision = cadclash::DecisionMode::Fast;
    x.reference = Reference::WithinT;
    x.is_mesh_reference_t = true;
  });
  const double t = w.deflection;
  peer("occt-t", [t] { return cb::make_occt_peer(t); }, Reference::WithinT);
  if (any_subset) {
    Method x;
    x.name = "cadclash default [subset]";
    x.options = base;
    x.is_default = true;
    x.subset = subset;
    m.insert(m.begin() + 1, std::move(x));
  }
  return m;
}

struct WorkloadResult {
  cb::Workload w;
  std::string description;
  cb::Subset subset;        // where the slow rows ran
  std::string subset_note;  // what that is, in words
  std::vector<Row> rows;
  std::size_t instance_triangles = 0, part_triangles = 0;
  // Core-to-core round trip (ns) before the first row and after the last: where the host had the
  // two vCPUs while this table ran (compare_workload.h).
  double round_trip_before = 0.0, round_trip_after = 0.0;
  // How much of a second CPU the host gave before the first row and after the last, and in which
  // run of the table (compare_workload.h, until_host_gave_both).
  cb::HostCheck host;
  // The instanced scene: copies reporting copy 0's pairs with its classes / its intersecting pairs.
  std::optional<std::array<std::uint32_t, 3>> copies_same;  // {copies, same classes, same intersecting}
};

void finish(WorkloadResult& r) {
  // Ratios against the default row on the same subset; agreement against the whole-workload default
  // (or the tolerance-t row), restricted to what the row checked.
  const Row* full_default = nullptr;
  const Row* t_row = nullptr;
  const Row* mesh_row = nullptr;
  const Row* mesh_t_row = nullptr;
  for (const Row& row : r.rows) {
    if (row.method.is_default && row.method.subset.whole()) full_default = &row;
    if (row.method.is_reference_t) t_row = &row;
    if (row.method.is_mesh_reference) mesh_row = &row;
    if (row.method.is_mesh_reference_t) mesh_t_row = &row;
  }
  for (Row& row : r.rows) {
    const Row* ratio_ref = full_default;
    for (const Row& d : r.rows)
      if (d.method.is_default && same_subset(d.method.subset, row.method.subset)) ratio_ref = &d;
    if (ratio_ref && !ratio_ref->times.empty() && !row.times.empty())
      row.ratio = median(row.times) / median(ratio_ref->times);
    const bool within_t = row.method.reference == Reference::WithinT;
    const Row* ref = row.method.is_cadclash && row.method.options.decision != cadclash::DecisionMode::Fast
                         ? (within_t ? t_row : full_default)
                         : (within_t ? mesh_t_row : mesh_row);
    if (!ref || ref == &row || row.times.empty()) continue;
    row.reference_name = ref == t_row        ? "cadclash tolerance t"
                         : ref == mesh_row   ? "cadclash --fast"
                         : ref == mesh_t_row ? "cadclash --fast, tolerance t"
                                             : "cadclash default";
    // The reference's pairs over what this row checked (the t row may itself be on the subset).
    const cb::Subset& sub = row.method.subset.whole() ? ref->method.subset : row.method.subset;
    const cb::PairSet expect = restricted(ref->found, sub);
    const cb::PairSet got = restricted(row.found, sub);
    for (const cb::PairKey& k : got) (expect.count(k) ? row.both : row.only_method)++;
    for (const cb::PairKey& k : expect)
      if (!got.count(k)) row.only_reference++;
  }
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string time_text(double s) {
  return s >= 1.0 ? fmt("%.2f s", s) : s >= 1e-3 ? fmt("%.2f ms", s * 1e3) : fmt("%.1f µs", s * 1e6);
}

std::string markdown(const std::vector<WorkloadResult>& results, const Settings& s) {
  std::ostringstream md;
  md << "# cadclash side by side (bench_compare" << (s.quick ? " --quick" : "") << ")\n\n"
     << "Median wall time over repeated runs in one process (reps column; a row stops repeating once it has used "
     << s.rep_cap << " s). Ratio = median / cadclash default's median on the same instances. "
     << "Agreement = surface pairs found by both / only by cadclash / only by the method, against cadclash's "
     << "intersecting surface pairs at tolerance 0 (OCCT tolerance t: against cadclash's pairs with triangles within t). "
     << "Peers run single-threaded; cadclash rows use " << results.front().rows.front().threads
     << " threads unless named. Build = time and bytes per triangle of the structures kept across queries "
     << "(cadclash: per-surface BVHs + triangles; FCL: BVHModel nodes, vertices, triangles, indices); CGAL and OCCT "
     << "build their boxes and trees inside every query, and FCL's AABB models are copied into the world frame and "
     << "rebuilt per query as fcl::collide does, so those costs are in the query time. "
     << "[subset] rows ran on the instances named under the table. "
     << "Before and after each table a fixed compute loop runs on one thread, then on both at once: when the slower "
     << "of the two ran below " << fmt("%.1f", cb::kFullSecondCpu) << " of one thread's speed (the host was "
     << "running other work on a vCPU), the whole table runs again, at most " << cb::kHostAttempts << " times.\n\n";
  for (const WorkloadResult& r : results) {
    md << "## " << r.w.name << "\n\n" << r.description << "\n\n";
    if (r.round_trip_before > 0.0)
      md << "Core-to-core round trip " << fmt("%.0f", r.round_trip_before) << " ns before the rows, "
         << fmt("%.0f", r.round_trip_after) << " ns after (the vCPUs "
         << (std::max(r.round_trip_before, r.round_trip_after) >= cb::kFarCoresNs ? "were far apart for part of it"
                                                                                  : "were near each other")
         << "; see the parallel-efficiency notes).\n\n";
    if (r.host.attempt > 0)
      md << (r.host.gave_both() ? "A compute loop ran on both vCPUs at once at full speed before and after the rows"
                                : "**The host took one vCPU for a while: timings disturbed**")
         << " (second CPU share " << fmt("%.2f", r.host.before) << " / " << fmt("%.2f", r.host.after)
         << (r.host.attempt > 1 ? "; run " + std::to_string(r.host.attempt) + " of the table, the earlier ones disturbed"
                                : std::string())
         << ").\n\n";
    if (!r.subset_note.empty()) md << "[subset]: " << r.subset_note << "\n\n";
    md << "| method | median time | reps | ratio | triangle tests | exact fallbacks | surface pairs | agreement (both/only cadclash/only method) | build | bytes/triangle |\n"
       << "|---|---:|---:|---:|---:|---:|---:|---|---:|---:|\n";
    for (const Row& row : r.rows) {
      md << "| " << row.method.name << " | ";
      if (!row.error.empty()) {
        md << "not run: " << row.error << " | | | | | | | | |\n";
        continue;
      }
      md << time_text(median(row.times)) << " | " << row.times.size() << " | " << fmt("%.2f", row.ratio) << " | "
         << (row.triangle_tests ? std::to_string(*row.triangle_tests) : "n/a") << " | "
         << (row.exact_fallbacks ? std::to_string(*row.exact_fallbacks) : "n/a") << " | " << row.found.size() << " | ";
      if (row.reference_name.empty()) md << "— | ";
      else
        md << (row.only_reference == 0 && row.only_method == 0 ? "agree " : "**differ** ") << row.both << "/"
           << row.only_reference << "/" << row.only_method << (row.method.reference == Reference::WithinT ? " (vs t)" : "")
           << " | ";
      md << (row.build_seconds >= 0 ? time_text(row.build_seconds) : "—") << " | "
         << (row.bytes_per_triangle >= 0 ? fmt("%.1f", row.bytes_per_triangle) : "—") << " |\n";
    }
    md << "\n";
  }
  return md.str();
}

nlohmann::json json_of(const std::vector<WorkloadResult>& results, const Settings& s) {
  nlohmann::json j;
  j["quick"] = s.quick;
  j["threads"] = s.threads;
  j["rep_cap_seconds"] = s.rep_cap;
  j["max_reps"] = s.reps;
  j["workloads"] = nlohmann::json::array();
  for (const WorkloadResult& r : results) {
    nlohmann::json w;
    w["name"] = r.w.name;
    w["round_trip_ns"] = {r.round_trip_before, r.round_trip_after};
    w["second_cpu_share"] = {r.host.before, r.host.after};
    w["table_attempt"] = r.host.attempt;
    w["description"] = r.description;
    w["deflection"] = r.w.deflection;
    w["instances"] = r.w.model->instances.size();
    w["instance_triangles"] = r.instance_triangles;
    w["part_triangles"] = r.part_triangles;
    w["steps"] = r.w.steps.size();
    w["moving_instances"] = r.w.moving.size();
    w["subset"] = {{"instances", r.subset.instances}, {"step_stride", r.subset.stride}, {"note", r.subset_note}};
    if (r.copies_same)
      w["copies"] = {{"copies", (*r.copies_same)[0]},
                     {"same_pairs_and_classes", (*r.copies_same)[1]},
                     {"same_intersecting_pairs", (*r.copies_same)[2]}};
    w["methods"] = nlohmann::json::array();
    for (const Row& row : r.rows) {
      nlohmann::json m;
      m["name"] = row.method.name;
      m["kind"] = row.method.is_cadclash ? "cadclash" : "peer";
      m["on_subset"] = !row.method.subset.whole();
      m["error"] = row.error;
      m["threads"] = row.threads;
      m["times_seconds"] = row.times;
      m["median_seconds"] = median(row.times);
      m["ratio_to_default"] = row.ratio;
      m["triangle_tests"] = row.triangle_tests ? nlohmann::json(*row.triangle_tests) : nlohmann::json(nullptr);
      m["exact_fallbacks"] = row.exact_fallbacks ? nlohmann::json(*row.exact_fallbacks) : nlohmann::json(nullptr);
      m["surface_pairs"] = row.found.size();
      m["build_seconds"] = row.build_seconds >= 0 ? nlohmann::json(row.build_seconds) : nlohmann::json(nullptr);
      m["bytes_per_triangle"] = row.bytes_per_triangle >= 0 ? nlohmann::json(row.bytes_per_triangle) : nlohmann::json(nullptr);
      if (row.reference_name.empty()) m["agreement"] = nullptr;
      else
        m["agreement"] = {{"reference", row.reference_name},
                          {"both", row.both},
                          {"only_reference", row.only_reference},
                          {"only_method", row.only_method},
                          {"agree", row.only_reference == 0 && row.only_method == 0}};
      w["methods"].push_back(std::move(m));
    }
    j["workloads"].push_back(std::move(w));
  }
  return j;
}

int usage() {
  std::fprintf(stderr,
               "usage: bench_compare [--data DIR] [--out DIR] [--quick] [--threads N] [--scale-triangles N]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  Settings s;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    if (a == "--quick") s.quick = true;
    else if (a == "--data" || a == "--out" || a == "--threads" || a == "--scale-triangles") {
      const char* v = value();
      if (!v) return usage();
      if (a == "--data") s.data = v;
      else if (a == "--out") s.out = v;
      else if (a == "--threads") s.threads = std::atoi(v);
      else s.scale_triangles = std::atof(v);
    } else return usage();
  }
  if (s.threads <= 0) s.threads = omp_get_max_threads();
  if (s.quick) {
    s.reps = 2;
    s.rep_cap = 0.2;
  }
  const std::string file = s.data + "/as1-tu-203.stp";
  if (!std::filesystem::exists(file)) {
    std::fprintf(stderr, "bench_compare: %s not found (run scripts/setup.sh)\n", file.c_str());
    return 77;
  }
  std::error_code ec;
  std::filesystem::create_directories(s.out, ec);

  // One import per deflection, kept alive for the workloads that use it.
  std::vector<std::unique_ptr<Model>> owned;
  std::map<double, std::unique_ptr<cadclash::ImportResult>> imports;
  auto load = [&](double deflection) -> Model& {
    auto& slot = imports[deflection];
    if (!slot) {
      cadclash::ImportOptions o;
      o.tessellation.linear_deflection = deflection;
      const auto t0 = std::chrono::steady_clock::now();
      slot = std::make_unique<cadclash::ImportResult>(cadclash::import_file(file, o));
      std::fprintf(stderr, "imported %s at %g mm: %zu triangles, %.1f s\n", file.c_str(), deflection,
                   cadclash::triangle_count(slot->model), seconds_since(t0));
      for (const auto& d : slot->diagnostics) std::fprintf(stderr, "  %s\n", cadclash::format_diagnostic(d).c_str());
    }
    return slot->model;
  };

  std::vector<WorkloadResult> results;
  std::vector<std::set<std::string>> slow;  // per workload: the rows that run on its subset
  auto add_static = [&](double deflection) {
    WorkloadResult r;
    r.w.name = "as1-tu-203.stp, deflection " + fmt("%g", deflection) + " mm";
    r.w.model = &load(deflection);
    r.w.deflection = deflection;
    r.w.steps = {{}};
    r.description = "Every instance pair of the assembly, one query.";
    results.push_back(std::move(r));
    slow.push_back({});
  };
  auto add_path = [&](double deflection, const cb::GeneratedPath& p) {
    WorkloadResult r;
    r.w.name = "as1 trajectory \"" + p.name + "\", deflection " + fmt("%g", deflection) + " mm";
    r.w.model = &load(deflection);
    r.w.deflection = deflection;
    r.w.moving = p.moving;
    r.w.steps = p.steps;
    r.description = p.description + " (" + p.name + ".csv; `cadclash check as1-tu-203.stp --deflection " +
                    fmt("%g", deflection) + " --path " + p.name + ".csv` replays it). Only pairs with a moving instance.";
    // 500 steps of sliding contact: the variants that only restate the static tables' comparisons
    // (triangle level, mode, predicates, tolerance) and the slow peers run on every 10th step.
    r.subset.stride = 10;
    r.subset_note = "every 10th step (" + std::to_string((p.steps.size() + 9) / 10) + " of " +
                    std::to_string(p.steps.size()) + "), poses following the whole path";
    results.push_back(std::move(r));
    slow.push_back({"brute", "flat", "bvh", "all", "float", "v2dynamic", "fcl-aabb", "occt", "t", "occt-t"});
  };

  const std::vector<double> deflections = s.quick ? std::vector<double>{0.1} : std::vector<double>{0.1, 0.01, 0.001};
  for (double d : deflections) add_static(d);

  // The paths at the coarse deflection: 500 steps of sliding contact are already the longest rows.
  const double path_deflection = 0.1;
  const int steps = s.quick ? 20 : 500;
  {
    Model& m = load(path_deflection);
    std::string error;
    cb::GeneratedPath unscrew, withdraw;
    if (cb::unscrew_path(m, "/as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::1/NUT::3",
                         "/as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::1/BOLT", steps, 5.0, unscrew, error)) {
      if (!cb::write_path_csv(m, unscrew, s.out + "/unscrew.csv"))
        std::fprintf(stderr, "bench_compare: cannot write %s/unscrew.csv\n", s.out.c_str());
      add_path(path_deflection, unscrew);
    } else std::fprintf(stderr, "bench_compare: unscrew path: %s\n", error.c_str());
    if (cb::withdraw_path(m, "/as1/L-BRACKET-ASSEMBLY::1", "/as1/PLATE", steps, withdraw, error)) {
      if (!cb::write_path_csv(m, withdraw, s.out + "/withdraw.csv"))
        std::fprintf(stderr, "bench_compare: cannot write %s/withdraw.csv\n", s.out.c_str());
      withdraw.description += "; the rod through both brackets stays, so the bracket and a bolt run into it (penetrating steps)";
      add_path(path_deflection, withdraw);
    } else std::fprintf(stderr, "bench_compare: withdraw path: %s\n", error.c_str());
  }

  for (std::size_t k = 0; k < results.size(); ++k) {
    WorkloadResult& r = results[k];
    r.instance_triangles = cb::instance_triangle_count(*r.w.model);
    r.part_triangles = cadclash::triangle_count(*r.w.model);
    r.host = cb::until_host_gave_both(
        [&] {
          r.rows.clear();
          r.round_trip_before = cb::core_round_trip_ns();
          for (Method& m : methods_for(r.w, s.threads, r.subset, slow[k])) {
            Row row;
            row.method = std::move(m);
            std::fprintf(stderr, "[%s] %s ...", r.w.name.c_str(), row.method.name.c_str());
            const auto t0 = std::chrono::steady_clock::now();
            if (row.method.is_cadclash) run_cadclash(s, r.w, row);
            else run_peer(s, r.w, row);
            std::fprintf(stderr, " %.2f s (%zu reps, %zu pairs)%s%s\n", seconds_since(t0), row.times.size(),
                         row.found.size(), row.error.empty() ? "" : " not run: ", row.error.c_str());
            r.rows.push_back(std::move(row));
          }
          r.round_trip_after = cb::core_round_trip_ns();
        },
        [&](const cb::HostCheck& h) {
          std::fprintf(stderr, "[%s] the host took a vCPU during the rows (second CPU share %.2f / %.2f): the table again\n",
                       r.w.name.c_str(), h.before, h.after);
        });
    finish(r);
  }

  // The instanced scene: whole copies of the assembly on a grid, apart from each other. Only cadclash
  // checks all of it; every other row is its copy 0, which is the as1 scene at the same deflection
  // unchanged (same ids, same poses), so those rows are that table's, compared with this run.
  {
    const double d = s.quick ? 0.1 : 0.001;
    const std::size_t source = static_cast<std::size_t>(
        std::find(deflections.begin(), deflections.end(), d) - deflections.begin());
    Model& base = load(d);
    const std::size_t per_copy = cb::instance_triangle_count(base);
    const std::size_t n = base.instances.size();
    const std::uint32_t copies = s.quick ? 4u : std::max<std::uint32_t>(
        static_cast<std::uint32_t>((s.scale_min_instances + n - 1) / n),
        static_cast<std::uint32_t>(std::ceil(s.scale_triangles / static_cast<double>(per_copy))));
    auto grid = std::make_unique<Model>(cb::instanced_grid(base, copies));
    WorkloadResult r;
    r.w.model = grid.get();
    r.w.deflection = d;
    r.w.steps = {{}};
    r.instance_triangles = cb::instance_triangle_count(*r.w.model);
    r.part_triangles = cadclash::triangle_count(*r.w.model);
    r.w.name = "instanced scene: " + std::to_string(copies) + " copies of as1 (" + std::to_string(r.w.model->instances.size()) +
               " instances, " + std::to_string(r.instance_triangles) + " triangles), deflection " + fmt("%g", d) + " mm";
    r.description = "Copies of the whole assembly on a grid, apart from each other; every instance pair, one query.";
    r.subset.instances = static_cast<std::uint32_t>(n);
    r.subset_note = "copy 0 (" + std::to_string(n) + " instances, " + std::to_string(per_copy) +
                    " triangles), which is the as1-tu-203.stp scene at this deflection unchanged: those rows are "
                    "the ones of that table, their agreement checked against this full-scale run restricted to copy 0";
    Row full;
    full.method.name = "cadclash default (OAABB, auto triangle level, early exit, V1 guided)";
    full.method.options.threads = s.threads;
    full.method.is_default = true;
    std::fprintf(stderr, "[%s] %s ...", r.w.name.c_str(), full.method.name.c_str());
    const auto t0 = std::chrono::steady_clock::now();
    run_cadclash(s, r.w, full);
    std::fprintf(stderr, " %.2f s (%zu reps, %zu pairs)\n", seconds_since(t0), full.times.size(), full.found.size());
    {  // Copies differ only by a translation: say how many report exactly copy 0's pairs and classes
       // (the certified verdicts, which must not depend on the placement), and how many find exactly
       // copy 0's intersecting triangle pairs (a fact about the triangles, whose coordinates the
       // shifted placement rounds differently).
      using CopyKey = std::array<std::uint32_t, 4>;
      auto copy_key = [&](const cb::PairKey& k) {
        return CopyKey{static_cast<std::uint32_t>(k[1] % n), static_cast<std::uint32_t>(k[2] % n), k[3], k[4]};
      };
      std::vector<std::map<CopyKey, cadclash::ContactClass>> per_copy_classes(copies);
      std::vector<std::set<CopyKey>> per_copy_pairs(copies);
      for (const auto& [k, c] : full.classes) per_copy_classes[k[1] / n][copy_key(k)] = c;
      for (const cb::PairKey& k : full.found) per_copy_pairs[k[1] / n].insert(copy_key(k));
      std::uint32_t same_classes = 0, same_pairs = 0;
      for (std::uint32_t k = 0; k < copies; ++k) {
        same_classes += per_copy_classes[k] == per_copy_classes[0];
        same_pairs += per_copy_pairs[k] == per_copy_pairs[0];
      }
      r.copies_same = std::array<std::uint32_t, 3>{copies, same_classes, same_pairs};
      r.description += " " + std::to_string(same_classes) + " of " + std::to_string(copies) +
                       " copies report exactly copy 0's " + std::to_string(per_copy_classes[0].size()) +
                       " surface pairs with the same contact classes (the certified verdicts); " +
                       std::to_string(same_pairs) + " of " + std::to_string(copies) + " find exactly copy 0's " +
                       std::to_string(per_copy_pairs[0].size()) + " pairs with intersecting triangles" +
                       (same_pairs < copies ? " (whether two triangles of faces that touch exactly meet is decided "
                                              "on their coordinates, which the shifted placement rounds differently" +
                                              std::string(same_classes == copies ? "; the classes do not depend on it)" : ")")
                                            : "") + ".";
    }
    r.rows.push_back(std::move(full));
    if (source < results.size()) {
      for (const Row& from : results[source].rows) {
        Row row = from;
        row.method.subset = r.subset;
        row.method.name = row.method.is_default ? "cadclash default [subset]" : row.method.name + " [subset]";
        row.both = row.only_reference = row.only_method = 0;
        row.reference_name.clear();
        r.rows.push_back(std::move(row));
      }
    }
    finish(r);
    results.push_back(std::move(r));
    owned.push_back(std::move(grid));
  }

  const std::string md = markdown(results, s);
  std::ofstream(s.out + "/compare.md") << md;
  std::ofstream(s.out + "/compare.json") << json_of(results, s).dump(1) << "\n";
  std::fputs(md.c_str(), stdout);
  std::fprintf(stderr, "wrote %s/compare.md and %s/compare.json\n", s.out.c_str(), s.out.c_str());
  return 0;
}
