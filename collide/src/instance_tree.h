// A persistent AABB tree over the instances' world boxes, for broad phases where one side of the
// selection is small (one part moving through a large scene): a moved instance refits its leaf's
// path to the root, and a query visits only the subtrees its box meets, so a check's broad phase
// costs O(|small side| · log N + pairs found) instead of a sweep over all N instances. Internal to
// cadclash::collide.
//
// The tree answers "which instances' boxes meet this box"; the caller then applies the sweep's own
// overlap test to each, so the pairs found do not depend on the tree's shape or history.
#pragma once

#include "cadclash/collide.h"

#include <cstdint>
#include <span>
#include <vector>

namespace cadclash::detail {

class InstanceTree {
 public:
  // Builds the tree over the instances with a non-empty box in `world_box` (indexed by instance id).
  void build(std::span<const Aabb> world_box);
  bool built() const { return !leaf_of_.empty() || built_empty_; }
  // The box of every instance in the tree (empty when there is none).
  Aabb bounds() const { return nodes_.empty() ? Aabb() : nodes_[0].box; }
  // The instance's box changed to `box` (emptiness unchanged): refits its leaf and the leaf's
  // ancestors. After as many refits as there are leaves, rebuild_if_worn rebuilds the tree from
  // `world_box`, so a tree distorted by long paths stays cheap to query.
  void refit(InstanceId instance, const Aabb& box);
  void rebuild_if_worn(std::span<const Aabb> world_box);
  // Calls f(instance) for every instance whose box meets `query` (closed boxes), in no set order.
  template <class F>
  void query(const Aabb& query, F&& f) const;
  std::uint64_t bytes() const { return nodes_.size() * sizeof(Node) + leaf_of_.size() * sizeof(std::uint32_t); }

 private:
  static constexpr std::uint32_t kNone = ~std::uint32_t{0};
  struct Node {
    Aabb box;
    std::uint32_t left = kNone, right = kNone;  // kNone for a leaf
    std::uint32_t parent = kNone;
    InstanceId instance = kInvalidId;           // leaves only
  };
  std::uint32_t build_range(std::span<const Aabb> world_box, std::vector<InstanceId>& ids, std::size_t begin,
                            std::size_t end, std::uint32_t parent);
  std::vector<Node> nodes_;               // nodes_[0] is the root
  std::vector<std::uint32_t> leaf_of_;    // per instance: its leaf, kNone when not in the tree
  std::uint64_t refits_ = 0;              // since the last build
  bool built_empty_ = false;
};

template <class F>
void InstanceTree::query(const Aabb& q, F&& f) const {
  if (nodes_.empty() || q.isEmpty()) return;
  // The median build keeps the depth <= log2(N) + 1 and refits never change the shape.
  std::uint32_t stack[72];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!((n.box.min().array() <= q.max().array()).all() && (q.min().array() <= n.box.max().array()).all())) continue;
    if (n.left == kNone) {
      f(n.instance);
    } else {
      stack[top++] = n.right;
      stack[top++] = n.left;
    }
  }
}

}  // namespace cadclash::detail
