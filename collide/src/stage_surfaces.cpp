// Stage 2: the object and surface levels (OAABB of the instance pair, surviving surfaces, candidate
// surface pairs), then the task list and the memory ledger.
#include "cadclash/geometry.h"
#include "decide.h"
#include "scene_stages.h"
#include "team_loop.h"

#include "cadclash/internal/progress_meter.h"

namespace cadclash::detail {
namespace {

// The object and surface levels of one instance pair take microseconds: a team pays off for many
// pairs, or for a few whose parts have many surfaces (the surface level compares every surviving
// surface of A with every one of B: about 20 ns a comparison).
constexpr std::ptrdiff_t kMinParallelPairs = 64;
constexpr std::uint64_t kMinParallelComparisons = 4096;

// Whether the pairs' surface levels are worth a team: their comparisons at most, against the bar.
bool worth_a_team(const SceneData& s, const std::vector<InstancePair>& pairs) {
  if (pairs.size() < 2) return false;
  if (pairs.size() >= static_cast<std::size_t>(kMinParallelPairs)) return true;
  std::uint64_t comparisons = 0;
  for (const InstancePair& ip : pairs) {
    const Part& a = s.model.parts[s.model.instances[ip.a].part];
    const Part& b = s.model.parts[s.model.instances[ip.b].part];
    comparisons += std::uint64_t{a.surface_count} * b.surface_count;
  }
  return comparisons >= kMinParallelComparisons;
}

// `part_share`: SceneData::part_reach_shares.
void surface_pairs(const SceneData& s, InstancePair& ip, const CollideOptions& o, const std::vector<double>& part_share);

// The candidate surface pairs of a restricted check (CheckRestriction) are those it names.
void surface_level(const SceneData& s, InstancePair& ip, const CollideOptions& o, const std::vector<double>& part_share,
                   const CheckRestriction* only) {
  surface_pairs(s, ip, o, part_share);
  if (only == nullptr) return;
  const auto it = only->pairs.find({ip.a, ip.b});
  std::erase_if(ip.candidates, [&](const std::array<SurfaceId, 2>& c) {
    return it == only->pairs.end() || !it->second.count({c[0], c[1]});
  });
}

void surface_pairs(const SceneData& s, InstancePair& ip, const CollideOptions& o, const std::vector<double>& part_share) {
  const Model& model = s.model;
  const Instance& ia = model.instances[ip.a];
  const Instance& ib = model.instances[ip.b];
  ip.t_ab = relative_pose(s.poses[ip.a], s.poses[ip.b]);
  ip.t_ba = ip.t_ab.inverse(Eigen::Isometry);
  if (o.decision != DecisionMode::Fast)
    ip.roundoff = pair_roundoff(s.poses[ip.a], s.poses[ip.b], s.part_norm[ia.part], s.part_norm[ib.part]);
  CollideCounters& c = ip.counters;
  if (o.detect_containment) {
    const Aabb& wa = s.world_box[ip.a];
    const Aabb& wb = s.world_box[ip.b];
    if (!wa.isEmpty() && !wb.isEmpty()) {
      if (wa.contains(wb)) ip.containment = 1;
      else if (wb.contains(wa)) ip.containment = 2;
    }
  }
  // A pair the caller has proved apart is left out (CollideOptions::proved_apart).
  auto settled = [&](SurfaceId sa, SurfaceId sb) {
    return o.proved_apart && o.proved_apart(ip.a, ip.b, sa, sb, s.eps[sa] + s.eps[sb]);
  };
  if (!o.use_oaabb) {
    for (SurfaceId sa = s.first(ia.part); sa < s.end(ia.part); ++sa)
      for (SurfaceId sb = s.first(ib.part); sb < s.end(ib.part); ++sb)
        if (!settled(sa, sb)) ip.candidates.push_back({sa, sb});
    c.surface_pairs += ip.candidates.size();
    return;
  }
  const double tol_margin = search_reach(o, part_share[ia.part], part_share[ib.part], ip.roundoff);
  // The OAABB in A's frame, then its single update into B's frame.
  const Aabb oaabb = pad_box(s.part_box[ia.part], tol_margin)
                         .intersection(transform_box(pad_box(s.part_box[ib.part], tol_margin), ip.t_ab));
  ++c.aabb_updates;
  if (oaabb.isEmpty()) return;
  const Aabb oaabb_b = transform_box(oaabb, ip.t_ba);
  ++c.aabb_updates;
  std::vector<SurfaceId> surv_a, surv_b;
  for (SurfaceId sid = s.first(ia.part); sid < s.end(ia.part); ++sid) {
    ++c.aabb_tests;
    if (boxes_overlap(s.surface_box(sid), oaabb)) surv_a.push_back(sid);
  }
  for (SurfaceId sid = s.first(ib.part); sid < s.end(ib.part); ++sid) {
    ++c.aabb_tests;
    if (boxes_overlap(s.surface_box(sid), oaabb_b)) surv_b.push_back(sid);
  }
  c.surfaces_a += surv_a.size();
  c.surfaces_b += surv_b.size();
  // B's boxes in A's frame with their round-off pads, and each side's reach share, once per surface
  // rather than once per comparison.
  std::vector<Aabb> box_b(surv_b.size());
  std::vector<double> pad_b(surv_b.size()), share_b(surv_b.size());
  for (std::size_t k = 0; k < surv_b.size(); ++k) {
    box_b[k] = transform_box(s.surface_box(surv_b[k]), ip.t_ab);
    ++c.aabb_updates;
    pad_b[k] = kRelativePad * (1.0 + box_magnitude(box_b[k]));
    share_b[k] = s.reach_share(surv_b[k], o);
  }
  for (SurfaceId sa : surv_a) {
    const Aabb box_a = s.surface_box(sa);
    const double share_a = s.reach_share(sa, o);
    for (std::size_t k = 0; k < surv_b.size(); ++k) {
      const double m = search_reach(o, share_a, share_b[k], ip.roundoff);
      ++c.aabb_tests;
      if (boxes_within(box_a, box_b[k], m + pad_b[k]) && !settled(sa, surv_b[k])) ip.candidates.push_back({sa, surv_b[k]});
    }
  }
  c.surface_pairs += ip.candidates.size();
}

}  // namespace

void surface_level_stage(SceneData& s, QueryState& q) {
  const Model& model = s.model;
  const auto npairs = static_cast<std::ptrdiff_t>(q.pairs.size());
  ProgressMeter meter(q.progress, ProgressStage::CheckPairs, q.pairs.size(), "surface level");
  const bool team = worth_a_team(s, q.pairs);
  if (q.o.use_oaabb) s.refresh_reach_shares();  // done already unless check_part (no broad phase)
  const std::vector<double>& part_share = s.part_reach_shares(q.o);
  runtime_loop(npairs, q.threads, team, [&](std::ptrdiff_t k) {
    InstancePair& ip = q.pairs[static_cast<std::size_t>(k)];
    if (q.deadline.expired()) ip.cut = true;
    else surface_level(s, ip, q.o, part_share, q.only);
    meter.add();
  });
  meter.finish();
  q.charge.assign(q.pairs.size(), 0);
  q.first_task.assign(q.pairs.size() + 1, 0);
  s.first_need.start();
  for (std::uint32_t k = 0; k < q.pairs.size(); ++k) {
    const InstancePair& ip = q.pairs[k];
    q.first_task[k] = q.tasks.size();
    q.charge[k] += ip.candidates.size() * sizeof(ip.candidates[0]);
    auto need = [&](SurfaceId sid) {
      if (s.first_need[sid] != kInvalidId) return;
      s.first_need.set(sid, k);
      q.needed.push_back(sid);
    };
    for (const auto& c : ip.candidates) {
      q.tasks.push_back({k, c[0], c[1]});
      need(c[0]);
      need(c[1]);
    }
    if (ip.containment) {
      for (InstanceId i : {ip.a, ip.b}) {
        const PartId p = model.instances[i].part;
        for (SurfaceId sid = s.first(p); sid < s.end(p); ++sid) need(sid);
      }
    }
  }
  q.first_task[q.pairs.size()] = q.tasks.size();
  q.cutoff = static_cast<std::uint32_t>(q.pairs.size());
  q.apply_memory_budget();
}

}  // namespace cadclash::detail
