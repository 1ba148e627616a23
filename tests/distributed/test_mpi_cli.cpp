// `cadclash check` under mpirun on localhost (1, 2 and 4 ranks, oversubscribed): the JSON report
// (--no-timings), the table on stdout and the HTML report are byte-identical to one process's; the
// per-rank lines are printed; a rank that crashes is named with its unfinished instance pairs.
#include "../test_temp.h"
#include "cadclash/export.h"
#include "cadclash/import.h"
#include "cadclash/testing/scenes.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

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
// counts); every output file and stdout must match.
void expect_identical(const std::string& args, bool html, const std::string& rank_args = "") {
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
    EXPECT_TRUE(slurp(scratch(tag + ".json")) == json) << ranks << " ranks: the JSON reports differ";
    EXPECT_TRUE(r.out == one.out) << ranks << " ranks: the tables differ\n" << r.out << "\nvs\n" << one.out;
    if (html) {
      EXPECT_TRUE(slurp(scratch(tag + ".html")) == slurp(scratch("one.html"))) << ranks << " ranks: HTML differs";
    }
    for (int k = 0; k < ranks; ++k) {  // one line per rank on stderr
      EXPECT_NE(r.err.find("rank " + std::to_string(k) + " of " + std::to_string(ranks) + ": "), std::string::npos)
          << r.err;
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

// The rod of as1 moved over eight steps (CSV written from the imported poses), lazily tessellated at
// a coarse deflection: steps reuse faces other ranks tessellated.
TEST(MpiCli, As1TrajectorySameReport) {
  REQUIRE_AS1();
  const ImportResult as1 = import_file(as1_path());
  std::ostringstream csv;
  csv << "step,instance_path,tx,ty,tz,qw,qx,qy,qz\n";
  for (const Instance& i : as1.model.instances) {
    if (i.path != "/as1/ROD-ASSEMBLY/ROD" && i.path != "/as1/ROD-ASSEMBLY/NUT::1") continue;
    for (int step = 0; step < 8; ++step) {
      Pose p = i.pose;
      p.pretranslate(Vec3(0.0, 0.0, (i.path.back() == 'D' ? 3.0 : -2.0) * step));
      p.rotate(Eigen::AngleAxisd(0.04 * step, Vec3::UnitX()));
      const Eigen::Quaterniond q(p.linear());
      csv.precision(17);
      csv << step << ',' << i.path << ',' << p.translation().x() << ',' << p.translation().y() << ','
          << p.translation().z() << ',' << q.w() << ',' << q.x() << ',' << q.y() << ',' << q.z() << '\n';
    }
  }
  const std::string path = testing::write_scratch_file("as1_path.csv", csv.str());
  expect_identical("check '" + as1_path() + "' --lazy --deflection 2 --path '" + path + "'", false);
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
  const std::string args = "check" + files + " --lazy --no-timings --json ";
  const Outcome one = run(0, args + "'" + scratch("bad_one.json") + "'");
  ASSERT_EQ(one.code, 1) << one.err;
  const std::string json = slurp(scratch("bad_one.json"));
  ASSERT_NE(json.find("#132"), std::string::npos) << json;  // the degenerate STEP face, by its id
  for (int ranks : {2, 3}) {
    const Outcome r = run(ranks, args + "'" + scratch("bad_np.json") + "'");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_TRUE(slurp(scratch("bad_np.json")) == json) << ranks << " ranks:\n" << slurp(scratch("bad_np.json"));
    EXPECT_TRUE(r.out == one.out) << ranks << " ranks";
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
