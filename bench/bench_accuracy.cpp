// Accuracy of the reported surface pairs against the exact B-rep geometry, and what it costs.
//
//   bench_accuracy [--file F.stp]... [--out DIR] [--cache DIR|--no-cache] [--deflections 1,0.3,...]
//                  [--tolerances 0,0.01,0.1] [--jitters 0,0.05] [--repeats N] [--threads N] [--no-plots] [--no-scenes]
//
// For each file, as read and with every instance moved by each --jitters distance: the ground truth
// (cadclash/testing/truth.h: exact face distance <= tolerance + εa + εb) per tolerance, read from
// DIR/cache when a run on the same file bytes made it; then per deflection one eager import, and per
// tolerance cadclash's own three decision modes (fast, certified = the default, exact) and OCCT's
// BRepExtrema_ShapeProximity as a peer, each scored as reported by the product (recall, precision,
// missed and false pairs by STEP #id), timed (best of --repeats; import and tessellation timed
// apart), and for cadclash split by what decided each pair (CollideCounters::decided_*).
// Writes DIR/accuracy.json, DIR/accuracy.md, the plot data DIR/accuracy_*.dat and, when gnuplot is
// installed, DIR/accuracy_trade.svg and DIR/accuracy_time.svg (scripts in bench/plots/).
#include "bench_accuracy_run.h"
#include "bench_accuracy_scenes.h"
#include "cadclash/testing/scenes.h"
#include "cadclash/testing/truth.h"

#include "cadclash/import.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace cadclash::bench {
namespace {

using truth::cache_path;
using truth::compute_ground_truth;
using truth::exact_face_distance;
using truth::file_hash;
using truth::load_ground_truth;
using truth::MeasuredPair;
using truth::save_ground_truth;
using truth::within;

// The CLI's defaults (tools/cli_common.h): the "default setting" of the report.
constexpr double kDefaultDeflection = 0.1;
constexpr double kDefaultTolerance = 0.0;

struct Args {
  std::vector<std::string> files;
  std::string out = "out/results";
  std::string cache;  // default: <out>/cache; empty after --no-cache
  bool no_cache = false;
  std::vector<double> deflections{1.0, 0.3, 0.1, 0.03, 0.01};
  std::vector<double> tolerances{0.0, 0.01, 0.1};
  // Scenes per file: 0 = as read; j > 0 = every instance moved by j mm in its own direction, which
  // turns exact contacts into small gaps and overlaps (where a deflection-sized τ reports false pairs).
  std::vector<double> jitters{0.0, 0.05};
  int repeats = 3;
  int threads = 1;
  bool plots = true;
  bool scenes = true;  // the truth-test scenes' matrix (board, as1 variants)
};

std::vector<double> parse_list(const std::string& s) {
  std::vector<double> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || *end != '\0' || !std::isfinite(v) || v < 0) return {};
    out.push_back(v);
  }
  return out;
}

bool parse_args(int argc, char** argv, Args& a) {
  bool files_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto value = [&](std::string& v) {
      if (i + 1 >= argc) return false;
      v = argv[++i];
      return true;
    };
    std::string v;
    if (k == "--file" && value(v)) {
      if (!files_given) a.files.clear();
      files_given = true;
      a.files.push_back(v);
    } else if (k == "--out" && value(v)) {
      a.out = v;
    } else if (k == "--cache" && value(v)) {
      a.cache = v;
    } else if (k == "--no-cache") {
      a.no_cache = true;
    } else if (k == "--deflections" && value(v)) {
      a.deflections = parse_list(v);
      if (a.deflections.empty() || std::count(a.deflections.begin(), a.deflections.end(), 0.0)) return false;
    } else if (k == "--tolerances" && value(v)) {
      a.tolerances = parse_list(v);
      if (a.tolerances.empty()) return false;
    } else if (k == "--jitters" && value(v)) {
      a.jitters = parse_list(v);
      if (a.jitters.empty()) return false;
    } else if (k == "--repeats" && value(v)) {
      a.repeats = std::max(1, std::atoi(v.c_str()));
    } else if (k == "--threads" && value(v)) {
      a.threads = std::atoi(v.c_str());
    } else if (k == "--no-scenes") {
      a.scenes = false;
    } else if (k == "--no-plots") {
      a.plots = false;
    } else {
      return false;
    }
  }
  if (a.files.empty()) a.files.push_back(std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp");
  if (a.cache.empty()) a.cache = a.out + "/cache";
  return true;
}

