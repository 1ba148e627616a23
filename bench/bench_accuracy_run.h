// One setting of the accuracy benchmark: cadclash in one of its own decision modes, or OCCT's
// BRepExtrema_ShapeProximity, on an imported model, scored against the exact ground truth
// (cadclash::truth). Used by bench_accuracy and its test.
#pragma once

#include "cadclash/testing/truth.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace cadclash::bench {

using truth::GroundTruth;
using truth::PairKey;
using truth::Score;

enum class Mode : std::uint8_t {
  Fast,           // CollideOptions::decision = DecisionMode::Fast: the triangles alone
  Certified,      // the library's default, DecisionMode::Certified
  Exact,          // DecisionMode::Exact: every reported pair's exact B-rep distance
  OcctProximity,  // BRepExtrema_ShapeProximity(tolerance) on the same face triangulations
};

inline constexpr Mode kModes[] = {Mode::Fast, Mode::Certified, Mode::Exact, Mode::OcctProximity};

// "fast", "certified", "exact", "occt-proximity".
const char* mode_name(Mode m);

struct RunResult {
  Mode mode = Mode::Certified;
  double tolerance = 0.0;
  // The surface pairs this mode reports in contact: cadclash's Penetrating and Touching rows (not
  // Clearance, Containment or Undecided), OCCT's overlapping face pairs. Nothing is filtered here.
  std::vector<PairKey> reported;
  std::vector<PairKey> undecided;  // cadclash rows of class Undecided (not counted as reported)
  double seconds = 0.0;            // best of the repeats: scene build + check (cadclash), load + perform (OCCT)
  CollideCounters counters;        // cadclash only: the best run's counters (decided_* and the work)
  std::uint64_t instance_pairs = 0;  // OCCT: instance pairs given to it
};

// The share of decided pairs per certificate, from the counters: mesh, mesh-exact, analytic,
// refined, exact, undecided (sums to 1 when any pair was decided; all 0 otherwise).
std::vector<double> decided_shares(const CollideCounters& c);

// decided_shares in percent, "97.5 / 2.5 / 0 / 0 / 0" (+ " / undecided x" when any); "-" when the
// mode counts no decisions (fast).
std::string decided_shares_text(const CollideCounters& c);

// Runs one mode on `model` (eagerly tessellated B-rep parts) at `tolerance` with the library's
// default options otherwise (containment off: whole-instance rows have no surface pair to score).
// `keep`, when given, restricts the instance pairs as in truth::compute_ground_truth.
// threads: cadclash's OpenMP threads (OCCT's tool is serial).
RunResult run_mode(Model& model, Mode mode, double tolerance, double deflection, int threads, int repeats,
                   const std::function<bool(InstanceId, InstanceId)>& keep = {});

}  // namespace cadclash::bench
