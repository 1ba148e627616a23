// cadclash/model.h — the surface-tagged model: parts, their surfaces (each CAD face or mesh patch
// with its triangles, provenance and exact-geometry facts), placed instances, and diagnostics.
//
// Part of cadclash::collide (cadclash/collide.h includes it; the queries over the model are there).
// It depends on Eigen and the standard library only. Importers (cadclash::import) fill a Model;
// a design-review tool can also build one by hand.
//
// Conventions
// - Ids are small integers that index the flat arrays of a Model (parts, surfaces, instances).
// - Units are millimetres; importers convert.
// - Caller mistakes (an id out of range, a malformed Model) are assertions. Untrusted input (files)
//   is reported through Diagnostic values; library code never prints.
#pragma once

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace cadclash {

// ---------------------------------------------------------------------------------------------
// Ids and basic geometry
// ---------------------------------------------------------------------------------------------

using PartId = std::uint32_t;
using SurfaceId = std::uint32_t;
using InstanceId = std::uint32_t;
inline constexpr std::uint32_t kInvalidId = ~std::uint32_t{0};

using Vec3 = Eigen::Vector3d;
// Axis-aligned box; a default-constructed box is empty (min > max).
using Aabb = Eigen::AlignedBox3d;
// Rigid transform (rotation + translation) from a part's local frame to the world frame.
using Pose = Eigen::Isometry3d;

// The range collide certifies. Every answer is certified for lengths of at most kMaxLength in
// magnitude: vertex coordinates and surface boxes (part-local), pose translations (a pose's rotation
// entries are at most 1), deflections, uncertainties, the tolerance and the clearance. Beyond it
// squares and fourth powers of lengths in the float steps of a query overflow, so the readers reject
// such values (a diagnostic naming the file and line or STEP #id and the value) and collide() and
// Scene refuse such a query (Report::stopped_by "out of range", an error diagnostic per offending
// instance or option). Small coordinates have no limit: a surface's ε is never taken below
// kMinUncertainty, which keeps every length that decides a contact far above the range where its
// products underflow (faces closer than 2 x kMinUncertainty + tolerance touch).
inline constexpr double kMaxLength = 0x1p128;        // mm, about 3.4e38
inline constexpr double kMinUncertainty = 0x1p-128;  // mm, about 2.9e-39

// True when |x| <= kMaxLength; false for NaN and infinities.
inline bool in_supported_range(double x) { return x >= -kMaxLength && x <= kMaxLength; }

// Indexed triangles in double precision, in the owning part's local frame.
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise seen from outside
};

// ---------------------------------------------------------------------------------------------
// Diagnostics: what went wrong in untrusted input, and where
// ---------------------------------------------------------------------------------------------

enum class Severity : std::uint8_t { Warning, Error };

struct Diagnostic {
  Severity severity = Severity::Error;
  std::string file;           // source file path as given by the caller; empty if none
  std::int64_t line = 0;      // 1-based line in `file`; 0 when the format has no lines
  std::int64_t step_id = -1;  // STEP entity #id the message is about; -1 when none
  std::string message;        // one sentence, no trailing newline
};

// Formats a diagnostic as "file:line: error: message" or "file: #id: error: message".
std::string format_diagnostic(const Diagnostic& d);

// Returns true if any diagnostic in `ds` is an error.
bool has_error(std::span<const Diagnostic> ds);

// ---------------------------------------------------------------------------------------------
// The surface-tagged model
// ---------------------------------------------------------------------------------------------

// Where a surface came from.
enum class SourceKind : std::uint8_t {
  StepFace,        // a face of a STEP B-rep; step_id is its ADVANCED_FACE (or FACE_SURFACE) #id
  IgesFace,        // a face of an IGES B-rep; step_id holds the IGES directory entry number if known
  BrepFace,        // a face of an OCCT .brep shape
  ObjGroup,        // an OBJ `g` group or `o` object
  OffColourGroup,  // all faces of an OFF file sharing one face colour
  MeshFile,        // one mesh of an STL/PLY/glTF/... file read whole
  Segment,         // a patch cut out of another surface by segmentation; see Provenance::parent
};

