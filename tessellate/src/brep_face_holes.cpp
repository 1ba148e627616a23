// The round holes of a planar face (SurfaceSource::circular_holes): a board's drilled holes, through
// which the pins of its components reach. A pin is kept off the board's face by its distance from
// the hole's axis; what makes that a proof is stated where each hole is accepted below.
#include "brep_internal.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <ElSLib.hxx>
#include <gp_Pnt2d.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Circ.hxx>
#include <gp_Pln.hxx>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

namespace cadclash::detail {
namespace {

Vec3 vec(const gp_XYZ& p) { return Vec3(p.X(), p.Y(), p.Z()); }

// One inner wire all of whose edges lie on one circle.
struct WireCircle {
  Vec3 centre = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  double radius = 0.0;
  double tolerance = 0.0;  // the largest of its edges' and vertices' tolerances
};

// The circle wire `w` runs once around, or nullopt: every edge on a circle of the same centre,
// radius and axis (within `same`), the sampled points covering every one of 64 sectors of it, and
// the parameter spans adding up to one turn (so no sector is run twice).
std::optional<WireCircle> wire_circle(const TopoDS_Wire& w, double same) {
  WireCircle c;
  bool first = true;
  double span = 0.0;
  std::vector<gp_Pnt> samples;
  for (TopExp_Explorer e(w, TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
    if (BRep_Tool::Degenerated(edge)) return std::nullopt;
    const BRepAdaptor_Curve curve(edge);
    if (curve.GetType() != GeomAbs_Circle) return std::nullopt;
    const gp_Circ circ = curve.Circle();
    const Vec3 centre = vec(circ.Location().XYZ()), axis = vec(circ.Axis().Direction().XYZ());
    if (first) {
      c.centre = centre, c.axis = axis, c.radius = circ.Radius();
      first = false;
    } else if ((centre - c.centre).norm() > same || std::abs(circ.Radius() - c.radius) > same ||
               axis.cross(c.axis).norm() > 1e-9) {
      return std::nullopt;
    }
    c.radius = std::min(c.radius, circ.Radius() - (centre - c.centre).norm());
    c.tolerance = std::max(c.tolerance, BRep_Tool::Tolerance(edge));
    for (TopExp_Explorer v(edge, TopAbs_VERTEX); v.More(); v.Next())
      c.tolerance = std::max(c.tolerance, BRep_Tool::Tolerance(TopoDS::Vertex(v.Current())));
    const double t0 = curve.FirstParameter(), t1 = curve.LastParameter();
    span += std::abs(t1 - t0);
    // Four samples per sector's width of arc at least, so an arc leaves none of its sectors out.
    const int count = std::max(4, static_cast<int>(std::ceil(std::abs(t1 - t0) / (2.0 * std::numbers::pi) * 256.0)));
    for (int k = 0; k <= count; ++k) samples.push_back(curve.Value(t0 + (t1 - t0) * k / count));
  }
  if (first || c.radius <= 0.0) return std::nullopt;
  constexpr double kTurn = 2.0 * std::numbers::pi;
  if (std::abs(span - kTurn) > 1e-9 * kTurn) return std::nullopt;
  // Sectors in the circle's own plane, from any direction across its axis.
  const Vec3 u = c.axis.unitOrthogonal(), v = c.axis.cross(u);
  std::array<bool, 64> covered{};
  for (const gp_Pnt& p : samples) {
    const Vec3 d = vec(p.XYZ()) - c.centre;
    const double a = std::atan2(d.dot(v), d.dot(u)) + std::numbers::pi;  // [0, 2pi]
    covered[std::min<std::size_t>(63, static_cast<std::size_t>(a / kTurn * 64.0))] = true;
  }
  if (!std::all_of(covered.begin(), covered.end(), [](bool b) { return b; })) return std::nullopt;
  return c;
}

}  // namespace

std::vector<SurfaceSource::CircularHole> face_circular_holes(const TopoDS_Face& face, const FaceLocator& where) {
  std::vector<SurfaceSource::CircularHole> holes;
  const BRepAdaptor_Surface surface(face);
  if (surface.GetType() != GeomAbs_Plane) return holes;
  const gp_Pln plane = surface.Plane();
  const Vec3 origin = vec(plane.Location().XYZ());
  const Vec3 n = vec(plane.Axis().Direction().XYZ()).normalized();
  const TopoDS_Wire outer = BRepTools::OuterWire(face);
  std::vector<TopoDS_Wire> wires;
  for (TopExp_Explorer w(face, TopAbs_WIRE); w.More(); w.Next()) wires.push_back(TopoDS::Wire(w.Current()));
  const double same = Precision::Confusion();
  for (const TopoDS_Wire& w : wires) {
    if (w.IsSame(outer)) continue;
    const std::optional<WireCircle> c = wire_circle(w, same);
    if (!c) continue;
    // The circle's points lie within R(1 - cos θ) of the line through its centre along n, θ the tilt
    // of its axis from n; the face's boundary there (its pcurves on the plane) within the edges'
    // tolerance of the circle. So every boundary point of this wire is at least ρ from the line:
    const double cos_tilt = std::min(1.0, std::abs(c->axis.dot(n)));
    const Vec3 centre = c->centre - n.dot(c->centre - origin) * n;  // on the plane
    const double magnitude = centre.cwiseAbs().maxCoeff() + origin.cwiseAbs().maxCoeff() + c->radius;
    const double rho = c->radius * cos_tilt - c->tolerance - 64.0 * std::numeric_limits<double>::epsilon() * magnitude;
    if (!(rho > 10.0 * std::max(c->tolerance, same))) continue;
    // ... the wire winds once around the centre, which lies outside the face: the disk of radius ρ
    // about it meets no boundary of this wire, so it is all outside the face, unless another wire
    // of the face lies inside it (a valid face has none; checked by one vertex of each).
    // (The face's classifier of its parameter domain, made once per face: the plane's parameters
    // are the same for the face's location applied to both.)
    double u = 0.0, v = 0.0;
    ElSLib::Parameters(plane, gp_Pnt(centre.x(), centre.y(), centre.z()), u, v);
    if (where.classify(u, v) != TopAbs_OUT) continue;
    const bool nested = std::any_of(wires.begin(), wires.end(), [&](const TopoDS_Wire& other) {
      if (other.IsSame(w)) return false;
      TopExp_Explorer first(other, TopAbs_VERTEX);
      if (!first.More()) return false;
      const Vec3 p = vec(BRep_Tool::Pnt(TopoDS::Vertex(first.Current())).XYZ()) - centre;
      return (p - n.dot(p) * n).norm() < c->radius + c->tolerance;
    });
    if (nested) continue;
    holes.push_back({centre, rho});
  }
  return holes;
}

}  // namespace cadclash::detail
