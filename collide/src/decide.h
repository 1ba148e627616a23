// The certified decision of one candidate surface pair (contact_classes.h, "Certified decisions"): what the
// triangles prove about the exact faces, and the analytic certificate. Internal to cadclash::collide.
#pragma once

#include "cadclash/collide.h"
#include "narrow_phase.h"
#include "surface_bvh.h"

#include <limits>
#include <optional>

namespace cadclash::detail {

// Bounds on the exact distance d* of two faces.
struct Interval {
  double lo = 0.0;
  double hi = std::numeric_limits<double>::infinity();
};

// A computed bound r on the rounding between the triangle arithmetic and exact arithmetic on the
// placed geometry, for an instance pair: mapping B's vertices (part-local magnitude <= mag_b) into
// A's frame with relative_pose (below) in doubles, the rotations' deviation from orthonormal (as
// stored), the vertices' own evaluation on their surfaces, and triangle_distance's error (64·2^-53
// of the pair's extent). Every term is a count of roundings times the magnitude it applies to.
double pair_roundoff(const Pose& pose_a, const Pose& pose_b, double mag_a, double mag_b);

// B's frame -> A's frame as the query computes it, (R_aᵀR_b, R_aᵀ(t_b - t_a)) in doubles: its
// rounding depends on where B lies relative to A, not on how far the pair is from the origin.
Pose relative_pose(const Pose& pose_a, const Pose& pose_b);

// ε of a surface as the decision uses it: Surface::uncertainty, or when that is 0 the
// single-precision representation bound 2^-24 of its part's largest coordinate magnitude; never below
// kMinUncertainty (model.h).
double effective_uncertainty(const Surface& s, double part_magnitude);

// How far the points the decision takes as a face's (its triangles' vertices, points on its
// analytic surface) may lie off the exact face: Surface::tolerance when set (never below
// kMinUncertainty), else the surface's effective uncertainty `eps`.
inline double face_slack(const Surface& s, double eps) {
  return s.tolerance > 0.0 ? std::max(kMinUncertainty, s.tolerance) : eps;
}

// The touching threshold T = tolerance + εa + εb (effective uncertainties).
inline double touch_threshold(double eps_a, double eps_b, double tolerance) { return tolerance + eps_a + eps_b; }

// How far the triangle level must search so that every pair with d* <= T is seen: T + δa + δb + r.
inline double certified_reach(const Surface& a, double eps_a, const Surface& b, double eps_b, double tolerance,
                              double roundoff) {
  return touch_threshold(eps_a, eps_b, tolerance) + a.deflection + b.deflection + roundoff;
}

// True when the surface's triangles are the surface: Surface::exact_triangles, or a part without a
// SurfaceSource whose triangles carry no deflection (a mesh).
bool triangles_are_exact(const Model& model, SurfaceId s);

// What the triangles say about d*: [0, band] when they intersect, else [dm - band, dm + band]
// clamped at 0, with band = δa + δb + r. dm = +inf (nothing within the search) gives lo = the
// search reach (no pair nearer than that exists) and hi = +inf.
Interval mesh_interval(const PairOutcome& o, double band, double reach);

enum class Verdict : std::uint8_t { Contact, Apart, Ambiguous };

// Contact when hi <= threshold, apart when lo > threshold, else ambiguous.
Verdict verdict(const Interval& d, double threshold);

// True when the triangles prove the exact faces cross deeper than `threshold`: they intersect with a
// crossing depth above threshold + band.
bool certainly_penetrating(const PairOutcome& o, double threshold, double band);

// Lower bound on the distance between the exact surface `an` (given in frame F) and every point of the
// triangles of `mesh` mapped into F by `to_f`, over the triangles whose boxes come within `reach` of
// `region` (a box in F); returns `reach` when none does (a farther triangle cannot matter) and nullopt
// for shapes without a certificate (Other, Cone, Torus). Subtract the mesh's deflection and the
// round-off to bound the exact faces' distance. Plane: signed heights (linear over a triangle);
// cylinder and sphere: the distance to the axis or centre is convex, so its maximum over a triangle
// is at a vertex (the inside case) and its minimum is the triangle's distance to the axis or centre.
std::optional<double> analytic_gap(const AnalyticSurface& an, const TriangleMesh& mesh, const Pose& to_f,
                                   const Aabb& region, double reach);

// Lower bound on the distance between a planar face with round holes (`plane`, its `holes`
// (SurfaceSource::circular_holes), both in frame F: every point of the face lies on the plane and at
// least a hole's radius from its axis) and the triangles of `mesh` mapped into F by `to_f`, over the
// triangles whose boxes come within `reach` of `region` (a box in F); `reach` when none does, nullopt
// when no hole's cylinder meets the mesh's box. A triangle is at least as far as its height off the
// plane, and as far inside a hole as its farthest vertex from that hole's axis (the distance to the
// axis is convex): pins through a board's drilled holes. Subtract as for analytic_gap.
std::optional<double> hole_gap(const AnalyticSurface& plane, std::span<const SurfaceSource::CircularHole> holes,
                               const TriangleMesh& mesh, const Pose& to_f, const Aabb& region, double reach);

// Lower bound on the distance between the points of surfaces `a` and `b` (both in one frame) that lie
// in `region` (a box enclosing every place where the faces can come within the threshold), from
// their parameters alone: plane, cylinder and sphere against each other. Tilts are not assumed away:
// the angle between normals or axes, as computed, widens the bound over the region's size. nullopt
// for other combinations. Subtract both ε and the round-off to bound the exact faces' distance.
std::optional<double> analytic_pair_gap(const AnalyticSurface& a, const AnalyticSurface& b, const Aabb& region);

// The edges of a mesh that only one triangle uses: the outline of the region it covers.
std::vector<std::array<Vec3, 2>> boundary_edges(const TriangleMesh& mesh);

// A surface's outline (boundary_edges) with a tree over its segments: the inside-the-face tests ask
// "is this point within m of the outline" for many points, a few box tests each instead of a scan.
struct Outline {
  std::vector<std::array<Vec3, 2>> segments;
  SurfaceBvh tree;  // over the segments' boxes
  bool empty() const { return segments.empty(); }
};
Outline make_outline(const TriangleMesh& mesh);

// True when some segment of `outline` lies within `margin` of p, its distance measured by projection
// in plain doubles (closest_on_segment): the answer of a scan over every segment, which the tree only
// speeds up (it skips boxes farther than margin by more than any rounding of either distance).
bool near_outline(const Outline& outline, const Vec3& p, double margin);

// Per surface: its outline once made, kept by the Scene beside the surface's tree and dropped with it
// (the outline depends on the triangles alone).
struct OutlineCache {
  std::vector<Outline> outline;
  std::vector<char> ready;
};

// Contact certificate from a surface's parameters: the smallest distance g from a vertex of
// `mesh_a` (mapped into B's frame by `to_b`, lying in `region` given in B's frame) to the full
// surface `an_b`, over the vertices whose foot point on that surface is provably a point of face B:
// within delta_b + slack of B's triangles and farther than 2·delta_b + slack from their outline
// (`outline_b`), where the exact face's outline runs within delta_b of it. Only vertices with
// g <= limit are tried (at most 4, nearest first). nullopt when no vertex qualifies or the shape
// has no foot point here (plane, cylinder and sphere do).
std::optional<double> analytic_witness(const AnalyticSurface& an_b, const TriangleMesh& mesh_b,
                                       const SurfaceBvh& bvh_b, const Outline& outline_b,
                                       double delta_b,
                                       const TriangleMesh& mesh_a, const Pose& to_b, const Aabb& region,
                                       double limit, double slack);

// `an` (part-local of one frame) expressed in another frame by `t`.
AnalyticSurface transform_analytic(const AnalyticSurface& an, const Pose& t);

}  // namespace cadclash::detail

