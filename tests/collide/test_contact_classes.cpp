// One labelled scene per contact class (definitions in collide.h).
#include "scene_fixtures.h"

#include <cstdio>
#include <gtest/gtest.h>

#include <algorithm>

namespace cadclash {
namespace {

using namespace cadclash::testing;

std::size_t count(const Report& r, ContactClass c) {
  return static_cast<std::size_t>(
      std::count_if(r.pairs.begin(), r.pairs.end(), [c](const SurfacePairResult& p) { return p.contact == c; }));
}

const SurfacePairResult* find(const Model& m, const Report& r, const std::string& sa, const std::string& sb) {
  for (const SurfacePairResult& p : r.pairs)
    if (p.surface_a != kInvalidId && m.surfaces[p.surface_a].name == sa && m.surfaces[p.surface_b].name == sb) return &p;
  return nullptr;
}

Model two_boxes(const Vec3& offset, int n = 1) {
  Model m;
  const PartId box = add_part(m, "box", box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), n));
  add_instance(m, "/a", box);
  add_instance(m, "/b", box, translation(offset.x(), offset.y(), offset.z()));
  return m;
}

TEST(ContactClass, OverlappingBoxesPenetrate) {
  Model m = two_boxes(Vec3(0.9, 0.3, 0.2));
  CollideOptions o;
  o.tolerance = 0.01;
  const Report r = collide(m, 0, 1, o);
  const SurfacePairResult* p = find(m, r, "x+", "y-");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->contact, ContactClass::Penetrating);
  EXPECT_TRUE(p->intersecting);
  EXPECT_EQ(p->distance, 0.0);
  EXPECT_GT(count(r, ContactClass::Penetrating), 3u);
  // All pairs visited: the estimate is the largest crossing depth, here the 0.1 overlap along x.
  o.mode = CollideMode::AllTrianglePairs;
  const Report all = collide(m, 0, 1, o);
  p = find(m, all, "x+", "y-");
  ASSERT_NE(p, nullptr);
  EXPECT_NEAR(p->penetration, 0.1, 1e-12);
  EXPECT_FALSE(p->triangle_pairs.empty());
  // A tolerance above the crossing depth turns the same contact into touching.
  o.tolerance = 0.2;
  const Report loose = collide(m, 0, 1, o);
  p = find(m, loose, "x+", "y-");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->contact, ContactClass::Touching);
}

TEST(ContactClass, FaceToFaceBoxesTouch) {
  Model m = two_boxes(Vec3(1, 0, 0), 2);
  const Report r = collide(m, 0, 1);
  const SurfacePairResult* p = find(m, r, "x+", "x-");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->contact, ContactClass::Touching);
  EXPECT_TRUE(p->intersecting);
  EXPECT_EQ(p->penetration, 0.0);
  EXPECT_EQ(count(r, ContactClass::Penetrating), 0u);
  // Side faces meeting along the shared edge touch too; faces far apart are not reported.
  EXPECT_NE(find(m, r, "y+", "y+"), nullptr);
  EXPECT_EQ(find(m, r, "x-", "x+"), nullptr);
}

TEST(ContactClass, CoaxialCylinderInHoleTouchesThroughDeflection) {
  Model m;
  // Bolt: 24 chords; hole: 36 chords, rotated, facing inwards. Both radii 5: the exact faces coincide.
  const PartId bolt = add_part(m, "bolt", {cylinder_surface("shank", 5.0, -1.0, 11.0, 24, 0.0)});
  const PartId nut = add_part(m, "nut", {cylinder_surface("bore", 5.0, 0.0, 10.0, 36, 0.1, false)});
  add_instance(m, "/bolt", bolt);
  add_instance(m, "/nut", nut);
  CollideOptions fast;
  fast.decision = DecisionMode::Fast;
  Report r = collide(m, 0, 1, fast);
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].contact, ContactClass::Touching);
  EXPECT_LE(r.pairs[0].penetration, m.surfaces[0].deflection + m.surfaces[1].deflection);
  // Certified: the chords only say the exact faces are within both deflections of each other, and
  // without exact geometry nothing can say more. Reported as undecided with that interval, never as
  // touching.
  r = collide(m, 0, 1);
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].contact, ContactClass::Undecided);
  EXPECT_EQ(r.pairs[0].decided_by, DecidedBy::Undecided);
  EXPECT_EQ(r.pairs[0].distance_lo, 0.0);
  EXPECT_GE(r.pairs[0].distance_hi, m.surfaces[0].deflection + m.surfaces[1].deflection);
  EXPECT_EQ(r.counters.undecided, 1u);
  // Without the deflections the chords' crossing looks like penetration: the tolerance needs them.
  m.surfaces[0].deflection = m.surfaces[1].deflection = 0.0;
  for (const CollideOptions& o : {fast, CollideOptions{}}) {
    r = collide(m, 0, 1, o);
    ASSERT_EQ(r.pairs.size(), 1u);
    EXPECT_EQ(r.pairs[0].contact, ContactClass::Penetrating);
  }
  EXPECT_EQ(r.pairs[0].decided_by, DecidedBy::MeshExact);
}

