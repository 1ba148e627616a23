#include "cadclash/testing/scenes.h"

#include "cadclash/geometry.h"
#include "cadclash/import.h"
#include "cadclash/tessellate.h"
#include "cadclash/testing/truth.h"

#include <BRepAdaptor_Surface.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepGProp.hxx>
#include <BRep_Builder.hxx>
#include <GProp_GProps.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <gp_Trsf.hxx>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <cstdio>
#include <tuple>
#include <utility>

namespace cadclash::truth {

bool BuiltScene::ok() const { return !model.instances.empty() && !has_error(diagnostics); }

namespace {

// Margin kept between placed parts, and between a part and an unused hole or the board's edge (mm).
constexpr double kMargin = 1.0;
// Step of the first-fit search over positions on the board (mm).
constexpr double kStep = 0.5;

const BrepSource& brep(const Model& m, PartId p) {
  const auto* src = dynamic_cast<const BrepSource*>(m.parts[p].source.get());
  if (!src) throw std::runtime_error("part " + m.parts[p].name + " is not a B-rep part");
  return *src;
}

Vec3 vec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

// A planar face of a part, part-local: outward unit normal (face orientation applied), a point of the
// plane, the face's centroid and area.
struct PlaneFace {
  Vec3 normal, point, centroid;
  double area = 0.0;
};

std::optional<PlaneFace> plane_face(const Model& m, PartId p, std::uint32_t local) {
  const TopoDS_Face& f = brep(m, p).face(local);
  BRepAdaptor_Surface ad(f);
  if (ad.GetType() != GeomAbs_Plane) return std::nullopt;
  const gp_Pln pl = ad.Plane();
  gp_Dir n = pl.Axis().Direction();
  if (f.Orientation() == TopAbs_REVERSED) n.Reverse();
  GProp_GProps g;
  BRepGProp::SurfaceProperties(f, g);
  return PlaneFace{vec(n.XYZ()), vec(pl.Location().XYZ()), vec(g.CentreOfMass().XYZ()), g.Mass()};
}

PlaneFace require_plane(const Model& m, PartId p, std::uint32_t local) {
  auto f = plane_face(m, p, local);
  if (!f) throw std::runtime_error("face " + std::to_string(local) + " of " + m.parts[p].name + " is not planar");
  return *f;
}

// The planar face of part p whose outward normal is `dir` (within 1e-9) with the largest area.
std::uint32_t largest_plane_facing(const Model& m, PartId p, const Vec3& dir) {
  std::optional<std::uint32_t> best;
  double best_area = 0.0;
  for (std::uint32_t k = 0; k < m.parts[p].surface_count; ++k) {
    const auto f = plane_face(m, p, k);
    if (f && (f->normal - dir).norm() < 1e-9 && f->area > best_area) best = k, best_area = f->area;
  }
  if (!best) throw std::runtime_error("no planar face of " + m.parts[p].name + " faces the requested way");
  return *best;
}

// The outermost planar face of part p facing `dir` (largest dir·point: the part lies behind it),
// the largest of those on that plane.
std::uint32_t outer_plane_facing(const Model& m, PartId p, const Vec3& dir) {
  std::optional<std::uint32_t> best;
  double best_h = 0.0, best_area = 0.0;
  for (std::uint32_t k = 0; k < m.parts[p].surface_count; ++k) {
    const auto f = plane_face(m, p, k);
    if (!f || (f->normal - dir).norm() >= 1e-9) continue;
    const double h = dir.dot(f->point);
    if (!best || h > best_h + 1e-9 || (std::abs(h - best_h) <= 1e-9 && f->area > best_area))
      best = k, best_h = h, best_area = f->area;
  }
  if (!best) throw std::runtime_error("no planar face of " + m.parts[p].name + " faces the requested way");
  return *best;
}

// Area-weighted centroid of some faces of a part (part-local).
Vec3 faces_centroid(const Model& m, PartId p, const std::vector<std::uint32_t>& locals) {
  GProp_GProps all;
  for (std::uint32_t k : locals) {
    GProp_GProps g;
    BRepGProp::SurfaceProperties(brep(m, p).face(k), g);
    all.Add(g);
  }
  return vec(all.CentreOfMass().XYZ());
}

// A cylinder face, part-local: axis point, unit axis, radius, and the axis points at the face's two
// ends (parameter range along the axis).
struct CylinderFace {
  Vec3 origin, axis, end0, end1;
  double radius = 0.0;
};

std::optional<CylinderFace> cylinder_face(const Model& m, PartId p, std::uint32_t local) {
  BRepAdaptor_Surface ad(brep(m, p).face(local));
  if (ad.GetType() != GeomAbs_Cylinder) return std::nullopt;
  const gp_Cylinder c = ad.Cylinder();
  CylinderFace out;
  out.origin = vec(c.Location().XYZ());
  out.axis = vec(c.Axis().Direction().XYZ());
  out.radius = c.Radius();
  out.end0 = out.origin + ad.FirstVParameter() * out.axis;
  out.end1 = out.origin + ad.LastVParameter() * out.axis;
  return out;
}

Aabb part_box(const Model& m, PartId p) {
  Aabb box;
  const Part& part = m.parts[p];
  for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s) box.extend(m.surfaces[s].aabb);
  return box;
}

// Rotation about world z by `deg` degrees, built entry by entry so that the third row and column are
// exactly (0, 0, 1): heights along z are not rounded by it.
Eigen::Matrix3d rot_z(double deg) {
  const double a = deg * std::numbers::pi / 180.0;
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, -s, 0, s, c, 0, 0, 0, 1;
  return r;
}

// A rotation taking unit `from` to unit `to`; exact (entries 0 and ±1) when both are the same
// coordinate axis up to sign along z.
Eigen::Matrix3d align(const Vec3& from, const Vec3& to) {
  if (from == to) return Eigen::Matrix3d::Identity();
  if (from == -to && std::abs(to.z()) == 1.0) return Eigen::Vector3d(1, -1, -1).asDiagonal();  // half turn about x
  return Eigen::Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
}

TopoDS_Compound part_compound(const Model& m, PartId p) {
  BRep_Builder b;
  TopoDS_Compound c;
  b.MakeCompound(c);
  for (std::uint32_t k = 0; k < m.parts[p].surface_count; ++k) b.Add(c, brep(m, p).face(k));
  return c;
}

// Exact distance from part p placed by `pose` to the plane {x : n·x = h} (a square face far larger
// than the part, centred under it).
double distance_to_plane(const Model& m, PartId p, const Pose& pose, const Vec3& n, double h) {
  const Aabb box = placed_box(part_box(m, p), pose);
  const double half = 10.0 * box.sizes().norm() + 1.0;
  const Vec3 c = box.center();
  const Vec3 on_plane = c - (n.dot(c) - h) * n;
  const gp_Pln pln(gp_Pnt(on_plane.x(), on_plane.y(), on_plane.z()), gp_Dir(n.x(), n.y(), n.z()));
  const TopoDS_Face plane = BRepBuilderAPI_MakeFace(pln, -half, half, -half, half).Face();
  const TopoDS_Shape placed = part_compound(m, p).Moved(TopLoc_Location(to_trsf(pose)));
  BRepExtrema_DistShapeShape d(placed, plane, Extrema_ExtFlag_MIN);
  if (!d.IsDone() || d.NbSolution() == 0) throw std::runtime_error("BRepExtrema failed on " + m.parts[p].name);
  return d.Value();
}

std::string fmt_mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

PartId find_part(const Model& m, const std::string& name, PartId from = 0) {
  for (PartId p = from; p < m.parts.size(); ++p)
    if (m.parts[p].name == name) return p;
  throw std::runtime_error("no part named " + name);
}

ImportResult read(const std::string& path, double deflection) {
  ImportOptions io;
  io.tessellation.linear_deflection = deflection;
  return import_file(path, io);
}

// 2D boxes (xy) of the board layout.
using Box2 = Eigen::AlignedBox2d;
Box2 xy(const Aabb& b) { return Box2(b.min().head<2>(), b.max().head<2>()); }
Box2 inflated(Box2 b, double d) {
  b.min().array() -= d;
  b.max().array() += d;
  return b;
}

// The board: the plate's top face (normal +z), its bottom face and its holes; the occupied areas of
// the top face and the first-fit search for a free spot.
class Layout {
 public:
  Layout(const Box2& region, std::vector<Box2> taken) : region_(region), taken_(std::move(taken)) {}

