// Continuous checks of one stretch of motion (trajectory.h, check_motion): contact between two
// steps is found, stretches proved free are not listed, and nothing in between is called free.
#include "scene_fixtures.h"

#include "cadclash/trajectory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace cadclash {
namespace {

using namespace cadclash::testing;

// A plate 20 x 20 x 1 (z in [0, 1]) and a 2 mm cube; the cube's pose at both ends of the stretch.
struct PlateAndCube {
  Model m;
  InstanceId plate = 0, cube = 1;
  PlateAndCube() {
    add_instance(m, "/plate", add_part(m, "plate", box_surfaces(Vec3(0, 0, 0), Vec3(20, 20, 1), 4)));
    add_instance(m, "/cube", add_part(m, "cube", box_surfaces(Vec3(0, 0, 0), Vec3(2, 2, 2), 2)));
  }
};

// Where a test places its whole assembly: at the origin, and turned and moved 20 m off it (the
// verdicts must not depend on it).
std::vector<Pose> placements() {
  Pose far = Pose::Identity();
  far.translate(Vec3(1.2e4, -2.0e4, 5.0e3));
  far.rotate(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  return {Pose::Identity(), far};
}

// The union of a pair's spans covers [lo, hi], and no span reaches below `before` or above `after`.
void expect_spans(const MotionResult& r, double lo, double hi, double before, double after) {
  ASSERT_EQ(r.pairs.size(), 1u);
  const auto& spans = r.pairs[0].spans;
  ASSERT_FALSE(spans.empty());
  double covered = lo;
  for (const MotionSpan& s : spans) {
    EXPECT_GE(s.s0, before);
    EXPECT_LE(s.s1, after);
    EXPECT_LE(s.s0, s.s1);
    if (s.s0 <= covered) covered = std::max(covered, s.s1);
  }
  EXPECT_GE(covered, hi);
}

// Two cubes 0.05 apart moved by one displacement (a sub-assembly pulled out 30 mm, or swung 90
// degrees about an axis 50 mm off it): their gap stays, so they are never listed, and the stretch is
// proved on a few checks (each side's travel would be 30 mm or more; theirs relative to each other
// is the poses' rounding). Touching, they are in contact over the whole stretch: one span, proved
// at its ends.
TEST(ContinuousMotion, PartsMovedTogetherKeepTheirGap) {
  // The same wherever the whole scene is placed: as built, and turned and moved 10^6 mm away (the
  // two displacements then differ in their last bits).
  Pose far = Pose::Identity();
  far.translate(Vec3(1e6, -4e5, 3e5));
  far.rotate(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  Pose swing = Pose::Identity();
  swing.translate(Vec3(0, 50, 0));
  swing.rotate(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3(1, 0, 1).normalized()));
  swing.translate(Vec3(0, -50, 0));
  for (const Pose& where : {Pose::Identity(), far})
  for (const Pose& moved : {translation(0, 0, -30), swing})
  for (const double gap : {0.05, 0.0}) {
    SCOPED_TRACE(gap);
    Model m;
    const InstanceId a = add_instance(m, "/a", add_part(m, "a", box_surfaces(Vec3(0, 0, 0), Vec3(2, 2, 2), 2)));
    const InstanceId b = add_instance(m, "/b", add_part(m, "b", box_surfaces(Vec3(0, 0, 0), Vec3(2, 2, 2), 2)));
    Scene scene(m);
    const Pose from_a = where * translation(0, 0, 0), from_b = where * translation(2 + gap, 0, 0);
    const Pose to_a = where * moved * translation(0, 0, 0), to_b = where * moved * translation(2 + gap, 0, 0);
    scene.set_pose(a, from_a);
    scene.set_pose(b, from_b);
    CollideOptions o;
    o.tolerance = 0.01;
    const InstanceId moving[] = {a, b};
    const Pose from[] = {from_a, from_b}, to[] = {to_a, to_b};
    const MotionResult r = check_motion(scene, m, moving, from, to, o);
    EXPECT_TRUE(r.complete);
    EXPECT_LE(r.checks, 4u);
    if (gap > 0.0) {
      EXPECT_TRUE(r.pairs.empty());
    } else {
      ASSERT_EQ(r.pairs.size(), 1u);
      ASSERT_EQ(r.pairs[0].spans.size(), 1u);
      EXPECT_EQ(r.pairs[0].spans[0].s0, 0.0);
      EXPECT_EQ(r.pairs[0].spans[0].s1, 1.0);
      EXPECT_TRUE(r.pairs[0].spans[0].contact_at_ends);
    }
  }
}

// The cube falls through the plate within one step: at both ends it is clear (a discrete check sees
// nothing); in between it passes through z in [0, 1] for s in [0.4, 0.7] (bottom 5 - 10 s, top 7 - 10 s).
TEST(ContinuousMotion, APartPassingThroughAThinPlateBetweenTwoStepsIsFound) {
  // The same wherever the whole scene is placed: as built, and turned and moved 10^6 mm away.
  Pose far = Pose::Identity();
  far.translate(Vec3(1e6, -4e5, 3e5));
  far.rotate(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  for (const Pose& where : {Pose::Identity(), far}) {
    PlateAndCube f;
    Scene scene(f.m);
    scene.set_pose(f.plate, where);
    const Pose from = where * translation(9, 9, 5), to = where * translation(9, 9, -5);
    scene.set_pose(f.cube, from);
    EXPECT_TRUE(scene.check().pairs.empty());
    scene.set_pose(f.cube, to);
    EXPECT_TRUE(scene.check().pairs.empty());
    MotionOptions mo;
    mo.resolution = 1e-3;
    const InstanceId moving[] = {f.cube};
    const Pose a[] = {from}, b[] = {to};
    const MotionResult r = check_motion(scene, f.m, moving, a, b, {}, mo);
    EXPECT_TRUE(r.complete);
    ASSERT_EQ(r.pairs.size(), 1u);
    expect_spans(r, 0.4, 0.7, 0.4 - 2 * mo.resolution, 0.7 + 2 * mo.resolution);
    // The spans where the contact begins and ends are at most the resolution wide; the rest of the
    // contact is proved at the ends of its spans.
    for (const MotionSpan& s : r.pairs[0].spans) {
      if (!s.contact_at_ends) {
        EXPECT_LE(s.s1 - s.s0, mo.resolution + 1e-15);
      }
    }
    // The scene is left at the stretch's end.
    EXPECT_TRUE(scene.pose(f.cube).isApprox(to));
    // Beside the plate, the same fall touches nothing: no pair, proved on a handful of checks.
    const Pose beside_a[] = {where * translation(30, 9, 5)}, beside_b[] = {where * translation(30, 9, -5)};
    const MotionResult clear = check_motion(scene, f.m, moving, beside_a, beside_b, {}, mo);
    EXPECT_TRUE(clear.pairs.empty());
    EXPECT_TRUE(clear.complete);
    EXPECT_LT(clear.checks, 64u);
  }
}

// A cube whose part frame's origin lies 60 mm above it turns by 60 degrees about that origin: its
// geometry swings along an arc of radius 60 through the plate although both ends lie far off it
// (the travel bound takes the turn times the part's reach from its origin). Turning the other way
// round, above the axis, it never comes near: free.
TEST(ContinuousMotion, RotationAboutAFarAxisSweepsThroughThePlate) {
  Model m;
  const InstanceId plate = add_instance(m, "/plate", add_part(m, "plate", box_surfaces(Vec3(0, 0, 0), Vec3(20, 20, 1), 4)));
  const InstanceId low = add_instance(m, "/low", add_part(m, "low", box_surfaces(Vec3(-1, -1, -61), Vec3(1, 1, -59), 2)));
  const InstanceId high = add_instance(m, "/high", add_part(m, "high", box_surfaces(Vec3(-1, -1, 59), Vec3(1, 1, 61), 2)));
  (void)plate;
  auto turned = [](double angle) {
    Pose p = Pose::Identity();
    p.translate(Vec3(10, 10, 60));
    p.rotate(Eigen::AngleAxisd(angle, Vec3::UnitY()));
    return p;
  };
  const Pose a[] = {turned(-std::numbers::pi / 6)}, b[] = {turned(std::numbers::pi / 6)};
  Scene scene(m);
  scene.set_pose(low, a[0]);
  scene.set_pose(high, a[0]);
  EXPECT_TRUE(scene.check().pairs.empty());
  scene.set_pose(low, b[0]);
  scene.set_pose(high, b[0]);
  EXPECT_TRUE(scene.check().pairs.empty());
  const InstanceId moving[] = {low, high};
  const Pose from[] = {a[0], a[0]}, to[] = {b[0], b[0]};
  const MotionResult r = check_motion(scene, m, moving, from, to, {}, {});
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].a, plate);
  EXPECT_EQ(r.pairs[0].b, low);
  bool mid = false;  // at s = 0.5 the low cube lies across the plate (z in [-1, 1])
  for (const MotionSpan& s : r.pairs[0].spans) mid |= s.s0 <= 0.5 && 0.5 <= s.s1;
  EXPECT_TRUE(mid);
}

// A square frame unscrewed off a square rod: each step turns it 120 degrees about the rod's axis and
// lifts it 1 mm, and its part frame's origin lies 30 mm off that axis (as a CAD part's often does).
// The motion between the steps is the screw about the rod's axis, whatever the part's origin: the
// frame stays around the rod, 0.5 mm clear of it everywhere, and no span is listed. (A translation
// blended linearly between the steps' origins would swing the frame 15 mm off the axis and through
// the rod.)
TEST(ContinuousMotion, AFrameUnscrewedOffARodStaysAroundIt) {
  Model m;
  const InstanceId rod = add_instance(m, "/rod", add_part(m, "rod", box_surfaces(Vec3(-1, -1, -10), Vec3(1, 1, 10), 2)));
  std::vector<Surface> bars;
  // Around (30, 0, 0) of its own frame: the hole |x - 30|, |y| < 2.5, the bars out to 4.
  for (const auto& [lo, hi] : {std::pair{Vec3(26, -4, -1), Vec3(34, -2.5, 1)}, std::pair{Vec3(26, 2.5, -1), Vec3(34, 4, 1)},
                               std::pair{Vec3(26, -2.5, -1), Vec3(27.5, 2.5, 1)}, std::pair{Vec3(32.5, -2.5, -1), Vec3(34, 2.5, 1)}})
    for (Surface& f : box_surfaces(lo, hi, 2)) bars.push_back(std::move(f));
  const InstanceId frame = add_instance(m, "/frame", add_part(m, "frame", std::move(bars)));
  auto step = [](int k) {  // turned k times 120 degrees about z, lifted k mm
    Pose p = Pose::Identity();
    p.translate(Vec3(0, 0, k));
    p.rotate(Eigen::AngleAxisd(k * 2.0 * std::numbers::pi / 3.0, Vec3::UnitZ()));
    p.translate(Vec3(-30, 0, 0));
    return p;
  };
  Scene scene(m);
  for (int k = 0; k < 3; ++k) {
    scene.set_pose(frame, step(k));
    EXPECT_TRUE(scene.check().pairs.empty()) << k;
    const InstanceId moving[] = {frame};
    const Pose from[] = {step(k)}, to[] = {step(k + 1)};
    const MotionResult r = check_motion(scene, m, moving, from, to, {}, {});
    EXPECT_TRUE(r.pairs.empty()) << k;
    EXPECT_TRUE(r.complete);
  }
  // Half way through a stretch the frame is turned 60 degrees and lifted 0.5 mm, centred on the rod.
  const Pose mid = interpolate_pose(step(0), step(1), 0.5);
  EXPECT_LT((mid * Vec3(30, 0, 0) - Vec3(0, 0, 0.5)).norm(), 1e-12);
  (void)rod;
}

// An 8 x 8 x 1 block over the plate (both placed by `place`), the block's pose at height z above
// the plate's bottom, turned by `turn` about the vertical through its centre.
struct BlockOverPlate {
  Model m;
  InstanceId plate = 0, block = 1;
  Pose place;
  explicit BlockOverPlate(const Pose& where) : place(where) {
    plate = add_instance(m, "/plate", add_part(m, "plate", box_surfaces(Vec3(0, 0, 0), Vec3(20, 20, 1), 4)), place);
    block = add_instance(m, "/block", add_part(m, "block", box_surfaces(Vec3(-4, -4, 0), Vec3(4, 4, 1), 2)));
  }
  Pose at(double turn, double z) const {
    Pose p = place;
    p.translate(Vec3(10, 10, z));
    p.rotate(Eigen::AngleAxisd(turn, Vec3::UnitZ()));
    return p;
  }
};

// A block 0.2 mm above the plate turned 170 degrees about the vertical through its centre while it
// rises 1 mm: its corners sweep 17 mm over the plate, so its travel proves nothing short of a
// hundredth of the stretch, but a turn about the vertical cannot bring a face nearer the plate
// than the rise does (screw.h): one check clears the stretch. Coming down 0.5 mm instead it meets
// the plate where it has come down 0.2 mm.
TEST(ContinuousMotion, ABlockTurningAboveThePlateIsClearedByWhatTheTurnKeeps) {
  // The same wherever the assembly is placed.
  for (const Pose& place : placements()) {
    BlockOverPlate f(place);
    Model& m = f.m;
    const InstanceId block = f.block;
    auto at = [&](double turn, double z) { return f.at(turn, z); };
    const double turn = 170.0 * std::numbers::pi / 180.0;
    Scene scene(m);
    const InstanceId moving[] = {block};
    {
      const Pose from[] = {at(0.0, 1.2)}, to[] = {at(turn, 2.2)};
      scene.set_pose(block, from[0]);
      // The checks the search grows leave out what the turn keeps apart (CollideOptions::
      // proved_apart): here every pair of the block and the plate, which they would have examined.
      MotionOptions mo;
      std::size_t grown = 0;
      mo.check = [&](Scene& sc, const CollideOptions& o) {
        Report r = sc.check(o);
        if (o.tolerance > 0.0) {
          ++grown;
          EXPECT_TRUE(r.pairs.empty());
          CollideOptions all = o;
          all.proved_apart = nullptr;
          EXPECT_FALSE(sc.check(all).pairs.empty());
        }
        return r;
      };
      const MotionResult r = check_motion(scene, m, moving, from, to, {}, mo);
      EXPECT_GE(grown, 1u);
      EXPECT_TRUE(r.pairs.empty());
      EXPECT_TRUE(r.complete);
      EXPECT_LE(r.checks, 3u);
      EXPECT_GT(travel_bound(from[0], to[0], m.surfaces[m.parts[1].first_surface].aabb, 0.0, 0.01), 0.15);
    }
    {
      const Pose from[] = {at(0.0, 1.2)}, to[] = {at(turn, 0.7)};
      scene.set_pose(block, from[0]);
      const MotionResult r = check_motion(scene, m, moving, from, to, {}, {});
      expect_spans(r, 0.4 + 1e-3, 1.0, 0.4 - 2e-3, 1.0);
      EXPECT_TRUE(r.complete);
    }
  }
}

// A block resting on the plate lifts off it while it turns 170 degrees (a nut unscrewed off its
// seat): in contact until it has risen T = 0.01 mm (s = 0.01), clear after. What the turn keeps
// (the rise) places the end of the contact within a hair: the search checks one resolution-wide
// span there and the contact before it, instead of halving down to it from the whole stretch (about
// two checks per halving, twenty for a resolution of 1/1000). Lowered onto the plate instead, the
// contact begins as it arrives (s = 0.99), found the same way.
TEST(ContinuousMotion, AContactTheShiftEndsIsBracketedWithoutHalvingDownToIt) {
  const double turn = 170.0 * std::numbers::pi / 180.0;
  CollideOptions o;
  o.tolerance = 0.01;
  MotionOptions mo;
  mo.resolution = 1e-3;
  for (const Pose& place : placements()) {
    BlockOverPlate f(place);
    Scene scene(f.m);
    const InstanceId moving[] = {f.block};
    for (const bool up : {true, false}) {
      SCOPED_TRACE(up);
      const Pose from[] = {up ? f.at(0.0, 1.0) : f.at(-turn, 2.0)}, to[] = {up ? f.at(turn, 2.0) : f.at(0.0, 1.0)};
      scene.set_pose(f.block, from[0]);
      const MotionResult r = check_motion(scene, f.m, moving, from, to, o, mo);
      EXPECT_TRUE(r.complete);
      ASSERT_EQ(r.pairs.size(), 1u);
      const double lo = up ? 0.0 : 0.99 + 1e-4, hi = up ? 0.01 - 1e-4 : 1.0;
      expect_spans(r, lo, hi, up ? 0.0 : 0.99 - mo.resolution, up ? 0.01 + mo.resolution : 1.0);
      for (const MotionSpan& s : r.pairs[0].spans) {
        if (!s.contact_at_ends) {
          EXPECT_LE(s.s1 - s.s0, mo.resolution + 1e-15);
        }
      }
      EXPECT_LE(r.checks, 8u);
    }
  }
}

// A cube falling through a slab 10 mm thick is inside it, touching none of its faces, while its
// bottom goes from 8 mm down to 0 (s in [0.23, 0.5]): in contact all the same (containment), so
// the pair's spans cover its whole passage, s in [1/6, 17/30], although what the fall keeps apart
// clears every pair of their faces over the middle of it.
TEST(ContinuousMotion, APartInsideAnotherBetweenItsFacesStaysInContact) {
  for (const Pose& place : placements()) {
    Model m;
    add_instance(m, "/slab", add_part(m, "slab", box_surfaces(Vec3(0, 0, 0), Vec3(20, 20, 10), 4)), place);
    const InstanceId cube = add_instance(m, "/cube", add_part(m, "cube", box_surfaces(Vec3(0, 0, 0), Vec3(2, 2, 2), 2)));
    Scene scene(m);
    const Pose from[] = {place * translation(9, 9, 15)}, to[] = {place * translation(9, 9, -15)};
    scene.set_pose(cube, from[0]);
    const InstanceId moving[] = {cube};
    MotionOptions mo;
    mo.resolution = 1e-3;
    const MotionResult r = check_motion(scene, m, moving, from, to, {}, mo);
    EXPECT_TRUE(r.complete);
    ASSERT_EQ(r.pairs.size(), 1u);
    expect_spans(r, 1.0 / 6.0 + 1e-3, 17.0 / 30.0 - 1e-3, 1.0 / 6.0 - 2e-3, 17.0 / 30.0 + 2e-3);
  }
}

// A face near the axis of a turn moves only as far as its own points do, not as far as the part's
// far end: a hub 0.5 mm from a wall, on a part whose arm reaches 50 mm from the axis, is cleared
// by the first check (the arm's travel would halve the stretch again and again). What the turn
// keeps proves nothing here: the boxes' distances from the axis overlap and so do their heights.
TEST(ContinuousMotion, AFaceNearTheAxisMovesOnlyAsFarAsItsOwnPoints) {
  for (const Pose& place : placements()) {
    Model m;
    std::vector<Surface> turning{grid_surface("hub", Vec3(1, -0.5, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), 2),
                                 grid_surface("arm", Vec3(-50, -0.5, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), 2)};
    const InstanceId part = add_instance(m, "/part", add_part(m, "part", std::move(turning)), place);
    add_instance(m, "/wall", add_part(m, "wall", {grid_surface("wall", Vec3(1.6, -1, 0), Vec3(0, 2, 0), Vec3(0, 0, 1), 2)}),
                 place);
    Scene scene(m);
    Pose end = place;
    end.rotate(Eigen::AngleAxisd(20.0 * std::numbers::pi / 180.0, Vec3::UnitZ()));
    const Pose from[] = {place}, to[] = {end};
    const InstanceId moving[] = {part};
    const MotionResult r = check_motion(scene, m, moving, from, to, {}, {});
    EXPECT_TRUE(r.pairs.empty());
    EXPECT_TRUE(r.complete);
    EXPECT_LE(r.checks, 3u);
  }
}

// A block resting on the plate stays while the cube falls through the plate beside it: the two
// that stay are in contact over the whole stretch, one span proved at its ends (their state is the
// one at the stretch's ends; the search is about the moving cube's pairs), and the cube's pair
// with the plate is found as alone.
TEST(ContinuousMotion, PairsThatStayKeepTheirContact) {
  PlateAndCube f;
  const InstanceId block = add_instance(f.m, "/block", add_part(f.m, "block", box_surfaces(Vec3(15, 15, 1), Vec3(18, 18, 3), 2)));
  Scene scene(f.m);
  const Pose from = translation(4, 4, 5), to = translation(4, 4, -5);
  scene.set_pose(f.cube, from);
  const InstanceId moving[] = {f.cube};
  const Pose a[] = {from}, b[] = {to};
  const MotionResult r = check_motion(scene, f.m, moving, a, b, {}, {});
  EXPECT_TRUE(r.complete);
  ASSERT_EQ(r.pairs.size(), 2u);
  const PairMotion& resting = r.pairs[0].b == block ? r.pairs[0] : r.pairs[1];
  const PairMotion& falling = r.pairs[0].b == block ? r.pairs[1] : r.pairs[0];
  EXPECT_EQ(resting.a, f.plate);
  EXPECT_EQ(resting.b, block);
  ASSERT_EQ(resting.spans.size(), 1u);
  EXPECT_EQ(resting.spans[0].s0, 0.0);
  EXPECT_EQ(resting.spans[0].s1, 1.0);
  EXPECT_TRUE(resting.spans[0].contact_at_ends);
  EXPECT_FALSE(resting.surfaces.empty());
  EXPECT_EQ(falling.b, f.cube);
  bool mid = false;  // at s = 0.5 the cube (z in [0, 2]) lies across the plate
  for (const MotionSpan& sp : falling.spans) mid |= sp.s0 <= 0.5 && 0.5 <= sp.s1;
  EXPECT_TRUE(mid);
}

// Two parts that stay and are undecided at the stretch's ends (a check hook reports them so, as a
// budget or a face no certificate settles would): their state cannot change while they stay, so the
// pair gets one span over the stretch, not proved either way, on a handful of checks (halving it
// to the resolution would take thousands).
TEST(ContinuousMotion, PairsThatStayUndecidedGetTheWholeStretch) {
  PlateAndCube f;
  const InstanceId block = add_instance(f.m, "/block", add_part(f.m, "block", box_surfaces(Vec3(15, 15, 1.5), Vec3(18, 18, 3), 2)));
  Scene scene(f.m);
  scene.set_pose(f.cube, translation(4, 4, 5));
  MotionOptions mo;
  mo.check = [&](Scene& sc, const CollideOptions& o) {
    Report r = sc.check(o);
    SurfacePairResult u;
    u.instance_a = f.plate;
    u.instance_b = block;
    u.surface_a = f.m.parts[f.m.instances[f.plate].part].first_surface;
    u.surface_b = f.m.parts[f.m.instances[block].part].first_surface;
    u.contact = ContactClass::Undecided;
    u.distance_lo = 0.0;
    u.distance_hi = 0.5;
    r.pairs.push_back(u);
    return r;
  };
  const InstanceId moving[] = {f.cube};
  const Pose a[] = {translation(4, 4, 5)}, b[] = {translation(4, 4, -5)};
  const MotionResult r = check_motion(scene, f.m, moving, a, b, {}, mo);
  EXPECT_TRUE(r.complete);
  EXPECT_LT(r.checks, 200u);
  const PairMotion* still = nullptr;
  for (const PairMotion& p : r.pairs)
    if (p.a == f.plate && p.b == block) still = &p;
  ASSERT_NE(still, nullptr);
  ASSERT_EQ(still->spans.size(), 1u);
  EXPECT_EQ(still->spans[0].s0, 0.0);
  EXPECT_EQ(still->spans[0].s1, 1.0);
  EXPECT_FALSE(still->spans[0].contact_at_ends);
}

// Two 2 mm cubes, both moving along x: from x = from_left and from_right to to_left and to_right.
MotionResult two_cubes_moving(double from_left, double from_right, double to_left, double to_right) {
  Model m;
  const PartId cube = add_part(m, "cube", box_surfaces(Vec3(0, 0, 0), Vec3(2, 2, 2), 2));
  const InstanceId left = add_instance(m, "/left", cube), right = add_instance(m, "/right", cube);
  Scene scene(m);
  const InstanceId moving[] = {left, right};
  const Pose from[] = {translation(from_left, 0, 0), translation(from_right, 0, 0)};
  const Pose to[] = {translation(to_left, 0, 0), translation(to_right, 0, 0)};
  MotionOptions mo;
  mo.resolution = 1e-3;
  return check_motion(scene, m, moving, from, to, {}, mo);
}

// Two cubes fly at each other and through each other within one stretch: each moves 20 mm, so a
// stretch is cleared only when their distance exceeds both travels together. They overlap for s in
// [0.45, 0.55] (faces meet at -8 + 20 s = 10 - 20 s); the spans must cover it.
TEST(ContinuousMotion, TwoMovingPartsPassingThroughEachOtherAreFound) {
  const MotionResult r = two_cubes_moving(-10, 10, 10, -10);
  ASSERT_EQ(r.pairs.size(), 1u);
  expect_spans(r, 0.45, 0.55, 0.45 - 2e-3, 0.55 + 2e-3);
}

// Two cubes moving at each other meet late in the stretch: their faces touch at s = 11/12 (gap
// 22 - 24 s). In the middle they are 10 mm apart, less than both travels over a half (12 mm) but
// more than either's (6 mm): the first check must be grown by the pair's travel, not one part's.
TEST(ContinuousMotion, TwoMovingPartsMeetingLateAreFound) {
  const MotionResult r = two_cubes_moving(-12, 12, 0, 0);
  ASSERT_EQ(r.pairs.size(), 1u);
  expect_spans(r, 11.0 / 12.0, 1.0, 11.0 / 12.0 - 2e-3, 1.0);
}

// A cube resting on the plate and sliding along it stays in contact: the stretch is listed with
// contact proved at its ends, not halved down to the resolution, for the instance pair and for each
// surface pair in contact (the plate's top against the cube's bottom and its four sides). The
// surface pairs 2 mm apart (the plate's top and the cube's top) are cleared once a stretch travels
// less than that: a few levels of halving (tens of checks), where halving to the resolution would
// take thousands.
TEST(ContinuousMotion, ContactThatLastsIsNotHalvedAway) {
  PlateAndCube f;
  Scene scene(f.m);
  const Pose a[] = {translation(2, 2, 1)}, b[] = {translation(12, 2, 1)};
  const InstanceId moving[] = {f.cube};
  const MotionResult r = check_motion(scene, f.m, moving, a, b, {}, {});
  ASSERT_EQ(r.pairs.size(), 1u);
  ASSERT_EQ(r.pairs[0].spans.size(), 1u);
  EXPECT_TRUE(r.pairs[0].spans[0].contact_at_ends);
  EXPECT_EQ(r.pairs[0].spans[0].s0, 0.0);
  EXPECT_EQ(r.pairs[0].spans[0].s1, 1.0);
  ASSERT_EQ(r.pairs[0].surfaces.size(), 5u);
  for (const SurfaceMotion& sm : r.pairs[0].surfaces) {
    EXPECT_EQ(sm.a, 5u);  // the plate's top
    ASSERT_EQ(sm.spans.size(), 1u);
    EXPECT_TRUE(sm.spans[0].contact_at_ends);
    EXPECT_EQ(sm.spans[0].s1 - sm.spans[0].s0, 1.0);
  }
  EXPECT_LE(r.checks, 48u);
}

// The spans of surface pair (a, b) of the pair's timeline (empty when it is not listed).
std::vector<MotionSpan> surface_spans(const PairMotion& p, SurfaceId a, SurfaceId b) {
  for (const SurfaceMotion& s : p.surfaces)
    if (s.a == a && s.b == b) return s.spans;
  return {};
}

// Whether `spans` cover [lo, hi] and stay within [before, after].
bool covers(const std::vector<MotionSpan>& spans, double lo, double hi, double before, double after) {
  double covered = lo;
  for (const MotionSpan& s : spans) {
    if (s.s0 < before || s.s1 > after || s.s0 > s.s1) return false;
    if (s.s0 <= covered) covered = std::max(covered, s.s1);
  }
  return !spans.empty() && covered >= hi;
}

// The cube falling through the plate, surface by surface (plate faces 0-5, cube faces 6-11, each
// x-, x+, y-, y+, z-, z+): a side of the cube crosses the plate's top face while the cube spans
// z = 1 (s in [0.4, 0.6]) and its bottom face while it spans z = 0 ([0.5, 0.7]); the cube's bottom
// face meets the plate's top face only as it arrives (s = 0.4) and the plate's bottom face as it
// passes z = 0 (s = 0.5). Each surface pair's spans cover its own contact and no more.
TEST(ContinuousMotion, EachSurfacePairGetsItsOwnSpans) {
  PlateAndCube f;
  Scene scene(f.m);
  MotionOptions mo;
  mo.resolution = 1e-3;
  const InstanceId moving[] = {f.cube};
  const Pose a[] = {translation(9, 9, 5)}, b[] = {translation(9, 9, -5)};
  const MotionResult r = check_motion(scene, f.m, moving, a, b, {}, mo);
  ASSERT_EQ(r.pairs.size(), 1u);
  const PairMotion& p = r.pairs[0];
  const double e = 2 * mo.resolution;
  EXPECT_TRUE(covers(surface_spans(p, 5, 6), 0.4, 0.6, 0.4 - e, 0.6 + e));   // top x cube's x- side
  EXPECT_TRUE(covers(surface_spans(p, 5, 9), 0.4, 0.6, 0.4 - e, 0.6 + e));   // top x cube's y+ side
  EXPECT_TRUE(covers(surface_spans(p, 4, 7), 0.5, 0.7, 0.5 - e, 0.7 + e));   // bottom x cube's x+ side
  EXPECT_TRUE(covers(surface_spans(p, 5, 10), 0.4, 0.4, 0.4 - e, 0.4 + e));  // top x cube's bottom
  EXPECT_TRUE(covers(surface_spans(p, 4, 10), 0.5, 0.5, 0.5 - e, 0.5 + e));  // bottom x cube's bottom
  EXPECT_TRUE(covers(surface_spans(p, 4, 11), 0.7, 0.7, 0.7 - e, 0.7 + e));  // bottom x cube's top
  EXPECT_TRUE(surface_spans(p, 0, 6).empty());  // the plate's far side x-: never near
  // Every surface pair's spans lie within the instance pair's.
  for (const SurfaceMotion& sm : p.surfaces)
    for (const MotionSpan& s : sm.spans) {
      bool inside = false;
      for (const MotionSpan& q : p.spans) inside |= q.s0 <= s.s0 && s.s1 <= q.s1;
      EXPECT_TRUE(inside) << sm.a << " x " << sm.b << " [" << s.s0 << ", " << s.s1 << "]";
    }
}

// A plate turning 170 degrees about a post that pierces it (in contact throughout) while it rises
// 2 mm past a ledge of the post's part at its own height half-way up, and along a fin of it 0.6 mm
// high: the plate touches the ledge while they are within T of one plane, s in [0.495, 0.505], and
// the fin for s in [0.495, 0.805]. What the rise keeps apart places the ends of each within a
// hair, in each part of the stretch the search looks at, where halving would go down to them level
// by level (the plate's corners sweep 10 mm: its travel proves nothing, and the fin is in contact
// in the middle of the parts around the ledge's end).
TEST(ContinuousMotion, ContactsThatBeginAndEndWithinAStretchAreFoundWhereTheShiftPlacesThem) {
  for (const Pose& place : placements()) {
    Model m;
    std::vector<Surface> frame = box_surfaces(Vec3(-1, -1, 0), Vec3(1, 1, 20), 2);
    frame.push_back(grid_surface("ledge", Vec3(2, -0.5, 10), Vec3(1.5, 0, 0), Vec3(0, 1, 0), 2));
    frame.push_back(grid_surface("fin", Vec3(-3.5, 0, 10), Vec3(1.5, 0, 0), Vec3(0, 0, 0.6), 2));
    add_instance(m, "/frame", add_part(m, "frame", std::move(frame)), place);
    const InstanceId plate = add_instance(
        m, "/plate", add_part(m, "plate", {grid_surface("face", Vec3(-4, -4, 0), Vec3(8, 0, 0), Vec3(0, 8, 0), 4)}));
    const SurfaceId ledge = 6, fin = 7, face = 8;
    auto at = [&](double turn, double z) {
      Pose p = place;
      p.translate(Vec3(0, 0, z));
      p.rotate(Eigen::AngleAxisd(turn, Vec3::UnitZ()));
      return p;
    };
    Scene scene(m);
    const Pose from[] = {at(0.0, 9.0)}, to[] = {at(170.0 * std::numbers::pi / 180.0, 11.0)};
    scene.set_pose(plate, from[0]);
    const InstanceId moving[] = {plate};
    CollideOptions o;
    o.tolerance = 0.01;
    MotionOptions mo;
    mo.resolution = 1e-3;
    const MotionResult r = check_motion(scene, m, moving, from, to, o, mo);
    EXPECT_TRUE(r.complete);
    ASSERT_EQ(r.pairs.size(), 1u);
    ASSERT_EQ(r.pairs[0].spans.size(), 1u);
    EXPECT_TRUE(r.pairs[0].spans[0].contact_at_ends);
    for (const auto& [with, end] : {std::pair{ledge, 0.505}, std::pair{fin, 0.805}}) {
      SCOPED_TRACE(with);
      const std::vector<MotionSpan> spans = surface_spans(r.pairs[0], with, face);
      ASSERT_FALSE(spans.empty());
      EXPECT_TRUE(covers(spans, 0.495, end, 0.495 - mo.resolution, end + mo.resolution));
    }
    // 13 checks; 16 when the parts' ends are not placed by the rise (the fin's contact in the
    // middle of a part halves it again), 37 without the resolution-wide pieces.
    EXPECT_LE(r.checks, 14u);
  }
}

// A whole path (replay_continuous): the cube goes down through the plate between steps 0 and 10
// and up through it between 10 and 20; every step is clear, so a discrete replay sees nothing. The
// timeline, in step numbers, covers [4, 7] and [13, 16] (a resolution of 1/1000 of a stretch: 0.01).
// A row naming no instance is a warning; a step number that goes back is an error, and the path
// stops there.
TEST(ContinuousPath, APathWhoseStepsAreAllClearPassesThroughThePlateTwice) {
  PlateAndCube f;
  Scene scene(f.m);
  std::vector<TrajectoryRow> rows = {{0, "/cube", translation(9, 9, 5), 1},
                                     {0, "/nothing", translation(0, 0, 0), 2},
                                     {10, "/cube", translation(9, 9, -5), 3},
                                     {20, "/cube", translation(9, 9, 5), 4},
                                     {15, "/cube", translation(9, 9, 5), 5}};
  std::vector<Diagnostic> ds;
  const PathResult r = replay_continuous(scene, f.m, rows, {}, {}, ds, "path.csv");
  ASSERT_EQ(r.steps.size(), 3u);
  for (const StepResult& s : r.steps) EXPECT_TRUE(s.report.pairs.empty()) << s.step;
  ASSERT_EQ(r.pairs.size(), 1u);
  const double e = 2 * 0.01;
  std::vector<MotionSpan> down, up;
  for (const MotionSpan& s : r.pairs[0].spans) (s.s1 <= 10 ? down : up).push_back(s);
  EXPECT_TRUE(covers(down, 4, 7, 4 - e, 7 + e));
  EXPECT_TRUE(covers(up, 13, 16, 13 - e, 16 + e));
  EXPECT_FALSE(r.complete);  // stopped at the step that goes back
  ASSERT_EQ(ds.size(), 2u);
  EXPECT_EQ(ds[0].severity, Severity::Warning);
  EXPECT_EQ(ds[0].line, 2);
  EXPECT_EQ(ds[1].severity, Severity::Error);
  EXPECT_EQ(ds[1].line, 5);
}

// A cube resting on the plate slides along it over three steps: one span, proved in contact at both
// ends, joined across the steps (for the instance pair and each surface pair in contact).
TEST(ContinuousPath, ContactAcrossStepsIsOneSpan) {
  PlateAndCube f;
  Scene scene(f.m);
  const std::vector<TrajectoryRow> rows = {
      {0, "/cube", translation(2, 2, 1), 1}, {1, "/cube", translation(7, 2, 1), 2}, {2, "/cube", translation(12, 2, 1), 3}};
  std::vector<Diagnostic> ds;
  const PathResult r = replay_continuous(scene, f.m, rows, {}, {}, ds, "slide.csv");
  EXPECT_TRUE(r.complete);
  EXPECT_TRUE(ds.empty());
  ASSERT_EQ(r.pairs.size(), 1u);
  ASSERT_EQ(r.pairs[0].spans.size(), 1u);
  EXPECT_TRUE(r.pairs[0].spans[0].contact_at_ends);
  EXPECT_EQ(r.pairs[0].spans[0].s0, 0.0);
  EXPECT_EQ(r.pairs[0].spans[0].s1, 2.0);
  ASSERT_EQ(r.pairs[0].surfaces.size(), 5u);
  for (const SurfaceMotion& sm : r.pairs[0].surfaces) {
    ASSERT_EQ(sm.spans.size(), 1u);
    EXPECT_EQ(sm.spans[0].s0, 0.0);
    EXPECT_EQ(sm.spans[0].s1, 2.0);
  }
}

// With a clearance, how close a pair comes (ClosestApproach): a cube flies diagonally past another,
// nearest at s = 0.49 (its corner region sqrt(0.5) mm from the other's: x gap 0.3 - a, y gap a + 0.7
// with a = -10 + 20 s). The minimum lies in [lo, hi], the time bracket holds 0.49 and is narrow; a
// cube far away within no clearance is not listed; without a clearance, no closest approach.
TEST(ContinuousMotion, ClosestApproachOfAPartFlyingPast) {
  Model m;
  const PartId cube = add_part(m, "cube", box_surfaces(Vec3(0, 0, 0), Vec3(2, 2, 2), 2));
  const InstanceId flying = add_instance(m, "/flying", cube), still = add_instance(m, "/still", cube),
                   far = add_instance(m, "/far", cube);
  Scene scene(m);
  scene.set_pose(still, translation(2.3, -2.7, 0));
  scene.set_pose(far, translation(50, 50, 0));
  const InstanceId moving[] = {flying};
  const Pose a[] = {translation(-10, -10, 0)}, b[] = {translation(10, 10, 0)};
  CollideOptions o;
  o.clearance = 2.0;
  const MotionResult r = check_motion(scene, m, moving, a, b, o, {});
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].a, flying);
  EXPECT_EQ(r.pairs[0].b, still);
  EXPECT_TRUE(r.pairs[0].spans.empty());
  ASSERT_TRUE(r.pairs[0].closest);
  const ClosestApproach& c = *r.pairs[0].closest;
  EXPECT_LE(c.lo, std::sqrt(0.5));
  EXPECT_GE(c.hi, std::sqrt(0.5) - 1e-12);
  EXPECT_LE(c.hi - c.lo, 0.03);  // the travel over a resolution-wide part: 28.3 mm / 1000
  EXPECT_LE(c.s0, 0.49);
  EXPECT_GE(c.s1, 0.49);
  EXPECT_LE(c.s1 - c.s0, 0.05);
  EXPECT_TRUE(r.complete);
  const MotionResult none = check_motion(scene, m, moving, a, b, {}, {});
  EXPECT_TRUE(none.pairs.empty());
}

}  // namespace
}  // namespace cadclash
