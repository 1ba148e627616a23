#include "refine.h"

#include "team_loop.h"

#include <chrono>
#include <map>

namespace cadclash::detail {

bool can_refine(const Model& model, SurfaceId s) {
  const Surface& surf = model.surfaces[s];
  return !surf.exact_triangles && surf.deflection > 0.0 && model.parts[surf.part].source != nullptr;
}

double refinement_deflection(const Surface& s) { return 0.1 * s.deflection; }

std::size_t refine_surfaces(const Model& model, std::span<const SurfaceId> surfaces,
                            std::vector<RefinedSurface>& cache, int threads, double* seconds) {
  std::map<PartId, std::vector<SurfaceId>> by_part;  // a source is thread-safe across parts only
  for (SurfaceId s : surfaces) {
    if (cache[s].attempted) continue;
    cache[s].attempted = true;
    by_part[model.surfaces[s].part].push_back(s);
  }
  std::vector<std::vector<SurfaceId>> work;
  for (auto& [part, ids] : by_part) work.push_back(std::move(ids));
  std::vector<std::size_t> meshed(work.size(), 0);
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
          ++meshed[static_cast<std::size_t>(w)];
        }
      }
      if (r.surface.mesh.triangles.empty() && surf.has_triangles) r.surface.mesh = surf.mesh;  // not finer
      r.ok = !r.surface.mesh.triangles.empty();
      if (r.ok) r.bvh = build_surface_bvh(r.surface.mesh);
    }
    took[static_cast<std::size_t>(w)] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  });
  std::size_t total = 0;
  for (std::size_t m : meshed) total += m;
  if (seconds != nullptr)
    for (double t : took) *seconds += t;
  return total;
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
