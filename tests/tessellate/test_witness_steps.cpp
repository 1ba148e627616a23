// The cheap certificates of the certified decision on B-rep parts built here: the source's surface
// and boundary points (SurfaceSource::surface_point, boundary_distance), the crossing witness for
// parts sunk into a flat face, the tangent witness for cylinders and spheres lying on one, the
// control-point hull of a B-spline face over a plane, and refinement of only the face that is not a
// plane. Each case is
// checked for its verdict first and then for what it cost (no OCCT face-face query where the
// geometry gives a cheaper proof): a wrong verdict fails, and so does a proof that silently falls
// back to the expensive path.
#include "witness_scene.h"
#include "cadclash/collide.h"
#include "cadclash/tessellate.h"

#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Trsf.hxx>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace cadclash {
namespace {

using namespace testing;  // build, place, moved, check_pair, Outcome (witness_scene.h)

// surface_point: on a cylinder of radius 3 (axis z), the foot of (5, 0, 4) is (3, 0, 4) with the
// normal ±x, whatever the face's boundary; boundary_distance is an upper bound on the distance to
// the face, realised on its edges, and equal to it for a point beyond the top rim.
TEST(SurfacePoint, FootAndNormalOnTheSurfaceAndBoundsOnTheEdges) {
  const Model m = build({BRepPrimAPI_MakeCylinder(3, 8).Shape()}, 0.1);
  const auto* src = dynamic_cast<const BrepSource*>(m.parts[0].source.get());
  ASSERT_NE(src, nullptr);
  std::uint32_t side = kInvalidId;
  for (std::uint32_t i = 0; i < src->face_count(); ++i)
    if (m.surfaces[i].aabb.sizes().z() > 7.0) side = i;
  ASSERT_NE(side, kInvalidId);
  const auto sp = src->surface_point(side, Vec3(5, 0, 4));
  ASSERT_TRUE(sp.has_value());
  EXPECT_NEAR((sp->point - Vec3(3, 0, 4)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(std::abs(sp->normal.x()), 1.0, 1e-9);
  EXPECT_GT(sp->rounding, 0.0);
  // Past the face's top rim (z = 8): the foot on the infinite surface is outside the face; the face's
  // nearest point is on the rim, which boundary_distance finds.
  const Vec3 above(4.0, 0.0, 9.0);
  const auto on_surface = src->surface_point(side, above);
  ASSERT_TRUE(on_surface.has_value());
  EXPECT_NEAR(on_surface->point.z(), 9.0, 1e-9) << "the foot is not clamped to the face";
  const auto rim = src->boundary_distance(side, above);
  ASSERT_TRUE(rim.has_value());
  BRepExtrema_DistShapeShape occt(BRepBuilderAPI_MakeVertex(gp_Pnt(above.x(), above.y(), above.z())).Vertex(),
                                  src->face(side), Extrema_ExtFlag_MIN);
  ASSERT_TRUE(occt.IsDone());
  EXPECT_GE(*rim, occt.Value() - 1e-12) << "an upper bound is never below the distance";
  EXPECT_NEAR(*rim, std::sqrt(2.0), 1e-9);
}

// Each thread keeps the surface adaptor of every face it has queried (brep_face_cache.h): a face of
// another source, or another face of the same one, never gets it, and neither does a source made
// where a freed one was (same address, same face index, other surface).
TEST(SurfacePoint, EachFaceOfEachSourceItsOwnSurfaceAcrossModels) {
  auto side_of = [](const Model& m) {
    std::uint32_t side = kInvalidId;
    for (std::uint32_t i = 0; i < m.surfaces.size(); ++i)
      if (m.surfaces[i].aabb.sizes().z() > 7.0) side = i;
    return side;
  };
  auto foot_radius = [](const Model& m, std::uint32_t face) {
    const auto* src = dynamic_cast<const BrepSource*>(m.parts[0].source.get());
    const auto sp = src->surface_point(face, Vec3(9, 0, 4));
    return sp ? std::hypot(sp->point.x(), sp->point.y()) : -1.0;
  };
  for (int round = 0; round < 3; ++round) {
    const double r = 2.0 + round;
    const Model thin = build({BRepPrimAPI_MakeCylinder(r, 8).Shape()}, 0.1);
    const Model thick = build({BRepPrimAPI_MakeCylinder(r + 0.5, 8).Shape()}, 0.1);
    const std::uint32_t side = side_of(thin);
    ASSERT_NE(side, kInvalidId);
    ASSERT_EQ(side, side_of(thick));
    for (int k = 0; k < 2; ++k) {
      EXPECT_NEAR(foot_radius(thin, side), r, 1e-9) << "round " << round;
      EXPECT_NEAR(foot_radius(thick, side), r + 0.5, 1e-9) << "round " << round;
    }
    // A top or bottom cap (a plane z = 0 or 8) of the same source: its foot keeps x = 9.
    const std::uint32_t cap = side == 0 ? 1 : 0;
    const auto* src = dynamic_cast<const BrepSource*>(thin.parts[0].source.get());
    const auto sp = src->surface_point(cap, Vec3(9, 0, 4));
    ASSERT_TRUE(sp.has_value());
    EXPECT_NEAR(sp->point.x(), 9.0, 1e-9);
    EXPECT_NEAR(std::abs(sp->normal.z()), 1.0, 1e-9);
  }
}

// The adaptors a thread keeps hold their faces' shapes (and triangulations): once the model is gone,
// the thread lets go of them as it goes on querying other faces.
TEST(SurfacePoint, AThreadLetsGoOfTheFacesOfAModelThatIsGone) {
  TopoDS_Face kept;
  {
    const Model gone = build({BRepPrimAPI_MakeBox(1, 2, 3).Shape()}, 0.1);
    const auto* src = dynamic_cast<const BrepSource*>(gone.parts[0].source.get());
    ASSERT_NE(src, nullptr);
    ASSERT_TRUE(src->surface_point(0, Vec3(0.5, 1.0, 1.5)).has_value());
    kept = src->face(0);
  }
  const int held_by_cache = kept.TShape()->GetRefCount();
  ASSERT_GE(held_by_cache, 2) << "the thread's adaptor holds the face";
  // 22 boxes: 132 faces never asked before.
  std::vector<TopoDS_Shape> boxes;
  for (int i = 0; i < 22; ++i) boxes.push_back(BRepPrimAPI_MakeBox(1.0 + i, 2, 3).Shape());
  const Model other = build(boxes, 0.1);
  for (PartId p = 0; p < other.parts.size(); ++p) {
    const auto* src = dynamic_cast<const BrepSource*>(other.parts[p].source.get());
    for (std::uint32_t f = 0; f < src->face_count(); ++f) src->surface_point(f, Vec3(0.5, 1.0, 1.5));
  }
  EXPECT_EQ(kept.TShape()->GetRefCount(), held_by_cache - 1) << "only this test's copy is left of the face";
}

// Asks `src` for the foot on `face` of 96 points (24 angles round the seam, each at 4 offsets from
// the surface: inside, on, just and well outside); at(k, angle, offset) gives a point and its exact
// foot.
template <class At>
void expect_exact_feet(const BrepSource& src, std::uint32_t face, const std::string& what, At at) {
  int checked = 0;
  for (int k = 0; k < 24; ++k) {
    const double a = 2.0 * std::numbers::pi * (k + 0.37) / 24.0;
    for (double off : {-0.01, 0.0, 0.004, 0.05}) {
      const auto [q, foot] = at(k, a, off);
      const auto sp = src.surface_point(face, q);
      ASSERT_TRUE(sp.has_value()) << what << " k " << k << " off " << off;
      EXPECT_NEAR((sp->point - foot).norm(), 0.0, 1e-9) << what << " k " << k << " off " << off;
      EXPECT_GT(sp->rounding, 0.0);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 96) << what;
}

// surface_point on B-spline faces (as1's faces of revolution are stored so): the foot of points
// near a NURBS cylinder and a NURBS torus is the exact one, from its own Gauss-Newton steps or
// OCCT's solver, at every angle round the seam and for points inside, outside and on the surface.
TEST(SurfacePoint, FootOnBsplineFacesIsTheExactFoot) {
  const TopoDS_Shape cylinder = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeCylinder(3, 8).Shape()).Shape();
  const TopoDS_Shape torus = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeTorus(10, 2).Shape()).Shape();
  const Model m = build({cylinder, torus}, 0.05);
  for (PartId part : {PartId{0}, PartId{1}}) {
    const auto* src = dynamic_cast<const BrepSource*>(m.parts[part].source.get());
    ASSERT_NE(src, nullptr);
    const std::uint32_t first = m.parts[part].first_surface;
    std::uint32_t face = kInvalidId;  // the cylinder's side; the torus's only face
    for (std::uint32_t i = 0; i < src->face_count(); ++i)
      if (part == 1 || m.surfaces[first + i].aabb.sizes().z() > 7.0) face = i;
    ASSERT_NE(face, kInvalidId);
    expect_exact_feet(*src, face, "part " + std::to_string(part), [&](int k, double a, double off) {
      if (part == 0)
        return std::pair{Vec3((3 + off) * std::cos(a), (3 + off) * std::sin(a), 1.0 + 0.25 * k),
                         Vec3(3 * std::cos(a), 3 * std::sin(a), 1.0 + 0.25 * k)};
      const double b = 0.7 + 0.2 * k;  // round the tube
      const Vec3 ring(10 * std::cos(a), 10 * std::sin(a), 0.0);
      const Vec3 out = std::cos(b) * Vec3(std::cos(a), std::sin(a), 0.0) + std::sin(b) * Vec3::UnitZ();
      return std::pair{Vec3(ring + (2 + off) * out), Vec3(ring + 2 * out)};
    });
  }
}

// surface_point on planes, cylinders and spheres (their foot in closed form): the exact foot, on
// faces whose shape carries a placement (a location turned and moved off the origin), at every angle
// round the seam, for points inside, outside and on the surface.
TEST(SurfacePoint, FootOnPlacedElementaryFacesIsTheExactFoot) {
  gp_Trsf turn;
  turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 2, 3)), 0.7);
  gp_Trsf shift;
  shift.SetTranslation(gp_Vec(120.0, -40.0, 65.0));
  const gp_Trsf place = shift * turn;
  const TopLoc_Location at(place);
  const Model m = build({BRepPrimAPI_MakeCylinder(3, 8).Shape().Moved(at), BRepPrimAPI_MakeSphere(4).Shape().Moved(at),
                         BRepPrimAPI_MakeBox(5, 6, 7).Shape().Moved(at)},
                        0.05);
  auto placed = [&](const Vec3& v) {
    const gp_Pnt q = gp_Pnt(v.x(), v.y(), v.z()).Transformed(place);
    return Vec3(q.X(), q.Y(), q.Z());
  };
  for (PartId part : {PartId{0}, PartId{1}, PartId{2}}) {
    const auto* src = dynamic_cast<const BrepSource*>(m.parts[part].source.get());
    ASSERT_NE(src, nullptr);
    // The cylinder's side, the sphere's face, the box's face z = 7 (in the shapes' own frames): the
    // face whose foot of one point is that point's foot on it.
    const Vec3 q0 = part == 0 ? Vec3(3.5, 0, 4) : part == 1 ? Vec3(0, 0.3, 4.5) : Vec3(2, 3, 7.5);
    const Vec3 foot0 = part == 0 ? Vec3(3, 0, 4) : part == 1 ? Vec3(q0 * (4 / q0.norm())) : Vec3(2, 3, 7);
    std::uint32_t face = kInvalidId;
    for (std::uint32_t i = 0; i < src->face_count(); ++i)
      if (const auto sp = src->surface_point(i, placed(q0)); sp && (sp->point - placed(foot0)).norm() < 1e-6) face = i;
    ASSERT_NE(face, kInvalidId) << "part " << part;
    expect_exact_feet(*src, face, "placed part " + std::to_string(part), [&](int k, double a, double off) {
      Vec3 q, foot;
      if (part == 0) {
        q = Vec3((3 + off) * std::cos(a), (3 + off) * std::sin(a), 1.0 + 0.25 * k);
        foot = Vec3(3 * std::cos(a), 3 * std::sin(a), q.z());
      } else if (part == 1) {
        const double b = -1.2 + 0.1 * k;
        const Vec3 out(std::cos(b) * std::cos(a), std::cos(b) * std::sin(a), std::sin(b));
        q = (4 + off) * out;
        foot = 4 * out;
      } else {
        q = Vec3(0.2 * k, 0.25 * k, 7 + off);
        foot = Vec3(q.x(), q.y(), 7);
      }
      return std::pair{placed(q), placed(foot)};
    });
  }
}

