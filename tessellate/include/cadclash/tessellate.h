// cadclash/tessellate.h — B-rep faces to tagged triangle surfaces (OCCT BRepMesh), and raw mesh
// repair / segmentation (CGAL). The one public header of cadclash::tessellate.
//
// B-rep parts: every face of a part becomes one Surface. Faces are numbered in the order of
// TopExp::MapShapes(shape, TopAbs_FACE) on the part's shape; that number is Provenance::face_index
// and the surface's local index within its part. A part's SurfaceSource (BrepSource) keeps the exact
// faces: it tessellates on demand (lazy mode, refinement) and answers exact distances.
//
// This header names OCCT types only by forward declaration: including it does not need OCCT headers,
// but calling the B-rep functions does (link cadclash::tessellate, which links OCCT).
#pragma once

#include "cadclash/collide.h"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

class TopoDS_Shape;
class TopoDS_Face;

namespace cadclash {

// How finely B-rep faces are triangulated.
struct TessellationOptions {
  double linear_deflection = 0.1;   // chord error bound; millimetres, or a fraction of the part size if relative
  bool relative = false;            // linear_deflection is relative to each part's bounding-box diagonal
  double angular_deflection = 0.5;  // radians between adjacent normals along a curve
  bool parallel = true;             // let BRepMesh mesh faces of one part in parallel
  // Measure each face's chord error at its triangle centroids (a few surface evaluations per
  // triangle) and re-mesh that face once, at half the deflection, where it exceeds the request (at
  // import: only where it exceeds it by less than 4x, since a much finer BRepMesh of a large trimmed
  // NURBS face can take minutes; triangulate() always tries). The
  // stored achieved deflection is max(BRepMesh's own figure, the measured error), so it may exceed
  // the request where even the finer mesh did not meet it: it is what collide should trust.
  bool verify_deflection = true;
  // Seconds one add_brep_parts call (at import: one file) may spend meshing; 0 = no limit. Past it
  // BRepMesh is asked to stop (it checks between faces, not inside one) and no face is re-meshed;
  // each face left without triangles keeps its surface and gets an error naming it and the limit.
  // Lazy tessellation (triangulate, require_triangles) is not limited.
  double time_limit_seconds = 0.0;
  // Told how far add_brep_parts is (CheckPart: parts of that call checked and healed; TessellatePart:
  // parts meshed, eager only; label the part's name; collide.h, "Progress of long work"), on the
  // thread that called it; empty = nothing. Import ignores it and reports through ImportOptions::progress.
  ProgressCallback progress;
};

// Caps the threads OCCT's own parallel loops use in this process (BRepMesh meshing a part's faces
// at once: TessellationOptions::parallel) at `threads`: they then run on OCCT's thread pool of that
// size instead of TBB's, which takes every core; threads == 0 puts them back on TBB's. Process-wide;
// cadclash's own loops (files read at once, parts meshed at once, lazy tessellation) follow
// omp_set_num_threads of the thread that starts them. Returns the threads OCCT's loops now run on.
// Precondition: threads >= 0; no meshing runs.
int limit_mesher_threads(int threads);

// OCCT's loops for a whole run on `threads` threads (0: every core), as `cadclash check --threads N`
// and the Python load(threads=N) hold them beside omp_set_num_threads: on a pool of that many when
// fewer than the machine's cores, else on TBB's, which meshes faster (as1 at 0.001 mm on 2 cores:
// 0.39 s on TBB's, 0.48-0.56 s on a pool of 2). Returns limit_mesher_threads' value.
// Precondition: threads >= 0; no meshing runs.
int hold_mesher_threads(int threads);

// Named settings a user understands, like Mayo's and FreeCAD's mesh quality choices.
// Absolute deflections in millimetres:
//   coarse     1.0   mm, 0.8  rad     quick look, collision broad checks
//   normal     0.1   mm, 0.5  rad     the default
//   fine       0.01  mm, 0.25 rad     close-contact checks
//   very-fine  0.001 mm, 0.1  rad     tolerance studies; slow on large assemblies
enum class TessellationPreset : std::uint8_t { Coarse, Normal, Fine, VeryFine };

// Returns the options of a preset (parallel and verify_deflection keep their defaults).
TessellationOptions tessellation_preset(TessellationPreset preset);

// `base` with the preset's absolute linear and angular deflections (the rest of `base` kept): what
// choosing a preset means wherever it is chosen (the CLI's --preset, Python's load(preset=)).
TessellationOptions apply_preset(TessellationOptions base, TessellationPreset preset);

// Parses "coarse", "normal", "fine", "very-fine" (also "very_fine", "veryfine"); nullopt otherwise.
std::optional<TessellationPreset> parse_tessellation_preset(std::string_view name);

// Returns "coarse", "normal", "fine" or "very-fine".
const char* tessellation_preset_name(TessellationPreset preset);

// ---------------------------------------------------------------------------------------------
// B-rep parts
// ---------------------------------------------------------------------------------------------

// What the file says about one face; indexed by face_index.
struct BrepFaceTag {
  std::int64_t entity_id = -1;  // STEP #id (or IGES directory entry number) of the face entity; -1 if unknown
  std::string name;             // the file's name for the face; may be empty
  std::optional<std::array<float, 3>> colour;  // RGB in [0,1]
};

// One part to add to a Model.
struct BrepPartInput {
  const TopoDS_Shape* shape = nullptr;  // not owned; copied (by handle) into the part's source
  std::string name;
  std::string source_file;
  SourceKind kind = SourceKind::BrepFace;  // StepFace, IgesFace or BrepFace
  std::vector<BrepFaceTag> tags;           // per face index; shorter (or empty) means "no tag" for the rest
};

// Appends one part per input to `model`, each with its surfaces (contiguous, face order) and a
// BrepSource. Eager (lazy == false): every face is tessellated now; lazy: only AABBs (from the exact
// geometry) are computed and has_triangles stays false until require_triangles() or
// BrepSource::triangulate(). Faces that BRepCheck finds invalid are fixed with ShapeFix_Face first
// (Provenance::healed). A face that fails to mesh keeps its surface with has_triangles == false and
// gets an Error diagnostic naming the part and the face's entity #id; `complete` is then set false.
// Returns the new parts' ids, in input order. `timings`, when given, gets the seconds spent added.
// Preconditions: every input's shape is non-null; options.linear_deflection > 0.
struct BrepPartTimings {
  double heal = 0.0;        // BRepCheck and ShapeFix of invalid faces, plane pcurves, exact boxes and face facts
  double tessellate = 0.0;  // BRepMesh, reading and measuring the triangles (eager only)
  // Per part checked and healed, appended in input order: its wall seconds on the thread that did it.
  std::vector<double> part_heal;
};
// `diagnostics_per_part`, when given, gets how many diagnostics each part appended, in input order.
std::vector<PartId> add_brep_parts(Model& model, std::span<const BrepPartInput> parts,
                                   const TessellationOptions& options, bool lazy,
                                   std::vector<Diagnostic>& diagnostics, bool& complete,
                                   BrepPartTimings* timings = nullptr,
                                   std::vector<std::size_t>* diagnostics_per_part = nullptr);

// The SurfaceSource of a B-rep part. Thread-safe: each part has a shared mutex; triangulate() calls
// on one part serialise, exact_distance() calls only read the faces and run concurrently.
// exact_distance is BRepExtrema_DistShapeShape's value on the two placed faces, bit for bit (the
// same sub-shape search, stopping once the distance is 0, or within `enough` when one is given).
class BrepSource final : public SurfaceSource {
 public:
  struct Impl;
  explicit BrepSource(std::unique_ptr<Impl> impl);
  ~BrepSource() override;
  BrepSource(const BrepSource&) = delete;
  BrepSource& operator=(const BrepSource&) = delete;

