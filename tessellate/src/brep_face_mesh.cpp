// One B-rep face: BRepMesh, reading its triangulation, measuring its chord error, its exact box.
#include "brep_internal.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepMesh_Context.hxx>
#include <BRepMesh_DelabellaMeshAlgoFactory.hxx>
#include <BRepMesh_FaceDiscret.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepMesh_MeshAlgoFactory.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <IMeshTools_MeshAlgoFactory.hxx>
#include <IMeshTools_Parameters.hxx>
#include <Message_ProgressIndicator.hxx>
#include <Message_ProgressScope.hxx>
#include <Poly_PolygonOnTriangulation.hxx>
#include <Poly_Triangulation.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS.hxx>
#include <gp_Vec.hxx>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

namespace cadclash::detail {
namespace {

// Distance from a triangle's centroid to the surface, estimated from the surface point at the
// triangle's UV centroid and refined by a few Gauss-Newton steps towards the foot point (the UV
// centroid alone overestimates badly where the parametrisation is distorted, e.g. near a sphere's
// pole). Every candidate is a point of the surface, so the result never underestimates by more
// than the steps' distance from the face's trimming.
double centroid_gap(const BRepAdaptor_Surface& surface, const Vec3& centroid, double u, double v) {
  const gp_Pnt c(centroid.x(), centroid.y(), centroid.z());
  const double u0 = surface.FirstUParameter(), u1 = surface.LastUParameter();
  const double v0 = surface.FirstVParameter(), v1 = surface.LastVParameter();
  double best = 1e300;
  for (int step = 0; step < 4; ++step) {
    gp_Pnt p;
    gp_Vec du, dv;
    surface.D1(u, v, p, du, dv);
    const gp_Vec r(c, p);  // from the centroid to the surface point
    best = std::min(best, r.Magnitude());
    if (step == 3) break;
    // Solve [du.du du.dv; du.dv dv.dv] [a b]^T = -[r.du r.dv]^T.
    const double a11 = du.Dot(du), a12 = du.Dot(dv), a22 = dv.Dot(dv);
    const double det = a11 * a22 - a12 * a12;
    if (!(std::abs(det) > 1e-300)) break;
    const double b1 = -r.Dot(du), b2 = -r.Dot(dv);
    u = std::clamp(u + (a22 * b1 - a12 * b2) / det, u0, u1);
    v = std::clamp(v + (a11 * b2 - a12 * b1) / det, v0, v1);
  }
  return best;
}

// How far the face's boundary polygons stray from its exact edges. A planar face bounded by a circle
// has a perfect interior (every triangle lies in the plane) yet its outline is a polygon whose chords
// cut up to the sagitta inside the arc: a bolt in a nut's hole is then seen apart or crossing by that
// much. Measured at chord midpoints against the curve at the mid parameter (exact for circles); where
// it cannot be measured, BRepMesh's own (requested, so pessimistic) figure for the edge stands.
double boundary_gap(const TopoDS_Face& face, const Handle(Poly_Triangulation)& tri, const TopLoc_Location& loc,
                    bool measure) {
  double worst = 0.0;
  for (TopExp_Explorer ex(face, TopAbs_EDGE); ex.More(); ex.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(ex.Current());
    if (BRep_Tool::Degenerated(edge)) continue;
    const Handle(Poly_PolygonOnTriangulation) poly = BRep_Tool::PolygonOnTriangulation(edge, tri, loc);
    if (poly.IsNull()) continue;
    if (!measure || !poly->HasParameters() || poly->NbNodes() < 2) {
      worst = std::max(worst, poly->Deflection());
      continue;
    }
    try {
      const BRepAdaptor_Curve curve(edge);  // in the face's frame, as the triangulation nodes are
      const gp_Trsf& trsf = loc.Transformation();
      const bool moved = !loc.IsIdentity();
      gp_Pnt prev = tri->Node(poly->Node(1));
      if (moved) prev.Transform(trsf);
      for (Standard_Integer i = 2; i <= poly->NbNodes(); ++i) {
        gp_Pnt next = tri->Node(poly->Node(i));
        if (moved) next.Transform(trsf);
        const double t = 0.5 * (poly->Parameter(i - 1) + poly->Parameter(i));
        const gp_Pnt mid((prev.XYZ() + next.XYZ()) * 0.5);
        worst = std::max(worst, mid.Distance(curve.Value(t)));
        prev = next;
      }
    } catch (const Standard_Failure&) {
      worst = std::max(worst, poly->Deflection());  // no evaluable curve: BRepMesh's own figure
    }
  }
  return worst;
}

// BRepMesh polls UserBreak between its stages and faces (from its worker threads too).
class DeadlineIndicator : public Message_ProgressIndicator {
 public:
  explicit DeadlineIndicator(std::chrono::steady_clock::time_point at) : at_(at) {}
  Standard_Boolean UserBreak() override { return std::chrono::steady_clock::now() >= at_; }
  void Show(const Message_ProgressScope&, const Standard_Boolean) override {}

