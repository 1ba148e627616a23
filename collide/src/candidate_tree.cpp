#include "candidate_tree.h"

#include <algorithm>
#include <array>

namespace cadclash::detail {
namespace {

constexpr std::uint32_t kLeafItems = 8;

FlatBox union_of(const FlatBox& a, const FlatBox& b) {
  FlatBox u;
  for (int k = 0; k < 3; ++k) {
    u.lo[k] = std::min(a.lo[k], b.lo[k]);
    u.hi[k] = std::max(a.hi[k], b.hi[k]);
  }
  return u;
}

}  // namespace

void CandidateTree::build(const std::vector<Aabb>& boxes) {
  nodes_.clear();
  items_.resize(boxes.size());
  for (std::size_t j = 0; j < boxes.size(); ++j) items_[j] = {flat_box(boxes[j]), static_cast<std::uint32_t>(j)};
  if (items_.empty()) return;
  nodes_.reserve(2 * (items_.size() / kLeafItems + 1));
  nodes_.push_back({});
  // Median splits along the widest extent of the items' centres; ties broken by index, so the
  // tree (and the order of query results, which the run sorts anyway) is deterministic.
  struct Range {
    std::uint32_t node, first, count;
  };
  std::vector<Range> stack{{0, 0, static_cast<std::uint32_t>(items_.size())}};
  while (!stack.empty()) {
    const Range r = stack.back();
    stack.pop_back();
    FlatBox box = items_[r.first].box;
    double clo[3], chi[3];
    for (int k = 0; k < 3; ++k) clo[k] = chi[k] = items_[r.first].box.lo[k] + items_[r.first].box.hi[k];
    for (std::uint32_t i = r.first + 1; i < r.first + r.count; ++i) {
      box = union_of(box, items_[i].box);
      for (int k = 0; k < 3; ++k) {
        const double c = items_[i].box.lo[k] + items_[i].box.hi[k];
        clo[k] = std::min(clo[k], c);
        chi[k] = std::max(chi[k], c);
      }
    }
    nodes_[r.node].box = box;
    if (r.count <= kLeafItems) {
      nodes_[r.node].first = r.first;
      nodes_[r.node].count = r.count;
      continue;
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
    const std::uint32_t half = r.count / 2;
    const auto begin = items_.begin() + r.first;
    std::nth_element(begin, begin + half, begin + r.count, [axis](const Item& x, const Item& y) {
      const double cx = x.box.lo[axis] + x.box.hi[axis], cy = y.box.lo[axis] + y.box.hi[axis];
      return cx < cy || (cx == cy && x.index < y.index);
    });
    const auto left = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back({});
    nodes_.push_back({});
    nodes_[r.node].first = left;
    nodes_[r.node].count = 0;
    stack.push_back({left + 1, r.first + half, r.count - half});
    stack.push_back({left, r.first, half});
  }
}

namespace {

// Nodes of the tree build() makes over n items: a leaf up to kLeafItems, else halves n / 2, n - n / 2.
std::size_t node_count(std::size_t n) { return n <= kLeafItems ? 1 : 1 + node_count(n / 2) + node_count(n - n / 2); }

}  // namespace

std::size_t CandidateTree::bytes_for(std::size_t items) {
  return items == 0 ? 0 : node_count(items) * sizeof(Node) + items * sizeof(Item);
}

void CandidateTree::query(const FlatBox& a, double margin, std::vector<std::uint32_t>& out,
                          std::uint64_t& tests) const {
  if (nodes_.empty()) return;
  std::array<std::uint32_t, 64> stack;
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    ++tests;
    if (!candidate_within(a, n.box, margin)) continue;
    if (n.count > 0) {
      for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
        ++tests;
        if (candidate_within(a, items_[i].box, margin)) out.push_back(items_[i].index);
      }
    } else {
      stack[top++] = n.first + 1;
      stack[top++] = n.first;
    }
  }
}

}  // namespace cadclash::detail
