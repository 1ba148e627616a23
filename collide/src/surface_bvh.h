// A flat AABB tree over one surface's triangles (or any items with boxes), in the part's local
// frame. Built once per surface and queried with a box (the surface-pair OAABB). Internal to
// cadclash::collide.
//
// Layout (issue 16: the whole collision model in <= 48 bytes per triangle): 28-byte nodes with
// float boxes rounded outward (each contains the exact double box of its items), leaves of up to
// kLeafSize items, all full but the last, no tree at all for small surfaces, and no per-item boxes:
// items are tested on their exact double boxes, computed from the vertices the model already holds. Culling by the rounded
// node boxes only ever keeps more, and every item is judged on its exact box, so a query returns the
// same items as a tree of exact boxes would; only the number of node tests differs.
#pragma once

#include "cadclash/collide.h"

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace cadclash::detail {

struct SurfaceBvh {
  static constexpr std::uint32_t kLeafSize = 8;
  // Up to this many items there is no tree: a query scans the items (a surface this small is mostly
  // a strip along a fillet or a chamfer; a tree would cost more bytes than its triangles).
  static constexpr std::uint32_t kFlatLimit = 2 * kLeafSize;
  struct Node {
    float lo[3], hi[3];  // rounded outward from the exact box of the node's items
    // Leaf: (first index into `order`) << 4 | count, count in 1..kLeafSize. Inner: (left child) << 4;
    // the right child is left + 1.
    std::uint32_t bits = 0;
    std::uint32_t count() const { return bits & 15u; }
    std::uint32_t first() const { return bits >> 4; }
    Aabb box() const {
      return Aabb(Vec3(double(lo[0]), double(lo[1]), double(lo[2])), Vec3(double(hi[0]), double(hi[1]), double(hi[2])));
    }
  };
  static_assert(sizeof(Node) == 28);

  Aabb root;                 // exact box of every item; empty when there are none
  std::uint32_t items = 0;   // number of items
  std::uint32_t node_count = 0;           // 0: no tree (items <= kFlatLimit); nodes[0] is the root
  std::unique_ptr<Node[]> nodes;          // node_count nodes
  std::unique_ptr<std::uint32_t[]> order; // with a tree: item indices, leaves hold contiguous runs

  bool empty() const { return items == 0; }
};

// The tree over items whose exact boxes are `boxes` (read during the build only).
// Precondition: boxes.size() < 2^28.
SurfaceBvh build_box_bvh(std::span<const Aabb> boxes);

// The bytes the tree holds besides the SurfaceBvh itself (nodes, order).
inline std::uint64_t bvh_heap_bytes(const SurfaceBvh& b) {
  return b.node_count * std::uint64_t{sizeof(SurfaceBvh::Node)} +
         (b.node_count > 0 ? b.items * std::uint64_t{sizeof(std::uint32_t)} : 0);
}

// Depth-first walk, left child first: `enter(node)` says whether to descend into a node (judged on
// its rounded box); `item(index)` is called for each item of an entered leaf, or for every item
// 0..items-1 when there is no tree, and returns true to end the walk.
template <class Enter, class Item>
void walk_bvh(const SurfaceBvh& b, Enter&& enter, Item&& item) {
  if (b.node_count == 0) {
    for (std::uint32_t t = 0; t < b.items; ++t)
      if (item(t)) return;
    return;
  }
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const SurfaceBvh::Node& node = b.nodes[stack[--top]];
    if (!enter(node)) continue;
    if (const std::uint32_t count = node.count(); count > 0) {
      for (std::uint32_t i = node.first(); i < node.first() + count; ++i)
        if (item(b.order[i])) return;
    } else {
      stack[top++] = node.first() + 1;
      stack[top++] = node.first();
    }
  }
}

// The exact box of triangle `t` of `mesh`.
inline Aabb triangle_box(const TriangleMesh& mesh, std::uint32_t t) {
  const auto& tri = mesh.triangles[t];
  Aabb b(mesh.vertices[tri[0]]);
  b.extend(mesh.vertices[tri[1]]).extend(mesh.vertices[tri[2]]);
  return b;
}

// Builds the tree over `mesh`'s triangles (split at a multiple of kLeafSize on the longest axis of
// the centroids, ties broken by index: the same tree on every run; none up to kFlatLimit triangles).
SurfaceBvh build_surface_bvh(const TriangleMesh& mesh);

// Appends, sorted ascending, the indices of the triangles of `mesh` (the mesh `bvh` was built on)
// whose exact box meets `query`. `box_tests` counts the box-box tests made (nodes and triangles).
void query_surface_bvh(const SurfaceBvh& bvh, const TriangleMesh& mesh, const Aabb& query,
                       std::vector<std::uint32_t>& out, std::uint64_t& box_tests);

// The smallest distance from `p` to a triangle of `mesh` (the mesh `bvh` was built on) whose box
// comes within `reach` of p, by point_triangle_distance; +inf when none does. Nearer triangles are never
// pruned, so a result <= reach is the distance to the whole mesh.
double point_mesh_distance(const SurfaceBvh& bvh, const TriangleMesh& mesh, const Vec3& p, double reach);

}  // namespace cadclash::detail