#include "budget.h"
#include "refine.h"

#include <memory>
#include <span>
#include <vector>

namespace cadclash::detail {

// One candidate surface pair the triangle level finished (the decision stage's input).
struct DecideTask {
  InstanceId ia = kInvalidId, ib = kInvalidId;
  SurfaceId sa = kInvalidId, sb = kInvalidId;
  const PairOutcome* outcome = nullptr;  // null when a surface has no triangles: decided exactly
  const Pose* ab = nullptr;              // B's frame into A's (the instance pair's, which outlives the task)
  const Pose* ba = nullptr;              // A's frame into B's
  double roundoff = 0.0;                 // pair_roundoff of the instance pair
  const Pose& t_ab() const { return *ab; }
  const Pose& t_ba() const { return *ba; }
};

struct DecideResult {
  std::optional<SurfacePairResult> result;  // nullopt: not reported (apart)
  bool cut = false;                         // the deadline stopped its refinement: no answer
};

// The decision stage (contact_classes.h, "Certified decisions"), per options.decision. Refinements run in
// parallel, each answer depending on its pair alone; results come back in task order, so the report
// is the same for any thread count. `refined` is the Scene's cache of finer faces and parts of faces,
// `outlines` its cache of the surfaces' outlines (made here for the surfaces of open pairs).
// Adds the decided_* / ambiguous / refined / exact / dismissed counters to `counters`, and the
// seconds each step took to `timings`' decide_* fields.
// Without `depth` the depth step is not run: a contact it would prove penetrating stays touching
// (for callers that ask only whether pairs are in contact: continuous motion).
// `eps` holds every surface's effective_uncertainty (the contact band), `slack` its face_slack (how
// far the points taken as the face's may lie off it), `bvh` the tree of every surface with triangles.
std::vector<DecideResult> decide_pairs(const Model& model, std::span<const Pose> poses, std::span<const double> eps,
                                       std::span<const double> slack,
                                       std::span<const SurfaceBvh> bvh, std::span<const DecideTask> tasks,
                                       RefineCache& refined, OutlineCache& outlines,
                                       const CollideOptions& options, int threads, const Deadline& deadline,
                                       CollideCounters& counters, CollideTimings& timings, bool depth = true);

// decide_pairs in two halves (certified or exact decision), for a caller that starts each task's
// decision as soon as its triangles are done, on the thread that did them: early(k) runs steps 1 to
// 3c of task k and answers it when they settle it (any thread, each task once, after its outcome is
// final; the outlines it needs are made on first need), skip(k) marks a task that gets no answer
// (cut before its decision), and
// finish() runs steps 4 to 6 over the pairs still open and returns decide_pairs' answer, once every
// task had early() or skip(). The answers are decide_pairs': each pair's steps depend on it alone.
// The spans and references given must outlive the run; a task's outcome pointer may be set until
// its early().
class DecisionRun {
 public:
  DecisionRun(const Model& model, std::span<const Pose> poses, std::span<const double> eps, std::span<const double> slack,
              std::span<const SurfaceBvh> bvh, std::span<const DecideTask> tasks, RefineCache& refined,
              OutlineCache& outlines, const CollideOptions& options, int threads, const Deadline& deadline,
              bool depth = true);
  ~DecisionRun();
  DecisionRun(const DecisionRun&) = delete;
  DecisionRun& operator=(const DecisionRun&) = delete;
  void early(std::size_t k);
  void skip(std::size_t k);
  std::vector<DecideResult> finish(CollideCounters& counters, CollideTimings& timings);
  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace cadclash::detail
