// A flat AABB tree over one surface's triangles (or any items with boxes), in the part's local
// frame. Built once per surface and queried with a box (the surface-pair OAABB). Internal to
// cadclash::collide.
//
// Layout (issue 16: the whole collision model in <= 48 bytes per triangle): 16-byte nodes whose
// boxes are 16-bit coordinates on a grid over the tree's exact root box (a power-of-two step per
// axis), rounded outward, so each decoded node box contains the exact double box of its items;
// leaves of up to kLeafSize items, all full but the last; item indices in 16 bits when they fit;
// no tree at all for small surfaces, and no per-item boxes: items are tested on their exact double
// boxes, computed from the vertices the model already holds. Culling by the rounded node boxes only
// ever keeps more, and every item is judged on its exact box, so a query returns the same items as
// a tree of exact boxes would; only the number of node tests differs.
#pragma once

#include "cadclash/collide.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace cadclash::detail {

// 2^e for a normal double exponent e (-1022..1023), without a library call.
inline double power_of_two(int e) { return std::bit_cast<double>(static_cast<std::uint64_t>(e + 1023) << 52); }

struct SurfaceBvh {
  static constexpr std::uint32_t kLeafSize = 8;
  // Up to this many items there is no tree: a query scans the items (a surface this small is mostly
  // a strip along a fillet or a chamfer; a tree would cost more bytes than its triangles).
  static constexpr std::uint32_t kFlatLimit = 2 * kLeafSize;
  static constexpr std::int32_t kGrid = 65535;  // largest grid coordinate
  struct Node {
    // Grid coordinates (node_box decodes them): lo rounded down, hi up from the items' exact box.
    std::uint16_t lo[3], hi[3];
    // Leaf: (first index into the item order) << 4 | count, count in 1..kLeafSize. Inner: (left
    // child) << 4; the right child is left + 1.
    std::uint32_t bits = 0;
    std::uint32_t count() const { return bits & 15u; }
    std::uint32_t first() const { return bits >> 4; }
  };
  static_assert(sizeof(Node) == 16);

  Aabb root;                 // exact box of every item; empty when there are none (the grid's origin: root.min())
  std::uint32_t items = 0;   // number of items
  std::uint32_t node_count = 0;           // 0: no tree (items <= kFlatLimit); nodes[0] is the root
  std::unique_ptr<Node[]> nodes;          // node_count nodes
  // With a tree: item indices, leaves hold contiguous runs; 16 bits each, or two halves (low first)
  // each when `wide` (more than 65536 items).
  std::unique_ptr<std::uint16_t[]> order;
  std::int16_t step_exponent[3] = {0, 0, 0};  // grid step per axis: 2^step_exponent
  bool wide = false;

  double step(int k) const { return power_of_two(step_exponent[k]); }
  bool empty() const { return items == 0; }
  std::uint32_t item(std::uint32_t i) const {
    return wide ? std::uint32_t{order[2 * i]} | std::uint32_t{order[2 * i + 1]} << 16 : order[i];
  }
  // A grid coordinate of axis k as a double: monotone in q, root.min()[k] at 0, >= root.max()[k] at kGrid.
  double decode(int k, std::int32_t q) const { return root.min()[k] + double(q) * step(k); }
  // The node's box: contains the exact box of its items.
  Aabb node_box(const Node& n) const {
    return Aabb(Vec3(decode(0, n.lo[0]), decode(1, n.lo[1]), decode(2, n.lo[2])),
                Vec3(decode(0, n.hi[0]), decode(1, n.hi[1]), decode(2, n.hi[2])));
  }
};

// A query box on a tree's grid: node n meets the box exactly when its decoded box does, i.e. when
// n.lo[k] <= hi[k] and n.hi[k] >= lo[k] on every axis.
struct GridBox {
  std::array<std::int32_t, 3> lo, hi;
};
GridBox grid_box(const SurfaceBvh& bvh, const Aabb& query);
inline bool node_meets(const SurfaceBvh::Node& n, const GridBox& q) {
  bool in = true;  // no branch per test: a tree walk's tests are unpredictable
  for (int k = 0; k < 3; ++k) {
    in &= std::int32_t{n.lo[k]} <= q.hi[k];
    in &= std::int32_t{n.hi[k]} >= q.lo[k];
  }
  return in;
}

// The tree over items whose exact boxes are `boxes` (read during the build only).
// Precondition: boxes.size() < 2^28.
SurfaceBvh build_box_bvh(std::span<const Aabb> boxes);

// The bytes the tree holds besides the SurfaceBvh itself (nodes, order).
inline std::uint64_t bvh_heap_bytes(const SurfaceBvh& b) {
  return b.node_count * std::uint64_t{sizeof(SurfaceBvh::Node)} +
         (b.node_count > 0 ? b.items * std::uint64_t{b.wide ? 4u : 2u} : 0);
}

// Depth-first walk, left child first: `enter(node)` says whether to descend into a node (judged on
// its grid box: node_meets, or node_box for distances); `item(index)` is called for each item of an
// entered leaf, or for every item 0..items-1 when there is no tree, and returns true to end the walk.
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
        if (item(b.item(i))) return;
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

// boxes_overlap(triangle_box(mesh, t), query) for a non-empty `query` and finite vertices, axis by
// axis with an early out (most triangles a query reaches in a leaf miss it on one axis).
inline bool triangle_meets_box(const TriangleMesh& mesh, std::uint32_t t, const Aabb& query) {
  const auto& tri = mesh.triangles[t];
  const Vec3& a = mesh.vertices[tri[0]];
  const Vec3& b = mesh.vertices[tri[1]];
  const Vec3& c = mesh.vertices[tri[2]];
  for (int k = 0; k < 3; ++k) {
    if (std::min(std::min(a[k], b[k]), c[k]) > query.max()[k]) return false;
    if (std::max(std::max(a[k], b[k]), c[k]) < query.min()[k]) return false;
  }
  return true;
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

// Whether some triangle of `mesh` lies within `reach` of `p` (point_mesh_distance(...) <= reach),
// stopping at the first one found: a point inside a face asks this of thousands of triangles
// whose boxes all contain it (a board's top face).
bool point_near_mesh(const SurfaceBvh& bvh, const TriangleMesh& mesh, const Vec3& p, double reach);

}  // namespace cadclash::detail
