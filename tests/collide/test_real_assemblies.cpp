// The OAABB narrow phase against brute force on the real sample files in data/external/: with every
// triangle pair listed (AllTrianglePairs), Scene::check with use_oaabb = true must give exactly the
// brute-force answer (same surface pairs, classes, distances, penetrations, triangle pairs), and the
// answer must be bit-identical for 1 and 2 threads and for both parallel versions.
// as1-tu-203.stp is a real assembly (18 instances of 5 parts). The other samples are one part each;
// they are checked against a second instance of themselves, shifted and turned so that the two copies
// cross over a large region (real curved faces meeting at arbitrary angles, not axis-aligned boxes).
#include "cadclash/collide.h"
#include "cadclash/import.h"

#include <gtest/gtest.h>

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace cadclash {
namespace {

std::string external(const std::string& name) { return std::string(CADCLASH_DATA_DIR) + "/external/" + name; }

// Bit pattern of a double, so that "equal" means byte-identical (and -0.0 != 0.0).
std::uint64_t bits(double v) {
  std::uint64_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  return u;
}

// Everything a report says except timings, one line per surface pair, doubles as bit patterns.
std::string serialize(const Report& r, bool with_counters) {
  std::ostringstream s;
  for (const SurfacePairResult& p : r.pairs) {
    s << p.instance_a << ' ' << p.instance_b << ' ' << p.surface_a << ' ' << p.surface_b << ' '
      << contact_class_name(p.contact) << ' ' << p.intersecting << ' ' << std::hex << bits(p.distance) << ' '
      << bits(p.penetration) << std::dec << ' ' << p.exact_distance.has_value() << " tri";
    for (const auto& t : p.triangle_pairs) s << ' ' << t[0] << ',' << t[1];
    s << '\n';
  }
  if (with_counters) {
    const CollideCounters& c = r.counters;
    s << "counters " << c.instance_pairs << ' ' << c.aabb_tests << ' ' << c.aabb_updates << ' ' << c.surfaces_a
      << ' ' << c.surfaces_b << ' ' << c.surface_pairs << ' ' << c.triangles_a << ' ' << c.triangles_b << ' '
      << c.triangle_tests << ' ' << c.exact_fallbacks << ' ' << c.distance_tests << ' ' << c.intersecting_pairs
      << '\n';
  }
  return s.str();
}

struct Case {
  const char* file;
  double deflection;
  bool release_only = false;  // brute force too slow for the Debug ASan+UBSan pass
};

std::string case_name(const testing::TestParamInfo<Case>& info) {
  std::string n = std::string(info.param.file) + "_" + std::to_string(info.param.deflection);
  for (char& ch : n) if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return n;
}

class RealAssembly : public testing::TestWithParam<Case> {};

TEST_P(RealAssembly, OaabbEqualsBruteForceForAnyThreadCount) {
  const Case c = GetParam();
  const std::string path = external(c.file);
  if (!std::ifstream(path)) GTEST_SKIP() << "run scripts/setup.sh for " << path;
#ifndef NDEBUG
  if (c.release_only) GTEST_SKIP() << c.file << ": brute force runs in optimized builds only";
#endif
  ImportOptions io;
  io.tessellation.linear_deflection = c.deflection;
  ImportResult imported = import_file(path, io);
  Model& model = imported.model;
  ASSERT_FALSE(model.instances.empty()) << path;
  if (model.instances.size() == 1) {
    Aabb box;
    for (const Surface& s : model.surfaces) box.extend(s.aabb);
    const Vec3 size = box.sizes();
    Pose pose = Pose::Identity();
    pose.translate(box.center() + Vec3(0.3 * size.x(), 0.1 * size.y(), 0.05 * size.z()));
    pose.rotate(Eigen::AngleAxisd(0.2, Vec3(1.0, 2.0, 3.0).normalized()));
    pose.translate(-box.center());
    model.instances.push_back(Instance{model.instances[0].path + "-copy", model.instances[0].part, pose});
  }
  std::size_t triangles = 0;
  for (const Surface& s : model.surfaces) triangles += s.mesh.triangles.size();

  // A fresh scene per query: the first check of a scene also counts the instances' world-box updates.
  auto check = [&model](const CollideOptions& options) { return Scene(model).check(options); };
  CollideOptions o;
  o.mode = CollideMode::AllTrianglePairs;
  o.tolerance = 0.01;
  o.threads = 1;
  const Report fast1 = check(o);
  o.threads = 2;
  const Report fast2 = check(o);
  o.version = ParallelVersion::V2;
  const Report fast2v2 = check(o);
  o.version = ParallelVersion::V1;
  o.use_oaabb = false;
  const Report brute2 = check(o);
  o.threads = 1;
  const Report brute1 = check(o);

  // The OAABB culls work but never changes the answer.
  EXPECT_EQ(serialize(fast1, false), serialize(brute1, false));
  // Thread count changes nothing, counters included; V2 changes only the counters' bookkeeping.
  EXPECT_EQ(serialize(fast1, true), serialize(fast2, true));
  EXPECT_EQ(serialize(fast1, false), serialize(fast2v2, false));
  EXPECT_EQ(serialize(brute1, true), serialize(brute2, true));
  EXPECT_LT(fast1.counters.triangle_tests, brute1.counters.triangle_tests);

  std::size_t listed = 0;
  for (const SurfacePairResult& p : fast1.pairs) listed += p.triangle_pairs.size();
  RecordProperty("instances", static_cast<int>(model.instances.size()));
  RecordProperty("parts", static_cast<int>(model.parts.size()));
  RecordProperty("triangles", static_cast<int>(triangles));
  RecordProperty("surface_pairs", static_cast<int>(fast1.pairs.size()));
  std::printf("[ info     ] %s @%g: %zu parts, %zu instances, %zu part triangles; %zu surface pairs, %zu triangle "
              "pairs; triangle tests oaabb %llu vs brute %llu\n",
              c.file, c.deflection, model.parts.size(), model.instances.size(), triangles, fast1.pairs.size(),
              listed, static_cast<unsigned long long>(fast1.counters.triangle_tests),
              static_cast<unsigned long long>(brute1.counters.triangle_tests));
}

INSTANTIATE_TEST_SUITE_P(Samples, RealAssembly,
                         testing::Values(Case{"as1-tu-203.stp", 0.1}, Case{"linkrods.step", 0.1},
                                         Case{"linkrods.step", 0.05}, Case{"screw.step", 0.1},
                                         Case{"screw.step", 0.05}, Case{"frame.step", 0.1, true},
                                         Case{"component8.step", 0.1}),
                         case_name);

}  // namespace
}  // namespace cadclash
