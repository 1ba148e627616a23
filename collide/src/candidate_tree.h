// The triangle level's candidates, made per triangle of A when the run reaches it: a tree over B's
// surviving boxes (in A's frame) built with the prepared pair. A run that settles its outcome early
// (the first intersecting pair of a contact whose crossings are bounded) never makes the candidates
// of the triangles it does not reach. Internal to cadclash::collide.
#pragma once

#include "cadclash/geometry.h"

#include <cstdint>
#include <vector>

namespace cadclash::detail {

// A box as the candidate test reads it.
struct FlatBox {
  double lo[3], hi[3];
};

inline FlatBox flat_box(const Aabb& b) {
  return {{b.min().x(), b.min().y(), b.min().z()}, {b.max().x(), b.max().y(), b.max().z()}};
}

// The candidate test of the triangle level: the boxes of triangle a (A's) and b (B's) come within
// `margin` on every axis (boxes_within's test, never empty boxes).
inline bool candidate_within(const FlatBox& a, const FlatBox& b, double margin) {
  bool in = true;
  for (int k = 0; k < 3; ++k) in &= (b.lo[k] - a.hi[k] <= margin) & (a.lo[k] - b.hi[k] <= margin);
  return in;
}

class CandidateTree {
 public:
  // Over `boxes` (item j has boxes[j]); nodes hold the exact union of their items' boxes, so a node
  // farther than the margin holds no candidate (subtraction rounds monotonically).
  void build(const std::vector<Aabb>& boxes);
  bool empty() const { return nodes_.empty(); }
  void clear() {
    nodes_.clear();
    items_.clear();
  }

  // Appends every item j with candidate_within(a, item_box(j), margin), in no particular order;
  // adds the node and item box tests made to `tests`.
  void query(const FlatBox& a, double margin, std::vector<std::uint32_t>& out, std::uint64_t& tests) const;

  std::size_t bytes() const { return nodes_.size() * sizeof(Node) + items_.size() * sizeof(Item); }
  // What bytes() is once built over `items` boxes (the node count depends on the count alone).
  static std::size_t bytes_for(std::size_t items);

 private:
  struct Node {
    FlatBox box;
    std::uint32_t first = 0;  // leaf: items_[first, first + count); inner: children first, first + 1
    std::uint32_t count = 0;  // 0 for an inner node
  };
  struct Item {
    FlatBox box;
    std::uint32_t index = 0;
  };
  std::vector<Node> nodes_;
  std::vector<Item> items_;
};

}  // namespace cadclash::detail
