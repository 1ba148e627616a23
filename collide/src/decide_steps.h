// The steps of the certified decision of one surface pair (stage_decide.cpp runs them over the open
// pairs, cheapest first): what each step proves about the exact faces, as bounds on their distance.
// Internal to cadclash::collide.
#pragma once

#include "decide.h"
#include "surface_bvh.h"

#include <array>
#include <optional>
#include <span>
#include <vector>

namespace cadclash::detail {

// Per surface: the outline of its triangles (boundary_edges), made for the surfaces that need it.
using Outlines = std::vector<std::vector<std::array<Vec3, 2>>>;

// Where one pair's decision stands between the steps.
struct Pending {
  Interval d;
  double threshold = 0.0;  // T
  double band = 0.0;       // δa + δb + r of the triangles the interval came from
  double mesh_band = 0.0;  // the same for the model's triangles: penetration is judged on them
  bool settled = false;
  bool dropped = false;    // settled apart and not reported
  std::optional<ContactClass> cls;
  DecidedBy by = DecidedBy::Mesh;
  std::optional<double> exact;  // BRepExtrema's value: realised by two points, so an upper bound only
  bool needs_lower = false;      // the exact value is above T: "apart" still needs a lower bound
  std::optional<PairOutcome> fine;  // the finer triangles' outcome, once refined
  bool cut = false;
};

// A face as one step sees it: the model's surface (or its finer copy), the tree over its triangles
// and, when made, the outline of its triangles (boundary_edges; null otherwise).
struct FaceView {
  const Surface& surface;
  const SurfaceBvh& bvh;
  const std::vector<std::array<Vec3, 2>>* outline = nullptr;
};

// Step 1: the interval of the model's triangles, settled when it decides (certified and exact modes).
Pending from_mesh(const Model& m, std::span<const double> eps, const DecideTask& t, const CollideOptions& o);

// Step 2: a plane, cylinder or sphere that the other face's triangles provably keep off (apart).
void analytic(const Model& m, std::span<const double> eps, const DecideTask& t, Pending& p, const CollideOptions& o);

// Step 2b: a vertex of one face on the other face's plane, cylinder or sphere, its foot point
// provably inside that face (analytic_witness): the faces are within εA + g + r (contact).
// Precondition: both views carry their outline.
void analytic_contact(std::span<const double> eps, const DecideTask& t, FaceView a, FaceView b, Pending& p,
                      const CollideOptions& o);

// Step 3: witness vertices (contact): vertices of each face near the other face's triangles, asked
// of the other exact face (SurfaceSource::point_distance), nearest first. `a`, `b` are the model's
// faces or finer ones (same part and index); `out` their outcome, `band` its band.
void witness_step(const Model& m, std::span<const double> eps, const DecideTask& t, FaceView a, FaceView b,
                  const PairOutcome* out, double band, Pending& p, const CollideOptions& o, CollideCounters& c);

// Step 3b: an edge witness (contact): where the faces' outlines come closest, a point on an edge of
// each (SurfaceSource::edge_distance) within T proves the faces meet edge to edge. Faces without an
// outline (closed ones) are skipped.
void edge_witness_step(const Model& m, std::span<const Pose> poses, const DecideTask& t, FaceView a, FaceView b,
                       Pending& p, const CollideOptions& o, CollideCounters& c);

// Step 4: the same interval on finer triangles of both faces.
void refined_step(const DecideTask& t, const std::vector<RefinedSurface>& cache, Pending& p, const CollideOptions& o,
                  CollideCounters& c);

// Step 5: the exact faces' distance (SurfaceSource::exact_distance). False when they have none.
bool exact_step(const Model& m, std::span<const Pose> poses, const DecideTask& t, Pending& p, const CollideOptions& o,
                CollideCounters& c);

// Step 6: an exact value above T corroborated (apart) or contradicted (contact) by finer triangles.
void corroborate(const Model& m, std::span<const double> eps, const DecideTask& t,
                 const std::vector<RefinedSurface>& cache, Pending& p, const CollideOptions& o, CollideCounters& c);

// Settles `p` when `v` decides, with the class it implies (penetrating only when `o` proves it).
void settle(Pending& p, Verdict v, DecidedBy by, const PairOutcome* o, double clearance);

// Adds one decided pair to the decided_* counter of `by`.
void count(CollideCounters& c, DecidedBy by);

// The reported result of a task with class `cls` (distance, penetration and triangle pairs from `out`).
SurfacePairResult make_result(const DecideTask& t, const PairOutcome* out, ContactClass cls);

// Fast mode: the band of the triangles alone, as before certification; nullopt when not reported.
std::optional<SurfacePairResult> fast(const Model& m, const DecideTask& t, const CollideOptions& o);

}  // namespace cadclash::detail
