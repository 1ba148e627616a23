// Triangle–triangle predicates used by the narrow phase. Internal to cadclash::collide.
#pragma once

#include "cadclash/collide.h"

#include <cstdint>

namespace cadclash::detail {

struct TrianglePredicateStats {
  std::uint64_t tests = 0;            // calls of triangles_intersect
  std::uint64_t exact_fallbacks = 0;  // calls whose float filter could not decide
};

// True iff the closed triangles (a0,a1,a2) and (b0,b1,b2) share at least one point, exactly as exact
// arithmetic on the given double coordinates decides (coplanar overlap and touching count).
// Degenerate triangles (collinear or repeated vertices) are handled as the point sets they are.
bool triangles_intersect(const Vec3& a0, const Vec3& a1, const Vec3& a2,
                         const Vec3& b0, const Vec3& b1, const Vec3& b2,
                         TrianglePredicateStats& stats);

// Euclidean distance between the closed triangles; 0 when they intersect. Double precision.
double triangle_distance(const Vec3& a0, const Vec3& a1, const Vec3& a2,
                         const Vec3& b0, const Vec3& b1, const Vec3& b2);

}  // namespace cadclash::detail