  // A translation (x, y) such that footprint + (x, y) lies in the region (only its y extent when
  // `fixed_x` is given, which is then the x) and keeps kMargin from everything taken; the first in
  // scan order (rows of increasing y, then increasing x). Marks it taken.
  Vec3 place(const std::string& what, const Box2& footprint, std::optional<double> fixed_x = {}) {
    const double x0 = fixed_x ? *fixed_x : region_.min().x() - footprint.min().x();
    const double x1 = fixed_x ? *fixed_x : region_.max().x() - footprint.max().x();
    const double y0 = region_.min().y() - footprint.min().y();
    const double y1 = region_.max().y() - footprint.max().y();
    for (double y = y0; y <= y1; y += kStep)
      for (double x = x0; x <= x1; x += kStep) {
        const Box2 at(footprint.min() + Eigen::Vector2d(x, y), footprint.max() + Eigen::Vector2d(x, y));
        const Box2 padded = inflated(at, kMargin);
        if (std::none_of(taken_.begin(), taken_.end(), [&](const Box2& t) { return t.intersects(padded); })) {
          taken_.push_back(at);
          return {x, y, 0.0};
        }
      }
    throw std::runtime_error("board_scene: no free spot on the board for " + what);
  }
  void take(const Box2& b) { taken_.push_back(b); }

