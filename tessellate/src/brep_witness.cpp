// A point of an exact face near a given point, found in microseconds: the certified decision needs
// an upper bound on a vertex's distance to a face (any point of the face realises one), not the
// minimum that BRepExtrema_DistShapeShape searches for in about half a millisecond.
#include "brep_internal.h"

#include "cadclash/geometry.h"  // box_norm: bounds every point and control point a face's evaluation combines

#include <BRepAdaptor_Curve.hxx>
#include <BRepBndLib.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <Bnd_Box.hxx>
#include <BRep_Tool.hxx>
#include <ElSLib.hxx>
#include <Extrema_GenLocateExtPS.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_BezierSurface.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BezierCurve.hxx>
#include <Geom_Circle.hxx>
#include <Geom_ElementarySurface.hxx>
#include <Geom_Ellipse.hxx>
#include <Geom_Line.hxx>
#include <Geom_SurfaceOfLinearExtrusion.hxx>
#include <Geom_SurfaceOfRevolution.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <GeomConvert.hxx>
#include <GeomConvert_BSplineSurfaceToBezierSurface.hxx>
#include <BRepTools.hxx>
#include <TColGeom_Array2OfBezierSurface.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <Extrema_LocateExtCC.hxx>
#include <Extrema_POnCurv.hxx>
#include <Poly_Triangulation.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS.hxx>
#include <gp_Pnt2d.hxx>
#include <gp_Vec.hxx>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <vector>

namespace cadclash::detail {
namespace {

// Rounding of a surface or curve evaluation and of |p - q|, relative to the magnitudes involved:
// de Boor / Horner evaluation of a (rational) B-spline of degree <= 25 is a chain of at most ~60
// convex combinations and one division, each rounding by at most 2^-53 of the largest control point
// it combines, which the face's box (built from the control polygon for B-splines) bounds.
// 2^-40 covers 8,000 such roundings.
constexpr double kEvaluationRounding = 0x1p-40;

// The parameters of the face's triangulation node nearest to `p`: a node lies on the surface, so
// Newton started there reaches the foot point of any point within a triangle's size of the face.
std::optional<gp_Pnt2d> nearest_node_parameters(const TopoDS_Face& face, const gp_Pnt& p) {
  TopLoc_Location loc;
  const Handle(Poly_Triangulation)& tri = BRep_Tool::Triangulation(face, loc);
  if (tri.IsNull() || !tri->HasUVNodes() || tri->NbNodes() == 0) return std::nullopt;
  const bool moved = !loc.IsIdentity();
  const gp_Trsf& trsf = loc.Transformation();
  int nearest = 1;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 1; i <= tri->NbNodes(); ++i) {
    gp_Pnt n = tri->Node(i);
    if (moved) n.Transform(trsf);
    const double d = n.SquareDistance(p);
    if (d < best) best = d, nearest = i;
  }
  return tri->UVNode(nearest);
}

// A point of the face's edges near `p`: per edge, Newton on |C(t) - p|^2 from the edge's sample
// nearest p (a point of the curve within its range; the edges bound the face): the edge, the
// parameter and the distance. Any point of an edge bounds the face's distance from above, so a
// local minimum serves; from the nearest of samples a few per polynomial span apart, it is the
// nearest point for any p within a span of the edge, where witnesses are asked. Edges are tried
// nearest box first; one whose box is farther than the best point so far cannot give a nearer one.
struct EdgePoint {
  std::size_t edge = 0;
  double t = 0.0;
  double distance = 0.0;
};

constexpr int kMaxEdgeNewtonSteps = 8;

std::optional<EdgePoint> nearest_edge_point(const FaceLocator& where, const gp_Pnt& p) {
  std::vector<std::pair<double, std::size_t>> order;
  for (std::size_t i = 0; i < where.edges.size(); ++i)
    order.emplace_back(where.edges[i].second.exteriorDistance(Vec3(p.X(), p.Y(), p.Z())), i);
  std::sort(order.begin(), order.end());
  std::optional<EdgePoint> best;
  for (const auto& [box_distance, i] : order) {
    if (best && box_distance > best->distance) break;
    const auto& samples = where.samples[i];
    if (samples.empty()) continue;
    std::size_t k = 0;
    double nearest = samples[0].second.SquareDistance(p);
    for (std::size_t j = 1; j < samples.size(); ++j)
      if (const double d2 = samples[j].second.SquareDistance(p); d2 < nearest) k = j, nearest = d2;
    const BRepAdaptor_Curve curve(where.edges[i].first);
    const double t0 = curve.FirstParameter(), t1 = curve.LastParameter();
    double t = samples[k].first;
    for (int step = 0; step < kMaxEdgeNewtonSteps; ++step) {
      gp_Pnt c;
      gp_Vec d1, d2;
      curve.D2(t, c, d1, d2);
      const gp_Vec w(p, c);
      const double slope = d1.Dot(w), curvature = d2.Dot(w) + d1.SquareMagnitude();
      if (!(curvature > 0.0)) break;
      const double next = std::clamp(t - slope / curvature, t0, t1);
      const bool done = std::abs(next - t) <= 1e-12 * (1.0 + std::abs(t));
      t = next;
      if (done) break;
    }
    double d = p.Distance(curve.Value(t));
    if (const double ds = p.Distance(samples[k].second); !(d <= ds)) d = ds, t = samples[k].first;
    if (!best || d < best->distance) best = EdgePoint{i, t, d};
  }
  return best;
}

// For a foot point on or past the boundary: there the face's nearest points are on an edge.
std::optional<double> edge_witness(const FaceLocator& where, const gp_Pnt& p, double magnitude) {
  const std::optional<EdgePoint> e = nearest_edge_point(where, p);
  if (!e) return std::nullopt;
  return e->distance + kEvaluationRounding * magnitude;
}

}  // namespace

