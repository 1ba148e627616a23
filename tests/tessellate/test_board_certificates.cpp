// Components standing off a board by less than their triangles' band (issue 42): the faces' control
// hulls decide them before any face is meshed again, including the swept walls (surfaces of
// revolution and of linear extrusion) KiCad's exports are full of; refinement is left for what the
// hulls cannot separate, such as a pin near the rim of its drilled hole.
#include "witness_scene.h"

#include "cadclash/collide.h"
#include "cadclash/geometry.h"
#include "cadclash/tessellate.h"
#include "surface_bvh.h"

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepPrimAPI_MakeRevol.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <TopoDS_Compound.hxx>
#include <GC_MakeArcOfEllipse.hxx>
#include <Geom_SurfaceOfLinearExtrusion.hxx>
#include <Geom_SurfaceOfRevolution.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <gp_Elips.hxx>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace cadclash {
namespace {

using namespace testing;  // build, place, moved, check_pair, Outcome (witness_scene.h)

// An elliptic prism: its wall is a surface of linear extrusion of an ellipse.
TopoDS_Shape elliptic_prism() {
  const gp_Elips e(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 4.0, 2.0);
  const TopoDS_Face base = BRepBuilderAPI_MakeFace(BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(e)).Wire());
  return BRepPrimAPI_MakePrism(base, gp_Vec(0, 0, 3)).Shape();
}

// A barrel: a profile whose outer side is a half ellipse (bulging to radius 2.5 between radius 2 at
// z = 0 and z = 3) revolved about z; its wall is a surface of revolution.
TopoDS_Shape barrel() {
  const gp_Elips e(gp_Ax2(gp_Pnt(2, 0, 1.5), gp_Dir(0, -1, 0), gp_Dir(0, 0, 1)), 1.5, 0.5);
  const Handle(Geom_TrimmedCurve) arc = GC_MakeArcOfEllipse(e, std::numbers::pi, 2 * std::numbers::pi, true).Value();
  BRepBuilderAPI_MakeWire w;
  w.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(2, 0, 0)));
  w.Add(BRepBuilderAPI_MakeEdge(arc));
  w.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(2, 0, 3), gp_Pnt(0, 0, 3)));
  w.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 3), gp_Pnt(0, 0, 0)));
  const TopoDS_Face profile = BRepBuilderAPI_MakeFace(w.Wire());
  return BRepPrimAPI_MakeRevol(profile, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1))).Shape();
}

// Whether some face of `shape` lies on a surface of type T.
template <class T>
bool has_surface(const TopoDS_Shape& shape) {
  for (TopExp_Explorer x(shape, TopAbs_FACE); x.More(); x.Next())
    if (!Handle(T)::DownCast(BRep_Tool::Surface(TopoDS::Face(x.Current()))).IsNull()) return true;
  return false;
}

// The walls of an elliptic prism and of a barrel stand 0.02 mm above a board: their triangles (0.1
// mm deflection) cannot tell, the surfaces' parameters have nothing to say about a swept surface,
// and their bottoms are a plane's own business. Their walls' control hulls prove them apart: no face
// meshed again, no OCCT query. At tolerance 0.03 they touch. The same wherever the pair is placed.
TEST(HullFirst, SweptWallsStandingOffABoardAreApartWithoutRefinement) {
  const TopoDS_Shape prism = elliptic_prism(), revolved = barrel();
  ASSERT_TRUE(has_surface<Geom_SurfaceOfLinearExtrusion>(prism));
  ASSERT_TRUE(has_surface<Geom_SurfaceOfRevolution>(revolved));
  for (const Pose& where : {Pose::Identity(), moved(Vec3(1e6, -3e5, 2e4), 0.7)})
    for (const bool extruded : {true, false}) {
      const std::string what = std::string(extruded ? "prism" : "barrel") + " at " + std::to_string(where.translation().x());
      Model m = build({BRepPrimAPI_MakeBox(40, 40, 2).Shape(), extruded ? prism : revolved}, 0.1);
      place(m, 0, "/board", where);
      place(m, 1, "/part", where * moved(Vec3(17, 15, 2 + 0.02), 0.3));
      const Outcome apart = check_pair(m, 1e-4);
      EXPECT_FALSE(apart.contact) << what;
      // Fast mode (the band alone) would call the wall touching: dismissed, by the hull.
      EXPECT_GE(apart.report.counters.dismissed_pairs, 1u) << what;
      EXPECT_EQ(apart.report.counters.decided_analytic, apart.report.counters.dismissed_pairs) << what;
      EXPECT_EQ(apart.report.counters.refined_surfaces, 0u) << what;
      EXPECT_EQ(apart.report.counters.exact_queries, 0u) << what;
      EXPECT_EQ(apart.report.counters.undecided, 0u) << what;
      EXPECT_TRUE(check_pair(m, 0.03).contact) << what;
    }
}