 private:
  std::chrono::steady_clock::time_point at_;
};

// Planes by OCCT's Delabella triangulation, every other surface by its default (Watson). On a plane
// BRepMesh adds no nodes inside the face: both build a constrained Delaunay triangulation of the
// same boundary nodes, covering the same region. Watson's insertion looks up circumcircles in a
// cell filter that long triangles between a face's holes cross end to end: a board's 1.6 mm plate
// with 1,400 drilled holes takes 8 s a face with it, 0.4 s with Delabella (same 39,202 triangles,
// same area). Named explicitly, so OCCT's CSF_MeshAlgo environment variable cannot change a mesh.
class PlanesByDelabella final : public IMeshTools_MeshAlgoFactory {
 public:
  Handle(IMeshTools_MeshAlgo) GetAlgo(const GeomAbs_SurfaceType type,
                                      const IMeshTools_Parameters& parameters) const override {
    return type == GeomAbs_Plane ? delabella_->GetAlgo(type, parameters) : watson_->GetAlgo(type, parameters);
  }

 private:
  Handle(IMeshTools_MeshAlgoFactory) delabella_ = new BRepMesh_DelabellaMeshAlgoFactory;
  Handle(IMeshTools_MeshAlgoFactory) watson_ = new BRepMesh_MeshAlgoFactory;
};

Handle(IMeshTools_Context) mesh_context(MeshAlgorithm algorithm) {
  Handle(IMeshTools_MeshAlgoFactory) factory;
  if (algorithm == MeshAlgorithm::Watson) factory = new BRepMesh_MeshAlgoFactory;
  else factory = new PlanesByDelabella;
  Handle(BRepMesh_Context) context = new BRepMesh_Context(IMeshTools_MeshAlgoType_Watson);
  context->SetFaceDiscret(new BRepMesh_FaceDiscret(factory));
  return context;
}

bool has_triangles(const TopoDS_Face& face) {
  TopLoc_Location loc;
  const Handle(Poly_Triangulation)& tri = BRep_Tool::Triangulation(face, loc);
  return !tri.IsNull() && tri->NbTriangles() > 0;
}

}  // namespace

MeshDeadline MeshDeadline::after(double seconds) {
  MeshDeadline d;
  if (!(seconds > 0.0)) return d;
  d.limit_seconds = seconds;
  d.at = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                std::chrono::duration<double>(std::min(seconds, 1e9)));
  return d;
}

std::string MeshDeadline::reason() const {
  std::ostringstream out;
  out << "the tessellation time limit of " << limit_seconds << " s ran out";
  return out.str();
}

bool run_brepmesh(const TopoDS_Shape& shape, double deflection, double angular, bool parallel, std::string& why,
                  const MeshDeadline& deadline, MeshAlgorithm algorithm) {
  BRepMesh_IncrementalMesh mesher;
  mesher.SetShape(shape);
  IMeshTools_Parameters& params = mesher.ChangeParameters();
  params.Deflection = deflection;
  params.Angle = angular;
  params.Relative = Standard_False;  // relative deflections are resolved per part by the caller
  params.InParallel = parallel ? Standard_True : Standard_False;
  try {
    if (!deadline.at) {
      mesher.Perform(mesh_context(algorithm));
      return true;
    }
    if (deadline.passed()) {
      why = deadline.reason();
      return false;
    }
    const Handle(DeadlineIndicator) indicator = new DeadlineIndicator(*deadline.at);
    mesher.Perform(mesh_context(algorithm), indicator->Start());
    if (deadline.passed()) {
      why = deadline.reason();
      return false;
    }
    return true;
  } catch (const Standard_Failure& e) {
    why = std::string("BRepMesh failed: ") + e.GetMessageString();
  } catch (const std::exception& e) {
    why = std::string("BRepMesh failed: ") + e.what();
  }
  return false;
}