// Sunk by less than a deflection: every vertex of the sunk part is that depth off the seat, so no
// vertex witnesses the contact. The crossing does: planar faces by their triangles (decided
// analytic), a cylinder by Newton on the curve where it meets the plane. Never OCCT's face-face
// distance; and lifted by the same amount the parts are apart (not reported).
TEST(CrossingWitness, SunkPartsTouchWithoutTheExactFaceDistance) {
  for (bool cylinder : {false, true}) {
    for (double offset : {-0.001, -0.01, 0.01}) {
      Model m = build({BRepPrimAPI_MakeBox(40, 40, 2).Shape(),
                       cylinder ? BRepPrimAPI_MakeCylinder(3, 5).Shape() : BRepPrimAPI_MakeBox(6, 4, 5).Shape()},
                      0.1);
      place(m, 0, "/board", Pose::Identity());
      place(m, 1, "/part", moved(Vec3(17, 15, 2 + offset), 0.3));
      const Outcome r = check_pair(m, 1e-4);
      const std::string what = std::string(cylinder ? "cylinder" : "box") + " at " + std::to_string(offset);
      EXPECT_EQ(r.contact, offset < 0) << what;
      if (offset < 0) {
        EXPECT_EQ(r.report.counters.exact_queries, 0u) << what;
        EXPECT_EQ(r.report.counters.undecided, 0u) << what;
      }
    }
  }
}