// A torus (no analytic certificate of its own) lying 0.02 mm above a disk (a plane bounded by a
// circle, so its triangles have a band too), meshed at 0.1 mm: the bands hide the gap. The hulls of
// the torus's patches clear the disk's: apart, nothing meshed again. At tolerance 0.03 they touch.
TEST(HullFirst, TorusStandingOffADiskIsApartWithoutRefinement) {
  Model m = build({BRepPrimAPI_MakeCylinder(20, 2).Shape(), BRepPrimAPI_MakeTorus(6, 1.5).Shape()}, 0.1);
  place(m, 0, "/disk", Pose::Identity());
  const double gap = 0.02;
  place(m, 1, "/ring", moved(Vec3(1, -2, 2 + 1.5 + gap), 0.2));
  ASSERT_GT(m.surfaces[m.parts[1].first_surface].deflection, gap / 2) << "the torus's mesh alone must not tell";
  const Outcome apart = check_pair(m, 1e-4);
  EXPECT_FALSE(apart.contact);
  EXPECT_GE(apart.report.counters.dismissed_pairs, 1u);
  EXPECT_EQ(apart.report.counters.exact_queries, 0u);
  EXPECT_EQ(apart.report.counters.refined_surfaces, 0u);
  EXPECT_EQ(apart.report.counters.undecided, 0u);
  EXPECT_TRUE(check_pair(m, 0.03).contact);
}

// The chords of a circular rim in a face's triangles (the face's part-local vertices on the circle
// of radius r about `centre`, in the plane z = `z`): the angle halfway along the chord that cuts
// deepest, and its sagitta.
struct Chord {
  double angle = 0.0, sagitta = 0.0;
};
Chord deepest_chord(const Model& m, double z, const Vec3& centre, double r) {
  std::vector<double> angles;
  for (std::uint32_t i = 0; i < m.parts[0].surface_count; ++i) {
    const Surface& s = m.surfaces[i];
    if (s.analytic.shape != SurfaceShape::Plane || s.aabb.min().z() < z - 1e-6) continue;
    for (const Vec3& v : s.mesh.vertices) {
      const Vec3 d = v - centre;
      if (std::abs(std::hypot(d.x(), d.y()) - r) < 1e-6) angles.push_back(std::atan2(d.y(), d.x()));
    }
  }
  std::sort(angles.begin(), angles.end());
  Chord out;
  for (std::size_t k = 0; k < angles.size(); ++k) {
    const double a = angles[k], b = k + 1 < angles.size() ? angles[k + 1] : angles[0] + 2 * std::numbers::pi;
    const double sagitta = r * (1 - std::cos((b - a) / 2));
    if (sagitta > out.sagitta) out = {(a + b) / 2, sagitta};
  }
  return out;
}

// A source that counts what refinement asks of the one it wraps (whole faces, parts of faces). It
// tells the decision of the face's round holes only when `holes` is set: without them, a pin near
// the rim of its hole is for refinement to decide.
class CountingSource final : public SurfaceSource {
 public:
  explicit CountingSource(std::shared_ptr<SurfaceSource> inner) : inner_(std::move(inner)) {}
  std::atomic<int> whole{0}, regions{0};
  bool holes = false;

