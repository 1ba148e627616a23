// What a Scene keeps between checks instead of walking the whole model each time (per-part search
// reaches, the bytes it holds) follows every change to the model's surfaces: its own lazy
// tessellation, what a memory budget gives back, triangles made outside it. After each, a check
// answers exactly as a fresh scene's on the model as it is then.
#include "scene_fixtures.h"

#include <gtest/gtest.h>

#include <mutex>

namespace cadclash {
namespace {

using namespace cadclash::testing;

// Faces made on demand, as a B-rep source would: loaded at `default_deflection`, meshed exactly
// (achieved deflection 0), so a face's share of the search reach drops from the default to 0 once
// it has triangles.
class LazyFaces : public SurfaceSource {
 public:
  LazyFaces(std::vector<Surface> faces, double default_deflection)
      : faces_(std::move(faces)), default_(default_deflection) {}
  bool triangulate(std::uint32_t local_index, double, TriangleMesh& out, double& achieved, Diagnostic&) override {
    std::lock_guard<std::mutex> lock(mutex_);
    out = faces_[local_index].mesh;
    achieved = 0.0;
    return true;
  }
  double default_deflection() const override { return default_; }

 private:
  std::vector<Surface> faces_;
  double default_;
  std::mutex mutex_;
};

// A unit box part whose faces have no triangles yet.
PartId lazy_box(Model& m, const std::string& name, double default_deflection) {
  const PartId p = add_part(m, name, box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 3));
  m.parts[p].source = std::make_shared<LazyFaces>(box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 3), default_deflection);
  for (SurfaceId s = m.parts[p].first_surface; s < m.parts[p].first_surface + m.parts[p].surface_count; ++s) {
    m.surfaces[s].has_triangles = false;
    m.surfaces[s].mesh = {};
  }
  return p;
}

void expect_same_report(const Report& x, const Report& y) {
  expect_same_pairs(x, y);
  expect_same_counters(x.counters, y.counters);
  EXPECT_EQ(x.unexamined_pairs, y.unexamined_pairs);
}

void expect_same_memory(const SceneMemory& a, const SceneMemory& b) {
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.hierarchies, b.hierarchies);
  EXPECT_EQ(a.instances, b.instances);
  EXPECT_EQ(a.triangle_count, b.triangle_count);
}

CollideOptions options() {
  CollideOptions o;
  o.tolerance = 0.01;
  o.clearance = 0.05;
  return o;
}

// Box A, loaded at 0.3 mm, and box C 0.2 mm to its -x side: while A's faces have no triangles its
// reach share is 0.3 and the pair is within the search reach; once they are meshed exactly it is not.
Model a_and_c() {
  Model m;
  const PartId a = lazy_box(m, "A", 0.3);
  const PartId c = lazy_box(m, "C", 0.0);
  add_instance(m, "/A", a);
  add_instance(m, "/C", c, translation(-1.2, 0, 0));
  return m;
}

// Triangles made outside the scene (require_triangles) shrink A's reach: the next check sees it.
TEST(SceneState, ReachFollowsTrianglesMadeOutsideTheScene) {
  Model m = a_and_c();
  Scene scene(m);
  const Report before = scene.check(options());
  EXPECT_EQ(before.counters.instance_pairs, 1u);  // within A's 0.3 mm while it is untessellated
  std::vector<SurfaceId> all(m.surfaces.size());
  for (SurfaceId s = 0; s < all.size(); ++s) all[s] = s;
  const std::uint64_t revision = m.revision;
  ASSERT_TRUE(require_triangles(m, all).empty());
  EXPECT_GT(m.revision, revision);
  const Report after = scene.check(options());
  EXPECT_EQ(after.counters.instance_pairs, 0u);  // 0.2 mm apart, meshed exactly: out of reach
  Model same = m;
  expect_same_report(after, Scene(same).check(options()));
}

// The scene's own lazy tessellation does the same: C first sits on A (every face of A meshed), then
// moves 0.2 mm off; the check there answers as a fresh scene's on the model as it is then.
TEST(SceneState, ReachFollowsTheScenesOwnTessellation) {
  Model m = a_and_c();
  Scene scene(m);
  scene.set_pose(1, Pose::Identity());
  const Report on = scene.check(options());
  ASSERT_FALSE(on.pairs.empty());
  for (SurfaceId s = m.parts[0].first_surface; s < m.parts[0].first_surface + 6; ++s) ASSERT_TRUE(m.surfaces[s].has_triangles);
  scene.set_pose(1, translation(-1.2, 0, 0));
  const Report off = scene.check(options());
  EXPECT_EQ(off.counters.instance_pairs, 0u);
  Model same = m;
  same.instances[1].pose = translation(-1.2, 0, 0);
  expect_same_report(off, Scene(same).check(options()));
  // And back: the pair is found again with A's exact reach.
  scene.set_pose(1, translation(-1.005, 0, 0));
  const Report near = scene.check(options());
  EXPECT_EQ(near.counters.instance_pairs, 1u);
  same.instances[1].pose = translation(-1.005, 0, 0);
  expect_same_report(near, Scene(same).check(options()));
}

// A memory budget gives back the triangles of the pairs past its cut, so their faces' reach goes back
// to the default, and the trees it built for them: the reaches and Scene::memory() follow.
TEST(SceneState, ReachAndMemoryFollowWhatABudgetGivesBack) {
  // A diagonal chain of boxes, each overlapping its next two neighbours, one part each.
  Model m;
  for (int i = 0; i < 6; ++i)
    add_instance(m, "/chain/b" + std::to_string(i), lazy_box(m, "box" + std::to_string(i), 0.3),
                 translation(0.45 * i, 0.1 * i, 0.05 * i));
  CollideOptions o = options();
  Model counted = m;
  const Report full = Scene(counted).check(o);
  ASSERT_TRUE(full.complete);
  o.memory_budget_bytes = full.memory_charged / 3;
  Scene scene(m);
  const Report cut = scene.check(o);
  ASSERT_FALSE(cut.complete);
  ASSERT_FALSE(cut.unexamined_pairs.empty());
  // What the scene holds now is what a fresh scene holds once it has built the trees of every face
  // that has triangles.
  Model held = m;
  Scene fresh(held);
  fresh.build_hierarchies(1);
  expect_same_memory(scene.memory(), fresh.memory());
  // The next check without a budget answers as a fresh scene's on the model as the cut left it.
  o.memory_budget_bytes = 0;
  Model same = m;
  const Report rest = scene.check(o);
  EXPECT_TRUE(rest.complete);
  expect_same_report(rest, Scene(same).check(o));
  Model after = m;
  Scene fresh_after(after);
  fresh_after.build_hierarchies(1);
  expect_same_memory(scene.memory(), fresh_after.memory());
}

}  // namespace
}  // namespace cadclash
