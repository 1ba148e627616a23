// Refinement of ambiguous surface pairs: faces re-tessellated finer through their SurfaceSource
// (cached per surface by the Scene) and the triangle level run again on them. Internal to collide.
#pragma once

#include "cadclash/collide.h"
#include "narrow_phase.h"
#include "surface_bvh.h"

#include <array>
#include <compare>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

namespace cadclash::detail {

// A surface as one refinement level sees it: the model's surface with finer triangles, or the model's
// own when it cannot be refined (its triangles are exact, or it has no SurfaceSource).
struct RefinedSurface {
  bool attempted = false;
  bool ok = false;        // `surface` has triangles and `bvh` is built
  Surface surface;        // provenance etc. copied; mesh and deflection the finer ones
  SurfaceBvh bvh;
  Diagnostic error;       // why the source could not mesh it finer (when !ok)
};

// Parts of faces meshed finer for the pairs that reach them (refine_region), by surface and the
// region snapped to a grid of power-of-two cells, so pairs whose regions snap alike share one.
struct RegionKey {
  SurfaceId surface = kInvalidId;
  int scale = 0;                      // cells of 2^scale mm
  std::array<std::int64_t, 3> cell{}; // the region's lowest cell; it spans two cells per axis
  auto operator<=>(const RegionKey&) const = default;
};

// What refinement keeps for later pairs and queries: finer whole faces (one slot per surface) and
// finer parts of large faces. Regions are made by the pairs' threads; the map is guarded.
struct RefineCache {
  std::vector<RefinedSurface> surfaces;
  std::mutex region_mutex;
  std::map<RegionKey, std::shared_ptr<const RefinedSurface>> regions;
  std::vector<std::uint32_t> regions_made;  // per surface: regions meshed so far (a query's work: the change)
};

// Whether face `s` is refined only near the other face of a pair (`region`, part-local): a large
// face (thousands of triangles) of which the pair reaches a small part.
bool refines_by_region(const Surface& s, const Aabb& region);

// The part of face `s` inside `region` (part-local; snapped outward to the cache's grid) meshed at
// refinement_deflection(s) by its source (SurfaceSource::triangulate_region), made once per snapped
// region and kept in `cache` (counted in regions_made). Null when the source cannot mesh a region.
// Adds the seconds the meshing took to `seconds`. Deterministic: the result depends on the face and
// the snapped region only. Precondition: cache.regions_made.size() == model.surfaces.size().
std::shared_ptr<const RefinedSurface> refine_region(const Model& model, SurfaceId s, const Aabb& region,
                                                    RefineCache& cache, double& seconds);

// Refinement helps only where a band exists and a source can mesh finer.
bool can_refine(const Model& model, SurfaceId s);

// The deflection asked for: a tenth of the achieved one, so the band shrinks tenfold.
double refinement_deflection(const Surface& s);

// Fills cache[s] for every listed surface not attempted yet: surfaces that can be refined are meshed
// by their source at refinement_deflection, in parallel across parts (a source serialises its own
// part); the rest copy the model's triangles. Deterministic: each result depends on its surface only.
// Appends the surfaces it meshed to `meshed` (ascending), and adds to `seconds` (when given) the
// time each part's meshing took, summed over the threads. Precondition: cache.size() ==
// model.surfaces.size().
void refine_surfaces(const Model& model, std::span<const SurfaceId> surfaces, std::vector<RefinedSurface>& cache,
                     int threads, std::vector<SurfaceId>& meshed, double* seconds = nullptr);

// Surface `s` meshed at `deflection` by its source when it can be refined (not cached; for a pair
// that needs a finer level than the cache holds), else the model's own triangles.
RefinedSurface refine_to(const Model& model, SurfaceId s, double deflection);

// The triangle level of surfaces a (A's frame) and b (mapped by t_ab) searching up to `reach` (and
// `clearance`), early exit: intersecting, crossing depth past `reach`, or the minimum distance.
PairOutcome pair_outcome(const Surface& a, const SurfaceBvh& bvh_a, const Surface& b, const SurfaceBvh& bvh_b,
                         const Pose& t_ab, const Pose& t_ba, double reach, double clearance,
                         CollideCounters& counters);

}  // namespace cadclash::detail