  bool triangulate(std::uint32_t i, double d, TriangleMesh& out, double& a, Diagnostic& e) override {
    ++whole;
    return inner_->triangulate(i, d, out, a, e);
  }
  bool triangulate_region(std::uint32_t i, double d, const Aabb& r, TriangleMesh& out, double& a, Diagnostic& e) override {
    ++regions;
    return inner_->triangulate_region(i, d, r, out, a, e);
  }
  double default_deflection() const override { return inner_->default_deflection(); }
  std::optional<double> point_distance(std::uint32_t i, const Vec3& p) const override { return inner_->point_distance(i, p); }
  std::optional<SurfacePoint> surface_point(std::uint32_t i, const Vec3& p) const override { return inner_->surface_point(i, p); }
  std::optional<std::array<double, 2>> height_range(std::uint32_t i, const Vec3& o, const Vec3& n) const override {
    return inner_->height_range(i, o, n);
  }
  std::optional<BezierPatches> bezier_patches(std::uint32_t i) const override { return inner_->bezier_patches(i); }
  std::shared_ptr<const std::vector<CircularHole>> circular_holes(std::uint32_t i) const override {
    return holes ? inner_->circular_holes(i) : nullptr;
  }
  std::optional<SurfacePoint> edge_support(std::uint32_t i, const Vec3& d, const Vec3& near) const override {
    return inner_->edge_support(i, d, near);
  }
  std::optional<double> boundary_distance(std::uint32_t i, const Vec3& p) const override {
    return inner_->boundary_distance(i, p);
  }
  std::optional<double> edge_distance(std::uint32_t a, const Pose& pa, const SurfaceSource& other, std::uint32_t b,
                                      const Pose& pb, const Vec3& na, const Vec3& nb) const override {
    return inner_->edge_distance(a, pa, unwrap(other), b, pb, na, nb);
  }
  std::optional<double> exact_distance(std::uint32_t a, const Pose& pa, const SurfaceSource& other, std::uint32_t b,
                                       const Pose& pb, double max_distance, double enough) const override {
    return inner_->exact_distance(a, pa, unwrap(other), b, pb, max_distance, enough);
  }

 private:
  static const SurfaceSource& unwrap(const SurfaceSource& s) {
    const auto* c = dynamic_cast<const CountingSource*>(&s);
    return c != nullptr ? *c->inner_ : s;
  }
  std::shared_ptr<SurfaceSource> inner_;
};

// A square pin through a round hole drilled in a board, a corner 0.003 mm farther from the rim than
// the deepest chord of the rim in the board's triangles: the board's top face is a plane whose
// outline its triangles cut by that chord, and the pin's sides cross the board's plane inside the
// hole, so neither the plane nor the hulls (the board's patch spans the hole) can tell. Finer
// triangles of the board's top face can: apart, by refinement, without OCCT's distance (the
// board's source tells nothing of its holes here: HoleBound below decides this pin without
// refinement). Pushed to the rim, the pin's corner reaches past it: contact.
TEST(RefinedAnalytic, APinNearTheRimOfItsHoleIsProvedApartByRefiningTheBoard) {
  const double r = 1.0;
  const Vec3 centre(10, 10, 2);
  const TopoDS_Shape board =
      BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(20, 20, 2).Shape(),
                      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(10, 10, -1), gp_Dir(0, 0, 1)), r, 4).Shape())
          .Shape();
  const Chord chord = deepest_chord(build({board}, 0.1), 2.0, centre, r);
  ASSERT_GT(chord.sagitta, 0.004);
  const double corner = r - chord.sagitta - 0.003, half = corner / std::sqrt(2.0);
  const TopoDS_Shape pin = BRepPrimAPI_MakeBox(gp_Pnt(-half, -half, -2), 2 * half, 2 * half, 6).Shape();
  Model m = build({board, pin}, 0.1);
  m.parts[0].source = std::make_shared<CountingSource>(m.parts[0].source);
  place(m, 0, "/board", Pose::Identity());
  // Turned so that a corner (at 45 degrees in the pin's frame) faces the middle of that chord.
  auto pin_at = [&](double out) {
    const Vec3 dir(std::cos(chord.angle), std::sin(chord.angle), 0.0);
    return moved(Vec3(10, 10, 0) + out * dir, chord.angle - std::numbers::pi / 4);
  };
  place(m, 1, "/pin", pin_at(0.0));
  const Outcome apart = check_pair(m, 1e-4);
  EXPECT_FALSE(apart.contact);
  EXPECT_GE(apart.report.counters.refined_surfaces, 1u);
  EXPECT_GE(apart.report.counters.decided_refined, 1u);
  EXPECT_EQ(apart.report.counters.exact_queries, 0u);
  EXPECT_EQ(apart.report.counters.undecided, 0u);
  Model near = m;
  near.instances[1].pose = pin_at(chord.sagitta + 0.004);
  EXPECT_TRUE(check_pair(near, 1e-4).contact);
}

