// Merging the parts of one query into the report one process gives (distributed.h, merge_parts).
#include "cadclash/distributed.h"
#include "cadclash/report.h"

#include <algorithm>
#include <cassert>
#include <map>
#include <tuple>

namespace cadclash {
namespace {

void add(CollideCounters& into, const CollideCounters& c) {
  for (const CounterField& f : kCounterFields) into.*f.member += c.*f.member;  // every member (report.h)
}

void add(SceneMemory& into, const SceneMemory& m) {
  into.triangles += m.triangles;
  into.vertices += m.vertices;
  into.hierarchies += m.hierarchies;
  into.instances += m.instances;
  into.triangle_count += m.triangle_count;
}

// The surfaces' work over all parts, one entry per surface (the first part's copy: every part
// computes the same triangles, hierarchy and diagnostic for a surface), flags or-ed.
std::map<SurfaceId, SurfaceWork> union_of(std::span<const PartialCheck> parts) {
  std::map<SurfaceId, SurfaceWork> all;
  for (const PartialCheck& p : parts)
    for (const SurfaceWork& w : p.surfaces) {
      auto [it, fresh] = all.emplace(w.surface, w);
      if (fresh) continue;
      SurfaceWork& u = it->second;
      u.asked = u.asked || w.asked;
      if (w.tessellated && !u.tessellated) {
        u.tessellated = true;
        u.deflection = w.deflection;
        u.mesh_bytes = w.mesh_bytes;
      }
      if (w.built && !u.built) {
        u.built = true;
        u.bvh_bytes = w.bvh_bytes;
        u.held = w.held;
      }
      u.refined = u.refined || w.refined;
      if (!u.error && w.error) u.error = w.error;
    }
  return all;
}

// Per-surface counters, charges and diagnostics, each surface once, then the history updated.
void merge_surfaces(const CheckPlan& plan, std::span<const PartialCheck> parts, const Model& model,
                    MergeHistory& h, MergedCheck& out) {
  Report& r = out.report;
  std::vector<std::uint32_t> first_need(model.surfaces.size(), static_cast<std::uint32_t>(plan.needed.size()));
  for (std::uint32_t i = 0; i < plan.needed.size(); ++i) first_need[plan.needed[i]] = i;
  const std::map<SurfaceId, SurfaceWork> all = union_of(parts);  // `failed` points into it
  std::vector<const SurfaceWork*> failed;
  for (const auto& [sid, w] : all) {
    if (w.asked && !h.tessellated[sid]) {
      ++r.counters.tessellated_surfaces;  // one process asks what has no triangles, failed before or not
      if (w.error) failed.push_back(&w);
    }
    if (w.tessellated && !h.tessellated[sid]) {
      r.memory_charged += w.mesh_bytes;
      out.new_deflections.emplace_back(sid, w.deflection);
      h.tessellated[sid] = 1;
    }
    if (w.built && !h.built[sid]) {
      r.memory_charged += w.bvh_bytes;
      add(h.held, w.held);
      h.built[sid] = 1;
    }
    if (w.refined && !h.refined[sid]) {
      ++r.counters.refined_surfaces;
      h.refined[sid] = 1;
    }
  }
  // require_triangles reports by part, then in the order it was given the surfaces: first need.
  std::sort(failed.begin(), failed.end(), [&](const SurfaceWork* x, const SurfaceWork* y) {
    return std::make_pair(model.surfaces[x->surface].part, first_need[x->surface]) <
           std::make_pair(model.surfaces[y->surface].part, first_need[y->surface]);
  });
  for (const SurfaceWork* w : failed) r.diagnostics.push_back(*w->error);
}

}  // namespace

MergeHistory::MergeHistory(std::size_t surface_count, const SceneMemory& start)
    : tessellated(surface_count, 0), built(surface_count, 0), refined(surface_count, 0), held(start) {
  held.instances = 0;
}

MergedCheck merge_parts(const CheckPlan& plan, std::span<const PartialCheck> parts, const Model& model,
                        MergeHistory& history) {
  assert(history.tessellated.size() == model.surfaces.size());
  MergedCheck out;
  Report& r = out.report;
  if (!plan.refused.empty()) {  // every part was refused alike
    r.diagnostics = plan.refused;
    r.complete = false;
    r.stopped_by = "out of range";
    return out;
  }
  r.counters = plan.broad;
  r.timings.broad = plan.seconds;
  bool time_cut = false;
  std::uint64_t instance_bytes = 0;
  for (const PartialCheck& p : parts) {
    const Report& pr = p.report;
    r.pairs.insert(r.pairs.end(), pr.pairs.begin(), pr.pairs.end());
    add(r.counters, pr.counters);
    r.memory_charged += pr.memory_charged;
    r.unexamined_pairs.insert(r.unexamined_pairs.end(), pr.unexamined_pairs.begin(), pr.unexamined_pairs.end());
    time_cut = time_cut || !pr.complete;
    instance_bytes = pr.model_memory.instances;  // the same on every replica
    r.timings.surface_level = std::max(r.timings.surface_level, pr.timings.surface_level);
    r.timings.tessellation = std::max(r.timings.tessellation, pr.timings.tessellation);
    r.timings.triangle_level = std::max(r.timings.triangle_level, pr.timings.triangle_level);
    r.timings.total = std::max(r.timings.total, plan.seconds + pr.timings.total);
    // The decision's steps: time summed over the pairs and threads, so over the ranks too.
    r.timings.decide_witness += pr.timings.decide_witness;
    r.timings.decide_depth += pr.timings.decide_depth;
    r.timings.decide_refine += pr.timings.decide_refine;
    r.timings.decide_hull += pr.timings.decide_hull;
    r.timings.decide_exact += pr.timings.decide_exact;
  }
  merge_surfaces(plan, parts, model, history, out);
  r.model_memory = history.held;
  r.model_memory.instances = instance_bytes;
  std::sort(r.pairs.begin(), r.pairs.end(), [](const SurfacePairResult& x, const SurfacePairResult& y) {
    return std::tie(x.instance_a, x.instance_b, x.surface_a, x.surface_b) <
           std::tie(y.instance_a, y.instance_b, y.surface_a, y.surface_b);
  });
  std::sort(r.unexamined_pairs.begin(), r.unexamined_pairs.end());
  r.complete = !time_cut;
  if (time_cut) r.stopped_by = "time budget";  // parts have no memory budget
  return out;
}

}  // namespace cadclash
