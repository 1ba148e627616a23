// Files read in parallel (ImportOptions::parallel_files): the same scene, diagnostics and order as
// one after another, whatever the files do (crash the reader, fail to parse, hold meshes).
#include "cadclash/import.h"
#include "../test_temp.h"
#include "import_cache.h"
#include "import_compare.h"
#include "isolated_run.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace cadclash {
namespace {

namespace fs = std::filesystem;
using testing_import::everything;
using testing_import::same_bytes;

const std::string kData = std::string(CADCLASH_DATA_DIR) + "/";

std::vector<std::string> messages(const ImportResult& r) {
  std::vector<std::string> out;
  for (const Diagnostic& d : r.diagnostics) out.push_back(format_diagnostic(d));
  return out;
}

TEST(ImportParallel, SameSceneForAnyNumberOfFilesAtOnce) {
  const std::vector<std::string> files{
      kData + "external/as1-tu-203.stp", kData + "cad/truncated.step",  kData + "external/screw.step",
      kData + "collide/box_a.obj",       kData + "cad/not_step.step",   kData + "cad/heal_unshared_vertices.brep",
      kData + "external/linkrods.step",  kData + "no-such-file.step",
  };
  for (const std::string& f : files)
    if (f.find("external/") != std::string::npos && !fs::exists(f)) GTEST_SKIP() << f << " missing: run scripts/setup.sh";
  ImportOptions options;
  options.parallel_files = 1;
  const ImportResult serial = import_files(files, options);
  ASSERT_EQ(serial.files.size(), files.size());
  for (std::size_t i = 0; i < files.size(); ++i) EXPECT_EQ(serial.files[i].path, files[i]);
  EXPECT_FALSE(serial.complete);
  for (const int at_once : {2, 3, 8}) {
    SCOPED_TRACE(at_once);
    options.parallel_files = at_once;
    const ImportResult parallel = import_files(files, options);
    EXPECT_EQ(messages(parallel), messages(serial));
    EXPECT_EQ(parallel.complete, serial.complete);
    EXPECT_TRUE(same_bytes(everything(parallel), everything(serial)));
    ASSERT_EQ(parallel.files.size(), files.size());
    for (std::size_t i = 0; i < files.size(); ++i) EXPECT_EQ(parallel.files[i].path, files[i]);
  }
}

// One STEP file's shapes transferred by several processes (ImportOptions::transfer_workers): the same
// scene, diagnostics and face #ids as the reader alone, on every sample STEP file; the files with
// several separate shapes are really spread (a fallback to the reader alone would pass the rest).
TEST(ImportParallel, OneFileTransferredBySeveralProcessesGivesTheSameScene) {
  const std::vector<std::string> files{
      kData + "external/as1-tu-203.stp",  kData + "external/linkrods.step", kData + "external/screw.step",
      kData + "external/component8.step", kData + "external/frame.step",    kData + "external/step_boundary_colors.stp",
      kData + "external/t20_data.step",   kData + "cad/valid_two_solids.step", kData + "cad/truncated.step",
      kData + "cad/dangling_ref.step",    kData + "cad/mesh_fail_degenerate.step",
  };
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    if (f.find("external/") != std::string::npos && !fs::exists(f)) GTEST_SKIP() << f << " missing: run scripts/setup.sh";
    ImportOptions options;
    options.transfer_workers = 1;
    const ImportResult alone = import_file(f, options);
    ASSERT_EQ(alone.files.size(), 1u);
    EXPECT_EQ(alone.files[0].transfer_workers, 1u);
    for (const int workers : {2, 3}) {
      SCOPED_TRACE(workers);
      options.transfer_workers = workers;
      const ImportResult spread = import_file(f, options);
      EXPECT_EQ(messages(spread), messages(alone));
      EXPECT_EQ(spread.complete, alone.complete);
      EXPECT_TRUE(same_bytes(everything(spread), everything(alone)));
      ASSERT_EQ(spread.files.size(), 1u);
      // as1 has 7 distinct parts, valid_two_solids two unconnected solids: both must be spread.
      if (f.find("as1-tu-203") != std::string::npos) {
        EXPECT_EQ(spread.files[0].transfer_workers, static_cast<std::size_t>(workers));
      }
      if (f.find("valid_two_solids") != std::string::npos) {
        EXPECT_EQ(spread.files[0].transfer_workers, 2u);
      }
    }
  }
}

