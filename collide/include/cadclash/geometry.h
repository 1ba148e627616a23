// cadclash/geometry.h — the geometric building blocks of the narrow phase, for callers that test
// triangles or boxes themselves (a design-review tool's own queries, benchmarks, fuzzers).
//
// Part of cadclash::collide. Depends on Eigen and the standard library only.
//
// triangles_intersect is exact: its answer equals what exact arithmetic on the given doubles decides.
// It is a Guigue–Devillers test whose every orientation sign is staged: a double filter with a proven
// error bound, then the same bound in long double, then (only for the signs both leave open) CGAL's
// filtered exact orientation (interval arithmetic, then exact arithmetic; zeros included). With exact signs the touching configurations
// are decided in the test itself: exactly coplanar triangles in any plane (a closed 2D overlap test
// after projecting along an axis the plane is not parallel to), vertices or edges on the other
// triangle's plane (CGAL's own case analysis, mirrored), shared vertices and edges (answered on
// sight). Only degenerate triangles (collinear or repeated vertices) and coordinates beyond 2^48 in
// magnitude still go to CGAL's whole-call do_intersect (`exact_fallbacks`): none on as1, and on the
// test families (tests/collide/test_triangle_predicates.cpp, which checks that every such call has
// a degenerate triangle or an out-of-range coordinate) only the collinear lattice points the
// generators draw (45-65% of the touching families' calls went there before the exact signs).
// The distance functions are plain double precision (see triangle_distance for the accuracy).
// The box helpers pad for rounding where they say so, so culling with them never drops what exact
// arithmetic would keep. All functions are pure and thread-safe (a stats object is the caller's).
#pragma once

#include "cadclash/model.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace cadclash {

// ---- Triangles ----------------------------------------------------------------------------------

// What the predicates did, summed by the caller over its calls.
struct TrianglePredicateStats {
  std::uint64_t tests = 0;            // calls of triangles_intersect, including those made for
                                      // triangle_distance(..., stats) and triangles_within
  std::uint64_t exact_fallbacks = 0;  // calls decided by CGAL (triangles_intersect_exact): degenerate
                                      // triangles, coordinates outside the supported range. In the
                                      // float-only benchmark mode (testing::set_float_only_for_
                                      // benchmark): calls the double / long-double filters and the
                                      // shared-vertex / coordinate-plane cases leave open, answered
                                      // "intersect" with no exact work at all (no exact stage, no CGAL)
  std::uint64_t extended_signs = 0;   // orientation signs the double filter left to long double
  std::uint64_t exact_signs = 0;      // orientation signs (3D or 2D) the float filters left open,
                                      // settled by the exact stage (zeros included)
};

// True iff the closed triangles (a0,a1,a2) and (b0,b1,b2) share at least one point, exactly as exact
// arithmetic on the given double coordinates decides (coplanar overlap and touching count).
// Degenerate triangles (collinear or repeated vertices) are handled as the point sets they are.
// Precondition: all coordinates are finite.
bool triangles_intersect(const Vec3& a0, const Vec3& a1, const Vec3& a2,
                         const Vec3& b0, const Vec3& b1, const Vec3& b2,
                         TrianglePredicateStats& stats);

// The exact decision alone (no float filter, no stats): what triangles_intersect falls back to.
// Slower; exposed for tests and benchmarks. Same contract as triangles_intersect.
bool triangles_intersect_exact(const Vec3& a0, const Vec3& a1, const Vec3& a2,
                               const Vec3& b0, const Vec3& b1, const Vec3& b2);

// Euclidean distance between the closed triangles; 0 when they intersect (decided exactly by
// triangles_intersect). Otherwise the minimum over the 9 edge pairs and the 6 vertex–face pairs,
// computed in double relative to a0: the absolute error is a small multiple of 2^-53 times the
// extent of the two triangles around a0, not times their distance from the origin (measured below
// 1e-15 x extent against a long-double reference). Every candidate is the distance between two
// points of the triangles, so slivers and nearly parallel edges cannot make it too small.
// Disjoint triangles get a result > 0 even if it rounds to below the smallest normal double.
// Degenerate triangles are measured as the segments or points they are. Holds over the whole double
// range: pairs far below or above an extent of 1 are scaled by a power of two first (exact).
// Precondition: all coordinates are finite.
double triangle_distance(const Vec3& a0, const Vec3& a1, const Vec3& a2,
                         const Vec3& b0, const Vec3& b1, const Vec3& b2);
double triangle_distance(const Vec3& a0, const Vec3& a1, const Vec3& a2,
                         const Vec3& b0, const Vec3& b1, const Vec3& b2,
                         TrianglePredicateStats& stats);

