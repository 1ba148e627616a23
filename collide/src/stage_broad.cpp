// Stage 1: instance world boxes and the broad phase.
#include "cadclash/geometry.h"
#include "scene_stages.h"

#include <algorithm>

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

}  // namespace

void broad_phase_stage(SceneData& s, QueryState& q) {
  const CollideOptions& o = q.o;
  Model& model = s.model;
  CollideCounters& total = q.report.counters;
  // Only moved instances get new world boxes.
  for (InstanceId i = 0; i < s.poses.size(); ++i) {
    if (!s.dirty[i]) continue;
    s.world_box[i] = transform_box(s.part_box[model.instances[i].part], s.poses[i]);
    ++total.aabb_updates;
    s.dirty[i] = 0;
  }
  std::vector<std::array<InstanceId, 2>> ids;
  if (o.use_oaabb) {
    double share = 0.0;  // the largest deflection (+ uncertainty) any surface brings to the reach
    for (PartId p = 0; p < model.parts.size(); ++p) share = std::max(share, s.part_reach_share(p, o));
    ids = sweep(s, search_reach(o, share, share, 0.0), total);
  } else {
    for (InstanceId i = 0; i < s.poses.size(); ++i)
      for (InstanceId j = i + 1; j < s.poses.size(); ++j)
        if (s.selected(i, j)) ids.push_back({i, j});
  }
  q.pairs.resize(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    q.pairs[k].a = ids[k][0];
    q.pairs[k].b = ids[k][1];
  }
  total.instance_pairs = q.pairs.size();
}

}  // namespace cadclash::detail