// Returns a stable lower-case name for a source kind ("step-face", "obj-group", ...).
const char* source_kind_name(SourceKind kind);

struct Provenance {
  SourceKind kind = SourceKind::MeshFile;
  std::string source_file;          // file the surface was read from
  std::int64_t step_id = -1;        // STEP entity #id of the face (as written in the file); -1 if none
  std::int32_t face_index = -1;     // index of the face / group / colour within its part, as read
  std::string source_name;          // the file's own name for it (group name, STEP face name); may be empty
  SurfaceId parent = kInvalidId;    // for Segment: the surface this patch was cut from
  std::optional<std::array<float, 3>> colour;  // RGB in [0,1] as the file writes it (STEP: sRGB, not linearised)
  bool healed = false;              // OCCT shape fixing changed the face before tessellation
  bool repaired = false;            // mesh repair changed the surface's triangles
};

// Where a surface's model uncertainty ε (Surface::uncertainty) came from.
enum class UncertaintySource : std::uint8_t {
  Coordinates,    // derived by collide from the part's coordinates (uncertainty 0: 2^-24 x the part's
                  // largest coordinate magnitude, the single-precision bound of mesh formats)
  OcctTolerance,  // the largest OCCT tolerance of the face, its edges and vertices
  Declared,       // the length uncertainty the face's STEP file declares (UNCERTAINTY_MEASURE_WITH_UNIT)
  Given,          // set by whoever built the model: ImportOptions' model_tolerance or uncertainty value
};

// Returns "coordinates", "occt tolerance", "declared" or "given".
const char* uncertainty_source_name(UncertaintySource source);

class SurfaceSource;

// The exact surface a face lies on, part-local, when it is one of the elementary kinds. Lets
// collide prove two faces apart without OCCT (see "Certified decisions" below).
enum class SurfaceShape : std::uint8_t { Other, Plane, Cylinder, Cone, Sphere, Torus };

struct AnalyticSurface {
  SurfaceShape shape = SurfaceShape::Other;
  Vec3 origin = Vec3::Zero();  // plane: a point on it; cylinder: a point on the axis; cone: the apex;
                               // sphere, torus: the centre
  Vec3 axis = Vec3::UnitZ();   // plane: unit normal; cylinder, cone, torus: unit axis direction
  double radius = 0.0;         // cylinder, sphere: radius; torus: major radius (centre to tube axis)
  double radius2 = 0.0;        // torus: minor (tube) radius; cone: half-angle, radians in (0, pi/2)
};

struct Surface {
  std::string name;        // unique within its part
  PartId part = kInvalidId;
  Provenance provenance;
  Aabb aabb;               // part-local; encloses the exact surface (B-rep) or its triangles (mesh)
  double deflection = 0.0; // achieved bound on the distance between triangles and the exact surface; 0 for meshes
  // Model uncertainty ε (mm): how far the stated geometry may be from the intended one. B-rep faces:
  // the largest OCCT tolerance of the face, its edges and vertices (never below Precision::Confusion,
  // 1e-7), or the STEP file's UNCERTAINTY_MEASURE_WITH_UNIT when larger (import's default;
  // ImportOptions::uncertainty chooses). Meshes: the single-precision
  // representation bound 2^-24 · (largest coordinate magnitude of the part), or the importer's
  // model_tolerance when given. 0 (a Model built by hand) means that same bound, derived by collide
  // from the part's box. Never taken below kMinUncertainty. Two faces touch when their exact distance
  // <= tolerance + εa + εb.
  double uncertainty = 0.0;
  // Where `uncertainty` came from; a surface whose uncertainty is 0 reports Coordinates whatever
  // this says (uncertainty_source below).
  UncertaintySource uncertainty_source = UncertaintySource::Given;
  // How far the face's own vertices, edges and triangle nodes may lie off its exact surface: B-rep
  // faces, the largest OCCT tolerance of the face, its edges and vertices (what `uncertainty` is
  // unless the file declares more). The certified decision's bounds on a face's points use it; the
  // contact band uses `uncertainty`. 0 (meshes, a Model built by hand) means `uncertainty`.
  double tolerance = 0.0;
  // The triangles are the surface itself, not an approximation: mesh surfaces, and planar B-rep faces
  // bounded by straight edges (deflection 0). Pairs of such surfaces are decided on the triangles.
  bool exact_triangles = false;
  AnalyticSurface analytic;  // shape Other when the face is not elementary or the source is a mesh
  bool has_triangles = false;  // false while a lazy source has not yet been asked for them
  TriangleMesh mesh;       // part-local triangles (empty until has_triangles)
};

