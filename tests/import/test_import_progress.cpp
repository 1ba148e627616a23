// ImportOptions::progress and a check of what was imported (import.h, collide.h "Progress of long
// work"): the calls each stage makes, rising to their totals, never overlapping, and the same model
// and report with and without a callback.
#include "cadclash/import.h"
#include "../progress_calls.h"
#include "import_compare.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

namespace cadclash {
namespace {

using testing_import::everything;
using testing_import::same_bytes;
using testing::ProgressCalls;
using testing::report_bytes;

const std::string kData = std::string(CADCLASH_DATA_DIR) + "/";
const std::string kAs1 = kData + "external/as1-tu-203.stp";

TEST(ImportProgress, OneFileItsReadAndItsPartsMeshed) {
  if (!std::filesystem::exists(kAs1)) GTEST_SKIP() << kAs1 << " missing: run scripts/setup.sh";
  const ImportResult plain = import_file(kAs1);
  ProgressCalls rec;
  ImportOptions options;
  options.progress = rec.callback();
  const ImportResult shown = import_file(kAs1, options);
  EXPECT_TRUE(same_bytes(everything(shown), everything(plain)));
  EXPECT_FALSE(rec.overlapped);

  ASSERT_GE(rec.seen.size(), 4u);
  const Progress& first = rec.seen.front();
  EXPECT_EQ(first.stage, ProgressStage::ReadFile);
  EXPECT_EQ(first.done, 0u);
  EXPECT_EQ(first.total, 1u);
  EXPECT_EQ(first.label, kAs1);
  const Progress& last = rec.seen.back();
  EXPECT_EQ(last.stage, ProgressStage::ReadFile);
  EXPECT_EQ(last.done, 1u);
  EXPECT_EQ(last.label, kAs1);
  EXPECT_EQ(rec.of(ProgressStage::ReadFile).size(), 2u);

  // One run over as1's parts: 0 first, rising, every part named, the last at the total.
  const std::vector<Progress> parts = rec.of(ProgressStage::TessellatePart);
  ASSERT_GE(parts.size(), 2u);
  EXPECT_EQ(parts.front().done, 0u);
  EXPECT_EQ(parts.back().done, plain.model.parts.size());
  for (std::size_t k = 0; k < parts.size(); ++k) {
    EXPECT_EQ(parts[k].total, plain.model.parts.size());
    if (k > 0) {
      EXPECT_GT(parts[k].done, parts[k - 1].done);
    }
    bool a_part = false;
    for (const Part& p : plain.model.parts) a_part = a_part || p.name == parts[k].label;
    EXPECT_TRUE(a_part) << parts[k].label;
  }
  EXPECT_TRUE(rec.of(ProgressStage::CheckPairs).empty());
  // One run over the parts as they are checked and healed, before they are meshed.
  const std::vector<Progress> checked = rec.of(ProgressStage::CheckPart);
  ASSERT_GE(checked.size(), 2u);
  EXPECT_EQ(checked.front().done, 0u);
  EXPECT_EQ(checked.back().done, plain.model.parts.size());
  EXPECT_EQ(checked.back().total, plain.model.parts.size());
}

TEST(ImportProgress, LazyImportMeshesNothingAndSaysNothingOfParts) {
  if (!std::filesystem::exists(kAs1)) GTEST_SKIP() << kAs1 << " missing: run scripts/setup.sh";
  ProgressCalls rec;
  ImportOptions options;
  options.lazy = true;
  options.progress = rec.callback();
  import_file(kAs1, options);
  EXPECT_TRUE(rec.of(ProgressStage::TessellatePart).empty());
  EXPECT_FALSE(rec.of(ProgressStage::CheckPart).empty());  // the faces are checked all the same
  EXPECT_EQ(rec.of(ProgressStage::ReadFile).size(), 2u);
}

TEST(ImportProgress, FilesReadInParallelCountUpOneCallAtATime) {
  const std::vector<std::string> files{kData + "cad/valid_two_solids.step", kData + "collide/box_a.obj",
                                       kData + "cad/heal_unshared_vertices.brep", kData + "no-such-file.step",
                                       kData + "collide/box_near.obj"};
  ImportOptions options;
  options.parallel_files = 3;
  const ImportResult plain = import_files(files, options);
  ProgressCalls rec;
  options.progress = rec.callback();
  const ImportResult shown = import_files(files, options);
  EXPECT_TRUE(same_bytes(everything(shown), everything(plain)));
  EXPECT_FALSE(rec.overlapped);

  const std::vector<Progress> reads = rec.of(ProgressStage::ReadFile);
  ASSERT_EQ(reads.size(), 2 * files.size());  // each file as it starts and as it ends
  for (std::size_t k = 0; k < reads.size(); ++k) {
    EXPECT_EQ(reads[k].total, files.size());
    if (k > 0) {
      EXPECT_GE(reads[k].done, reads[k - 1].done);
    }
  }
  EXPECT_EQ(reads.front().done, 0u);
  EXPECT_EQ(reads.back().done, files.size());
  EXPECT_EQ(rec.seen.back().stage, ProgressStage::ReadFile);  // the run's end is the last call
  // Two B-rep files meshed: a TessellatePart run each (0 first, the total last).
  std::size_t started = 0, ended = 0;
  for (const Progress& p : rec.of(ProgressStage::TessellatePart)) {
    started += p.done == 0;
    ended += p.done == p.total;
  }
  EXPECT_EQ(started, 2u);
  EXPECT_EQ(ended, 2u);
}

// A check of as1 and a trajectory over it: the same report bytes with and without a callback.
TEST(ImportProgress, CheckAndTrajectoryOfAs1KeepTheirReports) {
  if (!std::filesystem::exists(kAs1)) GTEST_SKIP() << kAs1 << " missing: run scripts/setup.sh";
  ImportResult in = import_file(kAs1);
  CollideOptions o;
  o.tolerance = 0.01;
  Scene plain_scene(in.model);
  const Report plain = plain_scene.check(o);

  ProgressCalls rec;
  o.progress = rec.callback();
  Scene scene(in.model);
  const Report shown = scene.check(o);
  EXPECT_EQ(report_bytes(in.model, shown), report_bytes(in.model, plain));
  EXPECT_EQ(shown.pairs.size(), 376u);
  EXPECT_FALSE(rec.other_thread);  // collide calls on the thread that asked, never its OpenMP threads
  const std::vector<Progress> calls = rec.of(ProgressStage::CheckPairs);
  ASSERT_EQ(calls.size(), rec.seen.size());
  std::vector<std::string> steps;
  for (const Progress& p : calls) {
    EXPECT_EQ(p.total, plain.counters.instance_pairs);
    if (p.done == 0) steps.push_back(p.label);
  }
  EXPECT_EQ(steps, (std::vector<std::string>{"surface level", "triangle level", "decisions"}));
  EXPECT_EQ(calls.back().done, calls.back().total);

  // Three steps moving the rod; each step's report is the same with and without the callback.
  const std::string rod = "/as1/ROD-ASSEMBLY/ROD";
  std::string csv;
  for (int k = 0; k < 3; ++k) csv += std::to_string(k) + "," + rod + ",0," + std::to_string(0.5 * k) + ",0,1,0,0,0\n";
  std::vector<Diagnostic> ds;
  const std::vector<TrajectoryRow> rows = parse_trajectory(csv, "rod.csv", ds);
  ASSERT_EQ(rows.size(), 3u);
  o.progress = nullptr;
  const std::vector<StepResult> plain_steps = replay_trajectory(plain_scene, rows, o, ds, "rod.csv");
  ProgressCalls steps_rec;
  o.progress = steps_rec.callback();
  const std::vector<StepResult> shown_steps = replay_trajectory(scene, rows, o, ds, "rod.csv");
  ASSERT_EQ(shown_steps.size(), 3u);
  ASSERT_EQ(plain_steps.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k)
    EXPECT_EQ(report_bytes(in.model, shown_steps[k].report), report_bytes(in.model, plain_steps[k].report));
  EXPECT_TRUE(ds.empty());
  ASSERT_EQ(steps_rec.seen.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(steps_rec.seen[k].stage, ProgressStage::TrajectoryStep);
    EXPECT_EQ(steps_rec.seen[k].done, k);
    EXPECT_EQ(steps_rec.seen[k].total, 3u);
  }
}

}  // namespace
}  // namespace cadclash