// triangle_distance for a pair the caller already knows to be disjoint (triangles_intersect returned
// false), without testing again. Always > 0. Precondition: the triangles do not intersect.
double triangle_distance_apart(const Vec3& a0, const Vec3& a1, const Vec3& a2,
                               const Vec3& b0, const Vec3& b1, const Vec3& b2);

// The distance from point p to the closed triangle (b0, b1, b2): triangle_distance(p, p, p, b0, b1,
// b2) to the last bit where p is off the triangle (so always > 0 there), without its intersection
// test; where p lies on the triangle, a value within that same rounding of 0 (never below 0).
// Precondition: all coordinates are finite.
double point_triangle_distance(const Vec3& p, const Vec3& b0, const Vec3& b1, const Vec3& b2);

// True iff triangle_distance(a, b) <= d, answered with early outs: boxes farther apart than d, or
// one triangle wholly beyond d on one side of the other's plane (with a certified bound, widened by
// 64 x 2^-53 x the pair's extent so it never contradicts triangle_distance), return false before any
// distance is computed; the distance loop stops at the first candidate clearly below d.
// d == 0 asks whether they intersect (exactly); d < 0 is never met; d = +inf always is.
// Precondition: d is not NaN; coordinates finite.
bool triangles_within(const Vec3& a0, const Vec3& a1, const Vec3& a2,
                      const Vec3& b0, const Vec3& b1, const Vec3& b2,
                      double d, TrianglePredicateStats& stats);

// ---- Boxes and segments -------------------------------------------------------------------------

// The point of the segment [a, b] nearest `p`, by projection in plain doubles (a few roundings of the
// coordinates' magnitude).
inline Vec3 closest_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double s = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return a + s * ab;
}

// Relative padding that absorbs the rounding of mapping points between frames (a few ulps of the
// largest coordinate involved), so culling never drops what exact arithmetic would keep.
inline constexpr double kRelativePad = 1e-12;

// The largest absolute coordinate of `b` (0 for an empty box).
inline double box_magnitude(const Aabb& b) {
  if (b.isEmpty()) return 0.0;
  return std::max(b.min().cwiseAbs().maxCoeff(), b.max().cwiseAbs().maxCoeff());
}

// `b` grown by `margin` plus the relative rounding pad on every side; empty stays empty.
inline Aabb pad_box(const Aabb& b, double margin) {
  if (b.isEmpty()) return b;
  const double p = margin + kRelativePad * (1.0 + box_magnitude(b));
  Aabb out = b;
  out.min().array() -= p;
  out.max().array() += p;
  return out;
}

// The AABB of `b`'s eight corners mapped by `t`, as computed in doubles (not padded); empty stays
// empty.
inline Aabb placed_box(const Aabb& b, const Pose& t) {
  Aabb out;
  if (b.isEmpty()) return out;
  for (int c = 0; c < 8; ++c) out.extend(t * b.corner(static_cast<Aabb::CornerType>(c)));
  return out;
}

// placed_box padded for the rounding of the mapping: it contains the exact image of `b`.
inline Aabb transform_box(const Aabb& b, const Pose& t) {
  if (b.isEmpty()) return b;
  return pad_box(placed_box(b, t), t.translation().cwiseAbs().maxCoeff() * kRelativePad);
}

// The largest Euclidean norm of a point of `b` (0 for an empty box): bounds every point inside.
inline double box_norm(const Aabb& b) {
  if (b.isEmpty()) return 0.0;
  return b.min().cwiseAbs().cwiseMax(b.max().cwiseAbs()).norm();
}

// True when the closed boxes share a point (touching counts); false when either is empty.
inline bool boxes_overlap(const Aabb& a, const Aabb& b) {
  return !a.isEmpty() && !b.isEmpty() && (a.min().array() <= b.max().array()).all() &&
         (b.min().array() <= a.max().array()).all();
}

// Overlap of boxes each grown by `margin` (per axis gap <= margin).
inline bool boxes_within(const Aabb& a, const Aabb& b, double margin) {
  if (a.isEmpty() || b.isEmpty()) return false;
  for (int k = 0; k < 3; ++k) {
    if (b.min()[k] - a.max()[k] > margin) return false;
    if (a.min()[k] - b.max()[k] > margin) return false;
  }
  return true;
}

// Lower bound of the Euclidean distance between the boxes.
inline double box_distance(const Aabb& a, const Aabb& b) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double g = std::max({0.0, b.min()[k] - a.max()[k], a.min()[k] - b.max()[k]});
    s += g * g;
  }
  return std::sqrt(s);
}

}  // namespace cadclash