// A board of 144 drilled holes (its top face thousands of triangles) and a square pin in one of
// them, a corner 0.003 mm farther from the rim than the deepest chord there: as above (the holes
// not told), only finer triangles of the board's top face prove the pin apart, and only near the pin are they made
// (SurfaceSource::triangulate_region; the whole face is never meshed again).
TEST(RegionalRefinement, APinInABoardOfManyHolesRefinesTheBoardOnlyNearIt) {
  const double r = 1.0;
  TopoDS_Compound drills;
  BRep_Builder builder;
  builder.MakeCompound(drills);
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
      builder.Add(drills, BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(6 + 8 * i, 6 + 8 * j, -1), gp_Dir(0, 0, 1)), r, 4).Shape());
  const TopoDS_Shape board = BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(100, 100, 2).Shape(), drills).Shape();
  const Vec3 centre(46, 54, 2);  // hole (5, 6)
  const Chord chord = deepest_chord(build({board}, 0.1), 2.0, centre, r);
  ASSERT_GT(chord.sagitta, 0.004);
  const double corner = r - chord.sagitta - 0.003, half = corner / std::sqrt(2.0);
  const TopoDS_Shape pin = BRepPrimAPI_MakeBox(gp_Pnt(-half, -half, -2), 2 * half, 2 * half, 6).Shape();
  Model m = build({board, pin}, 0.1);
  std::size_t top_triangles = 0;
  for (std::uint32_t i = 0; i < m.parts[0].surface_count; ++i)
    if (m.surfaces[i].aabb.min().z() > 1.9) top_triangles = m.surfaces[i].mesh.triangles.size();
  ASSERT_GT(top_triangles, 2000u) << "the board's top face must be large enough to refine near the pin only";
  auto counting = std::make_shared<CountingSource>(m.parts[0].source);
  m.parts[0].source = counting;
  place(m, 0, "/board", Pose::Identity());
  const Vec3 dir(std::cos(chord.angle), std::sin(chord.angle), 0.0);
  place(m, 1, "/pin", moved(Vec3(centre.x(), centre.y(), 0), chord.angle - std::numbers::pi / 4));
  const Outcome apart = check_pair(m, 1e-4);
  EXPECT_FALSE(apart.contact);
  EXPECT_GE(apart.report.counters.decided_refined, 1u);
  EXPECT_GE(apart.report.counters.refined_surfaces, 1u);
  EXPECT_EQ(apart.report.counters.exact_queries, 0u);
  EXPECT_EQ(apart.report.counters.undecided, 0u);
  EXPECT_GE(counting->regions.load(), 1);
  EXPECT_EQ(counting->whole.load(), 0);
  // Pushed past the rim: contact, whatever was refined.
  Model near = m;
  near.instances[1].pose = moved(Vec3(centre.x(), centre.y(), 0) + (chord.sagitta + 0.004) * dir,
                                 chord.angle - std::numbers::pi / 4);
  EXPECT_TRUE(check_pair(near, 1e-4).contact);
}

// triangulate_region meshes the part of a face inside a box: a cylinder's side within a box across
// part of it. The region's triangles lie on the face (their vertices on the cylinder, in the box) and
// cover every point of the face in the box (points of the exact cylinder there lie within the
// achieved deflection of them); a box the face misses gives no triangles.
TEST(RegionalRefinement, TriangulateRegionCoversThePartOfTheFaceInTheBox) {
  Model m = build({BRepPrimAPI_MakeCylinder(5, 10).Shape()}, 0.1);
  auto* src = dynamic_cast<BrepSource*>(m.parts[0].source.get());
  ASSERT_NE(src, nullptr);
  std::uint32_t side = kInvalidId;
  for (std::uint32_t i = 0; i < m.parts[0].surface_count; ++i)
    if (m.surfaces[i].analytic.shape == SurfaceShape::Cylinder) side = i;
  ASSERT_NE(side, kInvalidId);
  const Aabb box(Vec3(3, -2, 4), Vec3(6, 2, 6));
  TriangleMesh part;
  double achieved = 0.0;
  Diagnostic error;
  ASSERT_TRUE(src->triangulate_region(side, 0.01, box, part, achieved, error)) << error.message;
  ASSERT_FALSE(part.triangles.empty());
  EXPECT_LE(achieved, 0.01 + 1e-12);
  for (const Vec3& v : part.vertices) {
    EXPECT_NEAR(std::hypot(v.x(), v.y()), 5.0, 1e-6);
    EXPECT_TRUE(pad_box(box, 1e-6).contains(v));
  }
  // Points of the exact face in the box: within the achieved deflection of the region's triangles.
  const detail::SurfaceBvh tree = detail::build_surface_bvh(part);
  int inside = 0;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 10; ++j) {
      const double a = -0.5 + i * 0.025, z = 4.0 + 0.2 * j;
      const Vec3 x(5.0 * std::cos(a), 5.0 * std::sin(a), z);
      if (!box.contains(x)) continue;
      ++inside;
      EXPECT_TRUE(detail::point_near_mesh(tree, part, x, achieved + 1e-9)) << a << ' ' << z;
    }
  EXPECT_GT(inside, 100);
  TriangleMesh none;
  ASSERT_TRUE(src->triangulate_region(side, 0.01, Aabb(Vec3(20, 20, 20), Vec3(21, 21, 21)), none, achieved, error));
  EXPECT_TRUE(none.triangles.empty());
}