 private:
  Box2 region_;
  std::vector<Box2> taken_;
};

}  // namespace

BuiltScene as1_scene(const std::string& external_dir, double deflection) {
  ImportResult in = read(external_dir + "/as1-tu-203.stp", deflection);
  BuiltScene s;
  s.name = "as1";
  s.model = std::move(in.model);
  s.diagnostics = std::move(in.diagnostics);
  return s;
}

BuiltScene as1_moved(const BuiltScene& as1, const std::string& moved_path, const std::string& partner_path,
                     double distance) {
  BuiltScene s;
  s.model = as1.model;
  s.diagnostics = as1.diagnostics;
  Model& m = s.model;
  InstanceId moved = kInvalidId, partner = kInvalidId;
  for (InstanceId i = 0; i < m.instances.size(); ++i) {
    if (m.instances[i].path == moved_path) moved = i;
    if (m.instances[i].path == partner_path) partner = i;
  }
  if (moved == kInvalidId || partner == kInvalidId) throw std::runtime_error("as1_moved: unknown instance path");
  const Instance& im = m.instances[moved];
  const Instance& ip = m.instances[partner];
  const Part& pm = m.parts[im.part];
  const Part& pp = m.parts[ip.part];
  std::optional<Vec3> dir;
  for (std::uint32_t j = 0; j < pm.surface_count && !dir; ++j) {
    const auto fm = plane_face(m, im.part, j);
    if (!fm) continue;
    const Vec3 nm = im.pose.linear() * fm->normal;
    for (std::uint32_t k = 0; k < pp.surface_count && !dir; ++k) {
      const auto fp = plane_face(m, ip.part, k);
      if (!fp) continue;
      const Vec3 np = ip.pose.linear() * fp->normal;
      if (nm.dot(np) > -1.0 + 1e-9) continue;  // not facing each other
      const double d = exact_face_distance(m, std::min(moved, partner), std::min(moved, partner) == moved
                                                                              ? pm.first_surface + j
                                                                              : pp.first_surface + k,
                                           std::max(moved, partner),
                                           std::max(moved, partner) == moved ? pm.first_surface + j
                                                                             : pp.first_surface + k);
      if (d <= 1e-9) dir = np.normalized();
    }
  }
  if (!dir) throw std::runtime_error("as1_moved: no planar contact between " + moved_path + " and " + partner_path);
  m.instances[moved].pose.pretranslate(distance * *dir);
  s.name = "as1, " + moved_path + " moved " + fmt_mm(distance) + " mm off " + partner_path;
  s.placements.push_back({moved, s.name, partner, std::max(distance, 0.0), std::max(-distance, 0.0)});
  return s;
}

