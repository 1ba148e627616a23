// Prepared scenes: incremental poses, selections and exclusions, lazy tessellation, trajectories.
#include "scene_fixtures.h"

#include <gtest/gtest.h>

#include <atomic>
#include <map>
#include <tuple>
#include <mutex>

namespace cadclash {
namespace {

using namespace cadclash::testing;

Model row_of_boxes(int n) {
  Model m;
  const PartId box = add_part(m, "box", box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 2));
  for (int i = 0; i < n; ++i) add_instance(m, "/row/b" + std::to_string(i), box, translation(1.5 * i, 0, 0));
  return m;
}

TEST(Scene, OnlyMovedInstancesGetNewWorldBoxes) {
  Model m = row_of_boxes(5);
  Scene scene(m);
  CollideOptions o;
  Report r = scene.check(o);
  EXPECT_TRUE(r.pairs.empty());
  EXPECT_EQ(r.counters.instance_pairs, 0u);
  EXPECT_EQ(r.counters.aabb_updates, 5u);  // first check: every instance
  r = scene.check(o);
  EXPECT_EQ(r.counters.aabb_updates, 0u);  // nothing moved
  scene.set_pose(2, translation(1.5 * 2 - 0.5, 0, 0));  // b2 now touches b1 face to face
  r = scene.check(o);
  ASSERT_FALSE(r.pairs.empty());
  for (const SurfacePairResult& p : r.pairs) {
    EXPECT_EQ(p.instance_a, 1u);
    EXPECT_EQ(p.instance_b, 2u);
    EXPECT_EQ(p.contact, ContactClass::Touching);
  }
  EXPECT_EQ(r.counters.instance_pairs, 1u);
  // The moved scene answers like a fresh one built on the moved model, and like brute force.
  Model moved = m;
  moved.instances[2].pose = scene.pose(2);
  Scene fresh(moved);
  expect_same_pairs(r, fresh.check(o));
  o.use_oaabb = false;
  expect_same_pairs(r, fresh.check(o));
}

// build_hierarchies builds each surface's tree once, memory() counts what is held, and a check after
// it answers as one that built the trees itself.
TEST(Scene, BuildsHierarchiesUpFrontAndCountsItsBytes) {
  Model m;
  const PartId box = add_part(m, "box", box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 8));  // 128 triangles a face
  for (int i = 0; i < 3; ++i) add_instance(m, "/row/b" + std::to_string(i), box, translation(1.5 * i, 0, 0));
  m.instances[1].pose = translation(1.0, 0.2, 0.1);  // b1 overlaps b0
  std::uint64_t triangles = 0;
  for (const Surface& s : m.surfaces) triangles += s.mesh.triangles.size();
  Scene scene(m);
  const SceneMemory before = scene.memory();
  EXPECT_GT(before.hierarchies, 0u);  // every surface's slot (root box, sizes), built or not
  EXPECT_EQ(before.triangle_count, 0u);
  EXPECT_GT(before.instances, 3 * sizeof(Pose));
  EXPECT_EQ(scene.build_hierarchies(2), m.surfaces.size());
  EXPECT_EQ(scene.build_hierarchies(), 0u);  // nothing left to build
  const SceneMemory after = scene.memory();
  EXPECT_EQ(after.triangle_count, triangles);
  EXPECT_EQ(after.triangles, triangles * sizeof(m.surfaces[0].mesh.triangles[0]));
  EXPECT_GT(after.vertices, 0u);
  // The trees: float nodes over leaves of 8 and the triangle order, no box per triangle (issue 16's
  // 48 bytes per triangle leave the hierarchy ~12 after the model's triangles and vertices).
  EXPECT_GT(after.hierarchies, before.hierarchies);
  EXPECT_LE(after.hierarchies - before.hierarchies, triangles * 12);
  EXPECT_EQ(after.total(), after.triangles + after.vertices + after.hierarchies + after.instances);
  Scene lazy(m);
  const Report r = lazy.check();
  ASSERT_FALSE(r.pairs.empty());
  expect_same_pairs(scene.check(), r);
  EXPECT_EQ(lazy.memory().triangle_count, triangles);  // the overlap reached every face of b0 and b1
}

