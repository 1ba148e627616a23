// Whole parts meshed where a replica's share needs them (distributed.h, "Whole parts meshed where
// they are needed"): owners, facts, and what a share meshes and releases.
#include "cadclash/distributed.h"

#include <algorithm>
#include <cassert>

namespace cadclash {

std::vector<PartId> parts_of_pairs(const Model& model, const CheckPlan& plan, std::span<const std::uint32_t> pairs) {
  std::vector<char> seen(model.parts.size(), 0);
  for (std::uint32_t k : pairs) {
    assert(k < plan.pairs.size());
    seen[model.instances[plan.pairs[k].a].part] = 1;
    seen[model.instances[plan.pairs[k].b].part] = 1;
  }
  std::vector<PartId> out;
  for (PartId p = 0; p < seen.size(); ++p)
    if (seen[p]) out.push_back(p);
  return out;
}

std::vector<int> mesh_owners(const Model& model, const CheckPlan& plan, int ranks, std::span<const int> home) {
  assert(ranks >= 1);
  assert(home.empty() || home.size() == model.parts.size());
  std::vector<int> owner(model.parts.size(), -1);
  std::vector<std::uint64_t> surfaces(static_cast<std::size_t>(ranks), 0);
  const std::vector<std::vector<std::uint32_t>> runs = split_by_cost(plan, ranks);
  for (int r = 0; r < ranks; ++r)
    for (PartId p : parts_of_pairs(model, plan, runs[static_cast<std::size_t>(r)]))
      if (owner[p] < 0) {
        owner[p] = r;
        surfaces[static_cast<std::size_t>(r)] += model.parts[p].surface_count;
      }
  for (PartId p = 0; p < owner.size(); ++p) {
    if (owner[p] >= 0) continue;
    if (!home.empty()) {
      assert(home[p] >= 0 && home[p] < ranks);
      owner[p] = home[p];
      continue;
    }
    const auto least = std::min_element(surfaces.begin(), surfaces.end());
    owner[p] = static_cast<int>(least - surfaces.begin());
    *least += model.parts[p].surface_count;
  }
  return owner;
}

std::vector<SurfaceFacts> surface_facts(const Model& model, std::span<const PartId> parts) {
  std::vector<SurfaceFacts> out;
  for (PartId p : parts) {
    const Part& part = model.parts[p];
    for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s) {
      const Surface& surf = model.surfaces[s];
      out.push_back({surf.aabb, surf.deflection, surf.has_triangles ? surf.mesh.triangles.size() : 0,
                     surf.has_triangles});
    }
  }
  return out;
}

void apply_surface_facts(Model& model, std::span<const PartId> parts, std::span<const SurfaceFacts> facts,
                         PartMeshing& pm) {
  assert(pm.facts.size() == model.surfaces.size());
  std::size_t i = 0;
  for (PartId p : parts) {
    const Part& part = model.parts[p];
    const bool here = p < pm.held.size() && pm.held[p];
    for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s, ++i) {
      assert(i < facts.size());
      pm.facts[s] = facts[i];
      pm.model_triangles += facts[i].triangles;
      if (here) continue;
      model.surfaces[s].aabb = facts[i].box;
      model.surfaces[s].deflection = facts[i].deflection;
    }
  }
}

void note_surface_facts(Scene& scene, const PartMeshing& pm) {
  for (SurfaceId s = 0; s < pm.facts.size(); ++s)
    if (pm.facts[s].has_triangles) scene.note_deflection(s, pm.facts[s].deflection, pm.facts[s].triangles);
}

bool share_parts(Model& model, const CheckPlan& plan, std::span<const std::uint32_t> pairs, PartMeshing& pm) {
  pm.held.resize(model.parts.size(), 0);
  pm.facts_only.resize(model.parts.size(), 0);
  const std::vector<PartId> needed = parts_of_pairs(model, plan, pairs);
  std::vector<PartId> missing;
  std::vector<char> is_needed(model.parts.size(), 0);
  for (PartId p : needed) {
    is_needed[p] = 1;
    pm.facts_only[p] = 0;
    if (!pm.held[p]) missing.push_back(p);
  }
  bool ok = true;
  if (!missing.empty()) {
    const std::uint64_t before = held_triangles(model);
    ok = pm.mesher.mesh(missing);
    for (PartId p : missing) pm.held[p] = 1;
    pm.meshed_triangles += held_triangles(model) - before;
  }
  // Meshed for their facts and reached by no share here: nothing of a query refers to them yet.
  std::vector<PartId> unused;
  for (PartId p = 0; p < model.parts.size(); ++p)
    if (pm.facts_only[p] && !is_needed[p]) unused.push_back(p);
  if (!unused.empty()) {
    pm.mesher.release(unused);
    for (PartId p : unused) pm.held[p] = pm.facts_only[p] = 0;
  }
  return ok;
}

std::uint64_t held_triangles(const Model& model) {
  std::uint64_t n = 0;
  for (const Surface& s : model.surfaces)
    if (s.has_triangles) n += s.mesh.triangles.size();
  return n;
}

}  // namespace cadclash
