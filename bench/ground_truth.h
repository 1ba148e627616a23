// Ground truth for the accuracy benchmark: which B-rep face pairs of which instance pairs are within
// a tolerance of each other, measured on the exact faces (BRepExtrema_DistShapeShape on the placed
// faces), and how a set of reported surface pairs scores against it.
//
// Candidates: every instance pair (a < b) and every face pair whose world boxes, enlarged by the
// tolerance, overlap. The boxes are the surfaces' Surface::aabb (which encloses the exact face, not
// its triangles) mapped to world by the pose, so they enclose the placed faces: two faces within the
// tolerance always have boxes within the tolerance, and the prefilter never drops a true pair. Every
// candidate's exact distance is measured and kept (true or not), so a false pair can be looked up.
#pragma once

#include "cadclash/collide.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

class gp_Trsf;

namespace cadclash::bench {

// The OCCT transformation of a pose (part-local -> world), to place B-rep shapes like instances.
gp_Trsf to_trsf(const Pose& pose);

// Exact contact is "distance <= tolerance + kContactSlack": touching faces do not measure exactly 0
// (on as1-tu-203.stp they measure 0 or 1e-15..1e-11 mm; the next face pair is 1 mm away), and
// BRepExtrema works to Precision::Confusion() = 1e-7 mm. 1e-6 mm is far below any deliberate gap
// in a mechanical assembly.
inline constexpr double kContactSlack = 1e-6;

// One measured candidate face pair. Model ids (instance_a < instance_b).
struct MeasuredPair {
  InstanceId instance_a = kInvalidId, instance_b = kInvalidId;
  SurfaceId surface_a = kInvalidId, surface_b = kInvalidId;
  double distance = 0.0;  // exact face distance; +infinity when OCCT could not measure it
};

struct GroundTruth {
  double tolerance = 0.0;
  std::vector<MeasuredPair> measured;   // every candidate, sorted by ids
  std::uint64_t instance_pairs = 0;     // instance pairs with at least one candidate
  std::uint64_t failed = 0;             // candidates OCCT could not measure (counted as not within)
  double seconds = 0.0;                 // time to measure (0 when read from the cache)
  bool from_cache = false;
};

// True when the measured pair is within the truth's tolerance.
bool within(const MeasuredPair& p, double tolerance);

// Measures every candidate of `model` (a model whose parts are B-rep parts with BrepSource sources;
// other parts are skipped) for `tolerance`. Deterministic; runs on `threads` threads (<= 0: OpenMP's
// default). `keep`, when given, restricts the instance pairs (called with a < b).
GroundTruth compute_ground_truth(const Model& model, double tolerance, int threads,
                                 const std::function<bool(InstanceId, InstanceId)>& keep = {});

// The exact distance of two placed faces (BRepExtrema_DistShapeShape); +infinity when either
// surface is not a B-rep face or OCCT fails.
double exact_face_distance(const Model& model, InstanceId a, SurfaceId sa, InstanceId b, SurfaceId sb);

// FNV-1a 64 of the file's bytes, as 16 hex digits; empty when the file cannot be read.
std::string file_hash(const std::string& path);

// The cache file for `hash` and `tolerance` under `dir`: dir/truth-<hash>-t<tolerance>.json.
std::string cache_path(const std::string& dir, const std::string& hash, double tolerance);

// Reads a cache written by save_ground_truth for the same model (pairs are stored by instance path
// and face index, so ids are re-derived); nullopt when absent, unreadable or not matching.
std::optional<GroundTruth> load_ground_truth(const std::string& path, const Model& model, double tolerance);

// Writes the truth; returns false when the file cannot be written.
bool save_ground_truth(const std::string& path, const Model& model, const GroundTruth& truth);

// A surface pair as the scorer sees it (ids of one model, instance_a < instance_b).
struct PairKey {
  InstanceId instance_a = kInvalidId, instance_b = kInvalidId;
  SurfaceId surface_a = kInvalidId, surface_b = kInvalidId;
  friend auto operator<=>(const PairKey&, const PairKey&) = default;
};

struct Score {
  std::uint64_t truth = 0;      // true pairs
  std::uint64_t reported = 0;   // distinct reported pairs
  std::uint64_t hits = 0;       // reported and true
  std::vector<PairKey> missed;  // true, not reported (sorted)
  std::vector<PairKey> false_pairs;  // reported, not true (sorted)
  // recall = hits / truth (1 when there is no true pair); precision = hits / reported (1 when
  // nothing is reported).
  double recall() const;
  double precision() const;
};

// Scores `reported` (any order, duplicates ignored) against the pairs of `truth` within its tolerance.
Score score(const GroundTruth& truth, std::vector<PairKey> reported);

}  // namespace cadclash::bench