// import_files in two steps (import_each_file, merge_file_imports), and each file's result through its
// description (what another MPI rank receives): the same scene, B-rep parts with stand-in sources
// that know their deflection and mesh nothing.
TEST(ImportParallel, EachFileDescribedAndMergedGivesTheSameScene) {
  const std::vector<std::string> files{kData + "cad/truncated.step", kData + "collide/box_a.obj",
                                       kData + "cad/heal_unshared_vertices.brep", kData + "no-such-file.step"};
  ImportOptions options;
  options.lazy = true;
  const ImportResult whole = import_files(files, options);
  std::vector<ImportResult> each = import_each_file(files, options);
  std::vector<ImportResult> described(files.size());
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::string why;
    const std::string bytes = import_description(each[i]);
    ASSERT_TRUE(import_from_description(bytes, described[i], why)) << files[i] << ": " << why;
    EXPECT_EQ(described[i].files.size(), 1u);
    EXPECT_EQ(described[i].files[0].path, files[i]);
    ImportResult cut;
    EXPECT_FALSE(import_from_description(bytes.substr(0, bytes.size() - 1), cut, why));
  }
  const ImportResult merged = merge_file_imports(files, std::move(each));
  const ImportResult from_descriptions = merge_file_imports(files, std::move(described));
  EXPECT_TRUE(same_bytes(everything(merged), everything(whole)));
  EXPECT_EQ(messages(from_descriptions), messages(whole));
  ASSERT_EQ(from_descriptions.model.parts.size(), whole.model.parts.size());
  std::size_t stand_ins = 0;
  for (PartId p = 0; p < whole.model.parts.size(); ++p) {
    const auto& brep = whole.model.parts[p].source;
    const auto& stand_in = from_descriptions.model.parts[p].source;
    ASSERT_EQ(brep == nullptr, stand_in == nullptr) << p;
    if (!brep) continue;
    ++stand_ins;
    EXPECT_EQ(stand_in->default_deflection(), brep->default_deflection());
    TriangleMesh mesh;
    double achieved = 0.0;
    Diagnostic error;
    EXPECT_FALSE(stand_in->triangulate(0, 0.0, mesh, achieved, error));
  }
  EXPECT_GT(stand_ins, 0u);
  // Apart from the sources, the scene is the one import_files gives (surfaces, instances, poses).
  ImportResult plain = from_descriptions;
  for (Part& part : plain.model.parts) part.source.reset();
  ImportResult plain_whole = whole;
  for (Part& part : plain_whole.model.parts) part.source.reset();
  EXPECT_TRUE(same_bytes(*detail::save_import(plain), *detail::save_import(plain_whole)));
}

// Without the isolated reader, OCCT's translators run in this process: they take turns.
TEST(ImportParallel, UnisolatedReadersTakeTurns) {
  const std::vector<std::string> files{kData + "cad/valid_two_solids.step", kData + "cad/dangling_ref.step",
                                       kData + "cad/valid_two_solids.step", kData + "cad/wrong_schema.step"};
  ImportOptions options;
  options.isolate_cad_readers = false;
  options.parallel_files = 1;
  const ImportResult serial = import_files(files, options);
  options.parallel_files = 4;
  const ImportResult parallel = import_files(files, options);
  EXPECT_EQ(messages(parallel), messages(serial));
  EXPECT_TRUE(same_bytes(everything(parallel), everything(serial)));
}

// Children of several threads run at once: each child announces itself with a file and waits for the
// others' files, which children run one after another would never see.
TEST(IsolatedRun, ChildrenOfSeveralThreadsRunAtOnce) {
  constexpr int kThreads = 3;
  const fs::path dir = fs::path(testing::scratch_dir()) / "rendezvous";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::vector<detail::ChildRun> runs(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&runs, &dir, t] {
      const detail::CadWork work;  // as import_file holds it: let go of while the child runs
      runs[static_cast<std::size_t>(t)] = detail::run_in_child([&dir, t](const detail::Mark& mark) {
        mark(static_cast<char>('a' + t));
        std::ofstream(dir / std::to_string(t)) << t;
        for (int wait = 0; wait < 1000; ++wait) {  // 10 s at most
          int here = 0;
          for (int other = 0; other < kThreads; ++other) here += fs::exists(dir / std::to_string(other)) ? 1 : 0;
          if (here == kThreads) return "met the others";
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        return "alone";
      });
    });
  for (std::thread& t : threads) t.join();
  for (int t = 0; t < kThreads; ++t) {
    const detail::ChildRun& run = runs[static_cast<std::size_t>(t)];
    EXPECT_TRUE(run.isolated);
    EXPECT_FALSE(run.crashed) << run.how;
    EXPECT_EQ(run.marks, std::string(1, static_cast<char>('a' + t)));
    EXPECT_EQ(run.payload, "met the others");
  }
}

}  // namespace
}  // namespace cadclash
