// Time and memory budgets of a query: partial reports that say so, the same partial report for any
// thread count under a memory budget, and no change at all when the budget is generous.
#include "scene_fixtures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>
#include <set>

namespace cadclash {
namespace {

using namespace cadclash::testing;

// A diagonal chain of boxes, each overlapping its next two neighbours: many instance pairs, each with
// penetrating, touching and clearance surface pairs.
Model chain_of_boxes(int n) {
  Model m;
  const PartId box = add_part(m, "box", box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 3));
  for (int i = 0; i < n; ++i) add_instance(m, "/chain/b" + std::to_string(i), box, translation(0.45 * i, 0.1 * i, 0.05 * i));
  return m;
}

class LazyFaces : public SurfaceSource {
 public:
  explicit LazyFaces(std::vector<Surface> faces) : faces_(std::move(faces)) {}
  bool triangulate(std::uint32_t local_index, double, TriangleMesh& out, double& achieved, Diagnostic&) override {
    std::lock_guard<std::mutex> lock(mutex_);
    ++calls;
    out = faces_[local_index].mesh;
    achieved = 0.0;
    return true;
  }
  int calls = 0;

 private:
  std::vector<Surface> faces_;
  std::mutex mutex_;
};

// chain_of_boxes with one part per instance; when `lazy`, each part is tessellated on demand by its
// own source and holds no triangles yet.
Model lazy_chain(int n, bool lazy = true) {
  Model m;
  for (int i = 0; i < n; ++i) {
    const PartId p = add_part(m, "box" + std::to_string(i), box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 3));
    if (!lazy) {
      add_instance(m, "/chain/b" + std::to_string(i), p, translation(0.45 * i, 0.1 * i, 0.05 * i));
      continue;
    }
    m.parts[p].source = std::make_shared<LazyFaces>(box_surfaces(Vec3(0, 0, 0), Vec3(1, 1, 1), 3));
    for (SurfaceId s = m.parts[p].first_surface; s < m.parts[p].first_surface + m.parts[p].surface_count; ++s) {
      m.surfaces[s].has_triangles = false;
      m.surfaces[s].mesh = {};
    }
    add_instance(m, "/chain/b" + std::to_string(i), p, translation(0.45 * i, 0.1 * i, 0.05 * i));
  }
  return m;
}

// Fresh scenes each: their box updates agree too.
void expect_same_counts(const CollideCounters& x, const CollideCounters& y) {
  expect_same_counters(x, y);
  EXPECT_EQ(x.aabb_updates, y.aabb_updates);
}

// The results of `full` for the instance pairs that `partial` examined, in order.
Report restricted(const Report& full, const Report& partial) {
  const std::set<std::array<InstanceId, 2>> skipped(partial.unexamined_pairs.begin(), partial.unexamined_pairs.end());
  Report r;
  for (const SurfacePairResult& p : full.pairs)
    if (!skipped.count({p.instance_a, p.instance_b})) r.pairs.push_back(p);
  return r;
}

CollideOptions base_options(ParallelVersion v) {
  CollideOptions o;
  o.tolerance = 0.01;
  o.clearance = 0.2;
  o.mode = CollideMode::AllTrianglePairs;
  o.version = v;
  return o;
}