// A board of 12 x 12 holes drilled through a 100 x 100 x 2 plate, each of radius r.
TopoDS_Shape drilled_board(double r) {
  TopoDS_Compound drills;
  BRep_Builder builder;
  builder.MakeCompound(drills);
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
      builder.Add(drills, BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(6 + 8 * i, 6 + 8 * j, -1), gp_Dir(0, 0, 1)), r, 4).Shape());
  return BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(100, 100, 2).Shape(), drills).Shape();
}

// The planar face of part 0 whose box lies at height z.
std::uint32_t plane_at(const Model& m, double z) {
  for (std::uint32_t i = 0; i < m.parts[0].surface_count; ++i)
    if (m.surfaces[i].analytic.shape == SurfaceShape::Plane && std::abs(m.surfaces[i].aabb.min().z() - z) < 1e-6 &&
        std::abs(m.surfaces[i].aabb.max().z() - z) < 1e-6)
      return i;
  return kInvalidId;
}

// circular_holes lists a drilled plate's holes on its top face (centres on the plane at the drills'
// axes, radii the drill's less at most a micrometre), and none for faces whose circles are not holes
// or not circles: a disk (its circle the outer wire), a plate with a square hole, a plate drilled
// at a slant (its rim an ellipse).
TEST(HoleBound, CircularHolesListsTheDrilledHolesOfAPlate) {
  const Model m = build({drilled_board(1.0)}, 0.1);
  const std::uint32_t top = plane_at(m, 2.0);
  ASSERT_NE(top, kInvalidId);
  const auto holes = m.parts[0].source->circular_holes(top);
  ASSERT_NE(holes, nullptr);
  ASSERT_EQ(holes->size(), 144u);
  std::vector<std::pair<long, long>> at;
  for (const auto& h : *holes) {
    EXPECT_NEAR(h.centre.z(), 2.0, 1e-9);
    EXPECT_LE(h.radius, 1.0);
    EXPECT_GT(h.radius, 1.0 - 1e-6);
    at.emplace_back(std::lround(h.centre.x()), std::lround(h.centre.y()));
    EXPECT_NEAR(h.centre.x(), static_cast<double>(at.back().first), 1e-9);
    EXPECT_NEAR(h.centre.y(), static_cast<double>(at.back().second), 1e-9);
  }
  std::sort(at.begin(), at.end());
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) EXPECT_EQ(at[static_cast<std::size_t>(12 * i + j)], std::make_pair(6L + 8 * i, 6L + 8 * j));

  const auto none = [](const TopoDS_Shape& shape, double z) {
    const Model part = build({shape}, 0.1);
    const std::uint32_t face = plane_at(part, z);
    EXPECT_NE(face, kInvalidId);
    if (face == kInvalidId) return false;
    const auto h = part.parts[0].source->circular_holes(face);
    return h != nullptr && h->empty();
  };
  EXPECT_TRUE(none(BRepPrimAPI_MakeCylinder(5, 10).Shape(), 10.0));
  EXPECT_TRUE(none(BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(20, 20, 2).Shape(),
                                   BRepPrimAPI_MakeBox(gp_Pnt(8, 8, -1), 4, 4, 4).Shape())
                       .Shape(),
                   2.0));
  EXPECT_TRUE(none(BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(20, 20, 2).Shape(),
                                   BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(10, 10, -1), gp_Dir(0.3, 0, 1)), 1, 6).Shape())
                       .Shape(),
                   2.0));
}

// A pin in one of a board's 144 holes, its farthest reach from the hole's axis `reach` (< r):
// part 1 placed at the hole (46, 54), shifted from the axis by `shift` along x.
struct PinInHole {
  Model m;
  std::shared_ptr<CountingSource> board;
};
PinInHole pin_in_hole(const TopoDS_Shape& pin, double shift) {
  PinInHole out{build({drilled_board(1.0), pin}, 0.1), nullptr};
  out.board = std::make_shared<CountingSource>(out.m.parts[0].source);
  out.board->holes = true;
  out.m.parts[0].source = out.board;
  place(out.m, 0, "/board", Pose::Identity());
  place(out.m, 1, "/pin", moved(Vec3(46 + shift, 54, 0)));
  return out;
}

