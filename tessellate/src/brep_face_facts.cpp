// What collide's certified decisions need to know about an exact face: its uncertainty, its
// elementary surface, and whether its triangles are the face itself.
#include "brep_internal.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRep_Tool.hxx>
#include <Precision.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <gp_Cone.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <gp_Sphere.hxx>
#include <gp_Torus.hxx>

#include <algorithm>
#include <cmath>

namespace cadclash::detail {
namespace {

Vec3 vec(const gp_XYZ& p) { return Vec3(p.X(), p.Y(), p.Z()); }

AnalyticSurface analytic_of(const BRepAdaptor_Surface& s) {
  AnalyticSurface a;
  switch (s.GetType()) {
    case GeomAbs_Plane: {
      const gp_Pln p = s.Plane();
      a.shape = SurfaceShape::Plane;
      a.origin = vec(p.Location().XYZ());
      a.axis = vec(p.Axis().Direction().XYZ());
      break;
    }
    case GeomAbs_Cylinder: {
      const gp_Cylinder c = s.Cylinder();
      a.shape = SurfaceShape::Cylinder;
      a.origin = vec(c.Location().XYZ());
      a.axis = vec(c.Axis().Direction().XYZ());
      a.radius = c.Radius();
      break;
    }
    case GeomAbs_Cone: {
      const gp_Cone c = s.Cone();
      a.shape = SurfaceShape::Cone;
      a.origin = vec(c.Apex().XYZ());
      a.axis = vec(c.Axis().Direction().XYZ());
      a.radius2 = std::abs(c.SemiAngle());
      break;
    }
    case GeomAbs_Sphere: {
      const gp_Sphere sp = s.Sphere();
      a.shape = SurfaceShape::Sphere;
      a.origin = vec(sp.Location().XYZ());
      a.radius = sp.Radius();
      break;
    }
    case GeomAbs_Torus: {
      const gp_Torus t = s.Torus();
      a.shape = SurfaceShape::Torus;
      a.origin = vec(t.Location().XYZ());
      a.axis = vec(t.Axis().Direction().XYZ());
      a.radius = t.MajorRadius();
      a.radius2 = t.MinorRadius();
      break;
    }
    default: break;
  }
  return a;
}

}  // namespace

void describe_face(const TopoDS_Face& face, Surface& out) {
  double tol = std::max(Precision::Confusion(), BRep_Tool::Tolerance(face));
  bool straight = true;
  for (TopExp_Explorer ex(face, TopAbs_EDGE); ex.More(); ex.Next()) {
    const TopoDS_Edge& e = TopoDS::Edge(ex.Current());
    tol = std::max(tol, BRep_Tool::Tolerance(e));
    if (BRep_Tool::Degenerated(e)) continue;
    try {
      straight = straight && BRepAdaptor_Curve(e).GetType() == GeomAbs_Line;
    } catch (const Standard_Failure&) {
      straight = false;
    }
  }
  for (TopExp_Explorer ex(face, TopAbs_VERTEX); ex.More(); ex.Next())
    tol = std::max(tol, BRep_Tool::Tolerance(TopoDS::Vertex(ex.Current())));
  out.uncertainty = std::max(out.uncertainty, tol);
  out.uncertainty_source = UncertaintySource::OcctTolerance;
  out.tolerance = tol;
  try {
    const BRepAdaptor_Surface surface(face, Standard_False);  // part-local, as the triangles are
    out.analytic = analytic_of(surface);
  } catch (const Standard_Failure&) {
    out.analytic = AnalyticSurface{};
  }
  out.exact_triangles = out.analytic.shape == SurfaceShape::Plane && straight;
}

}  // namespace cadclash::detail