  std::uint32_t face_count() const;
  // The part-local face behind surface `local_index` (the healed one if healing changed it).
  // Precondition: local_index < face_count(). Do not mesh it while other threads use this part.
  const TopoDS_Face& face(std::uint32_t local_index) const;
  // The deflection used when triangulate() is given deflection <= 0 (absolute, millimetres).
  double default_deflection() const override;

  // Meshes the face with BRepMesh_IncrementalMesh when it has no triangulation or a coarser one than
  // `deflection`; otherwise reads the existing one. A deflection finer than default_deflection() is a
  // refinement: it is meshed on a copy of the face, which keeps the triangulation it had (the one the
  // model's surfaces, exporters and other readers of the shape were given). Triangles are part-local and
  // counter-clockwise seen from outside (winding flipped for reversed faces).
  bool triangulate(std::uint32_t local_index, double deflection, TriangleMesh& out,
                   double& achieved_deflection, Diagnostic& error) override;

  // The face's common part with the region's box (BRepAlgoAPI_Common on a copy, the arguments left
  // as they were), each face of it meshed by BRepMesh at `deflection` as triangulate() meshes a
  // refinement; concurrent calls run side by side (they read the part's faces only).
  bool triangulate_region(std::uint32_t local_index, double deflection, const Aabb& region, TriangleMesh& out,
                          double& achieved_deflection, Diagnostic& error) override;