// Apart without OCCT's distance, nothing undecided, `refined` faces meshed finer and none of them
// (nor any region) the board's.
void expect_apart_board_untouched(const Outcome& apart, const PinInHole& s, std::size_t refined) {
  EXPECT_FALSE(apart.contact);
  EXPECT_EQ(apart.report.counters.refined_surfaces, refined);
  EXPECT_EQ(apart.report.counters.exact_queries, 0u);
  EXPECT_EQ(apart.report.counters.undecided, 0u);
  EXPECT_EQ(s.board->regions.load() + s.board->whole.load(), 0);
}

// A square pin off the axis of its hole, its far corners 0.1 mm from the rim, the near ones deep
// inside: the board's round hole keeps its sides off the top and bottom faces by their farthest
// vertex from the axis, so at tolerance 0.095 it is apart by the surfaces' parameters alone
// (decided analytic): nothing meshed again, no OCCT distance. At 0.1005, contact (the exact gap is
// 0.1; the triangles cannot show it, a witness on the exact faces does, once the bound has not
// claimed the pair apart).
TEST(HoleBound, ASquarePinNearTheRimIsApartByTheHolesAxisWithoutRefinement) {
  const double half = 0.3;
  const double shift = 0.9 - half * std::sqrt(2.0);  // the far corners at 0.9 from the axis
  const TopoDS_Shape pin = BRepPrimAPI_MakeBox(gp_Pnt(-half, -half, -2), 2 * half, 2 * half, 6).Shape();
  // Turned so that a corner points along +x.
  PinInHole s = pin_in_hole(pin, 0.0);
  s.m.instances[1].pose = moved(Vec3(46 + shift, 54, 0), std::numbers::pi / 4);
  const Outcome apart = check_pair(s.m, 0.095);
  expect_apart_board_untouched(apart, s, 0);
  EXPECT_GE(apart.report.counters.decided_analytic, 1u);
  // The pin's far corner edge touches the hole's wall and both the board's faces at their rims.
  const Outcome near = check_pair(s.m, 0.1005);
  const std::uint32_t top = plane_at(s.m, 2.0), bottom = plane_at(s.m, 0.0);
  int faces = 0;
  for (const SurfacePairResult& p : near.report.pairs)
    faces += (p.surface_a == top || p.surface_a == bottom) && p.contact == ContactClass::Touching;
  EXPECT_EQ(faces, 2 * 2) << "the two sides meeting at the far corner touch both faces at the rim";
  // The same verdicts with the whole assembly turned and moved 10^6 mm away.
  Pose far = Pose::Identity();
  far.translate(Vec3(1e6, -4e5, 3e5));
  far.rotate(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  for (Instance& i : s.m.instances) i.pose = far * i.pose;
  const Outcome far_apart = check_pair(s.m, 0.095);
  expect_apart_board_untouched(far_apart, s, 0);
  EXPECT_GE(far_apart.report.counters.decided_analytic, 1u);
  int far_faces = 0;
  for (const SurfacePairResult& p : check_pair(s.m, 0.1005).report.pairs)
    far_faces += (p.surface_a == top || p.surface_a == bottom) && p.contact == ContactClass::Touching;
  EXPECT_EQ(far_faces, 2 * 2);
}

// A round pin 0.1 mm from the rim, its triangles up to 0.0036 mm inside its cylinder: too coarse
// for the hole's bound at tolerance 0.098, so the pin alone is meshed finer (never the board's
// face: at a hole, finer board triangles cannot help), and the finer pin is proved apart. At
// 0.102, contact.
TEST(HoleBound, ARoundPinNearTheRimRefinesThePinOnly) {
  PinInHole s = pin_in_hole(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -2), gp_Dir(0, 0, 1)), 0.5, 6).Shape(), 0.4);
  for (std::uint32_t i = s.m.parts[1].first_surface; i < s.m.surfaces.size(); ++i)
    ASSERT_GT(s.m.surfaces[i].deflection, 0.0025) << "the pin's triangles must be too coarse for the bound";
  const Outcome apart = check_pair(s.m, 0.098);
  expect_apart_board_untouched(apart, s, 1);
  EXPECT_GE(apart.report.counters.decided_refined, 1u);
  EXPECT_TRUE(check_pair(s.m, 0.102).contact);
}

}  // namespace
}  // namespace cadclash
