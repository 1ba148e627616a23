// The OAABB narrow phase against the brute-force oracle (every surface pair, every triangle pair,
// the same exact predicate, no culling), its counters, and determinism across thread counts.
#include "scene_fixtures.h"

#include <gtest/gtest.h>

namespace cadclash {
namespace {

using namespace cadclash::testing;

// A random scene: `instances` instances of `parts` random parts, placed so that some overlap.
Model random_scene(std::uint64_t seed, int parts, int instances, double offset = 0.0) {
  std::mt19937_64 rng(seed);
  Model m;
  for (int p = 0; p < parts; ++p) add_part(m, std::string("p").append(std::to_string(p)), random_surfaces(rng, 6, 3, 1.0));
  std::uniform_int_distribution<int> pick(0, parts - 1);
  for (int i = 0; i < instances; ++i) {
    Pose pose = random_pose(rng, 0.6);
    pose.translation() += Vec3(offset, -offset, offset);
    add_instance(m, "/i" + std::to_string(i), static_cast<PartId>(pick(rng)), pose);
  }
  return m;
}

CollideOptions brute(CollideOptions o) {
  o.use_oaabb = false;
  return o;
}

std::uint64_t oracle_pairs(const Model& m) {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < m.instances.size(); ++i)
    for (std::size_t j = i + 1; j < m.instances.size(); ++j) {
      const Part& a = m.parts[m.instances[i].part];
      const Part& b = m.parts[m.instances[j].part];
      std::uint64_t ta = 0, tb = 0;
      for (SurfaceId s = a.first_surface; s < a.first_surface + a.surface_count; ++s) ta += m.surfaces[s].mesh.triangles.size();
      for (SurfaceId s = b.first_surface; s < b.first_surface + b.surface_count; ++s) tb += m.surfaces[s].mesh.triangles.size();
      n += ta * tb;
    }
  return n;
}

struct OracleCase {
  double offset;
  double tolerance;
  double clearance;
};

class OracleTest : public ::testing::TestWithParam<OracleCase> {};

TEST_P(OracleTest, OaabbEqualsBruteForceOnRandomScenes) {
  const OracleCase c = GetParam();
  std::uint64_t pairs = 0, reported = 0, intersecting = 0;
#ifdef NDEBUG
  constexpr std::uint64_t kSeeds = 12;
#else
  constexpr std::uint64_t kSeeds = 4;  // sanitizer builds run ~20x slower
#endif
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    Model m = random_scene(seed, 3, 5, c.offset);
    pairs += oracle_pairs(m);
    for (CollideMode mode : {CollideMode::EarlyExit, CollideMode::AllTrianglePairs}) {
      CollideOptions o;
      o.tolerance = c.tolerance;
      o.clearance = c.clearance;
      o.mode = mode;
      o.threads = 1;
      Scene scene(m);
      const Report expected = scene.check(brute(o));
      for (TriangleLevel level : {TriangleLevel::Auto, TriangleLevel::Flat, TriangleLevel::Bvh}) {
        SCOPED_TRACE("seed " + std::to_string(seed) + " level " + std::to_string(int(level)));
        o.triangle_level = level;
        o.flat_limit = 64;
        const Report got = scene.check(o);
        expect_same_pairs(got, expected);
        EXPECT_EQ(got.counters.intersecting_pairs, expected.counters.intersecting_pairs);
      }
      if (mode == CollideMode::AllTrianglePairs) {
        // Version 2 cuts pairs into blocks; with every triangle pair visited the answer is the same.
        o.version = ParallelVersion::V2;
        expect_same_pairs(scene.check(o), expected);
        reported += expected.pairs.size();
        intersecting += expected.counters.intersecting_pairs;
      }
    }
  }
  // The scenes must exercise the classes, not only empty answers.
  EXPECT_GT(reported, 20u * kSeeds / 12);
  EXPECT_GT(intersecting, 5u * kSeeds / 12);
  RecordProperty("oracle_triangle_pairs", std::to_string(pairs));
}

INSTANTIATE_TEST_SUITE_P(Scenes, OracleTest,
                         ::testing::Values(OracleCase{0.0, 0.0, 0.0}, OracleCase{0.0, 0.02, 0.0},
                                           OracleCase{0.0, 0.0, 0.3}, OracleCase{1e8, 0.0, 0.0},
                                           OracleCase{1e8, 1e-3, 0.2}));