bool read_face_triangles(const TopoDS_Face& face, bool measure, TriangleMesh& out, double& achieved) {
  TopLoc_Location loc;
  const Handle(Poly_Triangulation)& tri = BRep_Tool::Triangulation(face, loc);
  if (tri.IsNull() || tri->NbTriangles() == 0 || tri->NbNodes() < 3) return false;
  const bool moved = !loc.IsIdentity();
  const gp_Trsf& trsf = loc.Transformation();
  out.vertices.clear();
  out.triangles.clear();
  out.vertices.reserve(static_cast<std::size_t>(tri->NbNodes()));
  for (Standard_Integer i = 1; i <= tri->NbNodes(); ++i) {
    gp_Pnt p = tri->Node(i);
    if (moved) p.Transform(trsf);
    out.vertices.emplace_back(p.X(), p.Y(), p.Z());
  }
  // A reversed face's outward normal is opposite to its surface normal; BRepMesh winds by the surface.
  const bool reversed = face.Orientation() == TopAbs_REVERSED;
  out.triangles.reserve(static_cast<std::size_t>(tri->NbTriangles()));
  for (Standard_Integer i = 1; i <= tri->NbTriangles(); ++i) {
    Standard_Integer a = 0, b = 0, c = 0;
    tri->Triangle(i).Get(a, b, c);
    if (reversed) std::swap(b, c);
    out.triangles.push_back({static_cast<std::uint32_t>(a - 1), static_cast<std::uint32_t>(b - 1),
                             static_cast<std::uint32_t>(c - 1)});
  }
  achieved = std::max(tri->Deflection(), boundary_gap(face, tri, loc, measure));
  if (!measure || !tri->HasUVNodes()) return true;
  try {
    const BRepAdaptor_Surface surface(face, Standard_False);  // applies the face's location
    double worst = 0.0;
    for (const auto& t : out.triangles) {
      const gp_Pnt2d uv0 = tri->UVNode(static_cast<Standard_Integer>(t[0]) + 1);
      const gp_Pnt2d uv1 = tri->UVNode(static_cast<Standard_Integer>(t[1]) + 1);
      const gp_Pnt2d uv2 = tri->UVNode(static_cast<Standard_Integer>(t[2]) + 1);
      const Vec3 centroid = (out.vertices[t[0]] + out.vertices[t[1]] + out.vertices[t[2]]) / 3.0;
      worst = std::max(worst, centroid_gap(surface, centroid, (uv0.X() + uv1.X() + uv2.X()) / 3.0,
                                           (uv0.Y() + uv1.Y() + uv2.Y()) / 3.0));
    }
    achieved = std::max(achieved, worst);
  } catch (const Standard_Failure&) {
    // No evaluable surface: keep BRepMesh's own figure.
  }
  return true;
}

bool mesh_face_to(const TopoDS_Face& face, double target, double angular, bool verify, TriangleMesh& out,
                  double& achieved, std::string& why, const MeshDeadline& deadline) {
  double param = target;
  bool have = false;
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (deadline.passed()) {
      // No time to refine: a triangulation the face already has is kept, with its honest deflection.
      if (have || read_face_triangles(face, verify, out, achieved)) return true;
      why = deadline.reason();
      return false;
    }
    TopLoc_Location loc;
    const Handle(Poly_Triangulation)& tri = BRep_Tool::Triangulation(face, loc);
    // BRepMesh accepts an existing triangulation up to ~1.1x the requested deflection; a refinement
    // must not, so a coarser one is removed first.
    if (tri.IsNull() || tri->Deflection() > param || attempt > 0) {
      try {
        BRepTools::Clean(face);
      } catch (const Standard_Failure&) {
      }
      bool ran = run_brepmesh(face, param, angular, false, why, deadline);
      if (!deadline.passed() && (!ran || !has_triangles(face))) {
        // What Delabella leaves bare (or throws on), Watson meshes (issue 117 of materializr-cad saw
        // Delabella leave valid faces bare).
        try {
          BRepTools::Clean(face);
        } catch (const Standard_Failure&) {
        }
        ran = run_brepmesh(face, param, angular, false, why, deadline, MeshAlgorithm::Watson);
      }
      if (!ran) return have;
    }
    TriangleMesh mesh;
    double got = 0.0;
    if (!read_face_triangles(face, verify, mesh, got)) {
      if (!have) why = "BRepMesh produced no triangles";
      return have;
    }
    out = std::move(mesh);
    achieved = got;
    have = true;
    if (!verify || achieved <= target) return true;
    param *= 0.5;
  }
  return true;  // still above target after the refinement: achieved says so honestly
}

Aabb face_aabb(const TopoDS_Face& face) {
  Bnd_Box box;
  try {
    const BRepAdaptor_Surface surface(face, Standard_False);
    switch (surface.GetType()) {
      case GeomAbs_Plane:
      case GeomAbs_Cylinder:
      case GeomAbs_Cone:
      case GeomAbs_Sphere:
      case GeomAbs_Torus: BRepBndLib::AddOptimal(face, box, Standard_False, Standard_False); break;
      default: BRepBndLib::Add(face, box, Standard_False); break;
    }
  } catch (const Standard_Failure&) {
    box.SetVoid();
    try {
      BRepBndLib::Add(face, box, Standard_True);
    } catch (const Standard_Failure&) {
      box.SetVoid();
    }
  }
  if (box.IsVoid() || box.IsOpen()) return Aabb{};
  double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
  box.Get(x0, y0, z0, x1, y1, z1);
  return Aabb(Vec3(x0, y0, z0), Vec3(x1, y1, z1));
}

gp_Trsf to_trsf(const Pose& pose) {
  const auto& m = pose.matrix();
  gp_Trsf t;
  t.SetValues(m(0, 0), m(0, 1), m(0, 2), m(0, 3), m(1, 0), m(1, 1), m(1, 2), m(1, 3), m(2, 0), m(2, 1), m(2, 2),
              m(2, 3));
  return t;
}

Pose to_pose(const gp_Trsf& trsf) {
  Pose p = Pose::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) p.matrix()(r, c) = trsf.Value(r + 1, c + 1);
    p.matrix()(r, 3) = trsf.Value(r + 1, 4);
  }
  return p;
}

}  // namespace cadclash::detail
