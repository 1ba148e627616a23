// A flat AABB tree over one surface's triangles, in the part's local frame. Built once per surface
// and queried with a box (the surface-pair OAABB). Internal to cadclash::collide.
#pragma once

#include "cadclash/collide.h"

#include <cstdint>
#include <vector>

namespace cadclash::detail {

struct SurfaceBvh {
  struct Node {
    Aabb box;
    std::uint32_t first = 0;  // leaf: first index into `order`; inner: index of the left child (right = first + 1)
    std::uint32_t count = 0;  // leaf: number of triangles; inner: 0
  };
  std::vector<Node> nodes;           // nodes[0] is the root; empty for a surface without triangles
  std::vector<std::uint32_t> order;  // triangle indices, leaves hold contiguous runs
  std::vector<Aabb> triangle_boxes;  // per triangle index, exact boxes of the stored vertices
};

// The same tree over any boxes (item k's box is boxes[k]; `triangle_boxes` holds them).
SurfaceBvh build_box_bvh(std::vector<Aabb> boxes);

// The bytes the tree holds (nodes, order, boxes).
inline std::uint64_t bvh_bytes(const SurfaceBvh& b) {
  return b.nodes.size() * sizeof(b.nodes[0]) + b.order.size() * sizeof(b.order[0]) +
         b.triangle_boxes.size() * sizeof(b.triangle_boxes[0]);
}

// Builds the tree (median split on the longest axis of the centroids; leaves of <= 4 triangles).
SurfaceBvh build_surface_bvh(const TriangleMesh& mesh);

// Appends, sorted ascending, the indices of the triangles whose box meets `query`.
// `box_tests` counts the box-box tests made.
void query_surface_bvh(const SurfaceBvh& bvh, const Aabb& query, std::vector<std::uint32_t>& out,
                       std::uint64_t& box_tests);

// The smallest distance from `p` to a triangle of `mesh` (the mesh `bvh` was built on) whose box
// comes within `reach` of p, by point_triangle_distance; +inf when none does. Nearer triangles are never
// pruned, so a result <= reach is the distance to the whole mesh.
double point_mesh_distance(const SurfaceBvh& bvh, const TriangleMesh& mesh, const Vec3& p, double reach);

}  // namespace cadclash::detail
