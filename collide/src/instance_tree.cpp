#include "instance_tree.h"

#include <algorithm>

namespace cadclash::detail {

void InstanceTree::build(std::span<const Aabb> world_box) {
  nodes_.clear();
  leaf_of_.assign(world_box.size(), kNone);
  refits_ = 0;
  std::vector<InstanceId> ids;
  for (InstanceId i = 0; i < world_box.size(); ++i)
    if (!world_box[i].isEmpty()) ids.push_back(i);
  built_empty_ = ids.empty();
  if (ids.empty()) return;
  nodes_.reserve(2 * ids.size() - 1);
  build_range(world_box, ids, 0, ids.size(), kNone);
}

std::uint32_t InstanceTree::build_range(std::span<const Aabb> world_box, std::vector<InstanceId>& ids,
                                        std::size_t begin, std::size_t end, std::uint32_t parent) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  nodes_[index].parent = parent;
  if (end - begin == 1) {
    nodes_[index].box = world_box[ids[begin]];
    nodes_[index].instance = ids[begin];
    leaf_of_[ids[begin]] = index;
    return index;
  }
  Aabb centres;
  for (std::size_t k = begin; k < end; ++k) centres.extend(world_box[ids[k]].center());
  int axis = 0;
  centres.sizes().maxCoeff(&axis);
  const std::size_t mid = begin + (end - begin) / 2;
  std::nth_element(ids.begin() + begin, ids.begin() + mid, ids.begin() + end, [&](InstanceId a, InstanceId b) {
    const double ca = world_box[a].center()[axis], cb = world_box[b].center()[axis];
    return ca < cb || (ca == cb && a < b);
  });
  const std::uint32_t left = build_range(world_box, ids, begin, mid, index);
  const std::uint32_t right = build_range(world_box, ids, mid, end, index);
  nodes_[index].left = left;
  nodes_[index].right = right;
  nodes_[index].box = nodes_[left].box.merged(nodes_[right].box);
  return index;
}

void InstanceTree::refit(InstanceId instance, const Aabb& box) {
  if (instance >= leaf_of_.size() || leaf_of_[instance] == kNone) return;
  std::uint32_t n = leaf_of_[instance];
  nodes_[n].box = box;
  for (n = nodes_[n].parent; n != kNone; n = nodes_[n].parent)
    nodes_[n].box = nodes_[nodes_[n].left].box.merged(nodes_[nodes_[n].right].box);
  ++refits_;
}

void InstanceTree::rebuild_if_worn(std::span<const Aabb> world_box) {
  // Rebuilding costs O(N log N); after N refits that is O(log N) per refit, as much as the refits.
  if (refits_ > 0 && refits_ >= leaf_of_.size()) build(world_box);
}

}  // namespace cadclash::detail
