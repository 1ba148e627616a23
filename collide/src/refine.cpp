#include "refine.h"

#include "team_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

namespace cadclash::detail {

bool can_refine(const Model& model, SurfaceId s) {
  const Surface& surf = model.surfaces[s];
  return !surf.exact_triangles && surf.deflection > 0.0 && model.parts[surf.part].source != nullptr;
}

double refinement_deflection(const Surface& s) { return 0.1 * s.deflection; }

void refine_surfaces(const Model& model, std::span<const SurfaceId> surfaces, std::vector<RefinedSurface>& cache,
                     int threads, std::vector<SurfaceId>& meshed_ids, double* seconds) {
  std::map<PartId, std::vector<SurfaceId>> by_part;  // a source is thread-safe across parts only
  for (SurfaceId s : surfaces) {
    if (cache[s].attempted) continue;
    cache[s].attempted = true;
    by_part[model.surfaces[s].part].push_back(s);
  }
  std::vector<std::vector<SurfaceId>> work;
  for (auto& [part, ids] : by_part) work.push_back(std::move(ids));
  std::vector<std::vector<SurfaceId>> meshed(work.size());
  std::vector<double> took(work.size(), 0.0);
  const auto n = static_cast<std::ptrdiff_t>(work.size());
  dynamic_loop(n, threads, true, [&](std::ptrdiff_t w) {
    const auto start = std::chrono::steady_clock::now();
    for (SurfaceId s : work[static_cast<std::size_t>(w)]) {
      const Surface& surf = model.surfaces[s];
      RefinedSurface& r = cache[s];
      r.surface = surf;
      r.surface.mesh = TriangleMesh{};
      if (can_refine(model, s)) {
        const Part& part = model.parts[surf.part];
        TriangleMesh mesh;
        double achieved = 0.0;
        if (part.source->triangulate(s - part.first_surface, refinement_deflection(surf), mesh, achieved, r.error) &&
            achieved < surf.deflection) {
          r.surface.mesh = std::move(mesh);
          r.surface.deflection = achieved;
          r.surface.has_triangles = true;
          meshed[static_cast<std::size_t>(w)].push_back(s);
        }
      }
      if (r.surface.mesh.triangles.empty() && surf.has_triangles) r.surface.mesh = surf.mesh;  // not finer
      r.ok = !r.surface.mesh.triangles.empty();
      if (r.ok) r.bvh = build_surface_bvh(r.surface.mesh);
    }
    took[static_cast<std::size_t>(w)] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  });
  const std::size_t before = meshed_ids.size();
  for (const auto& ids : meshed) meshed_ids.insert(meshed_ids.end(), ids.begin(), ids.end());
  std::sort(meshed_ids.begin() + static_cast<std::ptrdiff_t>(before), meshed_ids.end());
  if (seconds != nullptr)
    for (double t : took) *seconds += t;
}

namespace {

// Faces with fewer triangles are refined whole (one mesh for every pair that needs them); larger
// ones only near a pair whose region is a small part of them.
constexpr std::size_t kRegionMinTriangles = 2000;
constexpr double kRegionMaxShare = 0.25;  // of the face box's diagonal

// `region` snapped outward: the cells of side 2^scale (the smallest power of two at least the
// region's largest extent) from the one holding its lower corner, two per axis.
RegionKey snap(SurfaceId s, const Aabb& region, Aabb& snapped) {
  RegionKey key;
  key.surface = s;
  const double extent = std::max(region.sizes().maxCoeff(), 1e-9);
  int e = 0;
  std::frexp(extent, &e);  // extent < 2^e
  key.scale = e;
  const double side = std::ldexp(1.0, e);
  Vec3 lo, hi;
  for (int k = 0; k < 3; ++k) {
    const double c = std::floor(region.min()[k] / side);
    key.cell[static_cast<std::size_t>(k)] = static_cast<std::int64_t>(c);
    lo[k] = c * side;
    hi[k] = (c + 2.0) * side;
  }
  snapped = Aabb(lo, hi);
  return key;
}

}  // namespace

bool refines_by_region(const Surface& s, const Aabb& region) {
  if (s.mesh.triangles.size() < kRegionMinTriangles || region.isEmpty() || s.aabb.isEmpty()) return false;
  return region.diagonal().norm() <= kRegionMaxShare * s.aabb.diagonal().norm();
}

std::shared_ptr<const RefinedSurface> refine_region(const Model& model, SurfaceId s, const Aabb& region,
                                                    RefineCache& cache, double& seconds) {
  Aabb snapped;
  const RegionKey key = snap(s, region, snapped);
  {
    std::lock_guard<std::mutex> lock(cache.region_mutex);
    if (auto it = cache.regions.find(key); it != cache.regions.end()) return it->second;
  }
  // Made outside the lock (two threads may make the same region at once: the same triangles, the
  // first kept).
  const auto start = std::chrono::steady_clock::now();
  const Surface& surf = model.surfaces[s];
  auto r = std::make_shared<RefinedSurface>();
  r->attempted = true;
  r->surface = surf;
  r->surface.mesh = TriangleMesh{};
  const Part& part = model.parts[surf.part];
  double achieved = 0.0;
  std::shared_ptr<const RefinedSurface> made;
  if (can_refine(model, s) &&
      part.source->triangulate_region(s - part.first_surface, refinement_deflection(surf), snapped, r->surface.mesh,
                                      achieved, r->error) &&
      achieved < surf.deflection) {
    r->surface.deflection = achieved;
    r->surface.has_triangles = !r->surface.mesh.triangles.empty();
    r->ok = true;  // no triangles: the face does not reach the region
    if (r->surface.has_triangles) r->bvh = build_surface_bvh(r->surface.mesh);
    made = std::move(r);
  }
  seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::lock_guard<std::mutex> lock(cache.region_mutex);
  const auto [it, inserted] = cache.regions.emplace(key, made);
  if (inserted && made) ++cache.regions_made[s];
  return it->second;
}

RefinedSurface refine_to(const Model& model, SurfaceId s, double deflection) {
  const Surface& surf = model.surfaces[s];
  RefinedSurface r;
  r.attempted = true;
  r.surface = surf;
  if (can_refine(model, s) && deflection < surf.deflection) {
    const Part& part = model.parts[surf.part];
    TriangleMesh mesh;
    double achieved = 0.0;
    if (part.source->triangulate(s - part.first_surface, deflection, mesh, achieved, r.error) &&
        achieved < surf.deflection) {
      r.surface.mesh = std::move(mesh);
      r.surface.deflection = achieved;
    }
  }
  r.ok = !r.surface.mesh.triangles.empty();
  if (r.ok) r.bvh = build_surface_bvh(r.surface.mesh);
  return r;
}

PairOutcome pair_outcome(const Surface& a, const SurfaceBvh& bvh_a, const Surface& b, const SurfaceBvh& bvh_b,
                         const Pose& t_ab, const Pose& t_ba, double reach, double clearance,
                         CollideCounters& counters) {
  CollideOptions o;
  o.clearance = clearance;
  o.mode = CollideMode::EarlyExit;
  PreparedPair p;
  prepare_pair_reach(a, bvh_a, b, bvh_b, t_ab, t_ba, o, reach, p, counters);
  PairOutcome out;
  run_pair(a, p, 0, p.la.size(), o, out, counters);
  return out;
}

}  // namespace cadclash::detail
