// The truth-test scenes in bench_accuracy (bench_accuracy_scenes.h): the matrix the certified-decision
// tests check (tests/collide/test_certified_truth.cpp), with the time of each mode and what decided.
#include "bench_accuracy_scenes.h"

#include "cadclash/testing/scenes.h"

#include <cstdio>
#include <iostream>
#include <sstream>

namespace cadclash::bench {
namespace {

std::string fmt(double v, int precision = 4) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", precision, v);
  return buf;
}

}  // namespace

std::string scene_matrix(const std::string& external_dir, double deflection, const std::vector<double>& tolerances,
                         int threads, int repeats) {
  using truth::BuiltScene;
  std::vector<BuiltScene> scenes;
  scenes.push_back(truth::board_scene(external_dir, deflection));
  const BuiltScene as1 = truth::as1_scene(external_dir, deflection);
  scenes.push_back(as1);
  for (double d : {0.005, 0.02, 0.05})
    scenes.push_back(truth::as1_moved(as1, "/as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::1/NUT::3", "/as1/PLATE", d));
  std::ostringstream md;
  md << "| scene | tolerance | mode | true | reported | missed | false | undecided | recall | precision | time (ms) "
        "| decided by (%) mesh / mesh-exact / analytic / refined / exact | witness queries | exact queries |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (BuiltScene& s : scenes) {
    if (!s.ok()) {
      std::cerr << s.name << ": error: the scene could not be built\n";
      continue;
    }
    for (double t : tolerances) {
      const truth::GroundTruth truth = truth::compute_ground_truth(s.model, t, 0);
      for (Mode mode : {Mode::Fast, Mode::Certified, Mode::Exact}) {
        const RunResult r = run_mode(s.model, mode, t, deflection, threads, mode == Mode::Exact ? 1 : repeats);
        const truth::Score sc = truth::score(truth, r.reported);
        std::cout << "  " << s.name << " t=" << t << " " << mode_name(mode) << ": recall " << fmt(sc.recall())
                  << ", precision " << fmt(sc.precision()) << ", undecided " << r.undecided.size() << ", "
                  << fmt(r.seconds * 1e3, 3) << " ms\n";
        md << "| " << s.name << " | " << fmt(t) << " | " << mode_name(mode) << " | " << sc.truth << " | " << sc.reported
           << " | " << sc.missed.size() << " | " << sc.false_pairs.size() << " | " << r.undecided.size() << " | "
           << fmt(sc.recall()) << " | " << fmt(sc.precision()) << " | " << fmt(r.seconds * 1e3, 3) << " | "
           << decided_shares_text(r.counters) << " | " << r.counters.witness_queries << " | " << r.counters.exact_queries << " |\n";
      }
    }
  }
  return md.str();
}

}  // namespace cadclash::bench