std::string fmt(double v, int precision = 4) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", precision, v);
  return buf;
}

// Moves instance i by `jitter` mm along a direction fixed by i (splitmix64), the same in every run.
void move_instances(Model& m, double jitter) { truth::jitter_instances(m, jitter); }

std::string label(const Model& m, InstanceId i, SurfaceId s) {
  const Surface& surf = m.surfaces[s];
  std::string id = surf.provenance.step_id >= 0 ? "#" + std::to_string(surf.provenance.step_id) : surf.name;
  return m.instances[i].path + " " + id;
}

nlohmann::json pair_json(const Model& m, const PairKey& k, const std::map<PairKey, double>& measured) {
  nlohmann::json j{{"a", label(m, k.instance_a, k.surface_a)}, {"b", label(m, k.instance_b, k.surface_b)}};
  const auto it = measured.find(k);
  // Pairs outside the box prefilter are farther apart than the tolerance; measure them for the record.
  const double d = it != measured.end() ? it->second
                                        : exact_face_distance(m, k.instance_a, k.surface_a, k.instance_b, k.surface_b);
  j["exact_distance"] = std::isfinite(d) ? nlohmann::json(d) : nlohmann::json(nullptr);
  return j;
}

struct Row {
  std::string file;
  double deflection = 0, achieved = 0, tolerance = 0;
  std::size_t triangles = 0;
  RunResult run;
  Score score;
};

double max_achieved(const Model& m) {
  double d = 0;
  for (const Surface& s : m.surfaces) d = std::max(d, s.deflection);
  return d;
}