// A box, a cylinder, a sphere or a box whose faces are B-splines sunk into a disk's flat top (a plane
// bounded by a circle: its triangles' band is the 0.1 mm deflection) with every face's ε 0.01 mm, so
// T = 0.02 at tolerance 0. Sunk 0.06 mm, their side faces cross the top deeper than T but within T +
// the band: the triangles cannot tell, the exact surfaces do (penetrating, decided analytic, the
// proved depth in (T, 0.06]). Sunk 0.015 mm (within T) they are touching. The same wherever the
// pair is placed.
TEST(DepthWitness, FacesCrossingDeeperThanTheUncertaintyArePenetrating) {
  enum Kind { Box, Cylinder, Sphere, SplineBox };
  const char* names[] = {"box", "cylinder", "sphere", "B-spline box"};
  for (const Pose& where : {Pose::Identity(), moved(Vec3(1e6, -3e5, 2e4), 0.7)})
  for (const Kind kind : {Box, Cylinder, Sphere, SplineBox})
    for (const double sunk : {0.06, 0.015}) {
      const TopoDS_Shape part = kind == Cylinder ? BRepPrimAPI_MakeCylinder(3, 5).Shape()
                                : kind == Sphere ? BRepPrimAPI_MakeSphere(gp_Pnt(0, 0, 3), 3).Shape()
                                : kind == Box    ? BRepPrimAPI_MakeBox(6, 4, 5).Shape()
                                                 : BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeBox(6, 4, 5).Shape()).Shape();
      Model m = build({BRepPrimAPI_MakeCylinder(20, 2).Shape(), part}, 0.1);
      for (Surface& s : m.surfaces) s.uncertainty = 0.01;
      place(m, 0, "/disk", where);
      place(m, 1, "/part", where * moved(Vec3(-3, -2, 2 - sunk), 0.3));
      const Outcome r = check_pair(m, 0.0);
      const std::string what = std::string(names[kind]) + " sunk " + std::to_string(sunk) + " at " +
                               std::to_string(where.translation().x());
      EXPECT_EQ(r.report.counters.undecided, 0u) << what;
      int sides = 0;
      for (const SurfacePairResult& p : r.report.pairs) {
        const Surface& b = m.surfaces[p.surface_b];
        if (b.aabb.sizes().z() < 4.0) continue;  // the side faces (5 or 6 mm tall), not a bottom
        ++sides;
        if (sunk > 0.02) {
          EXPECT_EQ(p.contact, ContactClass::Penetrating) << what << " " << b.name;
          EXPECT_EQ(p.decided_by, DecidedBy::Analytic) << what << " " << b.name;
          EXPECT_GT(p.penetration, 0.02) << what << " " << b.name;
          EXPECT_LE(p.penetration, sunk + 1e-9) << what << " " << b.name;
          EXPECT_EQ(p.within, ContactWithin::Tolerance) << what;
        } else {
          EXPECT_EQ(p.contact, ContactClass::Touching) << what << " " << b.name;
        }
      }
      EXPECT_EQ(sides, kind == Cylinder || kind == Sphere ? 1 : 4) << what;
    }
}

