// Polygon triangulation for the mesh readers. Internal.
#pragma once

#include "cadclash/collide.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace cadclash::detail {

// Triangulates one polygon face whose corners are `corners` (indices into `points`, in the file's
// order) and appends the triangles to `out`, each as three entries of `corners`, keeping the
// polygon's orientation. A triangle is passed through; a convex polygon becomes a fan; any other
// polygon is ear-clipped in the plane of its Newell normal, which handles concave polygons.
// Returns false when the polygon is not simple (self-intersecting or without area), in which case
// the triangles are still a cover of its corners, made as well as possible.
// Precondition: corners.size() >= 3 and every corner < points.size().
bool triangulate_polygon(std::span<const Vec3> points, std::span<const std::uint32_t> corners,
                         std::vector<std::array<std::uint32_t, 3>>& out);

}  // namespace cadclash::detail