// Adversarial placements: coplanar faces, shared edges and vertices, at a 1e8 offset and rotated.
TEST(Oracle, CoplanarAndSharedEdgesFarFromOrigin) {
  std::mt19937_64 rng(7);
  for (int k = 0; k < 20; ++k) {
    Model m;
    const PartId big = add_part(m, "big", box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 3));
    const PartId small = add_part(m, "small", box_surfaces(Vec3(0, 0, 0), Vec3(1e-3, 1e-3, 1e-3), 2));
    Pose base = random_pose(rng, 1.0);
    base.translation() += Vec3(1e8, 1e8, -1e8);
    add_instance(m, "/a", big, base);
    add_instance(m, "/b", big, base * translation(1, 0, 0));         // face to face, shared edges
    add_instance(m, "/c", big, base * translation(1, 1, 0));         // edge to edge
    add_instance(m, "/d", small, base * translation(1, 0.5, 0.5));   // on a shared face
    add_instance(m, "/e", small, base * translation(0.25, 0.25, 1)); // on top, 1e-3 feature
    for (CollideMode mode : {CollideMode::EarlyExit, CollideMode::AllTrianglePairs}) {
      CollideOptions o;
      o.mode = mode;
      o.tolerance = (k % 2) ? 1e-6 : 0.0;
      Scene scene(m);
      const Report expected = scene.check(brute(o));
      const Report got = scene.check(o);
      expect_same_pairs(got, expected);
      if (k == 0 && mode == CollideMode::AllTrianglePairs) { EXPECT_FALSE(expected.pairs.empty()); }
    }
  }
}

TEST(Counters, OaabbCullsWhatBruteForceTests) {
  Model m;
  const PartId box = add_part(m, "box", box_surfaces(Vec3(0, 0, 0), Vec3(10, 10, 10), 8));
  add_instance(m, "/a", box);
  add_instance(m, "/b", box, translation(9, 9, 9));  // overlap only in a corner
  add_instance(m, "/far", box, translation(100, 0, 0));
  Scene scene(m);
  CollideOptions o;
  o.mode = CollideMode::AllTrianglePairs;
  const Report fast = scene.check(o);
  const Report slow = scene.check(brute(o));
  expect_same_pairs(fast, slow);
  EXPECT_EQ(fast.counters.instance_pairs, 1u);  // the far box is culled by the broad phase
  EXPECT_EQ(slow.counters.instance_pairs, 3u);
  EXPECT_EQ(fast.counters.surfaces_a, 3u);      // only A's x+, y+, z+ faces meet the corner OAABB
  EXPECT_EQ(fast.counters.surfaces_b, 3u);
  EXPECT_LT(fast.counters.triangles_a, 3u * 128u);
  EXPECT_LT(fast.counters.triangle_tests * 100, slow.counters.triangle_tests);
  EXPECT_EQ(fast.counters.intersecting_pairs, slow.counters.intersecting_pairs);
  EXPECT_GT(fast.counters.aabb_updates, 0u);
  EXPECT_EQ(slow.counters.surfaces_a, 0u);  // brute force does not filter
  // Crossing faces of the corner: A's x+ with B's y- and z-, and so on: six pairs, all intersecting.
  EXPECT_EQ(fast.counters.intersecting_pairs, 6u);
}

TEST(Determinism, SameReportForAnyThreadCountAndSchedule) {
  Model m = random_scene(99, 4, 12);
  for (ParallelVersion v : {ParallelVersion::V1, ParallelVersion::V2}) {
    for (CollideMode mode : {CollideMode::EarlyExit, CollideMode::AllTrianglePairs}) {
      CollideOptions o;
      o.version = v;
      o.mode = mode;
      o.clearance = 0.2;
      o.threads = 1;
      Scene scene(m);
      const Report one = scene.check(o);
      ASSERT_FALSE(one.pairs.empty());
      for (int threads : {2, 4}) {
        for (Schedule s : {Schedule::Guided, Schedule::Dynamic, Schedule::Static}) {
          o.threads = threads;
          o.schedule = s;
          const Report many = scene.check(o);
          expect_same_pairs(many, one);
          EXPECT_EQ(many.counters.triangle_tests, one.counters.triangle_tests);
          EXPECT_EQ(many.counters.aabb_tests, one.counters.aabb_tests);
          EXPECT_EQ(many.counters.distance_tests, one.counters.distance_tests);
        }
      }
    }
  }
}

TEST(Collide, OneOffQueryChecksOnlyThatPair) {
  Model m;
  const PartId box = add_part(m, "box", box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  add_instance(m, "/a", box);
  add_instance(m, "/b", box, translation(0.5, 0.5, 0.5));
  add_instance(m, "/c", box, translation(0.25, 0.25, 0.25));
  const Report r = collide(m, 0, 1);
  EXPECT_EQ(r.counters.instance_pairs, 1u);
  ASSERT_FALSE(r.pairs.empty());
  for (const SurfacePairResult& p : r.pairs) {
    EXPECT_EQ(p.instance_a, 0u);
    EXPECT_EQ(p.instance_b, 1u);
  }
}

}  // namespace
}  // namespace cadclash