int run(const Args& args) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(args.out, ec);
  if (!args.no_cache) fs::create_directories(args.cache, ec);
  nlohmann::json jfiles = nlohmann::json::array();
  std::ostringstream md;
  std::vector<Row> all_rows;
  struct TessTime {
    double deflection, seconds, achieved;
    std::size_t triangles;
  };
  std::vector<TessTime> tess_times;

  md << "Setting: cadclash on " << args.threads << " thread(s) (OCCT's proximity tool is serial); times are the best of "
     << args.repeats << " runs (exact: one run) of scene build + check (cadclash) or load + perform (OCCT), "
     << "import and tessellation excluded. Angular deflection 0.5 rad (the CLI default).\n\n";
  md << "Modes are the product's own, scored on what `Scene::check` reports (Penetrating and Touching rows; "
        "nothing filtered by the benchmark): **fast** `DecisionMode::Fast` (the triangles alone, τ = tolerance + both "
        "faces' achieved deflections); **certified** `DecisionMode::Certified`, the default (the triangles' "
        "interval, then analytic, refined and exact certificates for the ambiguous pairs); **exact** "
        "`DecisionMode::Exact` (every reported pair's exact B-rep distance); **occt-proximity** "
        "`BRepExtrema_ShapeProximity(tolerance)` on the same face triangulations, given the instance pairs whose "
        "boxes are within tolerance + 2 × deflection. \"decided by\" is the share of decided surface pairs per "
        "certificate (`CollideCounters::decided_*`: mesh / mesh-exact / analytic / refined / exact).\n\n";
  md << "Truth: `BRepExtrema_DistShapeShape` on the placed B-rep faces ≤ tolerance + εa + εb (each face's model "
        "uncertainty, `Surface::uncertainty`: the library's own contact definition), for every face pair whose "
        "exact face boxes (enlarged by that threshold) overlap — a box prefilter that never drops a true pair.\n\n";

  for (const std::string& file : args.files) for (double jitter : args.jitters) {
    std::string hash = file_hash(file);
    if (hash.empty()) {
      std::cerr << file << ": error: cannot read the file\n";
      return 1;
    }
    if (jitter != 0.0) hash += "-j" + fmt(jitter, 6);
    std::string name = fs::path(file).filename().string();
    if (jitter != 0.0) name += ", every instance moved by " + fmt(jitter) + " mm";
    std::cout << name << " (hash " << hash << ")\n";

    // The truth needs only the exact faces and their boxes: a lazy import (no tessellation).
    ImportOptions lazy;
    lazy.lazy = true;
    ImportResult exact_in = import_file(file, lazy);
    for (const Diagnostic& d : exact_in.diagnostics) std::cerr << format_diagnostic(d) << '\n';
    move_instances(exact_in.model, jitter);
    if (exact_in.model.instances.empty()) {
      std::cerr << file << ": error: no instances\n";
      return 1;
    }
    std::map<double, GroundTruth> truths;
    for (double t : args.tolerances) {
      const std::string cpath = cache_path(args.cache, hash, t);
      std::optional<GroundTruth> cached;
      if (!args.no_cache) cached = load_ground_truth(cpath, exact_in.model, t);
      GroundTruth truth = cached ? std::move(*cached) : compute_ground_truth(exact_in.model, t, 0);
      if (!cached && !args.no_cache && !save_ground_truth(cpath, exact_in.model, truth))
        std::cerr << cpath << ": warning: cannot write the ground-truth cache\n";
      std::size_t n_true = 0;
      for (const MeasuredPair& p : truth.measured) n_true += within(p);
      std::cout << "  truth t=" << t << ": " << truth.measured.size() << " candidates, " << n_true << " true"
                << (truth.from_cache ? " (cache)" : " (" + fmt(truth.seconds, 3) + " s)") << '\n';
      truths.emplace(t, std::move(truth));
    }

    std::size_t faces_over_instances = 0;
    for (const Instance& inst : exact_in.model.instances) faces_over_instances += exact_in.model.parts[inst.part].surface_count;
    nlohmann::json jf{{"file", name}, {"jitter", jitter}, {"hash", hash}, {"instances", exact_in.model.instances.size()},
                      {"part_faces", exact_in.model.surfaces.size()}, {"faces", faces_over_instances}};
    md << "### " << name << "\n\n" << exact_in.model.instances.size() << " instances, " << faces_over_instances
       << " faces (" << exact_in.model.surfaces.size() << " distinct part faces).";
    if (jitter != 0.0)
      md << " Every instance is moved by " << fmt(jitter) << " mm in its own fixed direction: exact contacts become "
         << "small gaps and overlaps.";
    md << "\n\n";
    md << "| tolerance (mm) | candidate face pairs | true pairs | truth time |\n|---|---|---|---|\n";
    for (const auto& [t, truth] : truths) {
      std::size_t n_true = 0;
      for (const MeasuredPair& p : truth.measured) n_true += within(p);
      md << "| " << fmt(t) << " | " << truth.measured.size() << " | " << n_true << " | "
         << (truth.from_cache ? "cached" : fmt(truth.seconds, 3) + " s") << " |\n";
      jf["truth"].push_back({{"tolerance", t}, {"candidates", truth.measured.size()}, {"true_pairs", n_true},
                             {"failed", truth.failed}, {"from_cache", truth.from_cache},
                             {"seconds", truth.seconds}});
    }
    md << "\n| deflection (mm) | max achieved (mm) | triangles | import + tessellation (s) |\n|---|---|---|---|\n";

    std::vector<Row> rows;
    for (double d : args.deflections) {
      ImportOptions io;
      io.tessellation.linear_deflection = d;
      const auto t0 = std::chrono::steady_clock::now();
      ImportResult in = import_file(file, io);
      const double import_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      Model& m = in.model;
      move_instances(m, jitter);
      if (m.instances.size() != exact_in.model.instances.size() || m.surfaces.size() != exact_in.model.surfaces.size()) {
        std::cerr << file << ": error: the eager and lazy imports differ\n";
        return 1;
      }
      const double achieved = max_achieved(m);
      const std::size_t tris = triangle_count(m);
      tess_times.push_back({d, import_s, achieved, tris});
      md << "| " << fmt(d) << " | " << fmt(achieved) << " | " << tris << " | " << fmt(import_s, 3) << " |\n";
      std::cout << "  deflection " << d << ": " << tris << " triangles, achieved " << achieved << ", import "
                << fmt(import_s, 3) << " s\n";
      for (double t : args.tolerances) {
        const GroundTruth& truth = truths.at(t);
        std::map<PairKey, double> measured;
        for (const MeasuredPair& p : truth.measured)
          measured[{p.instance_a, p.instance_b, p.surface_a, p.surface_b}] = p.distance;
        for (Mode mode : kModes) {
          Row r;
          r.file = name;
          r.deflection = d;
          r.achieved = achieved;
          r.tolerance = t;
          r.triangles = tris;
          // Exact mode is dominated by OCCT distance calls (seconds): one run is timing enough.
          r.run = run_mode(m, mode, t, d, args.threads, mode == Mode::Exact ? 1 : args.repeats);
          r.score = score(truth, r.run.reported);
          std::cout << "    t=" << t << " " << mode_name(mode) << ": recall " << fmt(r.score.recall()) << ", precision "
                    << fmt(r.score.precision()) << ", missed " << r.score.missed.size() << ", false "
                    << r.score.false_pairs.size() << ", undecided " << r.run.undecided.size() << ", "
                    << fmt(r.run.seconds * 1e3, 3) << " ms";
          if (mode != Mode::OcctProximity) std::cout << ", decided by " << decided_shares_text(r.run.counters);
          std::cout << '\n';
          nlohmann::json jr{{"deflection", d},
                            {"achieved_deflection", achieved},
                            {"tolerance", t},
                            {"mode", mode_name(mode)},
                            {"triangles", tris},
                            {"true_pairs", r.score.truth},
                            {"reported", r.score.reported},
                            {"hits", r.score.hits},
                            {"recall", r.score.recall()},
                            {"precision", r.score.precision()},
                            {"seconds", r.run.seconds},
                            {"missed", nlohmann::json::array()},
                            {"false", nlohmann::json::array()}};
          if (mode != Mode::OcctProximity) {
            const CollideCounters& c = r.run.counters;
            jr["triangle_tests"] = c.triangle_tests;
            jr["exact_fallbacks"] = c.exact_fallbacks;
            jr["decided"] = {{"mesh", c.decided_mesh},       {"mesh_exact", c.decided_mesh_exact},
                             {"analytic", c.decided_analytic}, {"refined", c.decided_refined},
                             {"exact", c.decided_exact},     {"undecided", c.undecided}};
            jr["ambiguous_pairs"] = c.ambiguous_pairs;
            jr["refined_surfaces"] = c.refined_surfaces;
            jr["exact_queries"] = c.exact_queries;
            jr["dismissed_pairs"] = c.dismissed_pairs;
            jr["undecided"] = nlohmann::json::array();
            for (const PairKey& k : r.run.undecided) jr["undecided"].push_back(pair_json(m, k, measured));
          }
          if (mode == Mode::OcctProximity) jr["instance_pairs"] = r.run.instance_pairs;
          for (const PairKey& k : r.score.missed) jr["missed"].push_back(pair_json(m, k, measured));
          for (const PairKey& k : r.score.false_pairs) jr["false"].push_back(pair_json(m, k, measured));
          jf["rows"].push_back(std::move(jr));
          rows.push_back(std::move(r));
        }
      }
    }

    md << "\n| deflection | tolerance | mode | true | reported | missed | false | undecided | recall | precision | "
          "time (ms) | decided by (%) mesh / mesh-exact / analytic / refined / exact | exact queries |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
      const bool is_default = r.deflection == kDefaultDeflection && r.tolerance == kDefaultTolerance &&
                              r.run.mode == Mode::Certified;
      const std::string b = is_default ? "**" : "";
      md << "| " << b << fmt(r.deflection) << b << " | " << fmt(r.tolerance) << " | " << mode_name(r.run.mode) << " | "
         << r.score.truth << " | " << r.score.reported << " | " << r.score.missed.size() << " | "
         << r.score.false_pairs.size() << " | ";
      if (r.run.mode == Mode::OcctProximity) md << "- | ";
      else md << r.run.undecided.size() << " | ";
      md << fmt(r.score.recall(), 4) << " | " << fmt(r.score.precision(), 4) << " | " << fmt(r.run.seconds * 1e3, 3)
         << " | ";
      if (r.run.mode == Mode::OcctProximity) md << "- | - |\n";
      else md << decided_shares_text(r.run.counters) << " | " << r.run.counters.exact_queries << " |\n";
    }
    md << "\nBold: the default setting (deflection " << fmt(kDefaultDeflection) << " mm, tolerance "
       << fmt(kDefaultTolerance) << ", certified). Missed, false and undecided pairs are listed by STEP #id, with "
          "their exact distances, in `accuracy.json`.\n\n";
    jfiles.push_back(std::move(jf));
    all_rows.insert(all_rows.end(), rows.begin(), rows.end());
  }

  if (args.scenes) {
    std::cout << "truth-test scenes (board, as1, as1 with a nut moved off the plate)\n";
    md << "### The truth-test scenes\n\n"
       << "The scenes of `tests/collide/test_certified_truth.cpp` (`cadclash/testing/scenes.h`): **board**, real parts on "
          "the as1 plate, seated (exact coplanar contact), at stand-offs of 0.005–0.03 mm, sunk in by 0.001–0.01 mm, "
          "turned by odd angles, tangent cylinders and a bolt through a hole; **as1** as read; as1 with a nut moved off "
          "the plate by 0.005, 0.02 and 0.05 mm. Deflection "
       << fmt(kDefaultDeflection) << " mm, " << args.threads << " thread(s); truth as above.\n\n"
       << scene_matrix(std::string(CADCLASH_DATA_DIR) + "/external", kDefaultDeflection, {1e-4, 0.025}, args.threads,
                       args.repeats)
       << "\n";
  }

  // Plot data: one gnuplot index (block) per mode.
  {
    std::ofstream dat(args.out + "/accuracy_trade.dat");
    dat << "# time_ms recall precision deflection tolerance\n";
    for (Mode mode : kModes) {
      dat << "# " << mode_name(mode) << '\n';
      for (const Row& r : all_rows)
        if (r.run.mode == mode)
          dat << r.run.seconds * 1e3 << ' ' << r.score.recall() << ' ' << r.score.precision() << ' ' << r.deflection
              << ' ' << r.tolerance << '\n';
      dat << "\n\n";
    }
    std::ofstream tdat(args.out + "/accuracy_time.dat");
    tdat << "# deflection tessellation_ms fast_ms certified_ms exact_ms occt_ms (tolerance "
         << fmt(args.tolerances.front()) << ", first scene)\n";
    for (const TessTime& tt : tess_times) {
      if (&tt - tess_times.data() >= static_cast<std::ptrdiff_t>(args.deflections.size())) break;  // first scene
      tdat << tt.deflection << ' ' << tt.seconds * 1e3;
      for (Mode mode : kModes)
        for (const Row& r : all_rows)
          if (r.file == all_rows.front().file && r.deflection == tt.deflection &&
              r.tolerance == args.tolerances.front() && r.run.mode == mode) {
            tdat << ' ' << r.run.seconds * 1e3;
            break;
          }
      tdat << '\n';
    }
  }
  bool plotted = false;
  if (args.plots && std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    const std::string plots = std::string(CADCLASH_SOURCE_DIR) + "/bench/plots/";
    bool ok = true;
    for (const char* script : {"accuracy_trade.gp", "accuracy_time.gp"}) {
      const std::string cmd = "gnuplot -e \"dir='" + args.out + "'\" '" + plots + script + "'";
      ok = std::system(cmd.c_str()) == 0 && ok;
    }
    plotted = ok;
    if (!ok) std::cerr << "warning: gnuplot failed; plots not written\n";
  }
  if (plotted)
    md << "![recall and precision against query time](accuracy_trade.svg)\n\n"
       << "![time against deflection](accuracy_time.svg)\n\n";
  else
    md << "(Plots not drawn: gnuplot is not installed or --no-plots was given.)\n\n";

  std::ofstream(args.out + "/accuracy.md") << md.str();
  const nlohmann::json j{{"schema", "cadclash-accuracy"},
                         {"contact", "exact face distance <= tolerance + eps_a + eps_b (Surface::uncertainty)"},
                         {"threads", args.threads},
                         {"repeats", args.repeats},
                         {"default", {{"deflection", kDefaultDeflection}, {"tolerance", kDefaultTolerance},
                                      {"mode", "certified"}}},
                         {"files", jfiles}};
  std::ofstream(args.out + "/accuracy.json") << j.dump(1) << '\n';
  std::cout << "wrote " << args.out << "/accuracy.md, accuracy.json" << (plotted ? ", accuracy_*.svg" : "") << '\n';
  return 0;
}

}  // namespace
}  // namespace cadclash::bench

int main(int argc, char** argv) {
  cadclash::bench::Args args;
  if (!cadclash::bench::parse_args(argc, argv, args)) {
    std::cerr << "usage: bench_accuracy [--file F]... [--out DIR] [--cache DIR|--no-cache] [--deflections a,b,...]\n"
                 "                      [--tolerances a,b,...] [--jitters a,b,...] [--repeats N] [--threads N]\n"
                 "                      [--no-plots] [--no-scenes]\n";
    return 2;
  }
  return cadclash::bench::run(args);
}