TEST(CollideBudget, MemoryBudgetKeepsTheSamePrefixForAnyThreadCount) {
  for (const ParallelVersion v : {ParallelVersion::V1, ParallelVersion::V2}) {
    SCOPED_TRACE(v == ParallelVersion::V1 ? "V1" : "V2");
    Model m = chain_of_boxes(8);
    CollideOptions o = base_options(v);
    const Report full = Scene(m).check(o);
    ASSERT_TRUE(full.complete);
    EXPECT_TRUE(full.stopped_by.empty());
    EXPECT_TRUE(full.unexamined_pairs.empty());
    ASSERT_GT(full.counters.instance_pairs, 4u);
    ASSERT_GT(full.memory_charged, 0u);

    o.memory_budget_bytes = full.memory_charged / 2;
    Report first;
    for (const int threads : {1, 2, 4}) {
      SCOPED_TRACE("threads " + std::to_string(threads));
      o.threads = threads;
      const Report r = Scene(m).check(o);  // a fresh scene: BVHs are charged again
      EXPECT_FALSE(r.complete);
      EXPECT_EQ(r.stopped_by, "memory budget");
      EXPECT_LE(r.memory_charged, o.memory_budget_bytes);
      EXPECT_FALSE(r.pairs.empty());
      EXPECT_FALSE(r.unexamined_pairs.empty());
      EXPECT_LT(r.unexamined_pairs.size(), r.counters.instance_pairs);
      EXPECT_EQ(r.counters.instance_pairs, full.counters.instance_pairs);
      EXPECT_TRUE(std::is_sorted(r.unexamined_pairs.begin(), r.unexamined_pairs.end()));
      // What is reported is exactly what the full query says about the examined pairs.
      expect_same_pairs(r, restricted(full, r));
      if (threads == 1) {
        first = r;
        continue;
      }
      expect_same_pairs(r, first);
      EXPECT_EQ(r.unexamined_pairs, first.unexamined_pairs);
      EXPECT_EQ(r.memory_charged, first.memory_charged);
      expect_same_counts(r.counters, first.counters);
    }
  }
}

TEST(CollideBudget, TinyMemoryBudgetExaminesNothingAndSaysSo) {
  Model m = chain_of_boxes(5);
  CollideOptions o = base_options(ParallelVersion::V1);
  o.memory_budget_bytes = 1;
  const Report r = Scene(m).check(o);
  EXPECT_FALSE(r.complete);
  EXPECT_EQ(r.stopped_by, "memory budget");
  EXPECT_TRUE(r.pairs.empty());
  EXPECT_EQ(r.unexamined_pairs.size(), r.counters.instance_pairs);
  EXPECT_EQ(r.counters.triangle_tests, 0u);
  EXPECT_LE(r.memory_charged, 1u);
}

TEST(CollideBudget, GenerousBudgetGivesTheSameReportAsNone) {
  for (const ParallelVersion v : {ParallelVersion::V1, ParallelVersion::V2}) {
    Model m = chain_of_boxes(6);
    CollideOptions o = base_options(v);
    const Report none = Scene(m).check(o);
    for (const std::size_t budget : {static_cast<std::size_t>(none.memory_charged), std::size_t{1} << 40}) {
      CollideOptions ob = o;
      ob.memory_budget_bytes = budget;
      ob.time_budget_seconds = 1e6;
      const Report r = Scene(m).check(ob);
      EXPECT_TRUE(r.complete);
      EXPECT_TRUE(r.stopped_by.empty());
      EXPECT_TRUE(r.unexamined_pairs.empty());
      EXPECT_EQ(r.memory_charged, none.memory_charged);
      expect_same_pairs(r, none);
      expect_same_counts(r.counters, none.counters);
    }
  }
}

TEST(CollideBudget, MemoryBudgetReleasesLazyTrianglesPastTheCut) {
  Model eager = lazy_chain(6, false);
  Model lazy = lazy_chain(6);
  CollideOptions o = base_options(ParallelVersion::V1);
  const Report full = Scene(eager).check(o);
  Model lazy_again = lazy_chain(6);
  const Report lazy_full = Scene(lazy_again).check(o);
  expect_same_pairs(lazy_full, full);
  ASSERT_GT(lazy_full.memory_charged, full.memory_charged);  // the tessellated triangles are charged too

  o.memory_budget_bytes = lazy_full.memory_charged / 3;
  Scene scene(lazy);
  const Report r = scene.check(o);
  EXPECT_FALSE(r.complete);
  EXPECT_EQ(r.stopped_by, "memory budget");
  EXPECT_LE(r.memory_charged, o.memory_budget_bytes);
  expect_same_pairs(r, restricted(full, r));
  // Parts met only by unexamined pairs hold no triangles again.
  std::set<InstanceId> examined;
  for (const SurfacePairResult& p : r.pairs) examined.insert({p.instance_a, p.instance_b});
  const auto last = static_cast<InstanceId>(lazy.instances.size() - 1);
  ASSERT_FALSE(examined.count(last));
  for (SurfaceId s = lazy.parts[last].first_surface; s < lazy.parts[last].first_surface + 6; ++s)
    EXPECT_FALSE(lazy.surfaces[s].has_triangles) << s;
  EXPECT_LT(r.counters.tessellated_surfaces, lazy_full.counters.tessellated_surfaces);
  // The same scene without a budget then finishes the job.
  o.memory_budget_bytes = 0;
  const Report rest = scene.check(o);
  EXPECT_TRUE(rest.complete);
  expect_same_pairs(rest, full);
}