BuiltScene board_scene(const std::string& external_dir, double deflection) {
  BuiltScene s;
  s.name = "board";
  Model& m = s.model;
  for (const char* file : {"as1-tu-203.stp", "screw.step", "linkrods.step"}) {
    ImportResult in = read(external_dir + "/" + file, deflection);
    s.diagnostics.insert(s.diagnostics.end(), in.diagnostics.begin(), in.diagnostics.end());
    if (in.model.parts.empty()) {
      s.diagnostics.push_back({Severity::Error, external_dir + "/" + file, 0, -1, "no part read"});
      return s;
    }
    in.model.instances.clear();
    append_model(m, std::move(in.model));
  }
  const PartId plate = find_part(m, "plate"), nut = find_part(m, "nut"), bolt = find_part(m, "bolt"),
               bracket = find_part(m, "l-bracket");
  const PartId screw = find_part(m, "the product name", bracket + 1);  // screw.step's one part
  const PartId linkrod = static_cast<PartId>(m.parts.size() - 1);     // linkrods.step's one part

  auto add = [&](const std::string& path, PartId part, const Pose& pose) {
    m.instances.push_back({path, part, pose});
    return static_cast<InstanceId>(m.instances.size() - 1);
  };
  const InstanceId board = add("/board/plate", plate, Pose::Identity());

  // The board's top and bottom faces: the outermost planar faces facing +z and -z.
  const Vec3 up = Vec3::UnitZ();
  const std::uint32_t top_face = outer_plane_facing(m, plate, up);
  const PlaneFace top = require_plane(m, plate, top_face);
  const PlaneFace bottom = require_plane(m, plate, outer_plane_facing(m, plate, -up));
  const double h_top = up.dot(top.point), h_bottom = up.dot(bottom.point);
  const Aabb plate_box = part_box(m, plate);

  // The holes: the plate's non-planar faces, grouped by overlapping boxes (two half cylinders each).
  struct Hole {
    std::vector<std::uint32_t> faces;
    Aabb box;
    Vec3 axis_point;  // on the top face's plane
  };
  std::vector<Hole> holes;
  for (std::uint32_t k = 0; k < m.parts[plate].surface_count; ++k) {
    if (plane_face(m, plate, k)) continue;
    const Aabb& b = m.surfaces[m.parts[plate].first_surface + k].aabb;
    auto it = std::find_if(holes.begin(), holes.end(), [&](const Hole& h) { return h.box.intersects(b); });
    if (it == holes.end()) it = holes.insert(holes.end(), Hole{});
    it->faces.push_back(k);
    it->box.extend(b);
  }
  for (Hole& h : holes) {
    const Vec3 c = faces_centroid(m, plate, h.faces);
    h.axis_point = c + (h_top - up.dot(c)) * up;
  }
  // The pin's hole: the one farthest from the board's centre (ties: larger x, then larger y).
  const Vec3 centre = plate_box.center();
  const auto pin_hole = std::max_element(holes.begin(), holes.end(), [&](const Hole& a, const Hole& b) {
    const Vec3 pa = a.axis_point, pb = b.axis_point;
    const double da = (pa - centre).head<2>().norm(), db = (pb - centre).head<2>().norm();
    return std::make_tuple(da, pa.x(), pa.y()) < std::make_tuple(db, pb.x(), pb.y());
  });
  if (pin_hole == holes.end()) throw std::runtime_error("board_scene: the plate has no hole");

  std::vector<Box2> taken;
  for (const Hole& h : holes)
    if (&h != &*pin_hole) taken.push_back(xy(h.box));
  Layout layout(inflated(xy(m.surfaces[m.parts[plate].first_surface + top_face].aabb), -kMargin), taken);

  // Seats part face `seat` (planar) of `part` on the board plane with outward normal `normal` at
  // height `h` (along `normal`), `offset` mm off it (negative: sunk in), turned `deg` about the
  // normal; the face point `ref` goes over the board point `at` (xy) when given, else the layout
  // finds a spot. Returns the pose.
  auto seat = [&](PartId part, std::uint32_t seat_face, const Vec3& normal, double h, double offset, double deg,
                  std::optional<Vec3> ref, std::optional<Vec3> at) {
    const PlaneFace f = require_plane(m, part, seat_face);
    const Eigen::Matrix3d r = rot_z(deg) * align(f.normal, -normal);
    const Vec3 point = ref ? *ref : f.centroid;
    Pose pose = Pose::Identity();
    pose.linear() = r;
    const Vec3 rp = r * point;
    // Height: normal·(R·point + t) = h + offset; normal is ±z, so only t.z is involved.
    const double tz = normal.z() * (h + offset) - rp.z();
    if (at) {
      pose.translation() = Vec3(at->x() - rp.x(), at->y() - rp.y(), tz);
    } else {
      pose.translation() = Vec3(0, 0, tz);
      const Vec3 t = layout.place(m.parts[part].name, xy(placed_box(part_box(m, part), pose)));
      pose.translation() = Vec3(t.x(), t.y(), tz);
    }
    return pose;
  };
  auto describe = [](const std::string& what, double offset, double deg) {
    std::string text = what;
    text += offset > 0 ? ", stand-off " + fmt_mm(offset) + " mm"
            : offset < 0 ? ", sunk in " + fmt_mm(-offset) + " mm"
                         : ", exact contact";
    if (deg != 0) text += ", turned " + fmt_mm(deg) + " deg";
    return text;
  };
  auto on_board = [&](const std::string& path, PartId part, const Pose& pose, const std::string& what, double offset,
                      double deg) {
    const InstanceId i = add(path, part, pose);
    s.placements.push_back({i, describe(what, offset, deg), board, std::max(offset, 0.0), std::max(-offset, 0.0)});
    return i;
  };

  // 1. The pin: a bolt through the chosen hole, the face under its head (facing the shaft) seated on
  // the top face, its shaft axis on the hole's axis; a nut on the shaft under the plate.
  {
    const std::uint32_t end = largest_plane_facing(m, bolt, up);  // the face under the head (annulus, +z)
    const PlaneFace under_head = require_plane(m, bolt, end);
    // The shaft axis: through the centroid of the shaft's end face (the other +z face) along z.
    std::uint32_t shaft_end = ~0u;
    for (std::uint32_t k = 0; k < m.parts[bolt].surface_count; ++k) {
      const auto f = plane_face(m, bolt, k);
      if (f && k != end && (f->normal - up).norm() < 1e-9) shaft_end = k;
    }
    if (shaft_end == ~0u) throw std::runtime_error("board_scene: the bolt has no shaft end face");
    const Vec3 axis_pt = require_plane(m, bolt, shaft_end).centroid;
    const Vec3 ref = axis_pt + (under_head.point - axis_pt).dot(up) * up;  // on the seated face's plane
    const Pose pb = seat(bolt, end, up, h_top, 0.0, 17.0, ref, pin_hole->axis_point);
    const InstanceId pin = add("/board/pin/bolt", bolt, pb);
    s.placements.push_back({pin, "bolt through a hole of the board (coaxial, equal radius), head seated, turned 17 deg",
                            board, 0.0, 0.0});
    layout.take(xy(placed_box(part_box(m, bolt), pb)));
    // The nut: its +z face against the plate's bottom face, bore axis on the hole axis.
    const std::uint32_t nut_top = outer_plane_facing(m, nut, up);
    std::vector<std::uint32_t> bore;
    for (std::uint32_t k = 0; k < m.parts[nut].surface_count; ++k)
      if (!plane_face(m, nut, k)) bore.push_back(k);
    const Vec3 bc = faces_centroid(m, nut, bore);
    const PlaneFace nt = require_plane(m, nut, nut_top);
    const Vec3 nut_ref = bc + (nt.point - bc).dot(up) * up;
    const Pose pn = seat(nut, nut_top, -up, -h_bottom, 0.0, -33.0, nut_ref, pin_hole->axis_point);
    const InstanceId pin_nut = add("/board/pin/nut", nut, pn);
    s.placements.push_back({pin_nut, "nut on the pin's shaft, seated against the board's bottom face, turned -33 deg",
                            board, 0.0, 0.0});
  }

  // 3. L-brackets seated on their foot (the largest -z face).
  {
    const std::uint32_t foot = outer_plane_facing(m, bracket, -up);
    on_board("/board/l-bracket::1", bracket, seat(bracket, foot, up, h_top, 0.0, 0.0, {}, {}), "l-bracket foot", 0.0, 0.0);
    on_board("/board/l-bracket::2", bracket, seat(bracket, foot, up, h_top, -0.01, 17.0, {}, {}), "l-bracket foot", -0.01,
             17.0);
  }

  // 2. The screw lying on its side: the analytic cylinder (the shaft) tangent to the top face, its
  // head beyond the board's +x edge (the shaft's head end 1 mm past the edge).
  {
    std::optional<CylinderFace> cyl;
    for (std::uint32_t k = 0; k < m.parts[screw].surface_count && !cyl; ++k) cyl = cylinder_face(m, screw, k);
    if (!cyl) throw std::runtime_error("board_scene: the screw has no cylindrical face");
    // The head end of the shaft: the end beyond which the part extends farther along the axis.
    const Aabb sb = part_box(m, screw);
    auto beyond = [&](const Vec3& end, const Vec3& out) {
      double far = 0.0;
      for (int c = 0; c < 8; ++c) far = std::max(far, (sb.corner(static_cast<Aabb::CornerType>(c)) - end).dot(out));
      return far;
    };
    const Vec3 a = (cyl->end1 - cyl->end0).normalized();
    const bool head_at_1 = beyond(cyl->end1, a) > beyond(cyl->end0, -a);
    const Vec3 head_end = head_at_1 ? cyl->end1 : cyl->end0;
    const Vec3 to_head = head_at_1 ? a : Vec3(-a);
    // Axis to +x (head side), turned 29.5 deg about its own axis.
    const double spin = 29.5 * std::numbers::pi / 180.0;
    const Eigen::Matrix3d r = align(to_head, Vec3::UnitX()) * Eigen::AngleAxisd(spin, to_head).toRotationMatrix();
    Pose ps = Pose::Identity();
    ps.linear() = r;
    const Vec3 he = r * head_end;
    const double tz = h_top + cyl->radius - (r * cyl->origin).z();
    const double tx = m.surfaces[m.parts[plate].first_surface + top_face].aabb.max().x() + kMargin - he.x();
    ps.translation() = Vec3(0, 0, tz);
    const Box2 fp = xy(placed_box(sb, ps));
    const Vec3 t = layout.place("the screw", fp, tx);
    ps.translation() = Vec3(tx, t.y(), tz);
    on_board("/board/screw", screw, ps, "screw lying on its side, analytic cylinder tangent, head over the edge", 0.0,
             0.0);
  }

  // 4. A bolt lying on its side: its axis (z) along the board, turned 29.5 deg about it and 17 deg
  // about the board normal, dropped onto the top face (exact distance by BRepExtrema).
  {
    Eigen::Matrix3d lie;
    lie << 0, 0, 1, 0, 1, 0, -1, 0, 0;  // part z to world x
    const double spin = 29.5 * std::numbers::pi / 180.0;
    Pose pl = Pose::Identity();
    pl.linear() = rot_z(17.0) * lie * Eigen::AngleAxisd(spin, Vec3::UnitZ()).toRotationMatrix();
    const Box2 fp = xy(placed_box(part_box(m, bolt), pl));
    const Vec3 t = layout.place("the lying bolt", fp);
    const double high = h_top + 2.0 * part_box(m, bolt).sizes().norm();
    pl.translation() = Vec3(t.x(), t.y(), high);
    const double d = distance_to_plane(m, bolt, pl, up, h_top);
    pl.translation().z() = high - d;
    on_board("/board/bolt-lying", bolt, pl, "bolt lying on its side, head cylinder (B-spline) tangent", 0.0, 17.0);
  }

  // 5. Nuts on either flat face, at stand-offs and sunk in; and the linkrod on its boss ends.
  {
    const std::uint32_t nut_down = outer_plane_facing(m, nut, -up), nut_up = outer_plane_facing(m, nut, up);
    struct NutCase {
      std::uint32_t face;
      double offset, deg;
    };
    const NutCase cases[] = {{nut_down, 0.0, 17.0},   {nut_up, 0.0, 0.0},      {nut_down, 0.005, 0.0},
                             {nut_up, 0.01, 29.5},    {nut_down, 0.02, -33.0}, {nut_up, 0.03, 0.0},
                             {nut_down, -0.001, 17.0}, {nut_up, -0.005, -33.0}, {nut_down, -0.01, 29.5}};
    int k = 0;
    for (const NutCase& c : cases) {
      const Pose p = seat(nut, c.face, up, h_top, c.offset, c.deg, {}, {});
      on_board("/board/nut::" + std::to_string(++k), nut, p, "nut face " + std::to_string(c.face), c.offset, c.deg);
    }
    const std::uint32_t boss = outer_plane_facing(m, linkrod, -up);
    on_board("/board/linkrod", linkrod, seat(linkrod, boss, up, h_top, -0.005, 29.5, {}, {}),
             "linkrod boss end " + std::to_string(boss), -0.005, 29.5);
  }
  return s;
}