// A sphere sunk 0.03 mm into a disk's flat top (T = 0.02: ε 0.01 mm on every face) whose triangles
// cross the top less deep than T: its nodes miss its lowest point, so the chord triangles there lie
// up to their sagitta above the sphere. The exact surfaces cross deeper than T, and wherever the
// triangles cross the top at all (deeper than the rounding), the pair is proved penetrating on them.
// Turned about a horizontal axis through its centre by angles that move its nodes about; some
// angles must leave its lowest node less than T below the top (else the test proves nothing new).
// The same wherever the pair is placed.
TEST(DepthWitness, CurvedFacesWhoseTrianglesCrossShallowerThanTArePenetrating) {
  constexpr double kSunk = 0.03, kT = 0.02;
  int shallow = 0;
  for (const Pose& where : {Pose::Identity(), moved(Vec3(1e6, -3e5, 2e4), 0.7)})
  for (int k = 0; k < 24; ++k) {
    const double tilt = 0.011 + 0.0237 * k;
    Model m = build({BRepPrimAPI_MakeCylinder(20, 2).Shape(), BRepPrimAPI_MakeSphere(gp_Pnt(0, 0, 3), 3).Shape()}, 0.1);
    for (Surface& s : m.surfaces) s.uncertainty = 0.01;
    // About the sphere's centre (0, 0, 3): its lowest point stays 0.03 below the disk's top (z = 2).
    Pose pose = Pose::Identity();
    pose.translate(Vec3(1, -2, 5 - kSunk));
    pose.rotate(Eigen::AngleAxisd(tilt, Vec3(1, 2, 0).normalized()));
    pose.translate(Vec3(0, 0, -3));
    place(m, 0, "/disk", where);
    place(m, 1, "/sphere", where * pose);
    const Surface& sphere = m.surfaces[m.parts[1].first_surface];
    double lowest = 1e300;
    for (const Vec3& v : sphere.mesh.vertices) lowest = std::min(lowest, (pose * v).z());
    const double below = 2.0 - lowest;  // how far its lowest node lies below the top
    const Outcome r = check_pair(m, 0.0);
    const std::string what = "tilt " + std::to_string(tilt) + ", lowest node " + std::to_string(below) + " below, at " +
                             std::to_string(where.translation().x());
    EXPECT_EQ(r.report.counters.undecided, 0u) << what;
    ASSERT_EQ(r.report.pairs.size(), 1u) << what;
    const SurfacePairResult& p = r.report.pairs[0];
    if (below > 1e-6) {
      EXPECT_EQ(p.contact, ContactClass::Penetrating) << what;
      EXPECT_GT(p.penetration, kT) << what;
      EXPECT_LE(p.penetration, kSunk + 1e-9) << what;
      shallow += below < kT;
    } else {
      EXPECT_NE(p.contact, ContactClass::Clearance) << what;
    }
  }
  EXPECT_GT(shallow, 0);
}