std::optional<double> edge_pair_witness(const FaceLocator& a, const gp_Trsf& place_a, const gp_Pnt& near_a,
                                        const FaceLocator& b, const gp_Trsf& place_b, const gp_Pnt& near_b) {
  const auto ea = nearest_edge_point(a, near_a);
  const auto eb = nearest_edge_point(b, near_b);
  if (!ea || !eb) return std::nullopt;
  const TopoDS_Edge edge_a = TopoDS::Edge(a.edges[ea->edge].first.Moved(TopLoc_Location(place_a)));
  const TopoDS_Edge edge_b = TopoDS::Edge(b.edges[eb->edge].first.Moved(TopLoc_Location(place_b)));
  const BRepAdaptor_Curve ca(edge_a), cb(edge_b);
  // Every evaluated point stays within the placed edges' reach of the origin.
  const gp_Pnt pa0 = ca.Value(ea->t), pb0 = cb.Value(eb->t);
  const double magnitude = 2.0 * (gp_Vec(pa0.XYZ()).Magnitude() + gp_Vec(pb0.XYZ()).Magnitude()) +
                           a.edges[ea->edge].second.diagonal().norm() + b.edges[eb->edge].second.diagonal().norm();
  // The start points are points of both edges already; Newton from them finds the local extremum.
  double d = pa0.Distance(pb0);
  Extrema_LocateExtCC local(ca, cb, ea->t, eb->t);
  if (local.IsDone()) {
    Extrema_POnCurv p1, p2;
    local.Point(p1, p2);
    const bool on_a = p1.Parameter() >= ca.FirstParameter() && p1.Parameter() <= ca.LastParameter();
    const bool on_b = p2.Parameter() >= cb.FirstParameter() && p2.Parameter() <= cb.LastParameter();
    if (on_a && on_b) d = std::min(d, ca.Value(p1.Parameter()).Distance(cb.Value(p2.Parameter())));
  }
  return d + kEvaluationRounding * magnitude;
}

FaceLocator::FaceLocator(const TopoDS_Face& face) : face_(face) {
  idle_.push_back(std::make_unique<BRepTopAdaptor_FClass2d>(face, Precision::PConfusion()));
  for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
    if (BRep_Tool::Degenerated(edge) || !BRep_Tool::IsGeometric(edge)) continue;
    Bnd_Box box;
    BRepBndLib::Add(edge, box, Standard_False);
    if (box.IsVoid()) continue;
    double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
    box.Get(x0, y0, z0, x1, y1, z1);
    edges.emplace_back(edge, Aabb(Vec3(x0, y0, z0), Vec3(x1, y1, z1)));
    std::vector<std::pair<double, gp_Pnt>> along;
    try {
      const BRepAdaptor_Curve curve(edge);
      const double t0 = curve.FirstParameter(), t1 = curve.LastParameter();
      const int n = std::clamp(8 * curve.NbIntervals(GeomAbs_C2), 16, 512);
      if (std::isfinite(t0) && std::isfinite(t1) && t1 >= t0)
        for (int k = 0; k < n; ++k) {
          const double t = k + 1 == n ? t1 : t0 + (t1 - t0) * k / (n - 1);
          along.emplace_back(t, curve.Value(t));
        }
    } catch (const Standard_Failure&) {
      along.clear();  // no samples: the edge gives no witness point
    }
    samples.push_back(std::move(along));
  }
}

