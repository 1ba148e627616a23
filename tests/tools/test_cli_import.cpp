// `cadclash check` end to end on the import's speed-ups: files read in parallel (--parallel-files) and
// the import cache (--cache) give byte-identical reports (--no-timings) to reading one file after
// another without a cache; with timings, every file's stages are in the table and the JSON.
#include <gtest/gtest.h>
#include "cli_runner.h"
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <sys/wait.h>

namespace {

namespace fs = std::filesystem;
using cadclash::testing::CliRun;
CliRun cadclash(const std::string& args) { return cadclash::testing::run_cadclash(args); }

const std::string kExternal = std::string(CADCLASH_DATA_DIR) + "/external/";

// The first of `files` that is missing ("" when all are there): tests skip without the external data.
std::string missing(std::initializer_list<std::string> files) {
  for (const std::string& f : files)
    if (!fs::exists(f)) return f;
  return {};
}

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
  if (const std::string m = missing({as1, screw, linkrods}); !m.empty()) GTEST_SKIP() << m << " missing: run scripts/setup.sh";
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

// The cache is keyed by the build that wrote it, not by how the command was typed: a run started
// by a relative path or through a link finds what a run started by the full path stored.
TEST(CliImport, CacheIsFoundHoweverTheProgramIsStarted) {
  const std::string as1 = kExternal + "as1-tu-203.stp";
  if (const std::string m = missing({as1}); !m.empty()) GTEST_SKIP() << m << " missing: run scripts/setup.sh";
  const std::string dir = cadclash::testing::scratch_dir();
  const std::string cache = dir + "/started-cache", json = dir + "/started.json", link = dir + "/cadclash-link";
  fs::remove_all(cache);
  fs::remove(link);
  fs::create_symlink(CADCLASH_EXE, link);
  (void)report_of("'" + as1 + "'", "--cache '" + cache + "'");  // stored by the full path
  const fs::path exe(CADCLASH_EXE);
  for (const std::string& start : {"cd '" + exe.parent_path().string() + "' && ./" + exe.filename().string(), "'" + link + "'"}) {
    fs::remove(json);
    const std::string command = start + " check '" + as1 + "' --cache '" + cache + "' --json '" + json + "' >/dev/null 2>&1";
    const int status = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(status) && (WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == 3)) << command;
    const nlohmann::json j = nlohmann::json::parse(cadclash::testing::slurp(json));
    EXPECT_EQ(j["import_timings"]["files"][0]["cache"], "hit") << command;
  }
}