// Where the ε collide uses for `s` came from: Coordinates when s.uncertainty is 0, else
// s.uncertainty_source.
inline UncertaintySource uncertainty_source(const Surface& s) {
  return s.uncertainty > 0.0 ? s.uncertainty_source : UncertaintySource::Coordinates;
}

struct Part {
  std::string name;
  std::string source_file;
  SurfaceId first_surface = 0;      // surfaces of a part are contiguous: [first_surface, first_surface + surface_count)
  std::uint32_t surface_count = 0;
  // Produces triangles on demand and answers exact-geometry queries; null for parts whose
  // surfaces all carry their triangles (meshes).
  std::shared_ptr<SurfaceSource> source;
};

struct Instance {
  std::string path;  // "/root/sub::2/leaf": names from the root joined by '/', "::k" when a name repeats among siblings
  PartId part = kInvalidId;
  Pose pose = Pose::Identity();  // part-local → world
};

// A whole scene: flat arrays indexed by the ids above.
struct Model {
  std::vector<Part> parts;
  std::vector<Surface> surfaces;
  std::vector<Instance> instances;
  // Counts changes to surfaces' triangles or deflections while scenes are built on the model:
  // require_triangles and a scene's own lazy tessellation add one. A Scene keeps what it derives from
  // those (per-part search reaches) until this changes, so whoever changes a surface's triangles or
  // deflection by hand while a Scene is on the model adds one too.
  std::uint64_t revision = 0;
};

// Supplies what a part's importer knows beyond triangles: lazy tessellation and exact geometry.
// Implemented in cadclash::tessellate for B-rep parts; collide never sees OCCT.
class SurfaceSource {
 public:
  virtual ~SurfaceSource() = default;

  // Triangulates the part's `local_index`-th surface with a deflection no larger than `deflection`
  // (<= 0 means the source's configured default). Writes triangles in the part's local frame and the
  // achieved deflection. Returns false and fills `error` if the face could not be meshed.
  // Thread-safe for concurrent calls on different parts; calls on one part may serialise.
  virtual bool triangulate(std::uint32_t local_index, double deflection, TriangleMesh& out,
                           double& achieved_deflection, Diagnostic& error) = 0;

  // Triangulates only the part of surface `local_index` inside `region` (an axis-aligned box in the
  // part's local frame) with a deflection no larger than `deflection` > 0: every point of the surface
  // inside the region lies within the achieved deflection of the triangles written, and every point of
  // them within it of the surface (they may reach past the region; none when the surface misses it).
  // For a refinement that only the neighbourhood of another face needs (a board's top face near one
  // pin). Returns false, with `error`, when the source cannot mesh a region: then the caller meshes the
  // whole surface. Thread-safe for concurrent calls on any parts; the default cannot.
  virtual bool triangulate_region(std::uint32_t local_index, double deflection, const Aabb& region, TriangleMesh& out,
                                  double& achieved_deflection, Diagnostic& error) {
    (void)local_index, (void)deflection, (void)region, (void)out, (void)achieved_deflection;
    error = Diagnostic{Severity::Error, "", 0, -1, "this source cannot mesh part of a surface"};
    return false;
  }

  // The deflection the part was loaded with (absolute, mm): what triangulate() meshes at when given
  // deflection <= 0, so what a query assumes for a lazy surface not tessellated yet. 0 when unknown.
  virtual double default_deflection() const { return 0.0; }