void jitter_instances(Model& model, double distance) {
  if (distance == 0.0) return;
  for (InstanceId i = 0; i < model.instances.size(); ++i) {
    std::uint64_t state = 0x5EED0000ull + i;
    auto uniform = [&state] {
      std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
      return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1p-52 - 1.0;  // [-1, 1)
    };
    Vec3 d;
    do {
      const double x = uniform(), y = uniform(), z = uniform();
      d = Vec3(x, y, z);
    } while (d.norm() < 0.1 || d.norm() > 1.0);
    model.instances[i].pose.pretranslate(distance * d.normalized());
  }
}

void move_scene(Model& model, const Pose& motion) {
  for (Instance& i : model.instances) i.pose = motion * i.pose;
}

Model grid_copies(const Model& model, int copies, double gap) {
  Aabb box;
  for (const Instance& i : model.instances) box.extend(placed_box(part_box(model, i.part), i.pose));
  const Vec3 size = box.sizes();
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(copies))));
  Model out;
  out.parts = model.parts;
  out.surfaces = model.surfaces;
  for (int k = 0; k < copies; ++k) {
    Pose shift = Pose::Identity();
    shift.translation() = Vec3((k % columns) * (size.x() + gap), (k / columns) * (size.y() + gap), 0.0);
    for (const Instance& i : model.instances)
      out.instances.push_back({"/copy" + std::to_string(k) + i.path, i.part, shift * i.pose});
  }
  return out;
}

}  // namespace cadclash::truth