FaceLocator::~FaceLocator() = default;

TopAbs_State FaceLocator::classify(double u, double v) const {
  std::unique_ptr<BRepTopAdaptor_FClass2d> mine;
  {
    std::lock_guard<std::mutex> lock(idle_mutex_);
    if (!idle_.empty()) {
      mine = std::move(idle_.back());
      idle_.pop_back();
    }
  }
  if (!mine) mine = std::make_unique<BRepTopAdaptor_FClass2d>(face_, Precision::PConfusion());
  const TopAbs_State state = mine->Perform(gp_Pnt2d(u, v));
  std::lock_guard<std::mutex> lock(idle_mutex_);
  idle_.push_back(std::move(mine));
  return state;
}

namespace {

// The local foot point of `p` on the face's surface by Newton from the nearest triangulation node:
// its parameters and the rounding bound of evaluating there.
struct Foot {
  double u = 0.0, v = 0.0;
  double magnitude = 0.0;
};

// Gauss-Newton on (S(u, v) - p)·S_u = (S(u, v) - p)·S_v = 0 from `start`, inside the surface's
// parameter range: the points asked are vertices of a touching face, a deflection or less from this
// surface, where it converges in a few steps, each one first-derivative evaluation. nullopt when it
// does not settle (a singular point, a far point, a step leaving the range), for OCCT's solver.
std::optional<gp_Pnt2d> gauss_newton_foot(const BRepAdaptor_Surface& surface, const gp_Pnt2d& start, const gp_Pnt& p,
                                          double magnitude) {
  const double u0 = surface.FirstUParameter(), u1 = surface.LastUParameter();
  const double v0 = surface.FirstVParameter(), v1 = surface.LastVParameter();
  double u = start.X(), v = start.Y();
  // A 3D step this small is far below the evaluation's own rounding (kEvaluationRounding · magnitude);
  // where it stops changes no proof: the point used is S(u, v), a point of the surface wherever it is.
  const double settled = 1e-2 * kEvaluationRounding * magnitude;
  for (int step = 0; step < 8; ++step) {
    gp_Pnt s;
    gp_Vec du, dv;
    surface.D1(u, v, s, du, dv);
    const gp_Vec r(s, p);
    const double a = du.Dot(du), b = du.Dot(dv), c = dv.Dot(dv);
    const double det = a * c - b * b;
    if (!(det > 1e-12 * a * c)) return std::nullopt;  // degenerate parametrisation here
    const double su = (c * du.Dot(r) - b * dv.Dot(r)) / det, sv = (a * dv.Dot(r) - b * du.Dot(r)) / det;
    const double nu = u + su, nv = v + sv;
    if (!(nu >= u0 && nu <= u1 && nv >= v0 && nv <= v1)) return std::nullopt;
    u = nu, v = nv;
    if ((su * du + sv * dv).Magnitude() <= settled) return gp_Pnt2d(u, v);
  }
  return std::nullopt;
}

std::optional<Foot> newton_foot(const BRepAdaptor_Surface& surface, const TopoDS_Face& face, const Aabb& face_box,
                                const gp_Pnt& p) {
  const std::optional<gp_Pnt2d> start = nearest_node_parameters(face, p);
  if (!start) return std::nullopt;
  Foot f;
  // Every evaluated point and the control points stay within the face box's reach of the origin.
  f.magnitude = gp_Vec(p.XYZ()).Magnitude() + box_norm(face_box);
  if (const std::optional<gp_Pnt2d> quick = gauss_newton_foot(surface, *start, p, f.magnitude)) {
    f.u = quick->X(), f.v = quick->Y();
    return f;
  }
  Extrema_GenLocateExtPS foot(surface);
  foot.Perform(p, start->X(), start->Y());
  if (!foot.IsDone()) return std::nullopt;
  foot.Point().Parameter(f.u, f.v);
  return f;
}

}  // namespace