  // An upper bound on the distance from `point` (this part's local frame) to surface `local_index`'s
  // exact face, realised by a point of that face (its distance to `point`, rounding included): the
  // exact distance is the tightest such bound. nullopt when there is no exact geometry or no point
  // was found. Thread-safe like exact_distance. The certified decision asks it about mesh vertices:
  // a vertex of one face within T of the other face proves the two in contact, at a fraction of a
  // face–face distance's cost.
  virtual std::optional<double> point_distance(std::uint32_t local_index, const Vec3& point) const {
    (void)local_index, (void)point;
    return std::nullopt;
  }

  // A point of the surface that face `local_index` lies on, near `point` (this part's local frame):
  // the local foot point of `point`, found by Newton from the face's nearest triangulation node, with
  // the unit surface normal there (either orientation) and a bound on the rounding of its evaluation.
  // It may lie outside the face's boundary: the caller decides that (the certified decision checks
  // it against the face's triangles, which is cheaper than an exact face classifier). nullopt when
  // there is no exact geometry or Newton failed. Thread-safe like exact_distance.
  struct SurfacePoint {
    Vec3 point = Vec3::Zero();
    Vec3 normal = Vec3::UnitZ();
    double rounding = 0.0;  // |point - the surface's true point at its parameters| is below this
  };
  virtual std::optional<SurfacePoint> surface_point(std::uint32_t local_index, const Vec3& point) const {
    (void)local_index, (void)point;
    return std::nullopt;
  }

  // Bounds [lo, hi] on the signed height n·(x - origin) over every point x of face `local_index`
  // (part-local; `normal` a unit vector), from a hull the face lies in: for B-spline and Bézier
  // surfaces the convex hull of their control points (positive weights), rounding included. A
  // lower bound on the face's distance to the plane (origin, normal) when lo > 0 or hi < 0. nullopt
  // when the source knows no such hull for the face. Thread-safe like exact_distance.
  virtual std::optional<std::array<double, 2>> height_range(std::uint32_t local_index, const Vec3& origin,
                                                            const Vec3& normal) const {
    (void)local_index, (void)origin, (void)normal;
    return std::nullopt;
  }

  // The surface face `local_index` lies on as rational Bézier patches in this part's local frame: every
  // point of the face lies on one of them (they may cover more of the surface than the face), up to
  // `rounding` (mm) for the conversion's arithmetic. A patch's surface lies in the convex hull of its
  // control points (all weights > 0), which is what lets collide bound two faces' distance from below
  // without OCCT. nullopt when there is no exact geometry or the surface has no such form.
  // Thread-safe like exact_distance.
  struct BezierPatch {
    int degree_u = 0, degree_v = 0;
    std::vector<Vec3> points;     // (degree_u + 1) x (degree_v + 1), index i * (degree_v + 1) + j
    std::vector<double> weights;  // the same size, each > 0
  };
  struct BezierPatches {
    std::vector<BezierPatch> patches;
    double rounding = 0.0;
  };
  virtual std::optional<BezierPatches> bezier_patches(std::uint32_t local_index) const {
    (void)local_index;
    return std::nullopt;
  }

  // The round holes of planar face `local_index` (a board's drilled holes): for each, a point `centre`
  // on the face's plane and a `radius` such that every point of the face lies at least `radius` from
  // the line through `centre` along the plane's normal (part-local; the edges' tolerances, the
  // circle's tilt and offset from the plane and all rounding already taken off). A part reaching
  // through a hole is kept off the face by its distance from that line. Empty when the face is not
  // planar or has no such hole. Computed once per face and kept; thread-safe like exact_distance.
  struct CircularHole {
    Vec3 centre = Vec3::Zero();
    double radius = 0.0;
  };
  virtual std::shared_ptr<const std::vector<CircularHole>> circular_holes(std::uint32_t local_index) const {
    (void)local_index;
    return nullptr;
  }