TEST(CollideBudget, ExpiredTimeBudgetGivesAMarkedPartialReport) {
  for (const ParallelVersion v : {ParallelVersion::V1, ParallelVersion::V2}) {
    for (const bool lazy : {false, true}) {
      SCOPED_TRACE(std::string(v == ParallelVersion::V1 ? "V1" : "V2") + (lazy ? " lazy" : " eager"));
      Model m = lazy_chain(6, lazy);
      CollideOptions o = base_options(v);
      Model untimed = lazy_chain(6, lazy);
      const Report full = Scene(untimed).check(o);
      o.time_budget_seconds = 1e-9;  // out before the first work item
      o.threads = 2;
      const Report r = Scene(m).check(o);
      EXPECT_FALSE(r.complete);
      EXPECT_EQ(r.stopped_by, "time budget");
      EXPECT_FALSE(r.unexamined_pairs.empty());
      EXPECT_EQ(r.counters.instance_pairs, full.counters.instance_pairs);
      EXPECT_LE(r.unexamined_pairs.size(), r.counters.instance_pairs);
      // Whatever was found is true: each reported surface pair is in the full report.
      for (const SurfacePairResult& p : r.pairs) {
        const auto it = std::find_if(full.pairs.begin(), full.pairs.end(), [&](const SurfacePairResult& q) {
          return q.instance_a == p.instance_a && q.instance_b == p.instance_b && q.surface_a == p.surface_a &&
                 q.surface_b == p.surface_b;
        });
        ASSERT_NE(it, full.pairs.end());
        EXPECT_EQ(it->contact, p.contact);
      }
    }
  }
}

TEST(CollideBudget, TrajectoryTimeBudgetCoversTheWholeReplay) {
  Model m = chain_of_boxes(4);
  const std::string csv =
      "0,/chain/b1,0.5,0,0,1,0,0,0\n"
      "1,/chain/b1,0.6,0,0,1,0,0,0\n"
      "2,/chain/b1,0.7,0,0,1,0,0,0\n";
  std::vector<Diagnostic> ds;
  const auto rows = parse_trajectory(csv, "p.csv", ds);
  ASSERT_EQ(rows.size(), 3u);
  Scene scene(m);
  CollideOptions o;
  o.time_budget_seconds = 1e-9;
  const auto steps = replay_trajectory(scene, rows, o, ds, "p.csv");
  // Either the budget ran out inside the first step's check (a partial step 0, steps 1 and 2 not
  // checked) or already before it (nothing checked); which one depends on the clock.
  ASSERT_LE(steps.size(), 1u);
  ASSERT_EQ(ds.size(), 1u);
  EXPECT_EQ(ds[0].severity, Severity::Warning);
  EXPECT_EQ(ds[0].file, "p.csv");
  if (steps.size() == 1) {
    EXPECT_FALSE(steps[0].report.complete);
    EXPECT_EQ(steps[0].report.stopped_by, "time budget");
    EXPECT_EQ(ds[0].line, 2);
    EXPECT_NE(ds[0].message.find("2 steps from step 1 on were not checked"), std::string::npos) << ds[0].message;
  } else {
    EXPECT_EQ(ds[0].line, 1);
    EXPECT_NE(ds[0].message.find("3 steps from step 0 on were not checked"), std::string::npos) << ds[0].message;
  }

  // A memory budget applies to each step on its own: no step is dropped.
  ds.clear();
  o.time_budget_seconds = 0.0;
  o.memory_budget_bytes = 1;
  Scene again(m);
  const auto mem_steps = replay_trajectory(again, rows, o, ds, "p.csv");
  EXPECT_EQ(mem_steps.size(), 3u);
  EXPECT_TRUE(ds.empty());
  for (const StepResult& s : mem_steps) EXPECT_FALSE(s.report.complete);
}

}  // namespace
}  // namespace cadclash
