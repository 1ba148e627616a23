#include "surface_bvh.h"

#include "cadclash/geometry.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace cadclash::detail {
namespace {

constexpr std::uint32_t kLeaf = SurfaceBvh::kLeafSize;

// The nearest float not above (below) x: node boxes must contain the exact boxes they stand for.
float float_down(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float float_up(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

struct Builder {
  std::span<const Aabb> boxes;
  std::vector<Vec3> centroids;
  SurfaceBvh& bvh;
  std::uint32_t used = 1;  // nodes handed out (the root first)

  void node(std::uint32_t index, std::uint32_t begin, std::uint32_t end) {
    Aabb box;
    Aabb centre_box;
    for (std::uint32_t i = begin; i < end; ++i) {
      box.extend(boxes[bvh.order[i]]);
      centre_box.extend(centroids[bvh.order[i]]);
    }
    SurfaceBvh::Node& n = bvh.nodes[index];
    for (int k = 0; k < 3; ++k) {
      n.lo[k] = float_down(box.min()[k]);
      n.hi[k] = float_up(box.max()[k]);
    }
    if (end - begin <= kLeaf) {
      n.bits = begin << 4 | (end - begin);
      return;
    }
    int axis = 0;
    centre_box.sizes().maxCoeff(&axis);
    // The left child takes half the items rounded up to whole leaves: every leaf but the last is
    // full, so there are ceil(n / kLeafSize) leaves (the node count the byte budget rests on).
    const std::uint32_t half = (end - begin) / 2;
    const std::uint32_t mid = begin + (half + kLeaf - 1) / kLeaf * kLeaf;
    // Ties broken by index so the tree (and every counter) is the same on every run.
    std::nth_element(bvh.order.get() + begin, bvh.order.get() + mid, bvh.order.get() + end,
                     [&](std::uint32_t a, std::uint32_t b) {
                       const double ca = centroids[a][axis], cb = centroids[b][axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    const std::uint32_t left = used;
    used += 2;
    assert(used <= bvh.node_count);
    n.bits = left << 4;
    node(left, begin, mid);
    node(left + 1, mid, end);
  }
};

// The overlap test of boxes_overlap, against a node's rounded box (never empty).
inline bool node_overlaps(const SurfaceBvh::Node& n, const Aabb& q) {
  for (int k = 0; k < 3; ++k)
    if (!(double(n.lo[k]) <= q.max()[k] && q.min()[k] <= double(n.hi[k]))) return false;
  return true;
}

}  // namespace

SurfaceBvh build_box_bvh(std::span<const Aabb> boxes) {
  SurfaceBvh bvh;
  const auto n = static_cast<std::uint32_t>(boxes.size());
  assert(boxes.size() < (std::size_t{1} << 28));
  bvh.items = n;
  for (const Aabb& b : boxes) bvh.root.extend(b);
  if (n <= SurfaceBvh::kFlatLimit) return bvh;
  // A binary tree with ceil(n / kLeafSize) leaves (see Builder::node) has twice that less one nodes.
  bvh.node_count = 2 * ((n + kLeaf - 1) / kLeaf) - 1;
  bvh.nodes = std::make_unique<SurfaceBvh::Node[]>(bvh.node_count);
  bvh.order = std::make_unique<std::uint32_t[]>(n);
  Builder b{boxes, std::vector<Vec3>(n), bvh};
  for (std::uint32_t t = 0; t < n; ++t) {
    b.centroids[t] = boxes[t].center();
    bvh.order[t] = t;
  }
  b.node(0, 0, n);
  assert(b.used == bvh.node_count);
  return bvh;
}

SurfaceBvh build_surface_bvh(const TriangleMesh& mesh) {
  std::vector<Aabb> boxes(mesh.triangles.size());
  for (std::size_t t = 0; t < boxes.size(); ++t) boxes[t] = triangle_box(mesh, static_cast<std::uint32_t>(t));
  return build_box_bvh(boxes);
}

void query_surface_bvh(const SurfaceBvh& bvh, const TriangleMesh& mesh, const Aabb& query,
                       std::vector<std::uint32_t>& out, std::uint64_t& box_tests) {
  if (bvh.empty() || query.isEmpty()) return;
  const std::size_t start = out.size();
  walk_bvh(
      bvh,
      [&](const SurfaceBvh::Node& node) {
        ++box_tests;
        return node_overlaps(node, query);
      },
      [&](std::uint32_t t) {
        ++box_tests;
        if (boxes_overlap(triangle_box(mesh, t), query)) out.push_back(t);
        return false;
      });
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(start), out.end());
}

double point_mesh_distance(const SurfaceBvh& bvh, const TriangleMesh& mesh, const Vec3& p, double reach) {
  double best = std::numeric_limits<double>::infinity();
  auto visit = [&](std::uint32_t t) {
    if (triangle_box(mesh, t).exteriorDistance(p) > std::min(best, reach)) return;
    const auto& tri = mesh.triangles[t];
    best = std::min(best, point_triangle_distance(p, mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]));
  };
  if (bvh.node_count == 0) {
    for (std::uint32_t t = 0; t < bvh.items; ++t) visit(t);
    return best;
  }
  // Nearer child first: the best so far shrinks sooner and prunes more. The minimum is the same in
  // any order.
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const SurfaceBvh::Node& node = bvh.nodes[stack[--top]];
    if (node.box().exteriorDistance(p) > std::min(best, reach)) continue;
    if (const std::uint32_t count = node.count(); count > 0) {
      for (std::uint32_t i = node.first(); i < node.first() + count; ++i) visit(bvh.order[i]);
    } else {
      const bool left_nearer = bvh.nodes[node.first()].box().squaredExteriorDistance(p) <=
                               bvh.nodes[node.first() + 1].box().squaredExteriorDistance(p);
      stack[top++] = left_nearer ? node.first() + 1 : node.first();
      stack[top++] = left_nearer ? node.first() : node.first() + 1;
    }
  }
  return best;
}

}  // namespace cadclash::detail