// The contact band's ε and how far a face's own points may lie off it are two things: a KiCad file
// declares 0.01 mm (ε, so T = 0.02 at tolerance 0) while its faces' OCCT tolerances are 1e-7. A box
// sunk 0.025 mm into a disk: its bottom lies 0.025 below the disk's top, parallel, farther than T,
// which the two planes prove (their faces' points lie within the OCCT tolerance of them), with no
// finer triangles and no OCCT distance; its sides cross the top deeper than T (penetrating).
TEST(FaceSlack, PlanesProveAGapBeyondTheDeclaredUncertaintyWithoutRefining) {
  for (const Pose& where : {Pose::Identity(), moved(Vec3(1e6, -3e5, 2e4), 0.7)}) {
    Model m = build({BRepPrimAPI_MakeCylinder(20, 2).Shape(), BRepPrimAPI_MakeBox(6, 4, 5).Shape()}, 0.1);
    for (Surface& s : m.surfaces) {
      EXPECT_GT(s.tolerance, 0.0);
      EXPECT_LT(s.tolerance, 1e-3);
      s.uncertainty = 0.01;
    }
    place(m, 0, "/disk", where);
    place(m, 1, "/part", where * moved(Vec3(-3, -2, 2 - 0.025), 0.3));
    const Outcome r = check_pair(m, 0.0);
    const std::string what = "at " + std::to_string(where.translation().x());
    EXPECT_EQ(r.report.counters.refined_surfaces, 0u) << what;
    EXPECT_EQ(r.report.counters.exact_queries, 0u) << what;
    EXPECT_EQ(r.report.counters.undecided, 0u) << what;
    int sides = 0;
    for (const SurfacePairResult& p : r.report.pairs) {
      const Surface& b = m.surfaces[p.surface_b];
      EXPECT_GT(b.aabb.sizes().z(), 4.0) << what << ": only the side faces meet the disk's top, not " << b.name;
      EXPECT_EQ(p.contact, ContactClass::Penetrating) << what << " " << b.name;
      ++sides;
    }
    EXPECT_EQ(sides, 4) << what;
  }
}