std::optional<double> face_point_witness(const BRepAdaptor_Surface& surface, const TopoDS_Face& face,
                                         const FaceLocator& where, const Aabb& face_box, const gp_Pnt& p) {
  const std::optional<Foot> f = newton_foot(surface, face, face_box, p);
  if (!f) return std::nullopt;
  // Parameters the classifier puts inside name a point of the face. A foot on or past the boundary
  // means the face's nearest points are on its edges.
  const TopAbs_State state = where.classify(f->u, f->v);
  if (state != TopAbs_IN) return edge_witness(where, p, f->magnitude);
  return p.Distance(surface.Value(f->u, f->v)) + kEvaluationRounding * f->magnitude;
}

std::optional<double> face_boundary_witness(const FaceLocator& where, const Aabb& face_box, const gp_Pnt& p) {
  const double magnitude = gp_Vec(p.XYZ()).Magnitude() + box_norm(face_box);
  return edge_witness(where, p, magnitude);
}

std::optional<SurfaceSource::SurfacePoint> face_edge_support(const FaceLocator& where, const Aabb& face_box,
                                                             const Vec3& d, const gp_Pnt& near) {
  const std::optional<EdgePoint> e = nearest_edge_point(where, near);
  if (!e) return std::nullopt;
  const BRepAdaptor_Curve curve(where.edges[e->edge].first);
  const double t0 = curve.FirstParameter(), t1 = curve.LastParameter();
  const gp_Vec dir(d.x(), d.y(), d.z());
  double t = e->t;
  for (int step = 0; step < 12; ++step) {
    gp_Pnt p;
    gp_Vec d1, d2;
    curve.D2(t, p, d1, d2);
    const double g1 = dir.Dot(d1), g2 = dir.Dot(d2);
    // A maximum of d·C needs g2 < 0; elsewhere step along the slope to the end it rises towards.
    double next = g2 < 0.0 ? t - g1 / g2 : (g1 > 0.0 ? t1 : t0);
    next = std::clamp(next, t0, t1);
    if (std::abs(next - t) <= 1e-15 * (1.0 + std::abs(t))) break;
    t = next;
  }
  const gp_Pnt p = curve.Value(t);
  SurfaceSource::SurfacePoint out;
  out.point = Vec3(p.X(), p.Y(), p.Z());
  out.normal = d;
  out.rounding = kEvaluationRounding * (box_norm(face_box) + out.point.norm());
  return out;
}

std::optional<SurfaceSource::SurfacePoint> face_surface_point(const BRepAdaptor_Surface& surface,
                                                              const TopoDS_Face& face, const Aabb& face_box,
                                                              const gp_Pnt& p) {
  // A plane's, cylinder's or sphere's foot point in closed form (ElSLib: the orthogonal projection,
  // as parameters of the face's own placed surface); other surfaces by Newton from the nearest node.
  // Either way the point used is S(u, v), a point of the surface.
  std::optional<Foot> f;
  switch (surface.GetType()) {
    case GeomAbs_Plane:
    case GeomAbs_Cylinder:
    case GeomAbs_Sphere: {
      f.emplace();
      f->magnitude = gp_Vec(p.XYZ()).Magnitude() + box_norm(face_box);
      if (surface.GetType() == GeomAbs_Plane) ElSLib::Parameters(surface.Plane(), p, f->u, f->v);
      else if (surface.GetType() == GeomAbs_Cylinder) ElSLib::Parameters(surface.Cylinder(), p, f->u, f->v);
      else ElSLib::Parameters(surface.Sphere(), p, f->u, f->v);
      break;
    }
    default: f = newton_foot(surface, face, face_box, p);
  }
  if (!f) return std::nullopt;
  gp_Pnt s;
  gp_Vec du, dv;
  surface.D1(f->u, f->v, s, du, dv);
  const gp_Vec n = du.Crossed(dv);
  if (!(n.Magnitude() > 0.0)) return std::nullopt;  // a singular point (apex, pole): no normal
  SurfaceSource::SurfacePoint out;
  out.point = Vec3(s.X(), s.Y(), s.Z());
  const gp_Vec nu = n.Normalized();
  out.normal = Vec3(nu.X(), nu.Y(), nu.Z());
  out.rounding = kEvaluationRounding * f->magnitude;
  return out;
}