  // The point of face `local_index`'s edges farthest along `direction` (a unit vector, part-local)
  // near `near`: Newton on the edge curve nearest `near` for the extremum of direction·C(t), clamped
  // to the edge's ends; the point, its rounding (normal unused). A point of the face: where a face
  // touches a plane at one point of a curved edge, this is that point. nullopt when there is no
  // exact geometry or no edge was found. Thread-safe like exact_distance.
  virtual std::optional<SurfacePoint> edge_support(std::uint32_t local_index, const Vec3& direction,
                                                   const Vec3& near) const {
    (void)local_index, (void)direction, (void)near;
    return std::nullopt;
  }

  // An upper bound on the distance from `point` (part-local) to face `local_index`'s boundary, realised
  // by a point of one of its edge curves (so a point of the face): what point_distance falls back to
  // for a foot point outside the face, without the foot point and the face classifier before it.
  // Cheaper when the caller knows the point lies on or next to the boundary. nullopt when there is
  // no exact geometry or no edge point was found. Thread-safe like exact_distance.
  virtual std::optional<double> boundary_distance(std::uint32_t local_index, const Vec3& point) const {
    (void)local_index, (void)point;
    return std::nullopt;
  }

  // An upper bound on the distance between this part's surface `local_a` placed by `pose_a` and
  // `other`'s surface `local_b` placed by `pose_b`, realised by a point on an edge of each: the local
  // extremum of the two edges nearest `near_a` and `near_b` (each in its own part frame; typically
  // the mesh outline points where the faces come closest), found by Newton from those points. Cheap
  // (no global search); proves contact where two faces meet edge to edge, as a curved edge tangent
  // to a straight one. nullopt when there is no exact geometry or no such point was found.
  // Thread-safe like exact_distance.
  virtual std::optional<double> edge_distance(std::uint32_t local_a, const Pose& pose_a, const SurfaceSource& other,
                                              std::uint32_t local_b, const Pose& pose_b, const Vec3& near_a,
                                              const Vec3& near_b) const {
    (void)local_a, (void)pose_a, (void)other, (void)local_b, (void)pose_b, (void)near_a, (void)near_b;
    return std::nullopt;
  }

  // Exact distance between this part's surface `local_a` placed by `pose_a` and `other`'s surface
  // `local_b` placed by `pose_b`, searching only up to `max_distance` (a value > max_distance means
  // "farther than that"). With `enough` > 0 the search may stop at the first two points of the faces
  // within `enough` of each other: the value is then their distance, an upper bound <= enough (the
  // certified decision needs no more to prove contact). Returns nullopt when either side has no
  // exact geometry. Called from several threads at once, also for the same parts: thread-safe.
  virtual std::optional<double> exact_distance(std::uint32_t local_a, const Pose& pose_a,
                                               const SurfaceSource& other, std::uint32_t local_b,
                                               const Pose& pose_b, double max_distance,
                                               double enough = 0.0) const {
    (void)local_a, (void)pose_a, (void)other, (void)local_b, (void)pose_b, (void)max_distance, (void)enough;
    return std::nullopt;
  }
};

// Appends `from` to `into`, shifting its ids. Used to form one scene from several files.
// Instance paths of `from` are prefixed with `path_prefix` (e.g. "/file.stp") when it is not empty.
void append_model(Model& into, Model from, const std::string& path_prefix = {});

// Computes a surface's AABB from its triangles (part-local). Empty box for an empty mesh.
Aabb mesh_aabb(const TriangleMesh& mesh);

// Makes sure every listed surface has triangles, asking its part's SurfaceSource for the missing
// ones (in parallel across parts, on `threads` threads; <= 0: all available). Surfaces that fail are
// listed in the returned diagnostics and keep has_triangles == false. `deflection` <= 0 uses each
// source's default. Adds one to model.revision when any listed surface was missing triangles.
// Precondition: every id < model.surfaces.size().
std::vector<Diagnostic> require_triangles(Model& model, std::span<const SurfaceId> surfaces,
                                          double deflection = 0.0, int threads = 0);

// Counts triangles over all surfaces that have them.
std::size_t triangle_count(const Model& model);

}  // namespace cadclash
