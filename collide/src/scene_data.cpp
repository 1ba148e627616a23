#include "scene_data.h"

#include "cadclash/geometry.h"
#include "decide.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace cadclash::detail {
namespace {

bool under(const std::string& path, const std::string& prefix) {
  if (prefix.empty() || path.size() < prefix.size() || path.compare(0, prefix.size(), prefix) != 0) return false;
  return path.size() == prefix.size() || path[prefix.size()] == '/' || prefix.back() == '/';
}

}  // namespace

SceneData::SceneData(Model& m, SceneSelection sel) : model(m), selection(std::move(sel)) {
  const std::size_t n = model.instances.size();
  poses.resize(n);
  world_box.resize(n);
  dirty.assign(n, 1);
  dirty_list.resize(n);
  for (InstanceId i = 0; i < n; ++i) {
    dirty_list[i] = i;
    assert(model.instances[i].part < model.parts.size());
    poses[i] = model.instances[i].pose;
    by_path.emplace(model.instances[i].path, i);
  }
  part_box.resize(model.parts.size());
  part_norm.resize(model.parts.size());
  for (PartId p = 0; p < model.parts.size(); ++p) {
    for (SurfaceId s = first(p); s < end(p); ++s) part_box[p].extend(surface_box(s));
    part_norm[p] = box_norm(part_box[p]);
  }
  part_length.assign(model.parts.size(), 0.0);
  for (PartId p = 0; p < model.parts.size(); ++p) {
    double& length = part_length[p];
    auto take = [&length](double x) { length = in_supported_range(x) ? std::max(length, std::abs(x)) : HUGE_VAL; };
    if (!part_box[p].isEmpty())
      for (int k = 0; k < 3; ++k) take(part_box[p].min()[k]), take(part_box[p].max()[k]);
    for (SurfaceId s = first(p); s < end(p); ++s) take(model.surfaces[s].deflection), take(model.surfaces[s].uncertainty), take(model.surfaces[s].tolerance);
  }
  eps.resize(model.surfaces.size());
  slack.resize(model.surfaces.size());
  for (SurfaceId s = 0; s < model.surfaces.size(); ++s) {
    eps[s] = effective_uncertainty(model.surfaces[s], part_norm[model.surfaces[s].part]);
    slack[s] = face_slack(model.surfaces[s], eps[s]);
  }
  bvh.resize(model.surfaces.size());
  bvh_ready.assign(model.surfaces.size(), 0);
  refined.surfaces.resize(model.surfaces.size());
  refined.regions_made.resize(model.surfaces.size(), 0);
  noted_deflection.assign(model.surfaces.size(), -1.0);
  noted_triangles.assign(model.surfaces.size(), kUntessellatedCost);
  first_need.resize(model.surfaces.size());
  in_a.assign(n, selection.set_a.empty() ? 1 : 0);
  in_b.assign(n, selection.set_b.empty() ? 1 : 0);
  for (InstanceId i : selection.set_a) {
    assert(i < n);
    in_a[i] = 1;
  }
  for (InstanceId i : selection.set_b) {
    assert(i < n);
    in_b[i] = 1;
  }
  for (const auto& [pa, pb] : selection.excluded_pairs) {
    const auto ia = by_path.find(pa), ib = by_path.find(pb);
    if (ia == by_path.end() || ib == by_path.end()) continue;
    excluded.emplace(std::min(ia->second, ib->second), std::max(ia->second, ib->second));
  }
}

Aabb SceneData::surface_box(SurfaceId s) const {
  const Surface& surf = model.surfaces[s];
  if (!surf.aabb.isEmpty()) return surf.aabb;
  return mesh_aabb(surf.mesh);
}

double SceneData::deflection(SurfaceId s) const {
  const Surface& surf = model.surfaces[s];
  if (surf.has_triangles) return surf.deflection;
  if (noted_deflection[s] >= 0.0) return noted_deflection[s];  // tessellated by another process
  // Not tessellated yet (lazy): it will be meshed at its source's load deflection.
  const SurfaceSource* source = model.parts[surf.part].source.get();
  return std::max(surf.deflection, source != nullptr ? source->default_deflection() : 0.0);
}

double SceneData::reach_share(SurfaceId s, const CollideOptions& o) const {
  return deflection(s) + (o.decision == DecisionMode::Fast ? 0.0 : eps[s]);
}