  // An upper bound on the distance from `point` (part-local) to the face, realised by a point of the
  // face: the foot point of a Newton projection started at the nearest node of the face's triangles,
  // when the face classifier puts it inside the face (microseconds); else BRepExtrema_DistShapeShape
  // between a vertex at `point` and the face.
  std::optional<double> point_distance(std::uint32_t local_index, const Vec3& point) const override;

  // Extrema_GenLocateExtPS (Newton) from the nearest node of the face's triangles, no classifier;
  // the normal from the surface's first derivatives.
  std::optional<SurfacePoint> surface_point(std::uint32_t local_index, const Vec3& point) const override;

  // The control points of the face's B-spline or Bézier surface (unwrapping trimmed surfaces), placed
  // by the face's location; nullopt for other surfaces and for non-positive weights.
  std::optional<std::array<double, 2>> height_range(std::uint32_t local_index, const Vec3& origin,
                                                    const Vec3& normal) const override;

  // GeomConvert's Bézier patches of the face's B-spline or Bézier surface (trimmed ones unwrapped), or
  // of its plane, cylinder, cone, sphere, torus, or surface of revolution or linear extrusion swept
  // from a line, circle, ellipse, B-spline or Bézier curve (exact conversions only) over the face's
  // parameter bounds; placed by the face's location. nullopt for other surfaces, for non-positive
  // weights and beyond 1024 patches.
  std::optional<BezierPatches> bezier_patches(std::uint32_t local_index) const override;

  // Inner wires of a planar face running once around one circle, its centre outside the face by
  // OCCT's face classifier (brep_face_holes.cpp); made on first use and kept.
  std::shared_ptr<const std::vector<CircularHole>> circular_holes(std::uint32_t local_index) const override;

  // Newton (first and second derivatives of BRepAdaptor_Curve) on the edge nearest `near`.
  std::optional<SurfacePoint> edge_support(std::uint32_t local_index, const Vec3& direction,
                                           const Vec3& near) const override;

  // ShapeAnalysis_Curve's projection onto the face's edges, nearest edge box first.
  std::optional<double> boundary_distance(std::uint32_t local_index, const Vec3& point) const override;

  // Extrema_LocateExtCC between the edge of each face nearest its given point, started at their
  // projections (ShapeAnalysis_Curve); `other` must be a BrepSource, else nullopt.
  std::optional<double> edge_distance(std::uint32_t local_a, const Pose& pose_a, const SurfaceSource& other,
                                      std::uint32_t local_b, const Pose& pose_b, const Vec3& near_a,
                                      const Vec3& near_b) const override;