// Tangent to a flat face: a cylinder lying on its side and a sphere resting on it touch along a line
// or at a point where no vertex of theirs need lie, and the cylinder's end disks touch it at one
// point of their rims. The support point of the surface, and the extremum of the rim, toward the
// plane prove it (no OCCT query); lifted by 0.01 mm they are apart.
TEST(TangentWitness, CylinderAndSphereOnAPlaneTouchWithoutTheExactFaceDistance) {
  for (bool sphere : {false, true}) {
    for (double lift : {0.0, 0.01}) {
      Model m = build({BRepPrimAPI_MakeBox(40, 40, 2).Shape(),
                       sphere ? BRepPrimAPI_MakeSphere(4).Shape() : BRepPrimAPI_MakeCylinder(3, 12).Shape()},
                      0.1);
      place(m, 0, "/board", Pose::Identity());
      Pose pose = Pose::Identity();
      pose.translate(Vec3(14, 15, 2 + (sphere ? 4.0 : 3.0) + lift));
      pose.rotate(Eigen::AngleAxisd(0.37, Vec3::UnitZ()));
      if (!sphere) pose.rotate(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()));  // the axis along the board
      place(m, 1, "/part", pose);
      const Outcome r = check_pair(m, 1e-4);
      const std::string what = std::string(sphere ? "sphere" : "cylinder") + " lifted " + std::to_string(lift);
      EXPECT_EQ(r.contact, lift == 0.0) << what;
      EXPECT_EQ(r.report.counters.undecided, 0u) << what;
      // Every contact is proved without OCCT's face-face distance: the curved face by its support
      // point, the cylinder's end disks (touching the board at one point of their rims) by the
      // extremum of the rim toward the board (SurfaceSource::edge_support).
      int curved_contacts = 0, rim_contacts = 0;
      for (const SurfacePairResult& p : r.report.pairs) {
        const SurfaceShape sa = m.surfaces[p.surface_a].analytic.shape, sb = m.surfaces[p.surface_b].analytic.shape;
        if (sa != SurfaceShape::Plane) continue;
        ++(sb == SurfaceShape::Plane ? rim_contacts : curved_contacts);
        EXPECT_FALSE(p.exact_distance.has_value()) << what;
      }
      EXPECT_EQ(curved_contacts, lift == 0.0 ? 1 : 0) << what;
      EXPECT_EQ(rim_contacts, lift == 0.0 && !sphere ? 2 : 0) << what;
      EXPECT_EQ(r.report.counters.exact_queries, 0u) << what;
      // Each contact is one the triangles' interval and the surfaces' parameters leave open (steps 1
      // and 2: ambiguous, counted once, however the pair is settled after); lifted, the parameters
      // prove every pair apart.
      EXPECT_EQ(r.report.counters.ambiguous_pairs, lift == 0.0 ? r.report.pairs.size() : 0u) << what;
    }
  }
}

