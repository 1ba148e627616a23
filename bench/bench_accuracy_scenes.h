// The scenes of the certified-decision truth tests (cadclash/testing/scenes.h: the board of real
// parts, as1, as1 with a nut moved off the plate by 0.005, 0.02 and 0.05 mm) in bench_accuracy: each
// product mode scored against the exact truth, with its time and what decided its pairs.
#pragma once

#include "bench_accuracy_run.h"

#include <string>
#include <vector>

namespace cadclash::bench {

// A markdown table: per scene, tolerance and mode (fast, certified, exact), the truth's pairs,
// recall, precision, undecided pairs, time (best of `repeats`; exact: one run) and the decided-by
// split. `external_dir` is data/external. Progress lines go to stdout.
std::string scene_matrix(const std::string& external_dir, double deflection, const std::vector<double>& tolerances,
                         int threads, int repeats);

}  // namespace cadclash::bench