TEST(ContactClass, ThinnerBoltInHoleIsClearance) {
  Model m;
  const PartId bolt = add_part(m, "bolt", {cylinder_surface("shank", 4.5, -1.0, 11.0, 48, 0.0)});
  const PartId nut = add_part(m, "nut", {cylinder_surface("bore", 5.0, 0.0, 10.0, 48, 0.0, false)});
  add_instance(m, "/bolt", bolt);
  add_instance(m, "/nut", nut);
  CollideOptions o;
  EXPECT_TRUE(collide(m, 0, 1, o).pairs.empty());
  o.clearance = 1.0;
  const Report r = collide(m, 0, 1, o);
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].contact, ContactClass::Clearance);
  EXPECT_FALSE(r.pairs[0].intersecting);
  EXPECT_NEAR(r.pairs[0].distance, 0.5, 0.01);
}

TEST(ContactClass, PlaneTangentToFacetedCylinderTouches) {
  Model m;
  // Chords from -pi/16 to pi/16 around the x axis: the facet facing the plane sits one sagitta
  // (= the achieved deflection) inside the exact cylinder, which the plane x = 10 touches.
  const double pi = std::numbers::pi;
  const PartId cyl = add_part(m, "roller", {cylinder_surface("mantle", 10.0, 0.0, 5.0, 16, -pi / 16)});
  const PartId plate = add_part(m, "plate", {grid_surface("top", Vec3(10, -5, -1), Vec3(0, 10, 0), Vec3(0, 0, 7), 1)});
  add_instance(m, "/roller", cyl);
  add_instance(m, "/plate", plate);
  CollideOptions o;
  o.tolerance = 1e-9;
  o.decision = DecisionMode::Fast;
  Report r = collide(m, 0, 1, o);
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].contact, ContactClass::Touching);
  EXPECT_FALSE(r.pairs[0].intersecting);
  EXPECT_NEAR(r.pairs[0].distance, m.surfaces[0].deflection, 1e-9);
  // Certified without exact geometry: the gap of one sagitta may be the faceting or a real gap.
  o.decision = DecisionMode::Certified;
  r = collide(m, 0, 1, o);
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].contact, ContactClass::Undecided);
  EXPECT_EQ(r.pairs[0].distance_lo, 0.0);
  EXPECT_NEAR(r.pairs[0].distance_hi, 2.0 * m.surfaces[0].deflection, 1e-9);
  // Told the roller's exact shape, the mesh-only plate is proved 0 from it within the band... still
  // only a lower bound of 0: a plane tangent to a cylinder is in contact, which needs exact geometry.
  m.surfaces[0].analytic.shape = SurfaceShape::Cylinder;
  m.surfaces[0].analytic.axis = Vec3::UnitZ();
  m.surfaces[0].analytic.radius = 10.0;
  r = collide(m, 0, 1, o);
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].contact, ContactClass::Undecided);
  // Moved 0.05 away (more than the band of one sagitta), the cylinder's parameters prove it apart.
  m.instances[1].pose.translation().x() += 0.05;
  o.decision = DecisionMode::Fast;
  const bool fast_touches = !collide(m, 0, 1, o).pairs.empty();
  o.decision = DecisionMode::Certified;
  r = collide(m, 0, 1, o);
  EXPECT_TRUE(r.pairs.empty());
  if (fast_touches) {
    EXPECT_EQ(r.counters.decided_analytic, 1u);
  }
  m.instances[1].pose.translation().x() -= 0.05;
  o.decision = DecisionMode::Fast;
  // A mesh without a recorded deflection is taken literally: the gap is a clearance.
  m.surfaces[0].deflection = 0.0;
  o.clearance = 1.0;
  r = collide(m, 0, 1, o);
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].contact, ContactClass::Clearance);
}

TEST(ContactClass, SeparatedBoxesWithinClearance) {
  Model m = two_boxes(Vec3(1.5, 0, 0));
  CollideOptions o;
  EXPECT_TRUE(collide(m, 0, 1, o).pairs.empty());
  o.clearance = 0.3;
  EXPECT_TRUE(collide(m, 0, 1, o).pairs.empty());
  o.clearance = 1.0;
  const Report r = collide(m, 0, 1, o);
  const SurfacePairResult* p = find(m, r, "x+", "x-");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->contact, ContactClass::Clearance);
  EXPECT_DOUBLE_EQ(p->distance, 0.5);
  EXPECT_EQ(count(r, ContactClass::Clearance), r.pairs.size());
}

TEST(ContactClass, SmallBoxInsideBigClosedBox) {
  Model m;
  const PartId big = add_part(m, "big", box_surfaces(Vec3(0, 0, 0), Vec3(10, 10, 10), 2));
  const PartId small = add_part(m, "small", box_surfaces(Vec3(4, 4, 4), Vec3(6, 6, 6)));
  add_instance(m, "/small", small);
  add_instance(m, "/big", big);
  Report r = collide(m, 0, 1);
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].contact, ContactClass::Containment);
  EXPECT_EQ(r.pairs[0].surface_a, kInvalidId);
  // The other instance order, and a small box poking through a wall (crossing: not containment).
  std::swap(m.instances[0], m.instances[1]);
  r = collide(m, 0, 1);
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].contact, ContactClass::Containment);
  m.instances[1].pose = translation(5, 0, 0);
  r = collide(m, 0, 1);
  EXPECT_EQ(count(r, ContactClass::Containment), 0u);
  EXPECT_GT(count(r, ContactClass::Penetrating), 0u);
  // Beside the big box (boxes do not nest): nothing.
  m.instances[1].pose = translation(20, 0, 0);
  EXPECT_TRUE(collide(m, 0, 1).pairs.empty());
}

}  // namespace
}  // namespace cadclash