  // BRepExtrema_DistShapeShape on the two placed faces; `other` must be a BrepSource, else nullopt.
  // When the faces' boxes are farther apart than max_distance, returns that box distance (a lower
  // bound > max_distance) without running the exact search. With `enough` > 0 the sub-shape search
  // stops at the first distance <= enough (vertex and edge levels come before the face–face one).
  std::optional<double> exact_distance(std::uint32_t local_a, const Pose& pose_a, const SurfaceSource& other,
                                       std::uint32_t local_b, const Pose& pose_b, double max_distance,
                                       double enough = 0.0) const override;

  // A part's source as bytes, for a cache of imported parts: its faces in OCCT's binary shape format
  // (BinTools, with their triangulations, so nothing is meshed again) and what add_brep_parts
  // computed about them. A source loaded from them answers every query bit for bit as this one does.
  // Do not call it while another thread meshes this part.
  friend std::string save_brep_source(const BrepSource& source);
  // Back from save_brep_source's bytes; nullptr and `why` when they are not whole. The bytes must be
  // ones save_brep_source wrote (check a cache entry's checksum first): OCCT's shape reader trusts them.
  friend std::shared_ptr<BrepSource> load_brep_source(std::string_view bytes, std::string& why);
  // The file's entity id of each face and the file its diagnostics name (what a part stored under
  // one file's ids and name is in another export of the same product, or another file holding it).
  // Precondition: entity_ids.size() == face_count(); no other thread uses the part meanwhile.
  friend void relabel_brep_faces(BrepSource& source, std::span<const std::int64_t> entity_ids,
                                 const std::string& source_file);
  friend std::size_t tessellate_parts(Model& model, std::span<const PartId> parts,
                                      std::vector<Diagnostic>& diagnostics, bool& complete);
  friend void release_part_triangles(Model& model, std::span<const PartId> parts);
  friend bool brep_parts_share_edges(const Model& model);

