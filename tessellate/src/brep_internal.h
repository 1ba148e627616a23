// Internal pieces of the B-rep tessellation shared by brep_source.cpp and brep_parts.cpp.
#pragma once

#include "cadclash/tessellate.h"

#include <TopoDS_Face.hxx>
#include <gp_Trsf.hxx>

#include <chrono>
#include <optional>
#include <shared_mutex>
#include <string>
#include <vector>

namespace cadclash {

struct BrepSource::Impl {
  std::string part_name;
  std::string source_file;
  std::vector<TopoDS_Face> faces;           // part-local, in face-index order
  std::vector<std::int64_t> entity_ids;     // per face; -1 if unknown
  std::vector<Aabb> boxes;                  // part-local box of each exact face
  std::vector<char> exact_faces;            // per face: planar and bounded by lines (deflection 0)
  double default_deflection = 0.1;          // absolute, mm
  double angular_deflection = 0.5;
  bool verify_deflection = true;
  // BRepMesh writes triangulations into the shared TShapes: meshing holds it exclusively; exact
  // distances only read the faces (OCCT's own parallel BRepExtrema does the same) and share it.
  mutable std::shared_mutex mutex;
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

// Runs BRepMesh_IncrementalMesh on `shape` (a face or a compound of faces) with an absolute linear
// deflection, asking it to stop at `deadline`. Returns false and fills `why` when OCCT throws or the
// deadline stopped it (some faces may then have triangles).
bool run_brepmesh(const TopoDS_Shape& shape, double deflection, double angular, bool parallel, std::string& why,
                  const MeshDeadline& deadline = {});

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

// Minimum distance between two shapes (here: placed faces), equal bit for bit to
// BRepExtrema_DistShapeShape(a, b, Extrema_ExtFlag_MIN).Value(), but it stops as soon as the distance
// is 0. nullopt when OCCT finds no solution. May throw Standard_Failure. Reads the shapes only.
std::optional<double> min_distance(const TopoDS_Shape& a, const TopoDS_Shape& b);

// What the exact face says about itself (collide.h, Surface): its model uncertainty (the largest
// OCCT tolerance of the face, its edges and vertices, never below Precision::Confusion), its
// elementary surface, and whether its triangles are exactly the face (a plane bounded by lines).
void describe_face(const TopoDS_Face& face, Surface& out);

gp_Trsf to_trsf(const Pose& pose);
Pose to_pose(const gp_Trsf& trsf);

}  // namespace detail
}  // namespace cadclash
