#include "surface_bvh.h"

#include "cadclash/geometry.h"


#include <algorithm>
#include <limits>

namespace cadclash::detail {
namespace {

constexpr std::uint32_t kLeafSize = 4;

void build_node(SurfaceBvh& bvh, const std::vector<Vec3>& centroids, std::uint32_t node_index,
                std::uint32_t begin, std::uint32_t end) {
  Aabb box;
  Aabb centre_box;
  for (std::uint32_t i = begin; i < end; ++i) {
    box.extend(bvh.triangle_boxes[bvh.order[i]]);
    centre_box.extend(centroids[bvh.order[i]]);
  }
  bvh.nodes[node_index].box = box;
  if (end - begin <= kLeafSize) {
    bvh.nodes[node_index].first = begin;
    bvh.nodes[node_index].count = end - begin;
    return;
  }
  int axis = 0;
  centre_box.sizes().maxCoeff(&axis);
  const std::uint32_t mid = begin + (end - begin) / 2;
  // Ties broken by index so the tree (and every counter) is the same on every run.
  std::nth_element(bvh.order.begin() + begin, bvh.order.begin() + mid, bvh.order.begin() + end,
                   [&](std::uint32_t a, std::uint32_t b) {
                     const double ca = centroids[a][axis], cb = centroids[b][axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  const auto left = static_cast<std::uint32_t>(bvh.nodes.size());
  bvh.nodes.emplace_back();
  bvh.nodes.emplace_back();
  bvh.nodes[node_index].first = left;
  bvh.nodes[node_index].count = 0;
  build_node(bvh, centroids, left, begin, mid);
  build_node(bvh, centroids, left + 1, mid, end);
}

}  // namespace

SurfaceBvh build_box_bvh(std::vector<Aabb> boxes) {
  SurfaceBvh bvh;
  const auto n = static_cast<std::uint32_t>(boxes.size());
  if (n == 0) return bvh;
  bvh.triangle_boxes = std::move(boxes);
  std::vector<Vec3> centroids(n);
  bvh.order.resize(n);
  for (std::uint32_t t = 0; t < n; ++t) {
    centroids[t] = bvh.triangle_boxes[t].center();
    bvh.order[t] = t;
  }
  bvh.nodes.reserve(2 * (n / kLeafSize + 1));
  bvh.nodes.emplace_back();
  build_node(bvh, centroids, 0, 0, n);
  return bvh;
}

SurfaceBvh build_surface_bvh(const TriangleMesh& mesh) {
  std::vector<Aabb> boxes(mesh.triangles.size());
  for (std::size_t t = 0; t < boxes.size(); ++t)
    for (std::uint32_t v : mesh.triangles[t]) boxes[t].extend(mesh.vertices[v]);
  return build_box_bvh(std::move(boxes));
}

void query_surface_bvh(const SurfaceBvh& bvh, const Aabb& query, std::vector<std::uint32_t>& out,
                       std::uint64_t& box_tests) {
  if (bvh.nodes.empty() || query.isEmpty()) return;
  const std::size_t start = out.size();
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const SurfaceBvh::Node& node = bvh.nodes[stack[--top]];
    ++box_tests;
    if (!boxes_overlap(node.box, query)) continue;
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const std::uint32_t t = bvh.order[i];
        ++box_tests;
        if (boxes_overlap(bvh.triangle_boxes[t], query)) out.push_back(t);
      }
    } else {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
    }
  }
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(start), out.end());
}

double point_mesh_distance(const SurfaceBvh& bvh, const TriangleMesh& mesh, const Vec3& p, double reach) {
  double best = std::numeric_limits<double>::infinity();
  if (bvh.nodes.empty()) return best;
  // Nearer child first: the best so far shrinks sooner and prunes more. The minimum is the same in
  // any order.
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const SurfaceBvh::Node& node = bvh.nodes[stack[--top]];
    if (node.box.exteriorDistance(p) > std::min(best, reach)) continue;
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const std::uint32_t t = bvh.order[i];
        if (bvh.triangle_boxes[t].exteriorDistance(p) > std::min(best, reach)) continue;
        const auto& tri = mesh.triangles[t];
        best = std::min(best, point_triangle_distance(p, mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]));
      }
    } else {
      const bool left_nearer = bvh.nodes[node.first].box.squaredExteriorDistance(p) <=
                               bvh.nodes[node.first + 1].box.squaredExteriorDistance(p);
      stack[top++] = left_nearer ? node.first + 1 : node.first;
      stack[top++] = left_nearer ? node.first : node.first + 1;
    }
  }
  return best;
}

}  // namespace cadclash::detail
