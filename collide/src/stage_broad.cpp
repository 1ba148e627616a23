// Stage 1: instance world boxes and the broad phase.
#include "cadclash/geometry.h"
#include "scene_stages.h"

#include <algorithm>
#include <cassert>

namespace cadclash::detail {
namespace {

// Sweep-and-prune over x of the instance world boxes grown by half the search margin each.
std::vector<std::array<InstanceId, 2>> sweep(const SceneData& s, double margin, CollideCounters& c) {
  std::vector<InstanceId> ids;
  std::vector<Aabb> boxes(s.world_box.size());
  for (InstanceId i = 0; i < s.world_box.size(); ++i) {
    if (!(s.in_a[i] || s.in_b[i]) || s.world_box[i].isEmpty()) continue;
    ids.push_back(i);
    boxes[i] = pad_box(s.world_box[i], 0.5 * margin);
  }
  std::sort(ids.begin(), ids.end(), [&](InstanceId x, InstanceId y) {
    return boxes[x].min().x() < boxes[y].min().x() || (boxes[x].min().x() == boxes[y].min().x() && x < y);
  });
  std::vector<std::array<InstanceId, 2>> out;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const Aabb& bk = boxes[ids[k]];
    for (std::size_t l = k + 1; l < ids.size() && boxes[ids[l]].min().x() <= bk.max().x(); ++l) {
      ++c.aabb_tests;
      const InstanceId i = std::min(ids[k], ids[l]), j = std::max(ids[k], ids[l]);
      if (boxes_overlap(bk, boxes[ids[l]]) && s.selected(i, j)) out.push_back({i, j});
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The side of the selection a persistent tree query serves better than a sweep: a side of at most
// 1/16 of the instances (one part moving through a large scene); nullptr when neither is that small.
const std::vector<InstanceId>* small_side(const SceneData& s) {
  const std::vector<InstanceId>& a = s.selection.set_a;
  const std::vector<InstanceId>& b = s.selection.set_b;
  const std::size_t limit = s.poses.size() / 16;
  const std::vector<InstanceId>* side = nullptr;
  if (!a.empty() && a.size() <= limit) side = &a;
  if (!b.empty() && b.size() <= limit && (side == nullptr || b.size() < side->size())) side = &b;
  return side;
}

// The sweep's pairs, found from each instance of `side` through the instance tree: every pair the
// sweep would test with one instance in `side` is tested here with the sweep's own overlap test
// (the tree only skips instances whose boxes cannot pass it), so the pairs are the same.
std::vector<std::array<InstanceId, 2>> tree_pairs(SceneData& s, const std::vector<InstanceId>& side,
                                                  double margin, CollideCounters& c) {
  if (!s.instance_tree.built()) s.instance_tree.build(s.world_box);
  s.instance_tree.rebuild_if_worn(s.world_box);
  const double half = 0.5 * margin;
  // pad_box(b, half) grows b by half + kRelativePad·(1 + |b|) <= half + kRelativePad·(1 + |bounds|);
  // twice that pad on the query box covers it and the rounding of the comparisons.
  const double reach = half + 2.0 * kRelativePad * (1.0 + box_magnitude(s.instance_tree.bounds()));
  std::vector<std::array<InstanceId, 2>> out;
  for (InstanceId i : side) {
    if (!(s.in_a[i] || s.in_b[i]) || s.world_box[i].isEmpty()) continue;
    const Aabb pi = pad_box(s.world_box[i], half);
    s.instance_tree.query(pad_box(pi, reach), [&](InstanceId j) {
      if (j == i) return;
      ++c.aabb_tests;
      const InstanceId a = std::min(i, j), b = std::max(i, j);
      if (boxes_overlap(pi, pad_box(s.world_box[j], half)) && s.selected(a, b)) out.push_back({a, b});
    });
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace

void broad_phase_stage(SceneData& s, QueryState& q) {
  const CollideOptions& o = q.o;
  Model& model = s.model;
  CollideCounters& total = q.report.counters;
  // Only moved instances get new world boxes (and refit the instance tree when there is one).
  for (InstanceId i : s.dirty_list) {
    s.world_box[i] = transform_box(s.part_box[model.instances[i].part], s.poses[i]);
    ++total.aabb_updates;
    s.dirty[i] = 0;
    if (s.instance_tree.built()) s.instance_tree.refit(i, s.world_box[i]);
  }
  s.dirty_list.clear();
  for (const InstanceId i : o.involving) assert(i < s.poses.size()), (void)i;
  std::vector<std::array<InstanceId, 2>> ids;
  if (o.use_oaabb) {
    s.refresh_reach_shares();
    // The largest deflection (+ uncertainty) any surface brings to the reach.
    const double share = s.largest_reach_share(o);
    const double margin = search_reach(o, share, share, 0.0);
    // The instances asked about (CollideOptions::involving) are a side as the selection's are: the
    // tree gives the sweep's pairs that have one of them.
    const std::vector<InstanceId>* side = !o.involving.empty() ? &o.involving : small_side(s);
    ids = side != nullptr ? tree_pairs(s, *side, margin, total) : sweep(s, margin, total);
  } else {
    std::vector<char> asked(s.poses.size(), o.involving.empty() ? 1 : 0);
    for (const InstanceId i : o.involving) asked[i] = 1;
    for (InstanceId i = 0; i < s.poses.size(); ++i)
      for (InstanceId j = i + 1; j < s.poses.size(); ++j)
        if ((asked[i] || asked[j]) && s.selected(i, j)) ids.push_back({i, j});
  }
  q.pairs.resize(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    q.pairs[k].a = ids[k][0];
    q.pairs[k].b = ids[k][1];
  }
  total.instance_pairs = q.pairs.size();
}

}  // namespace cadclash::detail
