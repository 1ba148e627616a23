// The `cadclash` binary on a real STEP assembly: tessellate to .glb, and the .glb read back by
// `info --json` keeps the instances and every surface's STEP id of the direct import.
#include <gtest/gtest.h>
#include "cli_runner.h"
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace {

using cadclash::testing::CliRun;
CliRun cadclash(const std::string& args) { return cadclash::testing::run_cadclash(args); }

struct SurfaceView {
  std::int64_t step_id = -1;
  std::size_t triangles = 0;
  bool operator==(const SurfaceView&) const = default;
};

// Instance path → the surfaces of its part, in face order.
std::map<std::string, std::vector<SurfaceView>> instances_of(const nlohmann::json& info) {
  std::map<std::string, std::vector<SurfaceView>> out;
  for (const auto& i : info.at("instances")) {
    std::vector<SurfaceView>& surfaces = out[i.at("path").get<std::string>()];
    for (const auto& s : info.at("parts").at(i.at("part").get<std::size_t>()).at("surfaces"))
      surfaces.push_back({s.value("step_id", std::int64_t{-1}), s.at("triangles").get<std::size_t>()});
  }
  return out;
}

TEST(CliCad, TessellateAs1ToGlbKeepsInstancesAndStepIds) {
  const std::string step = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
  if (!std::filesystem::exists(step)) GTEST_SKIP() << step << " missing: run scripts/setup.sh";
  const std::string glb = cadclash::testing::scratch_dir() + "/as1.glb";
  std::filesystem::remove(glb);

  const CliRun t = cadclash("tessellate '" + step + "' -o '" + glb + "' --deflection 0.05");
  ASSERT_EQ(t.code, 0) << t.err;
  ASSERT_TRUE(std::filesystem::exists(glb));

  const CliRun back = cadclash("info '" + glb + "' --json");
  ASSERT_EQ(back.code, 0) << back.err;
  const nlohmann::json from_glb = nlohmann::json::parse(back.out);
  const CliRun direct = cadclash("info '" + step + "' --json --deflection 0.05");
  ASSERT_EQ(direct.code, 0) << direct.err;
  const nlohmann::json from_step = nlohmann::json::parse(direct.out);

  EXPECT_EQ(from_glb.at("instances").size(), 18u);
  EXPECT_EQ(from_step.at("instances").size(), 18u);
  const auto glb_instances = instances_of(from_glb);
  const auto step_instances = instances_of(from_step);
  EXPECT_EQ(glb_instances.size(), 18u);  // paths unique
  std::size_t faces = 0;
  for (const auto& [path, surfaces] : step_instances) {
    faces += surfaces.size();
    const auto it = glb_instances.find(path);
    ASSERT_NE(it, glb_instances.end()) << path << " is missing from the .glb";
    // Same STEP id per surface in face order, and the same triangles (same deflection).
    EXPECT_EQ(it->second, surfaces) << path;
    for (const SurfaceView& s : surfaces) {
      EXPECT_GT(s.step_id, 0) << path;
      EXPECT_GT(s.triangles, 0u) << path << " #" << s.step_id;
    }
  }
  EXPECT_EQ(faces, 160u);
}

// --import-time-limit: a reader that cannot finish in time (as1 cannot be parsed in a millisecond)
// is stopped with an error naming the file and the limit, and the run fails as an input error.
// Without isolation the reader's limit is reported as not applied, while the tessellation's (the same
// flag) still stops meshing: each face left without triangles is named.
TEST(CliCad, ImportTimeLimitStopsTheReaderAndSaysSo) {
  const std::string step = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
  if (!std::filesystem::exists(step)) GTEST_SKIP() << step << " missing: run scripts/setup.sh";
  const CliRun stopped = cadclash("check '" + step + "' --import-time-limit 0.001");
  EXPECT_EQ(stopped.code, 1) << stopped.err;
  EXPECT_NE(stopped.err.find(step + ": error: the isolated reader did not finish within the time limit of 0.001 s"),
            std::string::npos)
      << stopped.err;
  const CliRun unapplied = cadclash("info '" + step + "' --import-time-limit 0.001 --no-isolation");
  EXPECT_EQ(unapplied.code, 1) << unapplied.err;
  EXPECT_NE(unapplied.err.find(step + ": warning: the reader time limit needs the isolated reader, which is off; not applied"),
            std::string::npos)
      << unapplied.err;
  EXPECT_NE(unapplied.err.find(" could not be tessellated (the tessellation time limit of 0.001 s ran out); its "
                               "surface is kept without triangles"),
            std::string::npos)
      << unapplied.err;
  EXPECT_EQ(cadclash("check '" + step + "' --import-time-limit -1").code, 2);  // a usage error
}

}  // namespace
