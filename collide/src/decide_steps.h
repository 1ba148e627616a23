// The steps of the certified decision of one surface pair (stage_decide.cpp runs them over the open
// pairs, cheapest first): what each step proves about the exact faces, as bounds on their distance.
// Internal to cadclash::collide.
#pragma once

#include "decide.h"
#include "cadclash/geometry.h"
#include "surface_bvh.h"

#include <algorithm>
#include <array>
#include <limits>
#include <optional>
#include <span>
#include <vector>

namespace cadclash::detail {

// In the steps below, `slack` is each face's face_slack (decide.h): how far the points a step takes
// as the face's (its triangles' vertices, points of its analytic surface) may lie off the exact face.
// The contact threshold T = tolerance + εa + εb, with the surfaces' uncertainties `eps`, is
// Pending::threshold, set by from_mesh.

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
  double depth = 0.0;  // a crossing depth depth_step proved on the exact faces (0: none)
};

// A face as one step sees it: the model's surface (or its finer copy), the tree over its triangles
// and, when made, the outline of its triangles (boundary_edges; null otherwise).
struct FaceView {
  const Surface& surface;
  const SurfaceBvh& bvh;
  const Outline* outline = nullptr;
};

// A box enclosing the exact face: Surface::aabb does for B-rep faces, but for a mesh it encloses the
// triangles, which may lie up to the deflection inside the surface they stand for.
inline Aabb own_box(const Surface& s) { return pad_box(s.aabb.isEmpty() ? mesh_aabb(s.mesh) : s.aabb, s.deflection); }

// Step 1: the interval of the model's triangles, settled when it decides (certified and exact modes).
Pending from_mesh(const Model& m, std::span<const double> eps, const DecideTask& t, const CollideOptions& o);

// Step 2: a plane, cylinder or sphere that the other face's triangles provably keep off (apart).
void analytic(const Model& m, std::span<const double> slack, const DecideTask& t, Pending& p, const CollideOptions& o);

// Step 2b: a vertex of one face on the other face's plane, cylinder or sphere, its foot point
// provably inside that face (analytic_witness): the faces are within εA + g + r (contact).
// Precondition: both views carry their outline.
void analytic_contact(std::span<const double> slack, const DecideTask& t, FaceView a, FaceView b, Pending& p,
                      const CollideOptions& o);

// True when `x`, a point of face `f`'s exact surface (its part frame), lies inside the face by its
// triangles: within the face's deflection of them and clear of their outline by twice that (plus
// `slack` each). `on_triangles`: x is known to lie on the face's triangles (the first test is moot).
// False when the view has no outline.
bool inside_face(FaceView f, const Vec3& x, double slack, bool on_triangles = false);

// Step 2c: where the faces cross a plane of the other (intersecting triangles; sunk or press-fitted
// parts), a point of one face on the other's plane, inside both faces (contact): on a planar face the
// crossing of its triangles with the plane; on a curved one Newton (SurfaceSource::surface_point)
// from there onto the curve where its surface meets the plane.
void crossing_step(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView a, FaceView b,
                   Pending& p, const CollideOptions& o, CollideCounters& c);

// Where a triangle (vertices v) crosses a plane, given the vertices' signed heights h over it: the
// two ends of the crossing segment, or nothing when the triangle does not reach both open sides.
inline std::optional<std::array<Vec3, 2>> plane_cut(const Vec3* const (&v)[3], const double (&h)[3]) {
  if (!(std::min({h[0], h[1], h[2]}) < 0.0 && std::max({h[0], h[1], h[2]}) > 0.0)) return std::nullopt;
  std::array<Vec3, 2> ends;
  int found = 0;
  for (int k = 0; k < 3 && found < 2; ++k) {
    const int l = (k + 1) % 3;
    if ((h[k] < 0.0) == (h[l] < 0.0)) continue;  // this edge stays on one side (or ends on the plane)
    const double s = h[k] / (h[k] - h[l]);
    ends[static_cast<std::size_t>(found++)] = *v[k] + s * (*v[l] - *v[k]);
  }
  if (found < 2) return std::nullopt;
  return ends;
}

// After a contact is proved: a planar face and a planar, cylindrical or other exact face whose
// triangles cross deeper than T less their band and than the rounding (PairOutcome::
// may_cross_threshold: the band hides whether the faces cross deeper than T) are proved penetrating on
// their exact surfaces (decide_depth.cpp): a point c of both surfaces where the triangles cross,
// inside both faces, and points of each face at height above +H and below -H over the other's
// exact surface (H > T; along a plane or a cylinder's generator from c, or a general face's
// vertices moved onto it), inside their own face, their feet on the other surface inside the other
// face (by the triangles, else the exact classifier, what it leaves given away from H). Sets p.cls
// Penetrating and p.depth (the largest H it proved, at most T + the band) and returns true; false
// leaves p as it was. Precondition: p settled in contact.
bool depth_step(const Model& m, const DecideTask& t, FaceView a, FaceView b, Pending& p, CollideCounters& c);
// Whether depth_step can apply to task t (a plane against a plane, a cylinder or a face with exact
// geometry, triangles that may cross deeper than T, the pair settled touching): the outlines are then needed.
bool depth_step_applies(const Model& m, const DecideTask& t, const Pending& p);

// Step 2d: a cylinder, cone or sphere tangent to the other face's plane: the point of its surface
// nearest the plane (closed form, near its lowest vertices), inside both faces, proves contact.
void tangent_step(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView a, FaceView b,
                  Pending& p, const CollideOptions& o, CollideCounters& c);

