// Components standing off a board by less than their triangles' band (issue 42): the faces' control
// hulls decide them before any face is meshed again, including the swept walls (surfaces of
// revolution and of linear extrusion) KiCad's exports are full of; refinement is left for what the
// hulls cannot separate, such as a pin near the rim of its drilled hole.
#include "witness_scene.h"

#include "cadclash/collide.h"
#include "cadclash/tessellate.h"

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepPrimAPI_MakeRevol.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRep_Tool.hxx>
#include <GC_MakeArcOfEllipse.hxx>
#include <Geom_SurfaceOfLinearExtrusion.hxx>
#include <Geom_SurfaceOfRevolution.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <gp_Elips.hxx>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace cadclash {
namespace {

using testing::build;
using testing::check_pair;
using testing::moved;
using testing::Outcome;
using testing::place;

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

// A square pin through a round hole drilled in a board, a corner 0.003 mm farther from the rim than
// the deepest chord of the rim in the board's triangles: the board's top face is a plane whose
// outline its triangles cut by that chord, and the pin's sides cross the board's plane inside the
// hole, so neither the plane nor the hulls (the board's patch spans the hole) can tell. Finer
// triangles of the board's top face can: apart, by refinement, without OCCT's distance. Pushed to
// the rim, the pin's corner reaches past it: contact.
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

}  // namespace
}  // namespace cadclash
