#include "cadclash/collide.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

namespace cadclash {
namespace {

Model one_triangle_model(const std::string& part_name, const std::string& path) {
  Model m;
  Part p;
  p.name = part_name;
  p.first_surface = 0;
  p.surface_count = 1;
  m.parts.push_back(p);
  Surface s;
  s.name = "s0";
  s.part = 0;
  s.mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 2, 3)};
  s.mesh.triangles = {{0, 1, 2}};
  s.has_triangles = true;
  s.aabb = mesh_aabb(s.mesh);
  m.surfaces.push_back(s);
  m.instances.push_back({path, 0, Pose::Identity()});
  return m;
}

TEST(Model, AppendShiftsIdsAndPrefixesPaths) {
  Model a = one_triangle_model("a", "/a");
  Model b = one_triangle_model("b", "/b");
  b.surfaces[0].provenance.parent = 0;
  append_model(a, b, "/second.obj");
  ASSERT_EQ(a.parts.size(), 2u);
  EXPECT_EQ(a.parts[1].first_surface, 1u);
  EXPECT_EQ(a.surfaces[1].part, 1u);
  EXPECT_EQ(a.surfaces[1].provenance.parent, 1u);
  EXPECT_EQ(a.instances[1].part, 1u);
  EXPECT_EQ(a.instances[1].path, "/second.obj/b");
  EXPECT_EQ(a.instances[0].path, "/a");
}

TEST(Model, MeshAabbEnclosesReferencedVerticesOnly) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 2, 3), Vec3(100, 100, 100)};
  mesh.triangles = {{0, 1, 2}};
  const Aabb box = mesh_aabb(mesh);
  EXPECT_EQ(box.min(), Vec3(0, 0, 0));
  EXPECT_EQ(box.max(), Vec3(1, 2, 3));
  EXPECT_TRUE(mesh_aabb(TriangleMesh{}).isEmpty());
}

TEST(Diagnostics, FormatNamesFileLineAndEntity) {
  EXPECT_EQ(format_diagnostic({Severity::Error, "a.obj", 12, -1, "index out of range"}),
            "a.obj:12: error: index out of range");
  EXPECT_EQ(format_diagnostic({Severity::Warning, "as1.stp", 0, 345, "face healed"}),
            "as1.stp: #345: warning: face healed");
  const std::vector<Diagnostic> ds{{Severity::Warning, "f", 0, -1, "w"}};
  EXPECT_FALSE(has_error(ds));
}

class CountingSource : public SurfaceSource {
 public:
  bool triangulate(std::uint32_t local_index, double, TriangleMesh& out, double& achieved, Diagnostic& error) override {
    ++calls;
    if (local_index == 1) {
      error = {Severity::Error, "p.step", 0, 77, "face failed to mesh"};
      return false;
    }
    out.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    out.triangles = {{0, 1, 2}};
    achieved = 0.25;
    return true;
  }
  int calls = 0;
};

TEST(Model, RequireTrianglesAsksSourceOnlyForMissingAndReportsFailures) {
  Model m;
  auto source = std::make_shared<CountingSource>();
  m.parts.push_back({"p", "p.step", 0, 3, source});
  for (int i = 0; i < 3; ++i) {
    Surface s;
    s.part = 0;
    m.surfaces.push_back(s);
  }
  const std::vector<SurfaceId> wanted{0, 1};
  std::vector<Diagnostic> errors = require_triangles(m, wanted);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].step_id, 77);
  EXPECT_TRUE(m.surfaces[0].has_triangles);
  EXPECT_DOUBLE_EQ(m.surfaces[0].deflection, 0.25);
  EXPECT_FALSE(m.surfaces[1].has_triangles);
  EXPECT_FALSE(m.surfaces[2].has_triangles);
  EXPECT_EQ(source->calls, 2);
  require_triangles(m, wanted);  // surface 0 is done; only the failed one is asked again
  EXPECT_EQ(source->calls, 3);
}

// Sources that note how many of them are meshing at once; each call takes a millisecond, so two
// threads given the work overlap.
struct Concurrency {
  std::atomic<int> now{0}, most{0};
};
class SlowSource : public SurfaceSource {
 public:
  explicit SlowSource(Concurrency& c) : c_(c) {}
  bool triangulate(std::uint32_t, double, TriangleMesh& out, double& achieved, Diagnostic&) override {
    const int n = ++c_.now;
    int most = c_.most.load();
    while (n > most && !c_.most.compare_exchange_weak(most, n)) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    out.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    out.triangles = {{0, 1, 2}};
    achieved = 0.0;
    --c_.now;
    return true;
  }

 private:
  Concurrency& c_;
};

// A caller that asks for one thread (a check with threads = 1, several processes sharing a machine)
// gets one, also for the lazy tessellation; with more, the parts are meshed side by side.
TEST(Model, RequireTrianglesUsesTheThreadsAskedFor) {
  Concurrency c;
  Model m;
  constexpr int kParts = 8;
  for (int p = 0; p < kParts; ++p) {
    m.parts.push_back({"p" + std::to_string(p), "p.step", static_cast<SurfaceId>(p), 1, std::make_shared<SlowSource>(c)});
    Surface s;
    s.part = static_cast<PartId>(p);
    m.surfaces.push_back(s);
  }
  std::vector<SurfaceId> all(kParts);
  for (int p = 0; p < kParts; ++p) all[static_cast<std::size_t>(p)] = static_cast<SurfaceId>(p);
  Model one = m;
  EXPECT_TRUE(require_triangles(one, all, 0.0, 1).empty());
  EXPECT_EQ(c.most.load(), 1);
  for (const Surface& s : one.surfaces) EXPECT_TRUE(s.has_triangles);
  c.most = 0;
  Model two = m;
  EXPECT_TRUE(require_triangles(two, all, 0.0, 2).empty());
  EXPECT_LE(c.most.load(), 2);
  for (const Surface& s : two.surfaces) EXPECT_TRUE(s.has_triangles);
  // A check on one thread tessellates its surfaces on one thread too.
  c.most = 0;
  for (Surface& s : m.surfaces) s.aabb = mesh_aabb(one.surfaces[0].mesh);
  for (int p = 0; p < kParts; ++p) m.instances.push_back({"/i" + std::to_string(p), static_cast<PartId>(p), Pose::Identity()});
  Scene scene(m);
  CollideOptions o;
  o.threads = 1;
  EXPECT_FALSE(scene.check(o).pairs.empty());
  for (const Surface& s : m.surfaces) EXPECT_TRUE(s.has_triangles);
  EXPECT_EQ(c.most.load(), 1);
}

}  // namespace
}  // namespace cadclash
