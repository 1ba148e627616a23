// The cheap certificates of the certified decision on B-rep parts built here: the source's surface
// and boundary points (SurfaceSource::surface_point, boundary_distance), the crossing witness for
// parts sunk into a flat face, and refinement of only the face that is not a plane. Each case is
// checked for its verdict first and then for what it cost (no OCCT face-face query where the
// geometry gives a cheaper proof): a wrong verdict fails, and so does a proof that silently falls
// back to the expensive path.
#include "built_parts.h"
#include "cadclash/collide.h"
#include "cadclash/tessellate.h"

#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <TopoDS_Shape.hxx>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace cadclash {
namespace {

Model build(const std::vector<TopoDS_Shape>& shapes, double deflection) {
  TessellationOptions t;
  t.linear_deflection = deflection;
  testing::Built b = testing::build_parts(shapes, t, false);
  EXPECT_TRUE(b.complete);
  return std::move(b.model);
}

void place(Model& m, PartId part, const std::string& path, const Pose& pose) {
  Instance in;
  in.path = path;
  in.part = part;
  in.pose = pose;
  m.instances.push_back(in);
}

Pose moved(const Vec3& offset, double angle_z = 0.0) {
  Pose p = Pose::Identity();
  p.translate(offset);
  p.rotate(Eigen::AngleAxisd(angle_z, Vec3::UnitZ()));
  return p;
}

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

struct Outcome {
  Report report;
  bool contact = false;  // some pair of the two instances is reported touching or penetrating
};

Outcome check_pair(Model& m, double tolerance) {
  Scene scene(m);
  CollideOptions o;
  o.tolerance = tolerance;
  o.threads = 1;
  Outcome out{scene.check(o)};
  for (const SurfacePairResult& p : out.report.pairs)
    out.contact |= p.contact == ContactClass::Touching || p.contact == ContactClass::Penetrating;
  return out;
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

// A torus (no analytic certificate of its own) lying 0.02 mm above a disk (a plane bounded by a
// circle, so its triangles have a band too), meshed at 0.1 mm: the bands hide the gap, and finer
// triangles of both would still. The disk's plane against the torus's finer triangles proves it
// apart: one refined face (the torus; the plane is not refined), no OCCT query. At tolerance 0.03
// the two touch.
TEST(RefinedAnalytic, StandOffOverAPlaneIsProvedByRefiningTheOtherFaceOnly) {
  Model m = build({BRepPrimAPI_MakeCylinder(20, 2).Shape(), BRepPrimAPI_MakeTorus(6, 1.5).Shape()}, 0.1);
  place(m, 0, "/disk", Pose::Identity());
  const double gap = 0.02;
  place(m, 1, "/ring", moved(Vec3(1, -2, 2 + 1.5 + gap), 0.2));
  ASSERT_GT(m.surfaces[m.parts[1].first_surface].deflection, gap / 2) << "the torus's mesh alone must not tell";
  double disk_deflection = 0.0;
  for (std::uint32_t i = 0; i < m.parts[0].surface_count; ++i)
    if (m.surfaces[i].analytic.shape == SurfaceShape::Plane) disk_deflection = std::max(disk_deflection, m.surfaces[i].deflection);
  ASSERT_GT(disk_deflection, gap) << "the disk's band alone hides the gap";
  const Outcome apart = check_pair(m, 1e-4);
  EXPECT_FALSE(apart.contact);
  EXPECT_EQ(apart.report.counters.exact_queries, 0u);
  EXPECT_EQ(apart.report.counters.refined_surfaces, 1u);
  EXPECT_EQ(apart.report.counters.undecided, 0u);
  const Outcome touching = check_pair(m, 0.03);
  EXPECT_TRUE(touching.contact);
}

}  // namespace
}  // namespace cadclash
