// Internal pieces of the B-rep tessellation shared by brep_source.cpp and brep_parts.cpp.
#pragma once

#include "cadclash/tessellate.h"

#include <TopoDS_Face.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <gp_Pnt.hxx>
#include <gp_Trsf.hxx>

#include <TopAbs_State.hxx>
#include <TopoDS_Edge.hxx>

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <vector>

class BRepTopAdaptor_FClass2d;

namespace cadclash {

namespace detail {
std::uint64_t next_source_id();  // brep_face_cache.h

// What a point query needs of one face, made once per face on first use: OCCT's classifier of its
// parameter domain (a polygon of the boundary's pcurves, points nearer than the polygon's measured
// deviation counting as on it) and its edges with their boxes.
struct FaceLocator {
  std::vector<std::pair<TopoDS_Edge, Aabb>> edges;  // edges with a 3D curve, each with its box
  // Per edge: points of its curve at evenly spaced parameters (t, point), where Newton starts.
  std::vector<std::vector<std::pair<double, gp_Pnt>>> samples;
  explicit FaceLocator(const TopoDS_Face& face);
  ~FaceLocator();
  // The classifier's state of the face's parameters (u, v) (BRepTopAdaptor_FClass2d::Perform, the
  // same answer from any thread). Thread-safe.
  TopAbs_State classify(double u, double v) const;

