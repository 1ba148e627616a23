// `cadclash check` end to end on the import's speed-ups: files read in parallel (--parallel-files) and
// the import cache (--cache) give byte-identical reports (--no-timings) to reading one file after
// another without a cache; with timings, every file's stages are in the table and the JSON.
#include <gtest/gtest.h>
#include "cli_runner.h"
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;
using cadclash::testing::CliRun;
CliRun cadclash(const std::string& args) { return cadclash::testing::run_cadclash(args); }

const std::string kExternal = std::string(CADCLASH_DATA_DIR) + "/external/";

// The --json report of `cadclash check FILES ARGS --json <scratch>`; fails the test on a bad exit.
std::string report_of(const std::string& files, const std::string& args) {
  const std::string json = cadclash::testing::scratch_dir() + "/import-report.json";
  fs::remove(json);
  const CliRun r = cadclash("check " + files + " " + args + " --json '" + json + "'");
  EXPECT_TRUE(r.code == 0 || r.code == 3) << r.err;
  return cadclash::testing::slurp(json);
}

TEST(CliImport, ParallelAndCachedReportsAreTheReference) {
  const std::string as1 = kExternal + "as1-tu-203.stp", screw = kExternal + "screw.step",
                    linkrods = kExternal + "linkrods.step";
  for (const std::string& f : {as1, screw, linkrods})
    if (!fs::exists(f)) GTEST_SKIP() << f << " missing: run scripts/setup.sh";
  const std::string files = "'" + as1 + "' '" + screw + "' '" + linkrods + "'";
  const std::string cache = cadclash::testing::scratch_dir() + "/cli-cache";
  fs::remove_all(cache);
  const std::string reference = report_of(files, "--no-timings --parallel-files 1 --threads 1");
  ASSERT_NE(reference.find("\"pairs\""), std::string::npos);
  EXPECT_EQ(reference.find("import_timings"), std::string::npos);
  EXPECT_EQ(report_of(files, "--no-timings --parallel-files 3"), reference);
  EXPECT_EQ(report_of(files, "--no-timings --cache '" + cache + "'"), reference);  // cold
  EXPECT_EQ(report_of(files, "--no-timings --cache '" + cache + "'"), reference);  // warm
  EXPECT_EQ(report_of(files, "--no-timings --lazy --cache '" + cache + "'"),
            report_of(files, "--no-timings --lazy"));
}

TEST(CliImport, StagesAreInTheTableAndTheJson) {
  const std::string as1 = kExternal + "as1-tu-203.stp";
  if (!fs::exists(as1)) GTEST_SKIP() << as1 << " missing: run scripts/setup.sh";
  const std::string box = std::string(CADCLASH_DATA_DIR) + "/collide/box_a.obj";
  const std::string cache = cadclash::testing::scratch_dir() + "/stage-cache";
  fs::remove_all(cache);
  const std::string files = "'" + as1 + "' '" + box + "'";
  (void)report_of(files, "--cache '" + cache + "'");
  const std::string json = cadclash::testing::scratch_dir() + "/stages.json";
  const CliRun r = cadclash("check " + files + " --cache '" + cache + "' --json '" + json + "'");
  ASSERT_TRUE(r.code == 0 || r.code == 3) << r.err;
  EXPECT_NE(r.out.find("stages: read "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" ms, query "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("as1-tu-203.stp"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(cadclash::testing::slurp(json));
  ASSERT_TRUE(j.contains("import_timings"));
  const auto& files_json = j["import_timings"]["files"];
  ASSERT_EQ(files_json.size(), 2u);
  EXPECT_EQ(files_json[0]["file"], as1);
  EXPECT_EQ(files_json[0]["cache"], "hit");
  EXPECT_EQ(files_json[1]["cache"], "hit");
  for (const auto& f : files_json)
    for (const char* stage : {"read", "transfer", "heal", "tessellate", "total"}) {
      ASSERT_TRUE(f[stage].is_number()) << stage;
      EXPECT_GE(f[stage].get<double>(), 0.0) << stage;
    }
  ASSERT_TRUE(j["import_timings"]["seconds"].is_number());
  EXPECT_GE(j["import_timings"]["seconds"].get<double>(), 0.0);
  const CliRun quiet = cadclash("check " + files + " --no-timings");
  EXPECT_EQ(quiet.out.find("stages:"), std::string::npos);
}

// A damaged entry: the check says so on stderr and in the report's diagnostics, and finds the same pairs.
TEST(CliImport, DamagedCacheEntryIsReadAgain) {
  const std::string box_a = std::string(CADCLASH_DATA_DIR) + "/collide/box_a.obj";
  const std::string box_b = std::string(CADCLASH_DATA_DIR) + "/collide/box_overlap.obj";
  const std::string cache = cadclash::testing::scratch_dir() + "/damaged-cache";
  fs::remove_all(cache);
  const std::string files = "'" + box_a + "' '" + box_b + "'";
  const std::string reference = report_of(files, "--no-timings --cache '" + cache + "'");
  for (const auto& e : fs::directory_iterator(cache)) fs::resize_file(e.path(), fs::file_size(e.path()) / 2);
  const std::string json = cadclash::testing::scratch_dir() + "/damaged.json";
  const CliRun r = cadclash("check " + files + " --no-timings --cache '" + cache + "' --json '" + json + "'");
  EXPECT_NE(r.err.find("is damaged"), std::string::npos) << r.err;
  nlohmann::json got = nlohmann::json::parse(cadclash::testing::slurp(json));
  nlohmann::json want = nlohmann::json::parse(reference);
  EXPECT_EQ(got["diagnostics"].size(), 2u);
  got.erase("diagnostics");
  want.erase("diagnostics");
  EXPECT_EQ(got, want);
  EXPECT_EQ(report_of(files, "--no-timings --cache '" + cache + "'"), reference);  // rewritten whole
}

}  // namespace
