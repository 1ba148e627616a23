// cadclash/contact_classes.h — what a reported class means, and how the certified decision proves it
// on the exact faces (part of cadclash::collide's public interface; cadclash/collide.h includes it).
#pragma once

#include <cstdint>

namespace cadclash {

// Contact classes of one surface pair (Sk of A, Sl of B). Let τ = tolerance + deflection(Sk) +
// deflection(Sl) be the touching bound: the tessellation of a B-rep face may lie up to its
// deflection away from the exact face, so two faces in exact contact can be τ apart or cross by τ
// on their triangles.
// - Penetrating: some triangle pair intersects and its crossing depth exceeds τ. The crossing depth of
//   an intersecting pair (Ta, Tb) is min(straddle(Ta, Tb), straddle(Tb, Ta)), where straddle(T, P)
//   takes the part of T inside P's normal prism (T clipped by the three planes through P's edges
//   perpendicular to P) and returns the smaller of its largest heights above and below P's plane: how
//   far one triangle reaches through the other on its shorter side. It is 0 for coplanar overlap and
//   for triangles that only meet at an edge or vertex. It is an ESTIMATE of penetration (a local,
//   per-triangle-pair quantity), not the penetration depth of the enclosed solids. Known blind spot:
//   two solids that overlap while every face of one meets the other only along face boundaries (boxes
//   shifted along one axis with equal cross-sections) give crossing depth 0 everywhere: touching.
// - Touching: not penetrating, and either some triangle pair intersects (depth <= τ: coplanar
//   contact, shared edges, chords of coincident cylinders crossing) or the minimum triangle distance
//   d satisfies d <= τ (tangency, faceted cylinder against a plane).
// - Clearance: no triangle pair intersects and τ < d <= clearance.
// - Containment (an instance pair, not a surface pair): every surface of one instance lies inside the
//   other instance's triangles, judged by the generalized winding number |w| >= 0.5 of the first
//   vertex of each surface of the inner part (|w| ≈ 1 inside a closed mesh, ≈ 0 outside), the
//   inner instance's box lies in the outer's box, and no surface pair of the two intersects. The
//   reported surface ids are kInvalidId (whole instances).

//
// Certified decisions (CollideOptions::decision == Certified, the default)
// ------------------------------------------------------------------------
// The classes above are statements about the EXACT faces, not their triangles. Two faces are in
// contact when their exact distance d* <= T = tolerance + εa + εb (Surface::uncertainty). What the
// triangles tell about d* is an interval [lo, hi]:
//   intersecting triangles:   [0, δa + δb + r]
//   mesh distance dm:         [max(0, dm - δa - δb - r), dm + δa + δb + r]
// with δ the surfaces' achieved deflections and r a computed bound on the round-off of mapping B's
// vertices into A's frame (from the poses' magnitudes) and of the triangle arithmetic (triangle_distance
// is accurate to 64·2^-53 of the pair's extent). hi <= T: certainly in contact; lo > T: certainly apart;
// else ambiguous. A pair is penetrating only when its crossing depth exceeds T + δa + δb + r (the
// exact faces cross); a contact whose crossing depth is only within the bands is touching, unless
// both faces are planar and their planes prove it (depth: below).
// Ambiguous pairs are refined, cheapest first, until decided:
//   analytic  the other face's triangles lie provably off a plane, cylinder or sphere (Surface::analytic)
//             by more than T + its deflection, or reach through a round hole of a planar face
//             (SurfaceSource::circular_holes: a board's drilled holes) no farther from the hole's
//             axis than its radius less T and that deflection (a pin near its rim): a lower bound on
//             d* (proves "apart"); or a vertex of
//             one face whose foot point on the other's plane, cylinder or sphere is provably inside
//             that face, within T (proves contact);
//   crossing  triangles crossing deeper than T where one face lies on a plane (a part sunk into or
//             pressed through a flat face): a point of the other face on that plane, inside both
//             faces — on a planar face the crossing of its triangles (decided_by Analytic), on a
//             curved one Newton on the curve where its surface meets the plane
//             (SurfaceSource::surface_point; decided_by Exact) — proves contact;
//   witness   a vertex of one face's triangles (a point of that exact face, within its ε) near the
//             other face's triangles, whose distance to the other exact face is within tolerance + ε
//             of that face, bounded by a point of that face: its foot point on the surface
//             (SurfaceSource::surface_point) when the face's triangles put the foot inside the face
//             (within its deflection of them, clear of their outline by twice that), else a point of
//             its edge curves (SurfaceSource::boundary_distance), else SurfaceSource::point_distance
//             (B-rep: OCCT's face classifier). Contact is proved (decided_by Exact: measured on the
//             exact face); the vertices of the triangle pair that decided the triangles' outcome
//             first, then the nearest vertices, at most 8 per pair; then, where the outlines come
//             closest, a point on an edge of each face (SurfaceSource::edge_distance: Newton on the
//             two edge curves) — faces meeting edge to edge, as a curved edge tangent to a straight one;
//             then, against a plane, the extremum toward it of the other face's edge near its lowest
//             outline points (SurfaceSource::edge_support) — a disk or a bolt's flat lying on its rim;
//   hull      (certified) both faces' surfaces as rational Bézier patches (SurfaceSource::bezier_patches:
//             B-spline and Bézier surfaces, planes, cylinders, cones, spheres, tori, and surfaces of
//             revolution and extrusion swept from lines, conics, B-spline or Bézier curves), halved where
//             they bend until a plane puts every pair of pieces' control points more than T + εa + εb
//             apart: a lower bound on d* (apart, decided_by Analytic) — a bolt drifting a micrometre
//             off its hole's axis, far inside every band; where pieces will not separate, a point of
//             A's surface there, or where A's surface crosses B's next to it (B's signed height from
//             SurfaceSource::surface_point, bisected on A's surface), within T of both faces
//             (SurfaceSource::point_distance) proves contact (decided_by Exact). A bounded search (at
//             most 16,384 pairs of pieces), so it comes before any face is meshed again: a wall of a
//             component standing off a board by less than its triangles' band is proved apart without
//             re-meshing the board;
//   refined   where finer triangles could show a gap (the triangles stay apart by more than T plus
//             the finer band), the faces re-tessellated at a tenth of their deflection by their
//             SurfaceSource (cached in the Scene) and the interval taken again, with the plane,
//             cylinder or sphere of either face against the other's finer triangles; a face of those
//             shapes is not refined when the other face is not one (its surface bounds the gap), nor
//             a planar face with round holes at a hole the other face reaches into (the hole does). A
//             large face (2,000 triangles and more) of which the pair's reach is a small part (a
//             quarter of its box's diagonal at most) is re-tessellated only there
//             (SurfaceSource::triangulate_region: a board's top face near one pin), by the pair's
//             thread, once per region (regions snap to a grid of power-of-two cells, so neighbouring
//             pairs share them); its points outside lie farther than 2 (T + the band) from the
//             other face, which caps the interval's bottom;
//   exact     SurfaceSource::exact_distance (OCCT BRepExtrema on the placed faces; the search stops at
//             the first two points within T), interval [d*, d*].
//   depth     (after any of the above proved contact) a planar face and a planar, cylindrical or
//             other exact face whose triangles cross deeper than T but within T + δa + δb + r: a
//             point where one's triangles cross the other's plane, moved onto both exact surfaces
//             and inside both faces, and points of each face at heights above +H and below -H over
//             the other's exact surface (H > T; a line of a plane across the crossing, a cylinder's
//             generator, a general face's vertices moved onto it by SurfaceSource::surface_point),
//             inside their own face, their feet on the other surface inside the other face (by the
//             triangles, else SurfaceSource::point_distance), prove the exact faces cross deeper
//             than T: penetrating (decided_by Analytic; penetration = the largest H proved, at most
//             T + the band). Heights are signed distances to the exact surfaces.
// A pair none of these decides (mesh-only input, no exact geometry, OCCT failed) is reported with
// class Undecided and its interval, never as touching. Clearance (T < d* <= clearance) is judged on
// the mesh distance (or d* when it was computed). Results do not depend on the thread count.
// Fast: the classes above on the triangles alone (τ = tolerance + δa + δb), decided_by Mesh, as
// before certification. Exact: every reported pair's d* from SurfaceSource::exact_distance where the
// faces have exact geometry; pairs farther than T become clearance (<= clearance) or leave the report
// (counted in CollideCounters::dismissed_pairs).

enum class ContactClass : std::uint8_t { Penetrating, Touching, Clearance, Containment, Undecided };

// Returns "penetrating", "touching", "clearance", "containment" or "undecided".
const char* contact_class_name(ContactClass c);

enum class DecisionMode : std::uint8_t { Certified, Fast, Exact };

// What settled a surface pair's class (see "Certified decisions").
enum class DecidedBy : std::uint8_t {
  Mesh,       // the triangles' interval, with deflection bands
  MeshExact,  // the triangles' interval where both surfaces' triangles are the surfaces (no band but r)
  Analytic,   // a plane/cylinder/sphere lower bound
  Refined,    // re-tessellation of the two faces
  Exact,      // the exact B-rep distance
  Undecided,  // nothing above could decide it
};

// Returns "mesh", "mesh-exact", "analytic", "refined", "exact" or "undecided".
const char* decided_by_name(DecidedBy d);

// Whether a contact holds within the tolerance alone, or only because of the model uncertainty
// (T = tolerance + εa + εb; docs/report-schema.md, "Classes"), from the pair's proven interval of the
// exact distance: Tolerance when its top is at most the tolerance (penetrating pairs always),
// ModelUncertainty when its bottom is above it, Unknown when the interval straddles it, for pairs
// that are not contacts, and in the fast mode (which does not use ε).
enum class ContactWithin : std::uint8_t { Unknown, Tolerance, ModelUncertainty };
// Returns "unknown", "tolerance" or "model uncertainty".
const char* contact_within_name(ContactWithin w);
// Returns "certified", "fast" or "exact".
const char* decision_mode_name(DecisionMode m);

}  // namespace cadclash
