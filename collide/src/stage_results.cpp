// Stage 7: the kept prefix of instance pairs — its results, counters and charge; the rest listed as
// unexamined — and what was built only for pairs past the memory budget given back.
#include "scene_stages.h"

#include <algorithm>
#include <tuple>

namespace cadclash::detail {
namespace {

// Leaves the model and the scene as if the query had stopped at the cutoff.
void release_past_cutoff(SceneData& s, const QueryState& q) {
  // The trees first: what they held is counted off from their meshes.
  for (SurfaceId sid : q.built) {
    if (s.first_need[sid] < q.cutoff) continue;
    s.hold(sid, -1);
    s.bvh[sid] = SurfaceBvh{};
    s.bvh_ready[sid] = 0;
    if (sid < s.outlines.ready.size() && s.outlines.ready[sid]) {
      s.outlines.outline[sid] = Outline{};
      s.outlines.ready[sid] = 0;
    }
  }
  std::vector<SurfaceId> released;
  for (std::size_t i = 0; i < q.tessellated.size(); ++i) {
    if (s.first_need[q.tessellated[i]] < q.cutoff) continue;
    Surface& surf = s.model.surfaces[q.tessellated[i]];
    surf.mesh = TriangleMesh{};
    surf.has_triangles = false;
    surf.deflection = q.old_deflection[i];
    released.push_back(q.tessellated[i]);
  }
  if (released.empty()) return;
  const std::uint64_t revision = s.model.revision++;
  s.surfaces_changed(revision, released);
}

// The ε each side's decision used, and whether the contact needs it (ContactWithin).
void note_uncertainty(const SceneData& s, const CollideOptions& o, SurfacePairResult& p) {
  if (p.contact == ContactClass::Containment) return;
  p.uncertainty_a = s.eps[p.surface_a];
  p.uncertainty_b = s.eps[p.surface_b];
  if (o.decision == DecisionMode::Fast) return;
  if (p.contact == ContactClass::Penetrating || (p.contact == ContactClass::Touching && p.distance_hi <= o.tolerance))
    p.within = ContactWithin::Tolerance;
  else if (p.contact == ContactClass::Touching && p.distance_lo > o.tolerance)
    p.within = ContactWithin::ModelUncertainty;
}

}  // namespace

void results_stage(SceneData& s, QueryState& q) {
  Report& report = q.report;
  CollideCounters& total = report.counters;
  report.pairs.reserve(report.pairs.size() + q.results.size());
  for (std::size_t i = 0; i < q.results.size(); ++i)
    if (q.result_pair[i] < q.cutoff) note_uncertainty(s, q.o, report.pairs.emplace_back(std::move(q.results[i])));
  for (std::uint32_t k = 0; k < q.pairs.size(); ++k) {
    if (k >= q.cutoff || q.pair_cut[k]) report.unexamined_pairs.push_back({q.pairs[k].a, q.pairs[k].b});
    if (k >= q.cutoff) continue;
    add(total, q.pairs[k].counters);
    report.memory_charged += q.charge[k];
    for (std::size_t t = q.first_task[k]; t < q.first_task[k + 1]; ++t) {
      if (q.task_cut[t]) continue;
      add(total, q.task_counters[t]);
      if (q.outcomes[t].intersecting) ++total.intersecting_pairs;
    }
  }
  for (SurfaceId sid : q.asked) total.tessellated_surfaces += s.first_need[sid] < q.cutoff;
  const bool memory_cut = q.cutoff < q.pairs.size();
  const bool time_cut =
      std::any_of(q.pair_cut.begin(), q.pair_cut.begin() + q.cutoff, [](char c) { return c != 0; });
  report.complete = !memory_cut && !time_cut;
  if (memory_cut && time_cut) report.stopped_by = "time and memory budget";
  else if (memory_cut) report.stopped_by = "memory budget";
  else if (time_cut) report.stopped_by = "time budget";
  std::sort(report.unexamined_pairs.begin(), report.unexamined_pairs.end());
  if (memory_cut) release_past_cutoff(s, q);
  // The keys are distinct (one result per surface pair, one containment result per instance pair), so
  // the order is the same whether or not the pairs came in it already (they mostly do: the decisions
  // come in task order, which is pair order).
  auto before = [](const SurfacePairResult& x, const SurfacePairResult& y) {
    return std::tie(x.instance_a, x.instance_b, x.surface_a, x.surface_b) <
           std::tie(y.instance_a, y.instance_b, y.surface_a, y.surface_b);
  };
  if (!std::is_sorted(report.pairs.begin(), report.pairs.end(), before))
    std::sort(report.pairs.begin(), report.pairs.end(), before);
}

}  // namespace cadclash::detail
