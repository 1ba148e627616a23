// cadclash/testing/truth.h — exact ground truth for tests and benchmarks: which B-rep face pairs of
// which instance pairs are in contact, measured on the exact faces (BRepExtrema_DistShapeShape on the
// placed faces), and how a set of reported surface pairs scores against it. Library cadclash::truth
// (tests/support); not part of the product.
//
// Contact is the library's own definition (contact_classes.h, "Certified decisions"): two faces are in
// contact when their exact distance d* <= T = tolerance + εa + εb, ε being each surface's model
// uncertainty (Surface::uncertainty, or when that is 0 the single-precision bound 2^-24 of its part's
// largest coordinate magnitude, as collide derives it). No extra slack.
//
// Candidates: every instance pair (a < b) and every face pair whose world boxes, enlarged by the
// pair's threshold T, overlap. The boxes are the surfaces' Surface::aabb (which encloses the exact
// face, not its triangles) mapped to world by the pose, so they enclose the placed faces: two faces
// within T always have boxes within T, and the prefilter never drops a true pair. Every candidate's
// exact distance is measured and kept (true or not), so a false pair can be looked up.
#pragma once

#include "cadclash/collide.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

class gp_Trsf;

namespace cadclash::truth {

// The OCCT transformation of a pose (part-local -> world), to place B-rep shapes like instances.
gp_Trsf to_trsf(const Pose& pose);

// ε of surface `s` as collide uses it: Surface::uncertainty when > 0, else 2^-24 times the largest
// Euclidean norm of a corner of its part's box (the union of the part's surface boxes).
double effective_uncertainty(const Model& model, SurfaceId s);

// The contact threshold of two surfaces: tolerance + ε(a) + ε(b).
double contact_threshold(const Model& model, SurfaceId a, SurfaceId b, double tolerance);

// One measured candidate face pair. Model ids (instance_a < instance_b).
struct MeasuredPair {
  InstanceId instance_a = kInvalidId, instance_b = kInvalidId;
  SurfaceId surface_a = kInvalidId, surface_b = kInvalidId;
  double distance = 0.0;   // exact face distance; +infinity when OCCT could not measure it
  double threshold = 0.0;  // contact_threshold of the two surfaces at the truth's tolerance
};

struct GroundTruth {
  double tolerance = 0.0;
  std::vector<MeasuredPair> measured;   // every candidate, sorted by ids
  std::uint64_t instance_pairs = 0;     // instance pairs with at least one candidate
  std::uint64_t failed = 0;             // candidates OCCT could not measure (counted as not in contact)
  double seconds = 0.0;                 // time to measure (0 when read from the cache)
  bool from_cache = false;
};

// True when the measured pair is in contact: distance <= threshold.
bool within(const MeasuredPair& p);

// Measures every candidate of `model` (a model whose parts are B-rep parts with BrepSource sources;
// other parts are skipped) for `tolerance`. Deterministic; runs on `threads` threads (<= 0: OpenMP's
// default). `keep`, when given, restricts the instance pairs (called with a < b).
GroundTruth compute_ground_truth(const Model& model, double tolerance, int threads,
                                 const std::function<bool(InstanceId, InstanceId)>& keep = {});

// The same measurements judged at a smaller tolerance (thresholds recomputed; candidates that the
// smaller tolerance's box prefilter would drop stay, measured, and are not in contact).
// Precondition: tolerance <= truth.tolerance.
GroundTruth with_tolerance(const GroundTruth& truth, const Model& model, double tolerance);

// The exact distance of two placed faces (BRepExtrema_DistShapeShape); +infinity when either
// surface is not a B-rep face or OCCT fails.
double exact_face_distance(const Model& model, InstanceId a, SurfaceId sa, InstanceId b, SurfaceId sb);

// The smallest exact face distance between instances a and b over the face pairs whose world boxes
// come within `search` mm of each other; +infinity when none do.
double instance_distance(const Model& model, InstanceId a, InstanceId b, double search);

// FNV-1a 64 of the file's bytes, as 16 hex digits; empty when the file cannot be read.
std::string file_hash(const std::string& path);

// The cache file for `hash` and `tolerance` under `dir`: dir/truth-<hash>-t<tolerance>.json.
std::string cache_path(const std::string& dir, const std::string& hash, double tolerance);

// Reads a cache written by save_ground_truth for the same model (pairs are stored by instance path
// and face index, so ids are re-derived; thresholds are recomputed from the model); nullopt when
// absent, unreadable or not matching.
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

// Scores `reported` (any order, duplicates ignored) against the pairs of `truth` in contact.
Score score(const GroundTruth& truth, std::vector<PairKey> reported);

}  // namespace cadclash::truth