 private:
  TopoDS_Face face_;
  // Perform() is const but not thread-safe: the classifier keeps its wires in NCollection_Sequence,
  // whose Value() moves a cached cursor. So each call takes a classifier no other call is using,
  // made on first need (most faces' calls never overlap: one; the witness steps of a check on two
  // threads often ask the same face at once, and waited for each other's OCCT face classifier).
  mutable std::mutex idle_mutex_;
  mutable std::vector<std::unique_ptr<BRepTopAdaptor_FClass2d>> idle_;
};
}  // namespace detail

struct BrepSource::Impl {
  std::string part_name;
  std::string source_file;
  std::vector<TopoDS_Face> faces;           // part-local, in face-index order
  std::vector<std::int64_t> entity_ids;     // per face; -1 if unknown
  std::vector<Aabb> boxes;                  // part-local box of each exact face
  std::vector<char> exact_faces;            // per face: planar and bounded by lines (deflection 0)
  std::vector<char> outside_range;          // per face: beyond cadclash::kMaxLength, dropped (no triangles)
  double default_deflection = 0.1;          // absolute, mm
  double angular_deflection = 0.5;
  bool verify_deflection = true;
  // BRepMesh writes triangulations into the shared TShapes: meshing holds it exclusively; exact
  // distances only read the faces (OCCT's own parallel BRepExtrema does the same) and share it.
  mutable std::shared_mutex mutex;
  // Per face, made by point_distance on first use (under locator_mutex); read-only afterwards.
  mutable std::vector<std::unique_ptr<const detail::FaceLocator>> locators;
  mutable std::mutex locator_mutex;
  // Per face, made by circular_holes on first use (under holes_mutex); read-only afterwards.
  struct HolesSlot {
    std::once_flag made;
    std::shared_ptr<const std::vector<SurfaceSource::CircularHole>> holes;
  };
  mutable std::unique_ptr<HolesSlot[]> holes;  // faces.size() slots once asked
  mutable std::mutex holes_mutex;
  const detail::FaceLocator& locator(std::uint32_t local_index) const;
  // Names this source in the witness queries' per-thread caches (brep_face_cache.h), which let go of
  // its faces once `alive` has expired.
  const std::uint64_t id = detail::next_source_id();
  const std::shared_ptr<const char> alive = std::make_shared<const char>(0);
};

namespace detail {

// When meshing must stop (TessellationOptions::time_limit_seconds); by default, never.
struct MeshDeadline {
  std::optional<std::chrono::steady_clock::time_point> at;
  double limit_seconds = 0.0;  // for messages
  static MeshDeadline after(double seconds);  // seconds <= 0: never
  bool passed() const { return at && std::chrono::steady_clock::now() >= *at; }
  std::string reason() const;  // "the tessellation time limit of 2 s ran out"
};

// How BRepMesh triangulates a face's parameter plane: planes by Delabella and the rest by Watson
// (the default: Watson's cost grows with the square of a plane's holes), or all by Watson (a face
// Delabella left without triangles is tried again so).
enum class MeshAlgorithm { PlanesByDelabella, Watson };

// Runs BRepMesh_IncrementalMesh on `shape` (a face or a compound of faces) with an absolute linear
// deflection, asking it to stop at `deadline`. Returns false and fills `why` when OCCT throws or the
// deadline stopped it (some faces may then have triangles).
bool run_brepmesh(const TopoDS_Shape& shape, double deflection, double angular, bool parallel, std::string& why,
                  const MeshDeadline& deadline = {}, MeshAlgorithm algorithm = MeshAlgorithm::PlanesByDelabella);

// Reads the face's triangulation into `out` (part-local, outward winding). When `measure` is set,
// `achieved` is max(triangulation deflection, distance from each triangle centroid to the surface
// point at its UV centroid); otherwise the triangulation's own deflection. False if no triangles.
bool read_face_triangles(const TopoDS_Face& face, bool measure, TriangleMesh& out, double& achieved);

// Makes the face's triangulation meet `target` (re-meshing when it has none or a coarser one, and
// finer once more, at half, when the measured error still exceeds target) and reads it.
// Past `deadline` nothing is meshed (false, why = its reason) and no refinement is tried.
bool mesh_face_to(const TopoDS_Face& face, double target, double angular, bool verify, TriangleMesh& out,
                  double& achieved, std::string& why, const MeshDeadline& deadline = {});

// Part-local box enclosing the exact face: BRepBndLib::AddOptimal for analytic surfaces (cheap and
// tight), BRepBndLib::Add (control polygons) for the rest.
Aabb face_aabb(const TopoDS_Face& face);

// BRepCheck_Analyzer's verdict on one face (false when it throws). A face with many wires is
// checked as pieces (the outer wire with each cluster of inner wires whose parameter boxes overlap),
// since BRepCheck compares every wire with every other: the same verdict in linear time for a plate
// with many holes (brep_face_check.cpp).
bool face_is_valid(const TopoDS_Face& face);
// Whether face_is_valid checks `face` in pieces: a BRepCheck of a whole shape holding it is slow.
bool face_has_many_wires(const TopoDS_Face& face);

// Minimum distance between two shapes (here: placed faces), equal bit for bit to
// BRepExtrema_DistShapeShape(a, b, Extrema_ExtFlag_MIN).Value(), but it stops as soon as the distance
// is at most `enough` (0: once it is 0), returning that distance. nullopt when OCCT finds no
// solution. May throw Standard_Failure. Reads the shapes only.
std::optional<double> min_distance(const TopoDS_Shape& a, const TopoDS_Shape& b, double enough = 0.0);

// What the exact face says about itself (collide.h, Surface): its model uncertainty (the largest
// OCCT tolerance of the face, its edges and vertices, never below Precision::Confusion), its
// elementary surface, and whether its triangles are exactly the face (a plane bounded by lines).
void describe_face(const TopoDS_Face& face, Surface& out);

// An upper bound on the distance from `p` (the face's part frame) to the exact face, realised by a
// point of the face: Newton from the nearest node of the face's triangulation to a foot point on the
// surface, kept when the face's classifier (`where`) puts its parameters inside the face, farther
// than the boundary polygon's measured deviation from it; otherwise the nearest point found on the
// face's edge curves. The evaluation's rounding is added. nullopt when the face has no triangulation
// with parameters or Newton fails. `surface`: the face's adaptor (face_surface). Reads the face only.
// May throw Standard_Failure.
std::optional<double> face_point_witness(const BRepAdaptor_Surface& surface, const TopoDS_Face& face,
                                         const FaceLocator& where, const Aabb& face_box, const gp_Pnt& p);

// An upper bound on the distance from `p` to the face's boundary: the nearest point found on its edge
// curves (ShapeAnalysis_Curve, nearest edge box first), the evaluation's rounding added. May throw.
std::optional<double> face_boundary_witness(const FaceLocator& where, const Aabb& face_box, const gp_Pnt& p);

// Bounds of n·(x - o) over the face from the control points of its B-spline or Bézier surface (the
// surface lies in their convex hull when the weights are positive), rounding included; nullopt for
// other surfaces. Reads the face only. May throw Standard_Failure.
std::optional<std::array<double, 2>> face_height_range(const TopoDS_Face& face, const Vec3& o, const Vec3& n);

// The round holes of a planar face (SurfaceSource::circular_holes; brep_face_holes.cpp): inner wires
// running once around one circle whose centre the face's classifier (`where`) puts outside the face, radius
// reduced by the tilt and the edges' tolerances. Empty for other faces. May throw Standard_Failure.
std::vector<SurfaceSource::CircularHole> face_circular_holes(const TopoDS_Face& face, const FaceLocator& where);

// The face's surface as rational Bézier patches (part-local, the face's location applied): B-spline and
// Bézier surfaces (trimmed ones unwrapped) whole, planes, cylinders, cones, spheres and tori over the
// face's parameter bounds (GeomConvert's exact rational form); nullopt for other surfaces, for
// non-positive weights and for more than 1024 patches. May throw Standard_Failure.
std::optional<SurfaceSource::BezierPatches> face_bezier_patches(const TopoDS_Face& face);

// The extremum along `d` of the face's edge nearest `near` (Newton on d·C(t), clamped to the edge's
// ends), with the evaluation's rounding. May throw Standard_Failure.
std::optional<SurfaceSource::SurfacePoint> face_edge_support(const FaceLocator& where, const Aabb& face_box,
                                                             const Vec3& d, const gp_Pnt& near);

// The foot point of `p` on the face's surface by the same Newton, with the unit normal there and the
// evaluation's rounding; not classified (it may lie outside the face). nullopt when Newton fails or
// the surface is singular there. `surface`: the face's adaptor (face_surface). Reads the face only.
// May throw Standard_Failure.
std::optional<SurfaceSource::SurfacePoint> face_surface_point(const BRepAdaptor_Surface& surface,
                                                              const TopoDS_Face& face, const Aabb& face_box,
                                                              const gp_Pnt& p);

// An upper bound on the distance between two placed faces realised by a point on an edge of each:
// the edges of `a` and `b` nearest `near_a` / `near_b` (part frames), Newton (Extrema_LocateExtCC)
// from the projections of those points, the curves placed by `place_a` / `place_b`; the nearer of
// the start and the extremum, plus the evaluation's rounding. nullopt when a face has no edge with a
// 3D curve near its point. Reads the faces only. May throw Standard_Failure.
std::optional<double> edge_pair_witness(const FaceLocator& a, const gp_Trsf& place_a, const gp_Pnt& near_a,
                                        const FaceLocator& b, const gp_Trsf& place_b, const gp_Pnt& near_b);

gp_Trsf to_trsf(const Pose& pose);
Pose to_pose(const gp_Trsf& trsf);

}  // namespace detail
}  // namespace cadclash
