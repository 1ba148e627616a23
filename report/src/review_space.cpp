// Where clashes are: the world box of each pair's contact, and clashes clustered by those boxes.
#include "cadclash/geometry.h"
#include "cadclash/review.h"

#include <algorithm>
#include <cassert>
#include <numeric>

namespace cadclash {
namespace {

Aabb surface_world_box(const Model& m, std::span<const Pose> poses, InstanceId i, SurfaceId s) {
  const Pose& pose = poses[i];
  if (s != kInvalidId) return placed_box(m.surfaces[s].aabb, pose);
  const Part& part = m.parts[m.instances[i].part];
  Aabb out;
  for (SurfaceId k = part.first_surface; k < part.first_surface + part.surface_count; ++k)
    out.extend(placed_box(m.surfaces[k].aabb, pose));
  return out;
}

// Box-to-box distance (0 when they touch or overlap).
double box_gap(const std::array<double, 6>& a, const std::array<double, 6>& b) {
  double sq = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double g = std::max({0.0, a[k] - b[k + 3], b[k] - a[k + 3]});
    sq += g * g;
  }
  return std::sqrt(sq);
}

std::size_t find(std::vector<std::size_t>& parent, std::size_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

std::vector<std::array<double, 6>> contact_boxes(const Model& model, std::span<const Pose> poses, const Report& r) {
  assert(poses.size() == model.instances.size());
  std::vector<std::array<double, 6>> out;
  out.reserve(r.pairs.size());
  for (const SurfacePairResult& p : r.pairs) {
    const Aabb a = surface_world_box(model, poses, p.instance_a, p.surface_a);
    const Aabb b = surface_world_box(model, poses, p.instance_b, p.surface_b);
    std::array<double, 6> box{};
    for (int k = 0; k < 3; ++k) {
      // The overlap on this axis, or the gap between the two when they do not overlap.
      double lo = std::max(a.min()[k], b.min()[k]), hi = std::min(a.max()[k], b.max()[k]);
      if (lo > hi) std::swap(lo, hi);
      box[k] = lo;
      box[k + 3] = hi;
    }
    out.push_back(box);
  }
  return out;
}

void cluster_clashes(std::vector<ReportClash>& clashes, double distance) {
  const std::size_t n = clashes.size();
  std::vector<std::size_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < n; ++k)
    if (clashes[k].box) order.push_back(k);
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return std::pair((*clashes[x].box)[0], x) < std::pair((*clashes[y].box)[0], y);
  });
  // Sweep along x: a clash can only join those whose x range reaches within `distance` of its start.
  std::vector<std::size_t> active;
  for (std::size_t k : order) {
    const std::array<double, 6>& b = *clashes[k].box;
    std::erase_if(active, [&](std::size_t j) { return (*clashes[j].box)[3] + distance < b[0]; });
    for (std::size_t j : active)
      if (box_gap(b, *clashes[j].box) <= distance) {
        const std::size_t x = find(parent, j), y = find(parent, k);
        parent[std::max(x, y)] = std::min(x, y);  // the root is the cluster's first clash
      }
    active.push_back(k);
  }
  std::vector<std::size_t> number(n, 0);
  std::size_t next = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t root = find(parent, k);
    if (number[root] == 0) number[root] = ++next;
    clashes[k].group = "cluster " + std::to_string(number[root]);
  }
}

}  // namespace cadclash