namespace {

// The surface the face lies on, trimmed surfaces unwrapped (a trimmed surface lies on its basis
// surface), and the face's location in `place`.
Handle(Geom_Surface) basis_surface(const TopoDS_Face& face, gp_Trsf& place) {
  TopLoc_Location loc;
  Handle(Geom_Surface) surface = BRep_Tool::Surface(face, loc);
  while (!surface.IsNull()) {
    const Handle(Geom_RectangularTrimmedSurface) trimmed = Handle(Geom_RectangularTrimmedSurface)::DownCast(surface);
    if (trimmed.IsNull()) break;
    surface = trimmed->BasisSurface();
  }
  place = loc.Transformation();
  return surface;
}

// The heights of `poles` (placed by `place`) over the plane, widened by their evaluation's rounding.
std::array<double, 2> pole_heights(const TColgp_Array2OfPnt& poles, const gp_Trsf& place, const Vec3& o, const Vec3& n) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, magnitude = o.norm();
  for (int i = poles.LowerRow(); i <= poles.UpperRow(); ++i)
    for (int j = poles.LowerCol(); j <= poles.UpperCol(); ++j) {
      const gp_Pnt p = poles(i, j).Transformed(place);
      const Vec3 v(p.X(), p.Y(), p.Z());
      const double h = n.dot(v - o);
      lo = std::min(lo, h);
      hi = std::max(hi, h);
      magnitude = std::max(magnitude, v.norm() + o.norm());
    }
  const double r = kEvaluationRounding * magnitude;
  return {lo - r, hi + r};
}

bool positive(const TColStd_Array2OfReal* weights) {
  if (weights == nullptr) return true;
  for (int i = weights->LowerRow(); i <= weights->UpperRow(); ++i)
    for (int j = weights->LowerCol(); j <= weights->UpperCol(); ++j)
      if (!((*weights)(i, j) > 0.0)) return false;
  return true;
}

}  // namespace

std::optional<std::array<double, 2>> face_height_range(const TopoDS_Face& face, const Vec3& o, const Vec3& n) {
  gp_Trsf place;
  const Handle(Geom_Surface) surface = basis_surface(face, place);
  if (surface.IsNull()) return std::nullopt;
  if (const Handle(Geom_BSplineSurface) b = Handle(Geom_BSplineSurface)::DownCast(surface); !b.IsNull()) {
    if (!positive(b->Weights())) return std::nullopt;
    return pole_heights(b->Poles(), place, o, n);
  }
  if (const Handle(Geom_BezierSurface) z = Handle(Geom_BezierSurface)::DownCast(surface); !z.IsNull()) {
    if (!positive(z->Weights())) return std::nullopt;
    return pole_heights(z->Poles(), place, o, n);
  }
  return std::nullopt;
}

