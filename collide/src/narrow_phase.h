// The triangle level of one candidate surface pair, split in a preparation (OAABB, BVH queries,
// mapping B's surviving triangles into A's frame) and a run over a range of A's survivors, so the
// parallel Version 2 can cut a pair into blocks. Internal to cadclash::collide.
#pragma once

#include "budget.h"
#include "candidate_tree.h"
#include "cadclash/collide.h"
#include "surface_bvh.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace cadclash::detail {

struct PreparedPair {
  double tau = 0.0;     // touching bound: tolerance + both deflections; a crossing deeper ends the run
  // Crossings deeper than this set PairOutcome::crosses_threshold (<= tau; certified, where one face
  // is a plane: T, where the decision's crossing step begins; else tau).
  double threshold = 0.0;
  // Crossings deeper than min(low, threshold) set PairOutcome::may_cross_threshold (certified, where
  // one face is a plane: where the exact faces may cross deeper than T; else tau, as threshold). The
  // min, not an invariant: a caller that lowers threshold alone (tests of the early exit) gets it.
  double low = 0.0;
  double margin = 0.0;  // search margin: max(tau, clearance) plus the rounding slack
  double slack = 0.0;   // that rounding slack: bounds any rounding of a height or box coordinate here
  std::vector<std::uint32_t> la, lb;           // surviving triangle indices of Sk and Sl, ascending
  std::vector<Aabb> box_a, box_b;              // their boxes in A's frame, parallel to la / lb
  std::vector<std::array<Vec3, 3>> tri_b;      // Sl's survivors mapped into A's frame
  CandidateTree tree_b;  // over box_b, when the triangle level will not use the flat loops
  // The run makes tree_b's candidates itself, scanning B's boxes until a tree pays (run_pair): a
  // run that settles within a few of A's triangles never builds one. Charged as if built.
  bool tree_deferred = false;
};

// The touching bound of fast mode (and of the paper's narrow phase): tolerance + both surfaces'
// deflections. Certified decisions use certified_reach (decide.h) instead.
inline double band_threshold(const Surface& a, const Surface& b, double tolerance) {
  return tolerance + (a.deflection + b.deflection);
}

// How far apart two boxes may be and still hold a pair the query must see: the tolerance plus what
// each side adds (deflection, uncertainty) plus the round-off bound, or the clearance when larger.
inline double search_reach(const CollideOptions& o, double share_a, double share_b, double roundoff) {
  return std::max(o.tolerance + share_a + share_b + roundoff, o.clearance);
}

struct PairOutcome {
  bool intersecting = false;
  // Crossing depth of an intersecting triangle pair deeper than PreparedPair::tau: the first in
  // visiting order (EarlyExit, which stops there) or the deepest (AllTrianglePairs); 0 when no pair
  // crosses deeper than tau. Shallower crossings are within the bands and say nothing about the
  // exact faces: they are not measured beyond what the two flags need.
  double penetration = 0.0;
  bool crosses_threshold = false;  // some intersecting pair crosses deeper than PreparedPair::threshold
  bool may_cross_threshold = false;  // some intersecting pair crosses deeper than PreparedPair::low
  // The smallest triangle distance when no pair intersects (+inf when no candidate came within the
  // margin). When one does, pairs met before it are not all measured: the value means nothing then.
  double distance = std::numeric_limits<double>::infinity();
  std::vector<std::array<std::uint32_t, 2>> triangle_pairs;
  // The triangle pair (indices in Sk's and Sl's meshes) that decided the outcome: the first
  // intersecting one, else the nearest (first in visiting order on ties); kInvalidId when none.
  std::array<std::uint32_t, 2> witness{kInvalidId, kInvalidId};
  bool cut = false;  // the deadline expired inside the run: the outcome covers only part of its range
};

// Bytes held by the survivor lists of a prepared pair (charged against the memory budget).
std::size_t prepared_bytes(const PreparedPair& p);

// Fills `out` for surfaces `sa` (of instance A, A's frame) and `sb` (of B, mapped by t_ab: B → A;
// t_ba its inverse). With use_oaabb false every triangle of both surfaces survives (brute force).
void prepare_pair(const Surface& sa, const SurfaceBvh& bvh_a, const Surface& sb, const SurfaceBvh& bvh_b,
                  const Pose& t_ab, const Pose& t_ba, const CollideOptions& options, PreparedPair& out,
                  CollideCounters& counters);

// prepare_pair with the touching bound given: `tau` is the depth past which a crossing ends the run
// and, with options.clearance, the search reach (certified decisions search T + both bands + r).
// `defer_tree`: leave the tree to the one run_pair over the whole pair (PreparedPair::tree_deferred).
void prepare_pair_reach(const Surface& sa, const SurfaceBvh& bvh_a, const Surface& sb, const SurfaceBvh& bvh_b,
                        const Pose& t_ab, const Pose& t_ba, const CollideOptions& options, double tau,
                        PreparedPair& out, CollideCounters& counters, bool defer_tree = false);

// Tests A's survivors la[begin, end) against all of B's, in ascending (triangle a, triangle b) order.
// Polls `deadline` (when given) every 256 triangle tests and stops with out.cut set once it expired.
// EarlyExit mode: once the run has found an intersecting pair, a later candidate is tested for
// intersection (and counted in triangle_tests) only if its crossing depth could exceed threshold
// (until one has) or tau; the vertices' heights over the other triangle's plane bound the crossing
// depth from above, so most candidates of a touching contact need no clipping. The outcome is the
// same as testing every candidate (test_crossing_depth).
void run_pair(const Surface& sa, const PreparedPair& p, std::size_t begin, std::size_t end,
              const CollideOptions& options, PairOutcome& out, CollideCounters& counters,
              const Deadline* deadline = nullptr);

// Merges the outcome of a later block into an earlier one (blocks in ascending order of A's triangles).
void merge_outcome(PairOutcome& into, PairOutcome&& later);

// Crossing depth of two intersecting triangles (see "Penetrating" in contact_classes.h).
double crossing_depth(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1,
                      const Vec3& b2);

// The class of a surface pair from its outcome, or nullopt when it is not reported (collide.h).
std::optional<ContactClass> classify(const PairOutcome& o, double tau, double clearance);

// Generalized winding number of point `p` with respect to the triangles of `surfaces` (their own frame).
double winding_number(const Vec3& p, std::span<const Surface* const> surfaces);

}  // namespace cadclash::detail
