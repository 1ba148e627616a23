// One setting of the accuracy benchmark: cadclash (three modes) or OCCT's BRepExtrema_ShapeProximity
// on an imported model, scored against the ground truth. Used by bench_accuracy and its test.
#pragma once

#include "ground_truth.h"

#include <cstdint>
#include <string>
#include <vector>

namespace cadclash::bench {

enum class Mode : std::uint8_t {
  MeshOnly,       // τ = tolerance alone: every surface's deflection is set to 0 for the query
  ErrorAware,     // cadclash's default τ = tolerance + both surfaces' achieved deflections
  ExactVerified,  // error-aware, then CollideOptions::exact_verification; pairs kept below
  OcctProximity,  // BRepExtrema_ShapeProximity(tolerance) on the same face triangulations
};

// "mesh-only", "error-aware", "exact-verified", "occt-proximity".
const char* mode_name(Mode m);

struct RunResult {
  Mode mode = Mode::ErrorAware;
  double tolerance = 0.0;
  std::vector<PairKey> reported;  // the surface pairs this mode calls "within the tolerance"
  double seconds = 0.0;           // best of the repeats: scene build + check (cadclash), load + perform (OCCT)
  std::uint64_t triangle_tests = 0, exact_fallbacks = 0;  // cadclash only
  std::uint64_t exact_queries = 0;                         // exact-verified: pairs sent to the B-rep
  std::uint64_t instance_pairs = 0;                        // OCCT: instance pairs given to it
};

// Runs one mode on `model` (eagerly tessellated B-rep parts). `keep`, when given, restricts the
// instance pairs as in compute_ground_truth. Exact-verified drops a reported pair whose
// SurfacePairResult::exact_distance is > tolerance + kContactSlack and keeps the rest (pairs the
// library did not verify — today those whose triangles intersect — and pairs without exact geometry).
// threads: cadclash's OpenMP threads (OCCT's tool is serial).
RunResult run_mode(Model& model, Mode mode, double tolerance, double deflection, int threads, int repeats,
                   const std::function<bool(InstanceId, InstanceId)>& keep = {});

}  // namespace cadclash::bench