namespace {

constexpr int kMaxPatches = 1024;

// The face's parameter bounds, widened by a little (never past a bounded surface's own ends): the
// pcurves' box, which the face lies in.
void face_bounds(const TopoDS_Face& face, const Handle(Geom_Surface)& s, double& u1, double& u2, double& v1,
                 double& v2) {
  BRepTools::UVBounds(face, u1, u2, v1, v2);
  double su1 = 0.0, su2 = 0.0, sv1 = 0.0, sv2 = 0.0;
  s->Bounds(su1, su2, sv1, sv2);
  const double du = 1e-9 * (u2 - u1) + 1e-12, dv = 1e-9 * (v2 - v1) + 1e-12;
  u1 -= du, u2 += du, v1 -= dv, v2 += dv;
  // Never past a bounded surface's ends, nor over more than one period of a periodic one (a
  // trimmed periodic surface takes its range modulo the period: a full turn widened would wrap to
  // almost nothing).
  if (!s->IsUPeriodic()) u1 = std::max(u1, su1), u2 = std::min(u2, su2);
  else if (u2 - u1 >= s->UPeriod()) u2 = u1 + s->UPeriod();
  if (!s->IsVPeriodic()) v1 = std::max(v1, sv1), v2 = std::min(v2, sv2);
  else if (v2 - v1 >= s->VPeriod()) v2 = v1 + s->VPeriod();
}

// A curve GeomConvert turns into a B-spline without approximating it (an offset curve, for
// example, it approximates).
bool curve_converts_exactly(Handle(Geom_Curve) c) {
  while (!c.IsNull() && c->IsKind(STANDARD_TYPE(Geom_TrimmedCurve))) c = Handle(Geom_TrimmedCurve)::DownCast(c)->BasisCurve();
  return !c.IsNull() && (c->IsKind(STANDARD_TYPE(Geom_Line)) || c->IsKind(STANDARD_TYPE(Geom_Circle)) ||
                         c->IsKind(STANDARD_TYPE(Geom_Ellipse)) || c->IsKind(STANDARD_TYPE(Geom_BSplineCurve)) ||
                         c->IsKind(STANDARD_TYPE(Geom_BezierCurve)));
}

// Surfaces GeomConvert::SurfaceToBSplineSurface converts exactly once trimmed to the face's
// parameter bounds: the elementary ones, and surfaces of revolution and of linear extrusion swept
// from a curve that converts exactly (KiCad's exports draw many component walls as those).
bool converts_exactly(const Handle(Geom_Surface)& s) {
  if (!Handle(Geom_ElementarySurface)::DownCast(s).IsNull()) return true;
  if (const auto r = Handle(Geom_SurfaceOfRevolution)::DownCast(s); !r.IsNull()) return curve_converts_exactly(r->BasisCurve());
  if (const auto e = Handle(Geom_SurfaceOfLinearExtrusion)::DownCast(s); !e.IsNull())
    return curve_converts_exactly(e->BasisCurve());
  return false;
}

}  // namespace

std::optional<SurfaceSource::BezierPatches> face_bezier_patches(const TopoDS_Face& face) {
  gp_Trsf place;
  const Handle(Geom_Surface) surface = basis_surface(face, place);
  if (surface.IsNull()) return std::nullopt;
  std::vector<Handle(Geom_BezierSurface)> beziers;
  if (const Handle(Geom_BezierSurface) z = Handle(Geom_BezierSurface)::DownCast(surface); !z.IsNull()) {
    beziers.push_back(z);
  } else {
    Handle(Geom_BSplineSurface) b = Handle(Geom_BSplineSurface)::DownCast(surface);
    if (b.IsNull()) {
      if (!converts_exactly(surface)) return std::nullopt;
      double u1 = 0.0, u2 = 0.0, v1 = 0.0, v2 = 0.0;
      face_bounds(face, surface, u1, u2, v1, v2);
      if (!(u1 < u2 && v1 < v2) || !std::isfinite(u2 - u1) || !std::isfinite(v2 - v1)) return std::nullopt;
      b = GeomConvert::SurfaceToBSplineSurface(new Geom_RectangularTrimmedSurface(surface, u1, u2, v1, v2));
      if (b.IsNull()) return std::nullopt;
    }
    GeomConvert_BSplineSurfaceToBezierSurface split(b);
    if (split.NbUPatches() * split.NbVPatches() > kMaxPatches) return std::nullopt;
    TColGeom_Array2OfBezierSurface patches(1, split.NbUPatches(), 1, split.NbVPatches());
    split.Patches(patches);
    for (int i = patches.LowerRow(); i <= patches.UpperRow(); ++i)
      for (int j = patches.LowerCol(); j <= patches.UpperCol(); ++j) beziers.push_back(patches(i, j));
  }
  SurfaceSource::BezierPatches out;
  double magnitude = 0.0;
  for (const Handle(Geom_BezierSurface)& z : beziers) {
    SurfaceSource::BezierPatch patch;
    patch.degree_u = z->UDegree();
    patch.degree_v = z->VDegree();
    for (int i = 1; i <= z->NbUPoles(); ++i)
      for (int j = 1; j <= z->NbVPoles(); ++j) {
        const gp_Pnt p = z->Pole(i, j).Transformed(place);
        const double w = z->Weight(i, j);
        if (!(w > 0.0)) return std::nullopt;
        patch.points.emplace_back(p.X(), p.Y(), p.Z());
        patch.weights.push_back(w);
        magnitude = std::max(magnitude, patch.points.back().norm());
      }
    out.patches.push_back(std::move(patch));
  }
  // Knot insertion and the conversion's sines and cosines round; far less than this.
  out.rounding = kEvaluationRounding * magnitude;
  return out;
}

}  // namespace cadclash::detail
