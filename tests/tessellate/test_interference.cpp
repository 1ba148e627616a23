// cadclash/interference.h against shapes whose overlap is known exactly: two boxes, a cylinder
// through a box, rotated placements; and the notes for an open shell and a part touching only.
#include "cadclash/interference.h"

#include "built_parts.h"

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <gp_Pln.hxx>

#include <gtest/gtest.h>

#include <cmath>

namespace cadclash {
namespace {

using testing::build_parts;

// Instances of parts 0 and 1 at the given poses.
Model placed(testing::Built b, const Pose& pa, const Pose& pb) {
  b.model.instances.push_back({"/a", 0, pa});
  b.model.instances.push_back({"/b", 1, pb});
  return std::move(b.model);
}

Pose translation(double x, double y, double z) {
  Pose p = Pose::Identity();
  p.translation() = Vec3(x, y, z);
  return p;
}

TEST(Interference, TwoBoxesOverlapInAKnownSlab) {
  // 10 x 20 x 30 box at the origin; a 5 x 5 x 5 cube moved to (8, 2, 3): overlap 2 x 5 x 5.
  const std::vector<TopoDS_Shape> shapes{BRepPrimAPI_MakeBox(10, 20, 30).Shape(), BRepPrimAPI_MakeBox(5, 5, 5).Shape()};
  const Model m = placed(build_parts(shapes, {}, true), Pose::Identity(), translation(8, 2, 3));
  const InterferenceResult r = measure_interference(m, 0, 1);
  ASSERT_TRUE(r.measured) << r.note;
  EXPECT_NEAR(r.volume, 50.0, 1e-6);
  EXPECT_NEAR(r.depth, 2.0, 1e-6);
  EXPECT_NEAR((r.centroid - Vec3(9, 4.5, 5.5)).norm(), 0.0, 1e-6);
  // Symmetric in the two instances.
  EXPECT_NEAR(measure_interference(m, 1, 0).volume, 50.0, 1e-6);
}

TEST(Interference, RotatedCylinderThroughABox) {
  // A cylinder r = 1, h = 40 along x (rotated from z), through a 10-thick slab: overlap pi * 10.
  const std::vector<TopoDS_Shape> shapes{BRepPrimAPI_MakeBox(10, 20, 20).Shape(), BRepPrimAPI_MakeCylinder(1, 40).Shape()};
  Pose along_x = Pose::Identity();
  along_x.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix();
  along_x.translation() = Vec3(-15, 10, 10);
  const InterferenceResult r = measure_interference(placed(build_parts(shapes, {}, true), Pose::Identity(), along_x), 0, 1);
  ASSERT_TRUE(r.measured) << r.note;
  EXPECT_NEAR(r.volume, M_PI * 10.0, 1e-3);
  EXPECT_NEAR(r.depth, 2.0, 1e-3);  // the cylinder's diameter is the slab's smallest extent
  EXPECT_NEAR((r.centroid - Vec3(5, 10, 10)).norm(), 0.0, 1e-6);
}

TEST(Interference, TouchingSolidsHaveNoVolume) {
  const std::vector<TopoDS_Shape> shapes{BRepPrimAPI_MakeBox(10, 10, 10).Shape(), BRepPrimAPI_MakeBox(5, 5, 5).Shape()};
  const InterferenceResult r = measure_interference(placed(build_parts(shapes, {}, true), Pose::Identity(), translation(10, 0, 0)), 0, 1);
  EXPECT_TRUE(r.measured) << r.note;
  EXPECT_NEAR(r.volume, 0.0, 1e-9);
  EXPECT_EQ(r.depth, 0.0);
}

TEST(Interference, AnOpenShellIsNotAClosedSolid) {
  const std::vector<TopoDS_Shape> shapes{BRepPrimAPI_MakeBox(10, 10, 10).Shape(),
                                         BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 5), gp::DZ()), -1, 1, -1, 1).Shape()};
  const InterferenceResult r = measure_interference(placed(build_parts(shapes, {}, true), Pose::Identity(), translation(5, 5, 0)), 0, 1);
  EXPECT_FALSE(r.measured);
  EXPECT_EQ(r.note, "part shape1 is not a closed solid (4 free edges)");
}

TEST(Interference, AMeshPartIsNotABrepPart) {
  testing::Built b = build_parts({BRepPrimAPI_MakeBox(1, 1, 1).Shape()}, {}, false);
  Part mesh;
  mesh.name = "soup";
  mesh.first_surface = b.model.parts[0].first_surface;  // its surfaces do not matter: it has no source
  mesh.surface_count = b.model.parts[0].surface_count;
  b.model.parts.push_back(mesh);
  const InterferenceResult r = measure_interference(placed(std::move(b), Pose::Identity(), Pose::Identity()), 0, 1);
  EXPECT_FALSE(r.measured);
  EXPECT_EQ(r.note, "part soup is not a B-rep part (a mesh): no solid to intersect");
}

}  // namespace
}  // namespace cadclash
