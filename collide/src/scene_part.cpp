// One check split over processes (collide.h, "One check split over processes"): the plan every
// process computes, the part one process checks, and what it did per surface for the merge.
#include "scene_stages.h"

#include <omp.h>

#include <cassert>
#include <map>

namespace cadclash {
namespace {

std::uint64_t triangles_of(const detail::SceneData& s, SurfaceId sid) {
  const Surface& surf = s.model.surfaces[sid];
  if (surf.has_triangles) return surf.mesh.triangles.size();
  return s.noted_deflection[sid] >= 0.0 ? s.noted_triangles[sid] : kUntessellatedCost;
}

// Each pair's estimated cost (PlannedPair::cost) from its candidate surface pairs.
std::vector<PlannedPair> costed_pairs(const detail::SceneData& s, const detail::QueryState& q) {
  std::vector<PlannedPair> out(q.pairs.size());
  for (std::size_t k = 0; k < q.pairs.size(); ++k) {
    const detail::InstancePair& ip = q.pairs[k];
    PlannedPair& p = out[k];
    p.a = ip.a;
    p.b = ip.b;
    for (std::size_t t = q.first_task[k]; t < q.first_task[k + 1]; ++t)
      p.cost += triangles_of(s, q.tasks[t].sa) + triangles_of(s, q.tasks[t].sb);
    if (ip.containment)
      for (InstanceId i : {ip.a, ip.b}) {
        const PartId part = s.model.instances[i].part;
        for (SurfaceId sid = s.first(part); sid < s.end(part); ++sid) p.cost += triangles_of(s, sid);
      }
  }
  return out;
}

// What the query did per surface (SurfaceWork), and its surfaces' bytes taken out of the charge.
std::vector<SurfaceWork> surface_work(const detail::SceneData& s, detail::QueryState& q) {
  const Model& model = s.model;
  std::map<SurfaceId, SurfaceWork> work;
  auto at = [&](SurfaceId sid) -> SurfaceWork& {
    SurfaceWork& w = work[sid];
    w.surface = sid;
    return w;
  };
  for (SurfaceId sid : q.asked) at(sid).asked = true;
  for (SurfaceId sid : q.tessellated) {
    SurfaceWork& w = at(sid);
    w.tessellated = true;
    w.deflection = model.surfaces[sid].deflection;
    w.mesh_bytes = detail::mesh_bytes(model.surfaces[sid].mesh);
  }
  for (SurfaceId sid : q.built) {
    SurfaceWork& w = at(sid);
    const TriangleMesh& mesh = model.surfaces[sid].mesh;
    w.built = true;
    w.bvh_bytes = detail::bvh_heap_bytes(s.bvh[sid]);
    w.held.triangles = mesh.triangles.size() * sizeof(mesh.triangles[0]);
    w.held.vertices = mesh.vertices.size() * sizeof(mesh.vertices[0]);
    w.held.hierarchies = w.bvh_bytes;
    w.held.triangle_count = mesh.triangles.size();
  }
  assert(q.failed.size() == q.report.diagnostics.size());
  for (std::size_t i = 0; i < q.failed.size(); ++i) at(q.failed[i]).error = q.report.diagnostics[i];
  // A face counts when its source meshed it, or a part of it, finer than its triangles. The
  // decisions refine only their tasks' faces, all of them in `needed`.
  assert(q.refined_before.size() == q.needed.size() && q.regions_before.size() == q.needed.size());
  for (std::size_t i = 0; i < q.needed.size(); ++i) {
    const SurfaceId sid = q.needed[i];
    if ((!q.refined_before[i] && s.refined.surfaces[sid].attempted &&
         s.refined.surfaces[sid].surface.deflection < model.surfaces[sid].deflection) ||
        s.refined.regions_made[sid] > q.regions_before[i])
      at(sid).refined = true;
  }
  std::vector<SurfaceWork> out;
  out.reserve(work.size());
  for (auto& [sid, w] : work) {
    q.report.memory_charged -= w.mesh_bytes + w.bvh_bytes;
    out.push_back(std::move(w));
  }
  return out;
}

}  // namespace

CheckPlan Scene::plan(const CollideOptions& options) {
  detail::SceneData& s = *impl_;
  CollideOptions o = options;  // the plan is boxes only: no budget cuts it
  o.time_budget_seconds = 0.0;
  o.memory_budget_bytes = 0;
  detail::QueryState q(o, std::chrono::steady_clock::now());
  q.threads = o.threads > 0 ? o.threads : omp_get_max_threads();
  CheckPlan plan;
  plan.refused = detail::range_errors(s, o);
  if (!plan.refused.empty()) return plan;
  detail::set_schedule(o.schedule);
  detail::broad_phase_stage(s, q);
  detail::surface_level_stage(s, q);
  plan.broad = q.report.counters;
  plan.broad.instance_pairs = 0;  // each part counts its own
  plan.pairs = costed_pairs(s, q);
  plan.needed = std::move(q.needed);
  plan.seconds = detail::seconds_since(q.t0);
  return plan;
}

PartialCheck Scene::check_part(const CollideOptions& o, const CheckPlan& plan, std::span<const std::uint32_t> part) {
  assert(o.tolerance >= 0.0 && o.clearance >= 0.0 && o.time_budget_seconds >= 0.0);
  assert(o.memory_budget_bytes == 0);
  detail::SceneData& s = *impl_;
  detail::QueryState q(o, std::chrono::steady_clock::now());
  if (!plan.refused.empty()) {
    PartialCheck out;
    detail::refuse(out.report, {});
    return out;
  }
  q.threads = o.threads > 0 ? o.threads : omp_get_max_threads();
  detail::set_schedule(o.schedule);
  q.pairs.resize(part.size());
  for (std::size_t i = 0; i < part.size(); ++i) {
    assert(part[i] < plan.pairs.size() && (i == 0 || part[i - 1] < part[i]));
    q.pairs[i].a = plan.pairs[part[i]].a;
    q.pairs[i].b = plan.pairs[part[i]].b;
  }
  q.report.counters.instance_pairs = part.size();
  q.note_refined = true;
  detail::narrow_stages(s, q);
  PartialCheck out;
  out.surfaces = surface_work(s, q);
  q.report.counters.tessellated_surfaces = 0;
  q.report.counters.refined_surfaces = 0;
  q.report.diagnostics.clear();
  out.report = std::move(q.report);
  return out;
}

void Scene::note_deflection(SurfaceId s, double deflection, std::uint64_t triangles) {
  assert(s < impl_->noted_deflection.size());
  impl_->noted_deflection[s] = deflection;
  impl_->noted_triangles[s] = triangles;
  impl_->surfaces_changed(impl_->model.revision, std::span<const SurfaceId>(&s, 1));
}

}  // namespace cadclash