// One box moving through a grid of 100 (a selection side of 1 of 100: the persistent instance tree,
// refitted every step and rebuilt once worn) finds, step by step, the pairs a fresh scene's sweep
// over every instance finds with the moving box; every 4th step a grid box is also moved into its
// way (its leaf must follow, or the pair is missed).
TEST(Scene, InstanceTreeFindsTheSweepsPairsAlongAPath) {
  Model m;
  const PartId box = add_part(m, "box", box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 2));
  for (int i = 0; i < 100; ++i)
    add_instance(m, "/grid/b" + std::to_string(i), box, translation(1.25 * (i % 10), 1.25 * (i / 10), 0));
  const InstanceId mover = add_instance(m, "/mover", box, translation(-2, -2, 0.2));
  SceneSelection sel;
  sel.set_a = {mover};
  Scene scene(m, sel);
  CollideOptions o;
  o.clearance = 0.1;
  std::size_t steps_with_pairs = 0, pairs_seen = 0;
  for (int step = 0; step < 160; ++step) {
    const double t = 0.1 * step;
    Pose p = translation(-2 + t, -2 + 0.8 * t, 0.2 + 0.05 * std::sin(t));
    p.rotate(Eigen::AngleAxisd(0.3 * t, Vec3(0.2, 0.3, 1).normalized()));
    scene.set_pose(mover, p);
    if (step % 4 == 0) scene.set_pose(static_cast<InstanceId>(step / 4 * 13 % 100), p * translation(0.7, 0.1, 0.0));
    const Report r = scene.check(o);
    Model placed = m;
    for (InstanceId i = 0; i < m.instances.size(); ++i) placed.instances[i].pose = scene.pose(i);
    Scene everything(placed);
    Report ref = everything.check(o);
    std::erase_if(ref.pairs, [&](const SurfacePairResult& x) { return x.instance_a != mover && x.instance_b != mover; });
    SCOPED_TRACE("step " + std::to_string(step));
    expect_same_pairs(r, ref);
    steps_with_pairs += r.pairs.empty() ? 0 : 1;
    pairs_seen += r.pairs.size();
  }
  EXPECT_GT(steps_with_pairs, 60u);  // the path crosses the grid
  EXPECT_GT(pairs_seen, 500u);
}

TEST(Scene, SelectionsAndExclusions) {
  Model m = row_of_boxes(4);
  for (InstanceId i = 0; i < 4; ++i) m.instances[i].pose = translation(0.3 * i, 0, 0);  // all overlap
  m.instances[3].path = "/other/b3";
  auto pairs_of = [&](SceneSelection sel) {
    Scene scene(m, std::move(sel));
    std::set<std::pair<InstanceId, InstanceId>> out;
    for (const SurfacePairResult& p : scene.check().pairs) out.insert({p.instance_a, p.instance_b});
    return out;
  };
  using Set = std::set<std::pair<InstanceId, InstanceId>>;
  EXPECT_EQ(pairs_of({}), (Set{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}));
  SceneSelection a_vs_b;
  a_vs_b.set_a = {0};
  a_vs_b.set_b = {2, 3};
  EXPECT_EQ(pairs_of(a_vs_b), (Set{{0, 2}, {0, 3}}));
  SceneSelection a_vs_all;
  a_vs_all.set_a = {1};
  EXPECT_EQ(pairs_of(a_vs_all), (Set{{0, 1}, {1, 2}, {1, 3}}));
  SceneSelection named;
  named.excluded_pairs = {{"/row/b2", "/row/b0"}};
  EXPECT_EQ(pairs_of(named), (Set{{0, 1}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}));
  SceneSelection sub;
  sub.excluded_subassemblies = {"/row"};
  EXPECT_EQ(pairs_of(sub), (Set{{0, 3}, {1, 3}, {2, 3}}));
  SceneSelection prefix_only;
  prefix_only.excluded_subassemblies = {"/ro"};  // a path prefix that is not a whole name excludes nothing
  EXPECT_EQ(pairs_of(prefix_only).size(), 6u);
}

