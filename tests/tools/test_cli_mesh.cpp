// The `cadclash` binary on mesh files: info, info --json, tessellate, exit codes and messages.
#include <gtest/gtest.h>
#include "cli_runner.h"
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace {

using cadclash::testing::CliRun;
using cadclash::testing::slurp;
CliRun cadclash(const std::string& args) { return cadclash::testing::run_cadclash(args); }

std::string mesh(const std::string& name) { return std::string("'") + CADCLASH_DATA_DIR + "/mesh/" + name + "'"; }
std::string bad(const std::string& name) { return std::string("'") + CADCLASH_DATA_DIR + "/bad/" + name + "'"; }
std::string temp(const std::string& name) { return cadclash::testing::scratch_dir() + "/" + name; }

// (name, kind, face_index, triangles) of every surface of every part.
std::vector<std::tuple<std::string, std::string, int, std::size_t>> surfaces_of(const nlohmann::json& info) {
  std::vector<std::tuple<std::string, std::string, int, std::size_t>> out;
  for (const auto& p : info.at("parts"))
    for (const auto& s : p.at("surfaces"))
      out.emplace_back(s.at("name"), s.at("kind"), s.at("face_index"), s.at("triangles"));
  return out;
}

TEST(CliMesh, InfoListsGroups) {
  const CliRun r = cadclash("info --surfaces " + mesh("groups.obj"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("1 parts, 1 instances, 4 surfaces"), std::string::npos) << r.out;
  for (const char* group : {"default", "left", "right", "lid"})
    EXPECT_NE(r.out.find(std::string("      ") + group + "  obj-group"), std::string::npos) << group << "\n" << r.out;
  EXPECT_EQ(r.err, "");
}

TEST(CliMesh, InfoJsonParses) {
  const CliRun r = cadclash("info --json " + mesh("groups.obj") + " " + mesh("colours.off"));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j.at("complete").get<bool>());
  ASSERT_EQ(j.at("parts").size(), 2u);
  EXPECT_EQ(j["parts"][0]["name"], "groups");
  EXPECT_EQ(j["parts"][0]["surfaces"].size(), 4u);
  EXPECT_EQ(j["parts"][0]["surfaces"][1]["name"], "left");
  EXPECT_EQ(j["parts"][0]["surfaces"][1]["triangles"], 3);
  EXPECT_EQ(j["parts"][1]["surfaces"][0]["name"], "colour-FF0000");
  EXPECT_EQ(j["parts"][1]["surfaces"][0]["kind"], "off-colour-group");
  ASSERT_EQ(j.at("instances").size(), 2u);
  EXPECT_EQ(j["instances"][0]["path"], "/groups.obj/groups");
}

TEST(CliMesh, BadFileExitsOneNamingFileAndLine) {
  const CliRun r = cadclash("info " + bad("index_out_of_range.obj"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("index_out_of_range.obj:8: error: face dropped: vertex index 9 is out of range"), std::string::npos)
      << r.err;
  // The good part of the file is still reported.
  EXPECT_NE(r.out.find("2 surfaces"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("INCOMPLETE"), std::string::npos) << r.out;

  const CliRun off = cadclash("info " + bad("off_nan.off"));
  EXPECT_EQ(off.code, 1);
  EXPECT_NE(off.err.find("off_nan.off:6: error:"), std::string::npos) << off.err;
  const CliRun garbage = cadclash("info " + bad("garbage.stl"));
  EXPECT_EQ(garbage.code, 1);
  EXPECT_NE(garbage.err.find("garbage.stl: error:"), std::string::npos) << garbage.err;
}

TEST(CliMesh, UsageErrorsExitTwo) {
  EXPECT_EQ(cadclash("info").code, 2);
  EXPECT_EQ(cadclash("").code, 2);
  EXPECT_EQ(cadclash("tessellate " + mesh("groups.obj")).code, 2);  // -o is required
  EXPECT_EQ(cadclash("info --no-such-flag " + mesh("groups.obj")).code, 2);
  const CliRun missing = cadclash("info " + bad("does_not_exist.obj"));
  EXPECT_NE(missing.code, 0);
  EXPECT_NE(missing.err.find("does_not_exist.obj"), std::string::npos) << missing.err;
  EXPECT_EQ(cadclash("info --help").code, 0);
  EXPECT_EQ(cadclash("tessellate --help").code, 0);
}

TEST(CliMesh, TessellateToGlbThenInfoGivesTheSameSurfaces) {
  const CliRun before = cadclash("info --json " + mesh("groups.obj"));
  ASSERT_EQ(before.code, 0) << before.err;
  const std::string out = temp("cli_groups.glb");
  const CliRun t = cadclash("tessellate " + mesh("groups.obj") + " -o '" + out + "'");
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.err.find("wrote"), std::string::npos) << t.err;
  EXPECT_EQ(t.err.find('\r'), std::string::npos) << "progress must stay quiet in pipes";
  const CliRun after = cadclash("info --json '" + out + "'");
  ASSERT_EQ(after.code, 0) << after.err;
  const nlohmann::json a = nlohmann::json::parse(before.out), b = nlohmann::json::parse(after.out);
  EXPECT_EQ(surfaces_of(a), surfaces_of(b));
  EXPECT_EQ(a["parts"][0]["name"], b["parts"][0]["name"]);
  EXPECT_EQ(a["instances"], b["instances"]);
}

TEST(CliMesh, TessellateToObjGroupsEverySurface) {
  const std::string out = temp("cli_groups.obj");
  const CliRun t = cadclash("tessellate " + mesh("usemtl.obj") + " -o '" + out + "'");
  ASSERT_EQ(t.code, 0) << t.err;
  const CliRun info = cadclash("info --json '" + out + "'");
  ASSERT_EQ(info.code, 0) << info.err;
  const auto s = surfaces_of(nlohmann::json::parse(info.out));
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(std::get<0>(s[0]), "/usemtl/alpha");
  EXPECT_EQ(std::get<3>(s[0]), 3u);
  EXPECT_EQ(std::get<0>(s[2]), "/usemtl/red");
}

TEST(CliMesh, TessellateRefusesAnUnknownOutputFormat) {
  const CliRun t = cadclash("tessellate " + mesh("groups.obj") + " -o '" + temp("x.xyz") + "'");
  EXPECT_EQ(t.code, 1);
  EXPECT_NE(t.err.find("unknown output format"), std::string::npos) << t.err;
}

}  // namespace