// A NURBS cylinder (BRepBuilderAPI_NurbsConvert: B-spline faces, no analytic certificate) lying
// 0.005 mm above a flat face, meshed at 0.1 mm, turned about its axis so that its triangles cannot
// tell (a vertex row within a deflection of the board) while the hull of its control points stays
// above the board: the hull proves it apart, without refining anything or asking OCCT.
TEST(HullBound, BSplineStandingOffAPlaneIsApartWithoutRefinement) {
  const TopoDS_Shape nurbs = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeCylinder(3, 12).Shape()).Shape();
  const double gap = 0.005;
  Model m = build({BRepPrimAPI_MakeBox(40, 40, 2).Shape(), nurbs}, 0.1);
  const auto* src = m.parts[1].source.get();
  ASSERT_NE(src, nullptr);
  // The lateral face: the one whose box spans the length.
  std::uint32_t side = kInvalidId;
  for (std::uint32_t i = 0; i < m.parts[1].surface_count; ++i)
    if (m.surfaces[m.parts[1].first_surface + i].aabb.sizes().z() > 11.0) side = i;
  ASSERT_NE(side, kInvalidId);
  const Surface& lateral = m.surfaces[m.parts[1].first_surface + side];
  ASSERT_EQ(lateral.analytic.shape, SurfaceShape::Other);
  // Turned by `angle` about its axis (z), the axis then laid along the board: heights over the board.
  auto pose_at = [&](double angle) {
    Pose p = Pose::Identity();
    p.translate(Vec3(14, 15, 2 + 3.0 + gap));
    p.rotate(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()));
    p.rotate(Eigen::AngleAxisd(angle, Vec3::UnitZ()));
    return p;
  };
  double chosen = -1.0;
  for (int k = 0; k < 360 && chosen < 0.0; ++k) {
    const double angle = k * M_PI / 180.0;
    const Pose p = pose_at(angle);
    double lowest = 1e9;
    for (const Vec3& v : lateral.mesh.vertices) lowest = std::min(lowest, (p * v).z() - 2.0);
    // The board's plane z = 2 in the rod's frame.
    const Pose inv = p.inverse(Eigen::Isometry);
    bool clear = true;  // every face's hull (the end disks are B-splines too) above the board
    for (std::uint32_t f = 0; f < m.parts[1].surface_count; ++f) {
      const auto range = src->height_range(f, inv * Vec3(0, 0, 2), (inv.linear() * Vec3::UnitZ()).normalized());
      ASSERT_TRUE(range.has_value());
      clear = clear && (*range)[0] > 2e-4;
    }
    if (lowest - lateral.deflection <= 1e-4 && clear) chosen = angle;
  }
  ASSERT_GE(chosen, 0.0) << "no turn where the triangles are ambiguous and the hull clears the board";
  place(m, 0, "/board", Pose::Identity());
  place(m, 1, "/rod", pose_at(chosen));
  const Outcome r = check_pair(m, 1e-4);
  EXPECT_FALSE(r.contact);
  // Fast mode (the band alone) would call the lateral face touching: dismissed, by the hull.
  EXPECT_GE(r.report.counters.dismissed_pairs, 1u);
  EXPECT_EQ(r.report.counters.decided_analytic, r.report.counters.dismissed_pairs);
  EXPECT_EQ(r.report.counters.refined_surfaces, 0u);
  EXPECT_EQ(r.report.counters.exact_queries, 0u);
  EXPECT_EQ(r.report.counters.undecided, 0u);
}

}  // namespace
}  // namespace cadclash