// CollideOptions::involving: only the pairs with an instance asked about, each as the whole check
// gives it, within the scene's selection; the plan of a split check the same.
TEST(Scene, ChecksOfSomeInstancesPairsOnly) {
  Model m = row_of_boxes(4);
  for (InstanceId i = 0; i < 4; ++i) m.instances[i].pose = translation(0.3 * i, 0, 0);  // all overlap
  using Set = std::set<std::pair<InstanceId, InstanceId>>;
  auto pairs_of = [&](SceneSelection sel, std::vector<InstanceId> involving) {
    Scene scene(m, std::move(sel));
    CollideOptions o;
    o.involving = std::move(involving);
    Set out;
    for (const SurfacePairResult& p : scene.check(o).pairs) out.insert({p.instance_a, p.instance_b});
    Set planned;
    for (const PlannedPair& p : scene.plan(o).pairs) planned.insert({p.a, p.b});
    EXPECT_EQ(planned, out);
    o.use_oaabb = false;  // brute force: the same pairs
    Set brute;
    for (const SurfacePairResult& p : scene.check(o).pairs) brute.insert({p.instance_a, p.instance_b});
    EXPECT_EQ(brute, out);
    return out;
  };
  EXPECT_EQ(pairs_of({}, {}), (Set{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}));
  EXPECT_EQ(pairs_of({}, {2}), (Set{{0, 2}, {1, 2}, {2, 3}}));
  EXPECT_EQ(pairs_of({}, {3, 0}), (Set{{0, 1}, {0, 2}, {0, 3}, {1, 3}, {2, 3}}));
  SceneSelection a_vs_b;
  a_vs_b.set_a = {0};
  a_vs_b.set_b = {2, 3};
  EXPECT_EQ(pairs_of(a_vs_b, {3}), (Set{{0, 3}}));
  // Each pair's result is the whole check's.
  Scene whole(m), some(m);
  CollideOptions o;
  const Report all = whole.check(o);
  o.involving = {1};
  const Report one = some.check(o);
  std::vector<SurfacePairResult> expected;
  for (const SurfacePairResult& p : all.pairs)
    if (p.instance_a == 1 || p.instance_b == 1) expected.push_back(p);
  Report want;
  want.pairs = std::move(expected);
  expect_same_pairs(one, want);
}

// CollideOptions::proved_apart: the surface pairs it names are left out, every other pair as the
// whole check gives it; it is asked with the two surfaces' uncertainties as the report gives them.
TEST(Scene, PairsProvedApartAreLeftOut) {
  Model m = row_of_boxes(3);
  for (InstanceId i = 0; i < 3; ++i) m.instances[i].pose = translation(0.3 * i, 0, 0);  // all overlap
  for (const bool brute : {false, true}) {
    Scene whole(m), some(m);
    CollideOptions o;
    o.use_oaabb = !brute;
    const Report all = whole.check(o);
    ASSERT_FALSE(all.pairs.empty());
    std::mutex asked_lock;
    std::map<std::tuple<InstanceId, InstanceId, SurfaceId, SurfaceId>, double> asked;
    // Every pair of the first reported pair's instance and surface is proved apart.
    const InstanceId zero = all.pairs[0].instance_a;
    const SurfaceId first = all.pairs[0].surface_a;
    o.proved_apart = [&](InstanceId a, InstanceId b, SurfaceId sa, SurfaceId sb, double eps) {
      std::lock_guard<std::mutex> lock(asked_lock);
      asked[{a, b, sa, sb}] = eps;
      return a == zero && sa == first;
    };
    const Report left = some.check(o);
    std::vector<SurfacePairResult> expected;
    for (const SurfacePairResult& p : all.pairs) {
      const auto it = asked.find({p.instance_a, p.instance_b, p.surface_a, p.surface_b});
      ASSERT_NE(it, asked.end());
      EXPECT_EQ(it->second, p.uncertainty_a + p.uncertainty_b);
      if (!(p.instance_a == zero && p.surface_a == first)) expected.push_back(p);
    }
    ASSERT_LT(expected.size(), all.pairs.size());
    Report want;
    want.pairs = std::move(expected);
    expect_same_pairs(left, want);
  }
}