// Step 3: witness vertices (contact): vertices of each face near the other face's triangles, asked
// of the other exact face (SurfaceSource::point_distance), nearest first. `a`, `b` are the model's
// faces or finer ones (same part and index); `out` their outcome, `band` its band.
void witness_step(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView a, FaceView b,
                  const PairOutcome* out, double band, Pending& p, const CollideOptions& o, CollideCounters& c);

// Step 3b: an edge witness (contact): where the faces' outlines come closest, a point on an edge of
// each (SurfaceSource::edge_distance) within T proves the faces meet edge to edge. Faces without an
// outline (closed ones) are skipped.
void edge_witness_step(const Model& m, std::span<const Pose> poses, const DecideTask& t, FaceView a, FaceView b,
                       Pending& p, const CollideOptions& o, CollideCounters& c);

// Step 3c: a face touching the other face's plane at one point of a curved edge: that edge's
// extremum toward the plane (SurfaceSource::edge_support), its foot inside the plane's face,
// proves contact.
void edge_support_step(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView a, FaceView b,
                       Pending& p, const CollideOptions& o, CollideCounters& c);

// A lower bound on d* from the faces' planes, cylinders and spheres: the two surfaces' parameters,
// and each one's triangles kept off the other's surface (0 when none helps). `a`, `b` are the
// model's faces or finer copies of them (same analytic surface and box).
double analytic_bound(const Surface& a, const Surface& b, double slack_a, double slack_b, const DecideTask& t,
                      double threshold);

// A lower bound on d* from a planar face with round holes (SurfaceSource::circular_holes) against the
// other face's triangles (hole_gap): a pin through a board's drilled hole is kept off the board's face
// by its distance from the hole's axis (0 when neither face is such a plane or it does not help). `a`,
// `b` are task t's faces or finer copies of them.
double hole_bound(const Model& m, const DecideTask& t, const Surface& a, const Surface& b, std::span<const double> slack,
                  double threshold);
// Whether face a (of_a) or b of task t is a planar face with round holes one of which the other
// face's box, in its frame, reaches into.
bool at_hole(const Model& m, const DecideTask& t, bool of_a);

// Step 4 and 6 helpers. A plane, cylinder or sphere bounds the distance to the other face's
// triangles by that face's band alone (analytic_gap), so only the other face is refined then.
bool bounds_by_shape(const Surface& s);
std::vector<SurfaceId> faces_to_refine(const Model& m, const DecideTask& t);
// True when finer triangles (faces_to_refine at refinement_deflection) could prove the pair apart:
// its triangles stay apart by more than T plus the finer band. Pairs closer than that (contacts
// the witnesses missed) go to the exact step first. Only what it costs depends on this.
bool refinement_can_separate(const Model& m, const DecideTask& t, const Pending& p);
// The finer copy of face `s` when refinement made one, else the model's face.
FaceView finer_view(const Model& m, std::span<const SurfaceBvh> bvh, const std::vector<RefinedSurface>& cache,
                    SurfaceId s);
// Where face a (of_a) or b of task t can come within `margin` of the other face: its own box and
// the other's mapped into its part frame and grown by `margin` (part-local; empty when farther).
Aabb reach_region(const DecideTask& t, const Surface& a, const Surface& b, bool of_a, double margin);

// Step 4: the interval on finer triangles `a`, `b` (finer_view, or a region of a large face: then
// `outside` is a lower bound on the distance of the face's points outside the region to the other
// face, and caps the interval's bottom), tightened by either face's plane, cylinder or sphere
// against the other's triangles.
void refined_step(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView a, FaceView b, Pending& p,
                  const CollideOptions& o, CollideCounters& c,
                  double outside = std::numeric_limits<double>::infinity());

// Step 3d (certified, before refinement): the two faces' surfaces as Bézier control hulls (SurfaceSource::bezier_patches),
// halved until every pair of pieces is farther apart than T (patch_gap.h): a lower bound on d*, so
// "apart" (decided_by Analytic) without OCCT's search. Where the pieces do not separate, a point of
// A's surface there, within T of both faces (SurfaceSource::point_distance), proves contact
// (decided_by Exact). True when it settled the pair.
bool hull_step(const Model& m, std::span<const Pose> poses, std::span<const double> slack, const DecideTask& t,
               Pending& p, const CollideOptions& o, CollideCounters& c);

// Step 5: the exact faces' distance (SurfaceSource::exact_distance). False when they have none.
bool exact_step(const Model& m, std::span<const Pose> poses, const DecideTask& t, Pending& p, const CollideOptions& o,
                CollideCounters& c);

// Step 6: an exact value above T corroborated (apart) or contradicted (contact) by finer triangles
// `a`, `b` (finer_view), and for this pair alone by triangles finer still.
void corroborate(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView a, FaceView b,
                 Pending& p, const CollideOptions& o, CollideCounters& c);

// Settles `p` when `v` decides, with the class it implies (penetrating only when `o` proves it).
void settle(Pending& p, Verdict v, DecidedBy by, const PairOutcome* o, double clearance);

// Adds one decided pair to the decided_* counter of `by`.
void count(CollideCounters& c, DecidedBy by);

// The reported result of a task with class `cls` (distance, penetration and triangle pairs from `out`).
SurfacePairResult make_result(const DecideTask& t, const PairOutcome* out, ContactClass cls);

// Fast mode: the band of the triangles alone, as before certification; nullopt when not reported.
std::optional<SurfacePairResult> fast(const Model& m, const DecideTask& t, const CollideOptions& o);

}  // namespace cadclash::detail
