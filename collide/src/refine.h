// Refinement of ambiguous surface pairs: faces re-tessellated finer through their SurfaceSource
// (cached per surface by the Scene) and the triangle level run again on them. Internal to collide.
#pragma once

#include "cadclash/collide.h"
#include "narrow_phase.h"
#include "surface_bvh.h"

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

// Refinement helps only where a band exists and a source can mesh finer.
bool can_refine(const Model& model, SurfaceId s);

// The deflection asked for: a tenth of the achieved one, so the band shrinks tenfold.
double refinement_deflection(const Surface& s);

// Fills cache[s] for every listed surface not attempted yet: surfaces that can be refined are meshed
// by their source at refinement_deflection, in parallel across parts (a source serialises its own
// part); the rest copy the model's triangles. Deterministic: each result depends on its surface only.
// Returns the number of surfaces meshed, and adds to `seconds` (when given) the time each part's
// meshing took, summed over the threads. Precondition: cache.size() == model.surfaces.size().
std::size_t refine_surfaces(const Model& model, std::span<const SurfaceId> surfaces,
                            std::vector<RefinedSurface>& cache, int threads, double* seconds = nullptr);

// Surface `s` meshed at `deflection` by its source when it can be refined (not cached; for a pair
// that needs a finer level than the cache holds), else the model's own triangles.
RefinedSurface refine_to(const Model& model, SurfaceId s, double deflection);

// The triangle level of surfaces a (A's frame) and b (mapped by t_ab) searching up to `reach` (and
// `clearance`), early exit: intersecting, crossing depth past `reach`, or the minimum distance.
PairOutcome pair_outcome(const Surface& a, const SurfaceBvh& bvh_a, const Surface& b, const SurfaceBvh& bvh_b,
                         const Pose& t_ab, const Pose& t_ba, double reach, double clearance,
                         CollideCounters& counters);

}  // namespace cadclash::detail