// A B-rep stand-in: triangles appear only when asked, and the asks are recorded.
class LazyBoxes : public SurfaceSource {
 public:
  explicit LazyBoxes(std::vector<Surface> faces) : faces_(std::move(faces)) {}
  bool triangulate(std::uint32_t local_index, double, TriangleMesh& out, double& achieved, Diagnostic& error) override {
    std::lock_guard<std::mutex> lock(mutex_);
    asked.push_back(local_index);
    if (local_index == fail_index) {
      error.message = "face " + std::to_string(local_index) + " failed to mesh";
      return false;
    }
    out = faces_[local_index].mesh;
    achieved = 0.0;
    return true;
  }
  std::vector<std::uint32_t> asked;
  std::uint32_t fail_index = kInvalidId;

 private:
  std::vector<Surface> faces_;
  std::mutex mutex_;
};

TEST(Scene, TessellatesOnlySurvivingSurfaces) {
  Model eager;
  const PartId lazy_box = add_part(eager, "lazy", box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 2));
  const PartId plain_box = add_part(eager, "plain", box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 2));
  add_instance(eager, "/a", lazy_box);
  add_instance(eager, "/b", plain_box, translation(0.9, 0.3, 0.3));  // meets A's x+ region only
  Model lazy = eager;
  auto source = std::make_shared<LazyBoxes>(box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 2));
  lazy.parts[lazy_box].source = source;
  for (SurfaceId s = 0; s < 6; ++s) {
    lazy.surfaces[s].has_triangles = false;
    lazy.surfaces[s].mesh = {};
  }
  const Report r = collide(lazy, 0, 1);
  expect_same_pairs(r, collide(eager, 0, 1));
  EXPECT_GT(r.counters.tessellated_surfaces, 0u);
  EXPECT_LT(r.counters.tessellated_surfaces, 6u);  // not every face of A was needed
  EXPECT_EQ(source->asked.size(), r.counters.tessellated_surfaces);
  for (std::uint32_t f : source->asked) EXPECT_NE(lazy.surfaces[f].name, "x-");  // far side of A, far from B
  EXPECT_FALSE(lazy.surfaces[0].has_triangles);
}