void SceneData::work_out_shares(PartId p) {
  CollideOptions fast, certified;
  fast.decision = DecisionMode::Fast;
  certified.decision = DecisionMode::Certified;
  double d[2] = {0.0, 0.0};
  for (SurfaceId s = first(p); s < end(p); ++s) {
    d[0] = std::max(d[0], reach_share(s, fast));
    d[1] = std::max(d[1], reach_share(s, certified));
  }
  shares.part[0][p] = d[0];
  shares.part[1][p] = d[1];
}

void SceneData::refresh_reach_shares() {
  ReachShares& r = shares;
  const bool all = !r.valid || r.revision != model.revision;
  if (!all && r.dirty.empty()) return;
  if (all) {
    for (auto& v : r.part) v.assign(model.parts.size(), 0.0);
    for (PartId p = 0; p < model.parts.size(); ++p) work_out_shares(p);
  } else {
    for (PartId p : r.dirty) work_out_shares(p);
  }
  for (PartId p : r.dirty) r.is_dirty[p] = 0;
  r.dirty.clear();
  for (int k = 0; k < 2; ++k)
    r.largest[k] = r.part[k].empty() ? 0.0 : *std::max_element(r.part[k].begin(), r.part[k].end());
  r.revision = model.revision;
  r.valid = true;
}

void SceneData::surfaces_changed(std::uint64_t revision_before, std::span<const SurfaceId> changed) {
  ReachShares& r = shares;
  // Only this scene's change since the shares were worked out: the parts it touched will do.
  if (r.valid && r.revision == revision_before) r.revision = model.revision;
  if (r.is_dirty.size() != model.parts.size()) r.is_dirty.assign(model.parts.size(), 0);
  for (SurfaceId s : changed) {
    const PartId p = model.surfaces[s].part;
    if (!r.is_dirty[p]) r.dirty.push_back(p);
    r.is_dirty[p] = 1;
  }
}

void SceneData::hold(SurfaceId s, int sign) {
  const TriangleMesh& mesh = model.surfaces[s].mesh;
  const auto add = [sign](std::uint64_t& into, std::uint64_t v) { into = sign > 0 ? into + v : into - v; };
  add(held.triangles, mesh.triangles.size() * sizeof(mesh.triangles[0]));
  add(held.vertices, mesh.vertices.size() * sizeof(mesh.vertices[0]));
  add(held.hierarchies, bvh_heap_bytes(bvh[s]));
  add(held.triangle_count, mesh.triangles.size());
}

bool SceneData::selected(InstanceId i, InstanceId j) const {
  if (!((in_a[i] && in_b[j]) || (in_a[j] && in_b[i]))) return false;
  if (excluded.count({std::min(i, j), std::max(i, j)})) return false;
  for (const std::string& prefix : selection.excluded_subassemblies)
    if (under(model.instances[i].path, prefix) && under(model.instances[j].path, prefix)) return false;
  return true;
}

QueryState::QueryState(const CollideOptions& options, std::chrono::steady_clock::time_point start)
    : o(options), t0(start), deadline(start, options.time_budget_seconds) {}

void QueryState::apply_memory_budget() {
  const std::uint64_t budget = o.memory_budget_bytes;
  if (budget == 0) return;
  std::uint64_t sum = 0;
  for (std::uint32_t k = 0; k < cutoff; ++k) {
    sum += charge[k];
    if (sum > budget) {
      cutoff = k;
      return;
    }
  }
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void add(CollideCounters& into, const CollideCounters& c) {
  into.instance_pairs += c.instance_pairs;
  into.aabb_tests += c.aabb_tests;
  into.aabb_updates += c.aabb_updates;
  into.surfaces_a += c.surfaces_a;
  into.surfaces_b += c.surfaces_b;
  into.surface_pairs += c.surface_pairs;
  into.triangles_a += c.triangles_a;
  into.triangles_b += c.triangles_b;
  into.triangle_tests += c.triangle_tests;
  into.exact_fallbacks += c.exact_fallbacks;
  into.distance_tests += c.distance_tests;
  into.intersecting_pairs += c.intersecting_pairs;
  into.tessellated_surfaces += c.tessellated_surfaces;
  into.decided_mesh += c.decided_mesh;
  into.decided_mesh_exact += c.decided_mesh_exact;
  into.decided_analytic += c.decided_analytic;
  into.decided_refined += c.decided_refined;
  into.decided_exact += c.decided_exact;
  into.undecided += c.undecided;
  into.ambiguous_pairs += c.ambiguous_pairs;
  into.refined_surfaces += c.refined_surfaces;
  into.exact_queries += c.exact_queries;
  into.witness_queries += c.witness_queries;
  into.dismissed_pairs += c.dismissed_pairs;
}

}  // namespace cadclash::detail