 private:
  std::unique_ptr<Impl> impl_;
};

std::string save_brep_source(const BrepSource& source);
std::shared_ptr<BrepSource> load_brep_source(std::string_view bytes, std::string& why);
void relabel_brep_faces(BrepSource& source, std::span<const std::int64_t> entity_ids, const std::string& source_file);

// Whole parts meshed later (distributed checks: a rank meshes only the parts its share of the work
// reaches, and must get the triangles one process's eager import gets).
//
// Meshes every face of the listed B-rep parts that a lazy add_brep_parts left without triangles
// exactly as an eager add_brep_parts would have: one BRepMesh call over the part's faces, the same
// triangles, achieved deflections (Surface::deflection) and boxes (the exact face box extended by its
// triangles'), at the deflection, angular deflection and verification the part was loaded with, no
// time limit. A face that fails gets the eager import's error, appended to `diagnostics` in the order
// of `parts`, and sets `complete` false. Parts without a BrepSource, parts any of whose surfaces
// already has triangles, and repeats are skipped. Parts are meshed in parallel unless they share
// edges. Returns how many parts it meshed. Identical to the eager import only when no two B-rep parts
// of the model share an edge (brep_parts_share_edges), since meshing writes into edges.
// Preconditions: every id < model.parts.size(); no other thread uses these parts meanwhile.
std::size_t tessellate_parts(Model& model, std::span<const PartId> parts, std::vector<Diagnostic>& diagnostics,
                             bool& complete);

// Drops the triangles of the listed B-rep parts: the surfaces' meshes (has_triangles false; their
// deflection and box stay) and the triangulations BRepMesh stored in the faces, so that
// tessellate_parts makes the same ones again. Parts without a BrepSource are skipped.
// Preconditions: every id < model.parts.size(); nothing (a Scene's hierarchy) refers to the triangles.
void release_part_triangles(Model& model, std::span<const PartId> parts);

// True when two B-rep parts of the model share an edge (a file may let two products reach one edge).
bool brep_parts_share_edges(const Model& model);
// The same for inputs of add_brep_parts, before they are added. Precondition: every shape non-null.
bool brep_inputs_share_edges(std::span<const BrepPartInput> parts);

// =============================================================================================
// Raw meshes: repair and segmentation (CGAL Polygon_mesh_processing)
// =============================================================================================
//
// Post-processing steps on an imported Model, for any mesh reader. They touch only "mesh parts":
// parts without a SurfaceSource (Part::source == nullptr), and within them only surfaces with
// triangles. B-rep parts are left alone (their SurfaceSource indexes surfaces by local index).
// Both steps are deterministic: the same Model and options give the same triangles, names and ids,
// whatever the thread count.

// What repair_meshes() does. Point merging and the three duplicate / degenerate removals always run.
struct MeshRepairOptions {
  bool orient = true;                   // make each connected component consistently oriented (see below)
  bool stitch_borders = true;           // glue border edges whose end points coincide exactly
  bool duplicate_non_manifold_vertices = true;  // split vertices whose faces do not form one fan
  bool remove_negligible_components = false;    // drop tiny components (CGAL's default thresholds: 1% of
                                                // the part's box diagonal, squared for area, cubed for volume)
  bool fill_holes = false;              // triangulate every border cycle (triangulate_hole)
  std::uint32_t max_hole_edges = 0;     // fill only holes with at most this many edges; 0 = any size
};

// What repair changed in one surface. Counts are exact and refer to that surface only.
struct SurfaceRepairStats {
  SurfaceId surface = kInvalidId;          // repair never adds, removes or renumbers surfaces
  std::uint32_t triangles_before = 0, triangles_after = 0;
  std::uint32_t vertices_before = 0, vertices_after = 0;
  // Vertices of this surface that repeat (bit-exactly, -0 == +0) an earlier vertex of the same
  // surface. Equal points of different surfaces of one part are joined too (that is what connects
  // the surfaces), but each surface keeps its own vertex array, so they are not counted here.
  std::uint32_t merged_points = 0;
  std::uint32_t unused_points = 0;         // vertices no triangle referenced, dropped
  std::uint32_t degenerate_faces = 0;      // triangles removed: two corners at the same point (or a
                                           // non-finite coordinate)
  std::uint32_t collinear_faces = 0;       // triangles removed: three distinct corners on one line, as
                                           // exact arithmetic on the coordinates decides (CGAL's
                                           // collinear predicate); zero area, so the geometry is the
                                           // same without them. A needle that is not exactly flat stays.
  std::uint32_t duplicate_faces = 0;       // triangles removed: same three points as an earlier triangle of
                                           // the part (either orientation); "earlier" = lower surface id,
                                           // then lower triangle index
  std::uint32_t flipped_faces = 0;         // kept triangles whose final winding is the reverse of the input's
  std::uint32_t stitched_edges = 0;        // border edges of this surface that stitching joined to a neighbour
  std::uint32_t duplicated_vertices = 0;   // vertex copies made to split non-manifold vertices (or
                                           // non-manifold / incompatibly oriented edges) that this
                                           // surface's triangles use
  std::uint32_t removed_component_faces = 0;  // triangles dropped with negligible components
  std::uint32_t filled_holes = 0;          // holes whose new triangles went to this surface
  std::uint32_t hole_faces = 0;            // triangles added by hole filling to this surface
  // The surface's vertex or triangle arrays differ from before (then provenance.repaired is set).
  // Stitching and vertex duplication between two surfaces can be counted above and still leave
  // both surfaces' own arrays as they were.
  bool changed = false;
};

struct MeshRepairReport {
  std::vector<SurfaceRepairStats> per_surface;  // one per surface repair looked at, ascending surface id
  SurfaceRepairStats total;                     // sums (surface = kInvalidId; changed = any changed)
  std::uint32_t parts_repaired = 0;             // mesh parts that had at least one changed surface
  std::vector<Diagnostic> diagnostics;          // parts repair had to leave unchanged, and why
};

// Repairs the triangles of every mesh surface, one part at a time, keeping every triangle on the
// surface it came from. Per part:
//  1. Points equal bit-for-bit are merged (within and across the part's surfaces); unused points go.
//  2. Triangles with two corners at one point or three exactly collinear corners are removed (they
//     cover no area; left in, segmentation would make a patch of them); so are repeats of an
//     earlier triangle.
//  3. The rest is oriented with orient_polygon_soup and turned into a halfedge mesh; points at
//     non-manifold spots are duplicated (orient_polygon_soup, then duplicate_non_manifold_vertices).
//  4. stitch_borders; then each connected component gets one orientation. A closed component faces
//     outward (positive enclosed volume), or inward when it lies inside an odd number of other
//     closed components (a cavity; nesting by generalized winding number). An open component keeps
//     the orientation that agrees with most of its input windings (ties: orient_polygon_soup's,
//     which follows its lowest triangle).
//  5. On request: negligible components removed; holes filled, each hole's triangles going to the
//     surface with the most triangles along the hole (ties: the lower surface id).
// Each surface's triangles keep their input order (hole triangles last); its vertex array is
// rebuilt in order of first use. Surfaces whose triangles changed get provenance.repaired = true
// and a fresh aabb. Surfaces, names, ids and provenance otherwise stay as they were.
// A part CGAL cannot turn into a mesh is left unchanged and named in a Warning diagnostic.
MeshRepairReport repair_meshes(Model& model, const MeshRepairOptions& options = {});

// How segment_surfaces() cuts surfaces into patches.
struct SegmentOptions {
  // An edge is sharp when the angle between its two faces' normals exceeds this (degrees, in (0, 180)).
  double sharp_angle_degrees = 60.0;
  // Region growing (Shape_detection::Region_growing, Least_squares_plane_fit_region) within each
  // sharp-edge patch: splits smooth-but-not-flat patches into planar regions.
  bool planar = false;
  double planar_max_distance = 0.0;        // mm from the fitted plane; <= 0: 1e-3 of the surface's box diagonal
  double planar_max_angle_degrees = 5.0;   // between a face normal and the fitted plane's normal
};

// What segmentation did to one input surface.
struct SurfaceSegments {
  SurfaceId input = kInvalidId;   // id before segment_surfaces()
  SurfaceId first = kInvalidId;   // its replacement range [first, first + count) after
  std::uint32_t count = 0;        // 1 when it was kept whole (one patch): then it is unchanged
};

struct SegmentReport {
  // One entry per input surface, in input order: where every surface went (ids shift when a surface
  // is replaced by several). Surfaces of B-rep parts and surfaces without triangles map to one.
  std::vector<SurfaceSegments> surfaces;
  std::uint32_t surfaces_split = 0;   // input surfaces replaced by two or more patches
  std::uint32_t patches = 0;          // surfaces created by splitting
  std::vector<Diagnostic> diagnostics;  // surfaces kept whole because CGAL could not mesh them
};

// Cuts every mesh surface into CAD-like patches: faces joined across edges that are not sharp
// (the steps of CGAL's sharp_edges_segmentation: detect_sharp_edges, then connected components
// across the other edges, on the surface's triangles joined at points equal bit-for-bit and
// oriented consistently), optionally refined by planar region growing. A surface with one patch is kept as it is. A surface with k > 1 patches is
// replaced, in place, by k surfaces named "<name>/patch-<j>" (j = 0..k-1) ordered by the lowest
// input triangle index each patch holds; triangles keep their input order and winding. A patch's
// provenance is its parent's (source file, step_id, face_index, source_name, colour, repaired) with
// kind = Segment and parent = the parent's id in the model as it was BEFORE this call (the report
// maps old ids to new ranges). Triangles a valid mesh cannot hold (degenerate, repeated) join the
// patch of the lowest triangle sharing a point with them, or form a patch of their own.
// Part::first_surface / surface_count stay contiguous; instances are untouched.
// Precondition: 0 < options.sharp_angle_degrees < 180.
SegmentReport segment_surfaces(Model& model, const SegmentOptions& options = {});

}  // namespace cadclash