TEST(Scene, FailedTessellationIsADiagnostic) {
  Model m;
  const PartId box = add_part(m, "box", box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  add_instance(m, "/a", box);
  add_instance(m, "/b", box, translation(0.9, 0.3, 0.3));
  auto source = std::make_shared<LazyBoxes>(box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  source->fail_index = 1;  // x+
  m.parts[0].source = source;
  for (Surface& s : m.surfaces) {
    s.has_triangles = false;
    s.mesh = {};
  }
  const Report r = collide(m, 0, 1);
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_NE(r.diagnostics[0].message.find("failed to mesh"), std::string::npos);
  // The face without triangles still takes part: its box reaches B, and without exact geometry its
  // pairs are reported undecided (with the box distance as the lower bound), never as touching.
  bool undecided_x = false;
  for (const SurfacePairResult& p : r.pairs) {
    if (m.surfaces[p.surface_a].name != "x+") continue;
    EXPECT_EQ(p.contact, ContactClass::Undecided);
    EXPECT_EQ(p.decided_by, DecidedBy::Undecided);
    undecided_x = true;
  }
  EXPECT_TRUE(undecided_x);
  EXPECT_FALSE(r.pairs.empty());  // the other faces are still checked
  // Fast mode, as before certification, leaves it out.
  CollideOptions fast;
  fast.decision = DecisionMode::Fast;
  for (const SurfacePairResult& p : collide(m, 0, 1, fast).pairs) EXPECT_NE(m.surfaces[p.surface_a].name, "x+");
}

TEST(Trajectory, ParsesRowsAndNamesBadLines) {
  const std::string csv =
      "step,instance_path,tx,ty,tz,qw,qx,qy,qz\n"
      "0,/a,1,2,3,1,0,0,0\n"
      "\n"
      "# comment\n"
      "1,/a,1,2,3,0,0,0,2\n"      // unnormalised: normalised to 180 degrees about z
      "x,/a,1,2,3,1,0,0,0\n"      // line 6: step
      "2,/a,1,2,nan,1,0,0,0\n"    // line 7: not finite
      "3,/a,1,2,3,0,0,0,0\n"      // line 8: zero quaternion
      "4,/a,1,2,3\n"              // line 9: fields
      "5,,1,2,3,1,0,0,0\n";       // line 10: empty path
  std::vector<Diagnostic> ds;
  const auto rows = parse_trajectory(csv, "t.csv", ds);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].line, 2);
  EXPECT_TRUE(rows[0].pose.translation().isApprox(Vec3(1, 2, 3)));
  EXPECT_EQ(rows[1].step, 1);
  EXPECT_TRUE((rows[1].pose.linear() * Vec3(1, 0, 0)).isApprox(Vec3(-1, 0, 0), 1e-12));
  ASSERT_EQ(ds.size(), 5u);
  const std::int64_t lines[] = {6, 7, 8, 9, 10};
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(ds[k].line, lines[k]);
    EXPECT_EQ(ds[k].file, "t.csv");
    EXPECT_EQ(ds[k].severity, Severity::Error);
  }
  EXPECT_NE(format_diagnostic(ds[2]).find("t.csv:8"), std::string::npos);
}

TEST(Trajectory, ReplaysStepsAndMatchesStaticChecks) {
  Model m = row_of_boxes(3);
  const std::string csv =
      "0,/row/b1,1.5,0,0,1,0,0,0\n"
      "1,/row/b1,1.0,0,0,1,0,0,0\n"     // touches b0
      "2,/row/b1,0.8,0.2,0.1,1,0,0,0\n"  // penetrates b0
      "2,/row/b2,2.0,0,0,1,0,0,0\n"
      "2,/nowhere,0,0,0,1,0,0,0\n";     // unknown: a warning, the row is skipped
  std::vector<Diagnostic> ds;
  const auto rows = parse_trajectory(csv, "p.csv", ds);
  ASSERT_TRUE(ds.empty());
  Scene scene(m);
  const auto steps = replay_trajectory(scene, rows, CollideOptions{}, ds, "p.csv");
  ASSERT_EQ(steps.size(), 3u);
  ASSERT_EQ(ds.size(), 1u);
  EXPECT_EQ(ds[0].severity, Severity::Warning);
  EXPECT_EQ(ds[0].line, 5);
  EXPECT_TRUE(steps[0].report.pairs.empty());
  ASSERT_FALSE(steps[1].report.pairs.empty());
  for (const auto& p : steps[1].report.pairs) EXPECT_EQ(p.contact, ContactClass::Touching);
  bool penetrating = false;
  for (const auto& p : steps[2].report.pairs) penetrating = penetrating || p.contact == ContactClass::Penetrating;
  EXPECT_TRUE(penetrating);
  // Step 2 equals a static check of the same placement.
  Model placed = m;
  placed.instances[1].pose = rows[2].pose;
  placed.instances[2].pose = rows[3].pose;
  Scene fresh(placed);
  expect_same_pairs(steps[2].report, fresh.check());
}

}  // namespace
}  // namespace cadclash
