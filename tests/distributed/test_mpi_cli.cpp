// `cadclash check` under mpirun on localhost (1, 2 and 4 ranks, oversubscribed): the JSON report
// (--no-timings), the table on stdout and the HTML report are byte-identical to one process's; the
// per-rank lines are printed; a rank that crashes is named with its unfinished instance pairs.
// With --eager the ranks mesh whole parts where their shares need them (part meshing): still one
// eagerly importing process's reports, with fewer triangles meshed per rank than the model holds.
// Several files are each read on one rank, and on another only when its share reaches them (with
// the default --lazy too); rank 0 reads for --volume only the files of the clashes it measures.
#include "../test_temp.h"
#include "cadclash/export.h"
#include "cadclash/import.h"
#include "cadclash/testing/scenes.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace cadclash {
namespace {

using testing::scratch_dir;

std::string as1_path() { return std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp"; }
#define REQUIRE_AS1() \
  if (!std::filesystem::exists(as1_path())) GTEST_SKIP() << "needs data/external/as1-tu-203.stp (scripts/setup.sh)"

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
std::string scratch(const std::string& name) { return scratch_dir() + "/" + name; }

struct Outcome {
  int code = -1;
  std::string out, err;
};

// `cadclash ARGS` in one process (ranks == 0) or under `mpirun -np RANKS`; stdout and stderr kept apart.
Outcome run(int ranks, const std::string& args, const std::string& env = "") {
  static const bool root = [] {
    if (::geteuid() == 0) {  // CI containers run as root: Open MPI refuses unless told
      ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
      ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    }
    // Containers often forbid the cross-memory attach the shared-memory transport tries first.
    ::setenv("OMPI_MCA_btl_vader_single_copy_mechanism", "none", 1);
    return true;
  }();
  (void)root;
  const std::string out = scratch("run_out.txt"), err = scratch("run_err.txt");
  std::string launcher;
  if (ranks > 0) launcher = std::string("'") + CADCLASH_MPIEXEC + "' --oversubscribe -np " + std::to_string(ranks) + " ";
  const std::string command = env + " timeout 300 " + launcher + "'" + CADCLASH_EXE + "' " + args + " >'" + out +
                              "' 2>'" + err + "' </dev/null";
  const int status = std::system(command.c_str());
  Outcome r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// Runs the check in one process and on 1, 2 and 4 ranks (`rank_args` added there: other thread
// counts); every output file and stdout must match. Every rank line must hold `rank_says` when given.
// `rank_errs`, when given, receives the stderr of the 1, 2 and 4 rank runs.
void expect_identical(const std::string& args, bool html, const std::string& rank_args = "",
                      const std::string& rank_says = "", std::vector<std::string>* rank_errs = nullptr) {
  auto files = [&](const std::string& tag) {
    return " --no-timings --json '" + scratch(tag + ".json") + "'" + (html ? " --html '" + scratch(tag + ".html") + "'" : "");
  };
  const Outcome one = run(0, args + files("one"));
  ASSERT_EQ(one.code, 0) << one.err;
  const std::string json = slurp(scratch("one.json"));
  ASSERT_FALSE(json.empty());
  for (int ranks : {1, 2, 4}) {
    const std::string tag = "np" + std::to_string(ranks);
    const Outcome r = run(ranks, args + rank_args + files(tag));
    ASSERT_EQ(r.code, 0) << ranks << " ranks:\n" << r.err;
    if (rank_errs != nullptr) rank_errs->push_back(r.err);
    EXPECT_TRUE(slurp(scratch(tag + ".json")) == json) << ranks << " ranks: the JSON reports differ";
    EXPECT_TRUE(r.out == one.out) << ranks << " ranks: the tables differ\n" << r.out << "\nvs\n" << one.out;
    if (html) {
      EXPECT_TRUE(slurp(scratch(tag + ".html")) == slurp(scratch("one.html"))) << ranks << " ranks: HTML differs";
    }
    for (int k = 0; k < ranks; ++k) {  // one line per rank on stderr
      const std::size_t line = r.err.find("rank " + std::to_string(k) + " of " + std::to_string(ranks) + ": ");
      EXPECT_NE(line, std::string::npos) << r.err;
      if (line != std::string::npos && !rank_says.empty()) {
        EXPECT_NE(r.err.substr(line, r.err.find('\n', line) - line).find(rank_says), std::string::npos) << r.err;
      }
    }
    EXPECT_NE(r.err.find("load imbalance"), std::string::npos) << r.err;
  }
}

TEST(MpiCli, As1LazyCertifiedSameReportHtmlAndTable) {
  REQUIRE_AS1();
  expect_identical("check '" + as1_path() + "' --lazy --tolerance 0.01 --clearance 1", true);
}

// One process on every core, ranks of one thread each.
TEST(MpiCli, As1ExactSameReportOtherThreadCount) {
  REQUIRE_AS1();
  expect_identical("check '" + as1_path() + "' --lazy --exact", false, " --threads 1");
}

// The second query of a prepared scene (--repeat 2) counts nothing the first one tessellated or built,
// whichever rank did it.
TEST(MpiCli, As1RepeatedQuerySameReport) {
  REQUIRE_AS1();
  expect_identical("check '" + as1_path() + "' --lazy --repeat 2", false);
}

// --eager: each rank meshes whole parts where its share needs them (part meshing), and the
// reports, table and HTML are one eagerly importing process's.
TEST(MpiCli, As1PartMeshingSameReportHtmlAndTable) {
  REQUIRE_AS1();
  expect_identical("check '" + as1_path() + "' --eager --tolerance 0.01 --clearance 1", true);
}

// Eight ranks (the largest count; more ranks than as1 has parts to mesh, oversubscribed on
// any small machine): the default check, eager and lazy, one thread each, is one process's.
TEST(MpiCli, As1EightRanksSameReportAndTable) {
  REQUIRE_AS1();
  for (const std::string mode : {" --eager", ""}) {
    const std::string args = "check '" + as1_path() + "'" + mode + " --no-timings --json '";
    const Outcome one = run(0, args + scratch("one8.json") + "'");
    ASSERT_EQ(one.code, 0) << one.err;
    const Outcome eight = run(8, args + scratch("np8.json") + "' --threads 1");
    ASSERT_EQ(eight.code, 0) << eight.err;
    EXPECT_TRUE(slurp(scratch("np8.json")) == slurp(scratch("one8.json"))) << "mode '" << mode << "': the JSON differs";
    EXPECT_TRUE(eight.out == one.out) << "mode '" << mode << "': the tables differ";
    for (int k = 0; k < 8; ++k) EXPECT_NE(eight.err.find("rank " + std::to_string(k) + " of 8: "), std::string::npos) << eight.err;
  }
}

// The rod of as1 and its first nut moved over eight steps, each turning a little more about x (CSV
// written from the imported poses), at a coarse deflection. `by_step`: the first three steps, the
// rows in step order (a continuous check's: every check of its motion is distributed), else
// instance by instance.
std::string as1_trajectory_csv(bool by_step = false) {
  const ImportResult as1 = import_file(as1_path());
  std::ostringstream csv;
  csv << "step,instance_path,tx,ty,tz,qw,qx,qy,qz\n";
  for (int outer = 0; outer < (by_step ? 3 : 1); ++outer)
  for (const Instance& i : as1.model.instances) {
    if (i.path != "/as1/ROD-ASSEMBLY/ROD" && i.path != "/as1/ROD-ASSEMBLY/NUT::1") continue;
    for (int step = by_step ? outer : 0; step < (by_step ? outer + 1 : 8); ++step) {
      Pose p = i.pose;
      p.pretranslate(Vec3(0.0, 0.0, (i.path.back() == 'D' ? 3.0 : -2.0) * step));
      p.rotate(Eigen::AngleAxisd(0.04 * step, Vec3::UnitX()));
      const Eigen::Quaterniond q(p.linear());
      csv.precision(17);
      csv << step << ',' << i.path << ',' << p.translation().x() << ',' << p.translation().y() << ','
          << p.translation().z() << ',' << q.w() << ',' << q.x() << ',' << q.y() << ',' << q.z() << '\n';
    }
  }
  return testing::write_scratch_file(by_step ? "as1_path_by_step.csv" : "as1_path.csv", csv.str());
}

// Lazily tessellated: steps reuse faces other ranks tessellated.
TEST(MpiCli, As1TrajectorySameReport) {
  REQUIRE_AS1();
  expect_identical("check '" + as1_path() + "' --lazy --deflection 2 --path '" + as1_trajectory_csv() + "'", false);
}

// --continuous: every static check of the path split over the ranks, its pairs on every rank (so
// every rank halves the same stretches); the timeline the same bytes as in one process.
TEST(MpiCli, ContinuousPathSameReport) {
  const std::string boxes = std::string(CADCLASH_DATA_DIR) + "/collide/";
  expect_identical("check '" + boxes + "box_a.obj' '" + boxes + "box_near.obj' --path '" + boxes +
                       "path_ok.csv' --continuous --tolerance 0.01",
                   true);
  EXPECT_NE(slurp(scratch("np4.json")).find("\"timeline\""), std::string::npos);
}

// --continuous on real parts that turn between steps (each stretch a screw about a far axis), the
// HTML page with its time slider too: the same bytes for 1, 2 and 4 ranks as in one process.
TEST(MpiCli, As1ContinuousTurningPathSameReportAndPage) {
  REQUIRE_AS1();
  expect_identical("check '" + as1_path() + "' --lazy --deflection 2 --path '" + as1_trajectory_csv(true) +
                       "' --continuous --time-resolution 0.01",
                   true);
  const std::string json = slurp(scratch("np4.json"));
  EXPECT_NE(json.find("\"timeline\""), std::string::npos);
  EXPECT_NE(json.find("\"steps_not_checked\": 0"), std::string::npos);  // every step checked (ascending)
}

// Part meshing: steps reach parts the rank has not meshed yet; the plan uses the deflections other
// ranks' parts achieved (below the asked 2 mm).
TEST(MpiCli, As1PartMeshingTrajectorySameReport) {
  REQUIRE_AS1();
  expect_identical("check '" + as1_path() + "' --deflection 2 --path '" + as1_trajectory_csv() + "'", false);
}

// `write_board_step OUT COPIES SHIFT [unshared]`: the truth tests' board (17 instances) COPIES times
// side by side as a STEP assembly, moved SHIFT mm along x; unshared: a product per instance.
std::string board_step(int copies, bool unshared, int shift = 0) {
  const std::string out = scratch("board" + std::to_string(copies) + (unshared ? "u" : "s") + "_" +
                                  std::to_string(shift) + ".step");
  const std::string command = std::string("'") + CADCLASH_WRITE_BOARD_STEP + "' '" + CADCLASH_DATA_DIR +
                              "/external' '" + out + "' " + std::to_string(copies) + " " + std::to_string(shift) +
                              (unshared ? " unshared" : "") + " >/dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  return out;
}

// 59 boards in one STEP assembly (1003 instances of 7 B-rep parts), part meshing.
TEST(MpiCli, ThousandInstanceStepSameReport) {
  REQUIRE_AS1();
  expect_identical("check '" + board_step(59, false) + "' --tolerance 0.01", false);
}

// "rank r of N: ... model triangles held H, meshed here M of the model's T": (H, M, T) per rank.
std::vector<std::array<std::uint64_t, 3>> meshed_per_rank(const std::string& err, int ranks) {
  std::vector<std::array<std::uint64_t, 3>> out;
  for (int r = 0; r < ranks; ++r) {
    const std::size_t at = err.find("rank " + std::to_string(r) + " of " + std::to_string(ranks) + ": ");
    const std::size_t held = err.find("model triangles held ", at);
    EXPECT_NE(at, std::string::npos) << err;
    EXPECT_NE(held, std::string::npos) << err;
    if (at == std::string::npos || held == std::string::npos) return {};
    std::array<std::uint64_t, 3> v{};
    std::istringstream line(err.substr(held, err.find('\n', held) - held));
    std::string w;
    line >> w >> w >> w >> v[0] >> w >> w >> w >> v[1] >> w >> w >> w >> v[2];
    EXPECT_EQ(w, "model's") << err;
    out.push_back(v);
  }
  return out;
}

// Four boards, a product per instance (68 parts): the pairs split by where the boards are, so a rank
// meshes only the parts of its boards. Every part is meshed somewhere (the ranks' counts cover the
// model), each rank meshes fewer triangles than the model, and one rank meshes all of it.
TEST(MpiCli, RanksMeshOnlyThePartsTheirShareReaches) {
  REQUIRE_AS1();
  const std::string step = board_step(4, true);
  const std::string args = "check '" + step + "' --eager --tolerance 0.01 --no-timings --threads 1 --json ";
  const Outcome single = run(0, args + "'" + scratch("parts_one.json") + "'");
  ASSERT_EQ(single.code, 0) << single.err;
  const std::string json = slurp(scratch("parts_one.json"));
  const Outcome one = run(1, args + "'" + scratch("parts_np1.json") + "'");
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_TRUE(slurp(scratch("parts_np1.json")) == json);
  const auto whole = meshed_per_rank(one.err, 1);
  ASSERT_EQ(whole.size(), 1u);
  const std::uint64_t model = whole[0][2];
  EXPECT_GT(model, 0u);
  EXPECT_EQ(whole[0][1], model);  // a single rank meshes everything ...
  EXPECT_EQ(whole[0][0], model);  // ... and keeps it
  for (int ranks : {2, 4}) {
    const std::string out = scratch("parts_np" + std::to_string(ranks) + ".json");
    const Outcome r = run(ranks, args + "'" + out + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(slurp(out) == json) << ranks << " ranks: the JSON reports differ";
    EXPECT_TRUE(r.out == single.out) << ranks << " ranks: the tables differ";
    std::uint64_t sum = 0;
    for (const auto& [held, meshed, total] : meshed_per_rank(r.err, ranks)) {
      EXPECT_EQ(total, model) << r.err;
      EXPECT_LT(meshed, model) << ranks << " ranks:\n" << r.err;
      EXPECT_LE(held, meshed) << r.err;
      EXPECT_LE(meshed, model / static_cast<std::uint64_t>(ranks) * 2) << ranks << " ranks:\n" << r.err;
      sum += meshed;
    }
    EXPECT_GE(sum, model) << r.err;
  }
}

// Rank r's line on stderr ("rank r of N: ..."); empty when missing.
std::string rank_line(const std::string& err, int r, int ranks) {
  const std::size_t at = err.find("rank " + std::to_string(r) + " of " + std::to_string(ranks) + ": ");
  return at == std::string::npos ? std::string() : err.substr(at, err.find('\n', at) - at);
}

// What CADCLASH_TEST_SHOW_READS=1 makes rank r say when it reads `file` (`why`: "its reader" or "its
// share reaches it").
std::string read_line(int r, int ranks, const std::string& file, const std::string& why) {
  return "cadclash check: rank " + std::to_string(r) + " of " + std::to_string(ranks) + " reads '" + file + "' (" +
         why + ")\n";
}

// `text` without the lines CADCLASH_TEST_SHOW_READS adds.
std::string without_read_lines(const std::string& text) {
  std::istringstream in(text);
  std::string out, line;
  while (std::getline(in, line))
    if (!(line.rfind("cadclash check: rank ", 0) == 0 && line.find(" reads '") != std::string::npos)) out += line + '\n';
  return out;
}

// Two files, two boards and one board 1000 mm away, the pairs selected within the boards (each file
// also holds an unused part at its origin, which write_board_step leaves as a free shape: it would
// pair across the files); `extra` added to the check's arguments.
struct BoardFiles {
  std::string first, second;
  std::string args;  // the check of both files, up to its --json
};
BoardFiles board_files(const std::string& extra) {
  BoardFiles f{board_step(2, false), board_step(1, false, 1000), ""};
  const std::string boards = "/" + std::filesystem::path(f.first).filename().string() + "/board /" +
                             std::filesystem::path(f.second).filename().string() + "/board";
  f.args = "check '" + f.first + "' '" + f.second + "' --select-a " + boards + " --select-b " + boards +
           " --tolerance 0.01 --no-timings --threads 1" + extra + " --json ";
  return f;
}

// `f` checked in one process and on two ranks (CADCLASH_TEST_SHOW_READS=1; their stderr into `err`):
// the same JSON and table. The larger first file is read by rank 0, the second by rank 1. Rank 0's
// run lies within the first file (it holds about 2/3 of the pairs), so rank 0 never reads the
// second file; rank 1 reads the first for its pairs.
void expect_read_where_needed(const BoardFiles& f, const std::string& tag, std::string& err) {
  const Outcome single = run(0, f.args + "'" + scratch(tag + "_one.json") + "'");
  ASSERT_EQ(single.code, 0) << single.err;
  const Outcome two = run(2, f.args + "'" + scratch(tag + "_np2.json") + "'", "CADCLASH_TEST_SHOW_READS=1");
  err = two.err;
  ASSERT_EQ(two.code, 0) << two.err;
  EXPECT_TRUE(slurp(scratch(tag + "_np2.json")) == slurp(scratch(tag + "_one.json")));
  EXPECT_TRUE(two.out == single.out);
  EXPECT_NE(rank_line(two.err, 0, 2).find("; files read here 1 of 2"), std::string::npos) << two.err;
  EXPECT_NE(rank_line(two.err, 1, 2).find("; files read here 2 of 2"), std::string::npos) << two.err;
  EXPECT_NE(two.err.find(read_line(0, 2, f.first, "its reader")), std::string::npos) << two.err;
  EXPECT_NE(two.err.find(read_line(1, 2, f.second, "its reader")), std::string::npos) << two.err;
  EXPECT_NE(two.err.find(read_line(1, 2, f.first, "its share reaches it")), std::string::npos) << two.err;
  EXPECT_EQ(two.err.find("rank 0 of 2 reads '" + f.second + "'"), std::string::npos) << two.err;
}

// Part meshing: rank 0 neither reads the second file nor keeps anything of it: it holds no more
// triangles than the first file has. Rank 1 holds the second file's board and what its pairs reach
// of the first.
TEST(MpiCli, RankReadsAndMeshesNothingOfAFileItsPairsDoNotReach) {
  REQUIRE_AS1();
  const BoardFiles f = board_files(" --eager");
  const Outcome alone = run(1, "check '" + f.first + "' --eager --tolerance 0.01 --no-timings --threads 1");
  ASSERT_EQ(alone.code, 0) << alone.err;
  const auto first_only = meshed_per_rank(alone.err, 1);
  ASSERT_EQ(first_only.size(), 1u);
  const std::uint64_t in_first = first_only[0][2];
  std::string err;
  expect_read_where_needed(f, "files", err);
  const auto ranks = meshed_per_rank(err, 2);
  ASSERT_EQ(ranks.size(), 2u);
  const std::uint64_t model = ranks[0][2];
  ASSERT_GT(model, in_first);
  EXPECT_LE(ranks[0][0], in_first) << "rank 0 holds parts of the second file:\n" << err;
  EXPECT_GT(ranks[1][0], 0u) << err;
  EXPECT_LT(ranks[1][0], model) << err;
}

// --lazy: the ranks tessellate faces, not parts, inside the check; a rank reads a file before its
// run starts when the run reaches a part of it, and else never.
TEST(MpiCli, LazyRankReadsNothingOfAFileItsPairsDoNotReach) {
  REQUIRE_AS1();
  std::string err;
  expect_read_where_needed(board_files(" --lazy"), "lazy_files", err);
  EXPECT_EQ(err.find("meshed here"), std::string::npos) << err;
}

// The same two files, every pair: on 1, 2 and 4 ranks the JSON, the table and the HTML (rank 0
// reads and meshes what it did not need before writing it) are one process's; every rank line says
// how many files the rank read.
TEST(MpiCli, FilesReadWhereNeededSameReportHtmlAndTable) {
  REQUIRE_AS1();
  const std::string first = board_step(2, false), second = board_step(1, false, 1000);
  expect_identical("check '" + first + "' '" + second + "' --tolerance 0.01", true, " --threads 1",
                   "; files read here ");
}

// --lazy: the same; on four ranks the last rank's run lies within the second file, which it
// reads as its reader, and it never reads the first.
TEST(MpiCli, FilesReadWhereNeededLazySameReportHtmlAndTable) {
  REQUIRE_AS1();
  const std::string first = board_step(2, false), second = board_step(1, false, 1000);
  std::vector<std::string> errs;
  expect_identical("check '" + first + "' '" + second + "' --lazy --tolerance 0.01", true, " --threads 1",
                   "; files read here ", &errs);
  ASSERT_EQ(errs.size(), 3u);
  EXPECT_NE(rank_line(errs[2], 3, 4).find("; files read here 1 of 2"), std::string::npos) << errs[2];
}

// as1 with its plate pushed 0.05 mm up into the two L-brackets (two penetrating clashes, whose
// volume --volume measures) beside a board file, the pairs selected within as1. On two ranks the
// board file is read by rank 1 only: rank 0 reads as1, its file, and measures the clashes from it,
// without reading the board's file. Reports as one process's, with and without --lazy.
TEST(MpiCli, VolumeReadsOnlyTheFilesOfMeasuredClashes) {
  REQUIRE_AS1();
  const std::string pushed = scratch("as1_plate_up.stp");
  const std::string rewrite = std::string("'") + STEP_REWRITE_EXE + "' '" + as1_path() + "' '" + pushed +
                              "' PLATE 0 0 0.05 >/dev/null 2>&1";
  ASSERT_EQ(std::system(rewrite.c_str()), 0) << rewrite;
  const std::string board = board_step(1, false, 1000);
  for (const char* lazy : {"", " --lazy"}) {
    SCOPED_TRACE(lazy);
    const std::string args = "check '" + pushed + "' '" + board +
                             "' --select-a /as1_plate_up.stp --select-b /as1_plate_up.stp --volume --no-timings "
                             "--threads 1" + std::string(lazy) + " --json ";
    const Outcome one = run(0, args + "'" + scratch("volume_one.json") + "'");
    ASSERT_EQ(one.code, 0) << one.err;
    const std::string json = slurp(scratch("volume_one.json"));
    std::size_t measured = 0;
    for (std::size_t at = json.find("\"measured\": true"); at != std::string::npos;
         at = json.find("\"measured\": true", at + 1))
      ++measured;
    ASSERT_EQ(measured, 2u) << json;
    const Outcome two = run(2, args + "'" + scratch("volume_np2.json") + "'", "CADCLASH_TEST_SHOW_READS=1");
    ASSERT_EQ(two.code, 0) << two.err;
    EXPECT_TRUE(slurp(scratch("volume_np2.json")) == json);
    EXPECT_TRUE(two.out == one.out);
    EXPECT_NE(two.err.find(read_line(0, 2, pushed, "its reader")), std::string::npos) << two.err;
    EXPECT_NE(two.err.find(read_line(1, 2, board, "its reader")), std::string::npos) << two.err;
    EXPECT_EQ(two.err.find("rank 0 of 2 reads '" + board + "'"), std::string::npos) << two.err;
    EXPECT_NE(rank_line(two.err, 0, 2).find("; files read here 1 of 2"), std::string::npos) << two.err;
  }
}

// A truncated STEP file beside the boards, read on rank 1 only (the smaller file; the pairs are
// selected within the first file's boards, so no rank's share reaches it and its unused parts are
// meshed on its reader): its diagnostics (file and line, STEP #ids, the face kept unhealed) come out
// once, exactly as one process prints and writes them, exit code 1.
TEST(MpiCli, BadFileReadOnOneRankReportedAsInOneProcess) {
  REQUIRE_AS1();
  const std::string first = board_step(2, false);
  const std::string bad = scratch("truncated_copy.step");
  std::filesystem::copy_file(std::string(CADCLASH_DATA_DIR) + "/cad/truncated.step", bad,
                             std::filesystem::copy_options::overwrite_existing);
  const std::string boards = "/" + std::filesystem::path(first).filename().string() + "/board";
  const std::string args = "check '" + first + "' '" + bad + "' --select-a " + boards + " --select-b " + boards +
                           " --tolerance 0.01 --no-timings --threads 1 --json ";
  const Outcome one = run(0, args + "'" + scratch("trunc_one.json") + "'");
  ASSERT_EQ(one.code, 1) << one.err;
  const std::string json = slurp(scratch("trunc_one.json"));
  ASSERT_NE(one.err.find(bad + ":383: error: STEP file is truncated"), std::string::npos) << one.err;
  ASSERT_NE(json.find("#325"), std::string::npos) << json;
  const Outcome two = run(2, args + "'" + scratch("trunc_np2.json") + "'", "CADCLASH_TEST_SHOW_READS=1");
  EXPECT_EQ(two.code, 1) << two.err;
  EXPECT_TRUE(slurp(scratch("trunc_np2.json")) == json) << slurp(scratch("trunc_np2.json"));
  EXPECT_TRUE(two.out == one.out);
  const std::string err = without_read_lines(two.err);
  EXPECT_EQ(err.substr(0, one.err.size()), one.err);  // the import's messages once, in one process's order
  EXPECT_NE(two.err.find(read_line(1, 2, bad, "its reader")), std::string::npos) << two.err;
  EXPECT_EQ(two.err.find("rank 0 of 2 reads '" + bad + "'"), std::string::npos) << two.err;
  EXPECT_NE(rank_line(two.err, 0, 2).find("; files read here 1 of 2"), std::string::npos) << two.err;
}

// With --lazy the ranks tessellate face by face: no part meshing.
TEST(MpiCli, LazyRanksSayNothingOfPartMeshing) {
  REQUIRE_AS1();
  const Outcome r = run(2, "check '" + as1_path() + "' --lazy --no-timings");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("model triangles held "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("meshed here"), std::string::npos) << r.err;
}

// 56 copies of as1 in one .glb (1008 instances, meshes only).
TEST(MpiCli, ThousandInstancesSameReport) {
  REQUIRE_AS1();
  const ImportResult as1 = import_file(as1_path());
  const Model many = truth::grid_copies(as1.model, 56, 0.5);
  ASSERT_GE(many.instances.size(), 1000u);
  const std::string glb = scratch("as1x56.glb");
  ASSERT_FALSE(has_error(export_model(many, glb)));
  expect_identical("check '" + glb + "' --tolerance 0.01", false);
}

// Rank 1 crashes (SIGSEGV, CADCLASH_TEST_CRASH_RANK) as it starts its part: a non-zero exit, an error
// naming rank 1 and its unfinished instance pairs, and no report file.
TEST(MpiCli, CrashedRankIsNamedWithItsPairs) {
  REQUIRE_AS1();
  const std::string json = scratch("crash.json");
  std::filesystem::remove(json);
  const Outcome r = run(2, "check '" + as1_path() + "' --lazy --json '" + json + "'", "CADCLASH_TEST_CRASH_RANK=1");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("cadclash check: rank 1 of 2 crashed (signal SIGSEGV"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("before finishing its "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" x /as1/"), std::string::npos) << r.err;  // its pairs, by instance path
  EXPECT_FALSE(std::filesystem::exists(json)) << "a report was written although rank 1 died";
}

// Faces that cannot be meshed, met by pairs on several ranks: their errors (naming the file and the
// STEP #id or face) are listed once, in the order one process lists them; exit code 1 as there.
TEST(MpiCli, UnmeshableFacesReportedAsInOneProcess) {
  std::string files;
  for (const char* name : {"mesh_fail_degenerate.step", "mesh_fail_bowtie.brep"})
    for (const char* copy : {"a_", "b_", "c_"}) {
      const std::string to = scratch(std::string(copy) + name);
      std::filesystem::copy_file(std::string(CADCLASH_DATA_DIR) + "/cad/" + name, to,
                                 std::filesystem::copy_options::overwrite_existing);
      files += " '" + to + "'";
    }
  // Lazily: the faces fail during the check. Without --lazy, in the import: part meshing cannot
  // rebuild the eager import's diagnostics, so every rank imports eagerly after all (same stderr).
  for (const char* lazy : {" --lazy", ""}) {
    SCOPED_TRACE(lazy);
    const std::string args = "check" + files + lazy + " --no-timings --json ";
    const Outcome one = run(0, args + "'" + scratch("bad_one.json") + "'");
    ASSERT_EQ(one.code, 1) << one.err;
    const std::string json = slurp(scratch("bad_one.json"));
    ASSERT_NE(json.find("#132"), std::string::npos) << json;  // the degenerate STEP face, by its id
    for (int ranks : {2, 3}) {
      const Outcome r = run(ranks, args + "'" + scratch("bad_np.json") + "'");
      EXPECT_EQ(r.code, 1) << r.err;
      EXPECT_TRUE(slurp(scratch("bad_np.json")) == json) << ranks << " ranks:\n" << slurp(scratch("bad_np.json"));
      EXPECT_TRUE(r.out == one.out) << ranks << " ranks";
      EXPECT_EQ(r.err.substr(0, one.err.size()), one.err) << ranks << " ranks";  // the import's messages once
      EXPECT_EQ(r.err.find("meshed here"), std::string::npos) << r.err;
    }
  }
}

// A time budget that has run out before any rank starts: every instance pair is listed unexamined,
// the same partial report as one process's, exit code 4.
TEST(MpiCli, ExpiredTimeBudgetListsEveryPairUnexamined) {
  REQUIRE_AS1();
  const std::string args = "check '" + as1_path() + "' --lazy --time-budget 1e-9 --no-timings --json ";
  const Outcome one = run(0, args + "'" + scratch("budget_one.json") + "'");
  ASSERT_EQ(one.code, 4) << one.err;
  const Outcome two = run(2, args + "'" + scratch("budget_np2.json") + "'");
  EXPECT_EQ(two.code, 4) << two.err;
  const std::string json = slurp(scratch("budget_np2.json"));
  EXPECT_TRUE(json == slurp(scratch("budget_one.json"))) << json;
  EXPECT_NE(json.find("\"stopped_by\": \"time budget\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"/as1/PLATE\""), std::string::npos) << json;  // in unexamined_pairs
}

TEST(MpiCli, MemoryBudgetIsAUsageError) {
  REQUIRE_AS1();
  const Outcome r = run(2, "check '" + as1_path() + "' --memory-budget 10");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("cannot be split over MPI ranks"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace cadclash