TEST(CliImport, StagesAreInTheTableAndTheJson) {
  const std::string as1 = kExternal + "as1-tu-203.stp";
  if (const std::string m = missing({as1}); !m.empty()) GTEST_SKIP() << m << " missing: run scripts/setup.sh";
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

// --threads 1 holds for the import too: files are read one after another (without it, as many at
// once as there are cores), so the import's wall clock covers every file's own. Read at once, the
// files' times overlap and add up to more than the import's.
TEST(CliImport, ThreadsOneReadsOneFileAtATime) {
  const std::string as1 = kExternal + "as1-tu-203.stp", screw = kExternal + "screw.step",
                    linkrods = kExternal + "linkrods.step";
  if (const std::string m = missing({as1, screw, linkrods}); !m.empty()) GTEST_SKIP() << m << " missing: run scripts/setup.sh";
  const std::string json = cadclash::testing::scratch_dir() + "/threads-one.json";
  fs::remove(json);
  const CliRun r = cadclash("check '" + as1 + "' '" + screw + "' '" + linkrods + "' --threads 1 --json '" + json + "'");
  ASSERT_TRUE(r.code == 0 || r.code == 3) << r.err;
  const nlohmann::json j = nlohmann::json::parse(cadclash::testing::slurp(json));
  const auto& files_json = j["import_timings"]["files"];
  ASSERT_EQ(files_json.size(), 3u);
  double sum = 0.0;
  for (const auto& f : files_json) sum += f["total"].get<double>();
  EXPECT_GE(j["import_timings"]["seconds"].get<double>(), sum) << "the files' reads overlapped";
}

// `tessellate` and `info` take --threads too; meshing on one thread (OCCT's own pool instead of TBB)
// writes the same triangles, eager and lazy.
TEST(CliImport, ThreadsChangeNoTriangle) {
  const std::string as1 = kExternal + "as1-tu-203.stp", screw = kExternal + "screw.step";
  if (const std::string m = missing({as1, screw}); !m.empty()) GTEST_SKIP() << m << " missing: run scripts/setup.sh";
  const std::string files = "'" + as1 + "' '" + screw + "'";
  const std::string dir = cadclash::testing::scratch_dir();
  for (const std::string lazy : {"", " --lazy"}) {
    SCOPED_TRACE(lazy);
    const std::string all = dir + "/threads-all.obj", one = dir + "/threads-one.obj";
    ASSERT_EQ(cadclash("tessellate " + files + lazy + " --deflection 0.01 -o '" + all + "'").code, 0);
    const CliRun r = cadclash("tessellate " + files + lazy + " --deflection 0.01 --threads 1 -o '" + one + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(cadclash::testing::slurp(one), cadclash::testing::slurp(all));
  }
  const CliRun info_all = cadclash("info " + files + " --json");
  const CliRun info_one = cadclash("info " + files + " --json --threads 1");
  ASSERT_EQ(info_one.code, 0) << info_one.err;
  EXPECT_EQ(info_one.out, info_all.out);
}

// One large STEP file read on several processes (its text cut into pieces, docs/import.md): the
// board of the truth tests written with a product per instance (3 MB, 17 B-rep items) gives the
// same report and the same surfaces (#ids, names, boxes, triangles) on 1, 2 and 3 threads, and
// with 2 it was really read by 2 processes.
TEST(CliImport, ThreadsDoNotChangeABoardsReport) {
#ifndef WRITE_BOARD_STEP_EXE
  GTEST_SKIP() << "built without the test support programs";
#else
  const std::string as1 = kExternal + "as1-tu-203.stp";
  if (const std::string m = missing({as1}); !m.empty()) GTEST_SKIP() << m << " missing: run scripts/setup.sh";
  const std::string board = cadclash::testing::scratch_dir() + "/threads-board.step";
  const std::string write = std::string(WRITE_BOARD_STEP_EXE) + " '" + kExternal + "' '" + board + "' 1 0 unshared > /dev/null";
  ASSERT_EQ(std::system(write.c_str()), 0);
  ASSERT_GT(fs::file_size(board), 1u << 20) << "smaller than the size read in parallel";
  const std::string file = "'" + board + "'";
  const std::string reference = report_of(file, "--no-timings --threads 1");
  ASSERT_NE(reference.find("\"pairs\""), std::string::npos);
  EXPECT_EQ(report_of(file, "--no-timings --threads 2"), reference);
  EXPECT_EQ(report_of(file, "--no-timings --threads 3"), reference);
  const CliRun info_one = cadclash("info " + file + " --json --surfaces --threads 1");
  const CliRun info_two = cadclash("info " + file + " --json --surfaces --threads 2");
  ASSERT_EQ(info_one.code, 0) << info_one.err;
  EXPECT_EQ(info_two.out, info_one.out);
  const nlohmann::json timed = nlohmann::json::parse(report_of(file, "--threads 2"));
  EXPECT_EQ(timed["import_timings"]["files"][0]["processes"], 2);
  const nlohmann::json alone = nlohmann::json::parse(report_of(file, "--threads 1"));
  EXPECT_EQ(alone["import_timings"]["files"][0]["processes"], 1);
#endif
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

// Runs sharing one cache directory at once: each writes its entries through a temporary file and a
// rename, so none ever reads half an entry; all give the reference report, and the directory ends
// with one whole entry per file (and per B-rep part) and no temporary files.
TEST(CliImport, ConcurrentRunsShareACache) {
  const std::string as1 = kExternal + "as1-tu-203.stp", screw = kExternal + "screw.step";
  if (const std::string m = missing({as1, screw}); !m.empty()) GTEST_SKIP() << m << " missing: run scripts/setup.sh";
  const std::string dir = cadclash::testing::scratch_dir();
  const std::string cache = dir + "/shared-cache";
  fs::remove_all(cache);
  const std::string files = "'" + as1 + "' '" + screw + "'";
  const std::string reference = report_of(files, "--no-timings");
  constexpr int kRuns = 3;
  for (int round = 0; round < 2; ++round) {  // all cold at once, then all warm at once
    std::string command = "for k in";
    for (int k = 0; k < kRuns; ++k) {
      command += ' ';
      command += std::to_string(k);
    }
    command += std::string("; do timeout 120 '") + CADCLASH_EXE + "' check " + files + " --no-timings --cache '" + cache +
               "' --json '" + dir + "/shared'$k.json >/dev/null 2>'" + dir + "/shared'$k.err & done; wait";
    ASSERT_EQ(std::system(command.c_str()), 0);
    for (int k = 0; k < kRuns; ++k) {
      SCOPED_TRACE("round " + std::to_string(round) + ", run " + std::to_string(k));
      EXPECT_EQ(cadclash::testing::slurp(dir + "/shared" + std::to_string(k) + ".json"), reference);
      const std::string err = cadclash::testing::slurp(dir + "/shared" + std::to_string(k) + ".err");
      EXPECT_EQ(err.find("damaged"), std::string::npos) << err;
      EXPECT_EQ(err.find("could not store"), std::string::npos) << err;
    }
  }
  int entries = 0;
  for (const auto& e : fs::directory_iterator(cache)) {
    EXPECT_EQ(e.path().extension(), ".entry") << e.path();
    ++entries;
  }
  EXPECT_GT(entries, 2);  // the two files' entries and their B-rep parts' (docs/import.md), no temporary left
}

}  // namespace
