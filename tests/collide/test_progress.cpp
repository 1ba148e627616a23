// CollideOptions::progress: what a check and a trajectory replay tell the callback (collide.h,
// "Progress of long work"), on which thread, and that the reports do not change with it.
#include "cadclash/collide.h"
#include "../progress_calls.h"
#include "scene_fixtures.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace cadclash {
namespace {

using testing::add_instance;
using testing::add_part;
using testing::box_surfaces;
using testing::progress_runs;
using testing::ProgressCalls;
using testing::report_bytes;
using testing::translation;

// A row of 24 boxes, each touching the next (and the one after it through a long box's reach):
// enough instance pairs that a percentage is more than one pair.
Model row_of_boxes() {
  Model m;
  const PartId box = add_part(m, "box", box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 3));
  const PartId bar = add_part(m, "bar", box_surfaces(Vec3(0, 0, 0), Vec3(3, 0.5, 0.5), 2));
  for (int k = 0; k < 24; ++k) add_instance(m, "/row/box" + std::to_string(k), box, translation(k, 0, 0));
  for (int k = 0; k < 8; ++k) add_instance(m, "/row/bar" + std::to_string(k), bar, translation(3 * k, 0.25, 0.25));
  return m;
}

TEST(CollideProgress, CheckReportsItsStepsOverTheInstancePairsOnTheCallingThread) {
  for (const ParallelVersion version : {ParallelVersion::V1, ParallelVersion::V2}) {
    for (const int threads : {1, 2}) {
      SCOPED_TRACE(std::string(parallel_version_name(version)) + " threads " + std::to_string(threads));
      Model m = row_of_boxes();
      CollideOptions o;
      o.tolerance = 0.01;
      o.version = version;
      o.threads = threads;
      Scene plain_scene(m);
      const Report plain = plain_scene.check(o);
      ASSERT_GT(plain.counters.instance_pairs, 30u);

      ProgressCalls calls;
      o.progress = calls.callback();
      Scene scene(m);
      const Report shown = scene.check(o);
      EXPECT_EQ(report_bytes(m, shown), report_bytes(m, plain));
      EXPECT_FALSE(calls.other_thread);
      const auto r = progress_runs(calls.seen, ProgressStage::CheckPairs);
      ASSERT_EQ(r.size(), 3u);
      EXPECT_EQ(r[0].first, "surface level");
      EXPECT_EQ(r[1].first, "triangle level");
      EXPECT_EQ(r[2].first, "decisions");
      for (const auto& [label, total] : r) EXPECT_EQ(total, plain.counters.instance_pairs) << label;
      // Throttled to whole percentages: at most 101 calls a run, plus its last.
      EXPECT_LE(calls.seen.size(), 3u * 102u);
      for (const Progress& p : calls.seen) EXPECT_EQ(p.stage, ProgressStage::CheckPairs);
    }
  }
}

TEST(CollideProgress, ABudgetCutRunStillEndsAtItsTotal) {
  Model m = row_of_boxes();
  CollideOptions o;
  o.memory_budget_bytes = 1;  // nothing fits: every pair is left unexamined
  ProgressCalls calls;
  o.progress = calls.callback();
  Scene scene(m);
  const Report r = scene.check(o);
  EXPECT_FALSE(r.complete);
  EXPECT_EQ(progress_runs(calls.seen, ProgressStage::CheckPairs).size(), 3u);
}

TEST(CollideProgress, ReplayReportsItsStepsNotTheChecksInside) {
  Model m = row_of_boxes();
  std::string csv = "step,instance_path,tx,ty,tz,qw,qx,qy,qz\n";
  for (int step = 0; step < 7; ++step)
    csv += std::to_string(10 + step) + ",/row/box0," + std::to_string(-0.1 * step) + ",0,0,1,0,0,0\n";
  csv += "16,/row/box1,1,0,0,1,0,0,0\n";  // two rows of one step
  std::vector<Diagnostic> ds;
  const std::vector<TrajectoryRow> rows = parse_trajectory(csv, "path.csv", ds);
  ASSERT_TRUE(ds.empty());

  CollideOptions o;
  o.tolerance = 0.01;
  Scene plain_scene(m);
  const std::vector<StepResult> plain = replay_trajectory(plain_scene, rows, o, ds, "path.csv");

  ProgressCalls calls;
  o.progress = calls.callback();
  Scene scene(m);
  const std::vector<StepResult> shown = replay_trajectory(scene, rows, o, ds, "path.csv");
  ASSERT_EQ(shown.size(), plain.size());
  for (std::size_t k = 0; k < shown.size(); ++k) EXPECT_EQ(report_bytes(m, shown[k].report), report_bytes(m, plain[k].report));
  EXPECT_FALSE(calls.other_thread);
  for (const Progress& p : calls.seen) EXPECT_EQ(p.stage, ProgressStage::TrajectoryStep);
  const auto r = progress_runs(calls.seen, ProgressStage::TrajectoryStep);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].second, 7u);
  EXPECT_EQ(r[0].first, "10");
  // Seven steps: every step is a whole percentage, so every step is told, the last one last.
  ASSERT_EQ(calls.seen.size(), 8u);
  for (std::size_t k = 0; k < calls.seen.size(); ++k) EXPECT_EQ(calls.seen[k].done, k);
  EXPECT_EQ(calls.seen.back().label, "16");
}

TEST(CollideProgress, StageNames) {
  EXPECT_STREQ(progress_stage_name(ProgressStage::ReadFile), "read file");
  EXPECT_STREQ(progress_stage_name(ProgressStage::TessellatePart), "tessellate part");
  EXPECT_STREQ(progress_stage_name(ProgressStage::CheckPart), "check part");
  EXPECT_STREQ(progress_stage_name(ProgressStage::CheckPairs), "check instance pairs");
  EXPECT_STREQ(progress_stage_name(ProgressStage::TrajectoryStep), "trajectory step");
}

}  // namespace
}  // namespace cadclash
