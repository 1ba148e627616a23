// A check split into parts on replicas of the scene and merged (cadclash/distributed.h, no MPI):
// the merged report must be the report of Scene::check() byte for byte (--no-timings JSON), for any
// number of parts, in every decision mode, lazily tessellated or not, and over a trajectory whose
// steps reuse what earlier steps tessellated on other parts.
#include "cadclash/distributed.h"
#include "cadclash/import.h"
#include "cadclash/report.h"
#include "cadclash/tessellate.h"
#include "cadclash/testing/scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace cadclash {
namespace {

std::string as1_path() { return std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp"; }

#define REQUIRE_AS1() \
  if (!std::filesystem::exists(as1_path())) GTEST_SKIP() << "needs data/external/as1-tu-203.stp (scripts/setup.sh)"

// A rank's part as rank 0 receives it: through bytes, appended to `parts` when they read back.
void through_bytes(const PartialCheck& part, std::vector<PartialCheck>& parts) {
  std::string error;
  std::optional<PartialCheck> back = partial_check_from_bytes(partial_check_bytes(part), error);
  EXPECT_TRUE(back.has_value()) << error;
  if (back) parts.push_back(std::move(*back));
}

// Step `step` of the rod's trajectory in these tests: lifted 4 mm and turned 0.05 rad per step.
Pose rod_at_step(Pose start, int step) {
  start.pretranslate(Vec3(0.0, 0.0, 4.0 * step));
  start.rotate(Eigen::AngleAxisd(0.05 * step, Vec3::UnitX()));
  return start;
}

// The id of as1's rod (the trajectories here move it), or kInvalidId.
InstanceId rod_of(const Model& m) {
  for (InstanceId i = 0; i < m.instances.size(); ++i)
    if (m.instances[i].path == "/as1/ROD-ASSEMBLY/ROD") return i;
  return kInvalidId;
}

Model import_as1(bool lazy, double deflection = 0.1) {
  ImportOptions io;
  io.lazy = lazy;
  io.tessellation.linear_deflection = deflection;
  ImportResult r = import_file(as1_path(), io);
  EXPECT_FALSE(has_error(r.diagnostics));
  return std::move(r.model);
}

// The report file `cadclash check --no-timings --json` would write for `r` over `model`.
std::string report_text(const Model& model, const Report& r) {
  CheckReport c;
  c.query = query_report(model, r);
  c.query->timings.reset();
  for (const Diagnostic& d : r.diagnostics) c.diagnostics.push_back(format_diagnostic(d));
  return check_report_text(c, {.timings = false});
}

// Empty when equal; else the first line that differs, in both.
std::string first_difference(const std::string& got, const std::string& expected) {
  if (got == expected) return {};
  std::istringstream g(got), e(expected);
  std::string lg, le;
  for (int line = 1;; ++line) {
    const bool more_g = static_cast<bool>(std::getline(g, lg)), more_e = static_cast<bool>(std::getline(e, le));
    if (lg != le || more_g != more_e)
      return "line " + std::to_string(line) + ": split '" + lg + "', one process '" + le + "'";
  }
}

// `parts` replicas of a model, each with its scene, checked as the MPI ranks would check them.
class Split {
 public:
  Split(const Model& model, int parts) : history_(model.surfaces.size(), {}) {
    for (int r = 0; r < parts; ++r) {
      models_.push_back(std::make_unique<Model>(model));
      scenes_.push_back(std::make_unique<Scene>(*models_.back()));
    }
    history_ = MergeHistory(model.surfaces.size(), scenes_[0]->memory());
  }
  const Model& model() const { return *models_[0]; }  // rank 0's: the report's names

  void set_pose(InstanceId i, const Pose& p) {
    for (auto& s : scenes_) s->set_pose(i, p);
  }

  Report check(const CollideOptions& o) {
    std::vector<CheckPlan> plans;
    for (auto& s : scenes_) plans.push_back(s->plan(o));
    for (const CheckPlan& p : plans) {  // every replica plans the same pairs (costs: rank 0's decide)
      EXPECT_EQ(p.pairs.size(), plans[0].pairs.size());
      for (std::size_t k = 0; k < p.pairs.size() && k < plans[0].pairs.size(); ++k)
        EXPECT_TRUE(p.pairs[k].a == plans[0].pairs[k].a && p.pairs[k].b == plans[0].pairs[k].b);
      EXPECT_EQ(p.needed, plans[0].needed);
    }
    const auto split = split_by_cost(plans[0], static_cast<int>(scenes_.size()));
    std::vector<PartialCheck> parts;
    for (std::size_t r = 0; r < scenes_.size(); ++r) {
      through_bytes(scenes_[r]->check_part(o, plans[r], split[r]), parts);
    }
    MergedCheck m = merge_parts(plans[0], parts, *models_[0], history_);
    for (std::size_t r = 0; r < scenes_.size(); ++r)
      for (const auto& [sid, d] : m.new_deflections) {
        Surface& s = models_[r]->surfaces[sid];
        if (s.has_triangles) continue;
        s.deflection = d;
        scenes_[r]->note_deflection(sid, d);
      }
    return std::move(m.report);
  }

 private:
  std::vector<std::unique_ptr<Model>> models_;
  std::vector<std::unique_ptr<Scene>> scenes_;
  MergeHistory history_;
};

void expect_same_as_one_process(const Model& model, const CollideOptions& o, int parts) {
  Model single_model = model;
  Scene single(single_model);
  const Report expected = single.check(o);
  Split split(model, parts);
  const Report got = split.check(o);
  EXPECT_EQ(first_difference(report_text(split.model(), got), report_text(single_model, expected)), "")
      << parts << " parts";
}

TEST(SplitMerge, As1EveryModeAndPartCount) {
  REQUIRE_AS1();
  for (bool lazy : {false, true}) {
    const Model as1 = import_as1(lazy);
    for (DecisionMode mode : {DecisionMode::Certified, DecisionMode::Fast, DecisionMode::Exact}) {
      CollideOptions o;
      o.decision = mode;
      o.tolerance = 0.01;
      o.clearance = 2.0;
      for (int parts : {1, 3, 8}) {
        SCOPED_TRACE(std::string(lazy ? "lazy " : "eager ") + decision_mode_name(mode));
        expect_same_as_one_process(as1, o, parts);
      }
    }
  }
}

TEST(SplitMerge, As1AllTrianglePairsVersion2) {
  REQUIRE_AS1();
  const Model as1 = import_as1(true);
  CollideOptions o;
  o.mode = CollideMode::AllTrianglePairs;
  o.version = ParallelVersion::V2;
  o.threads = 1;
  for (int parts : {2, 4}) expect_same_as_one_process(as1, o, parts);
}

// The rod of as1 moved over six steps, lazily tessellated: later steps reach surfaces that earlier
// steps tessellated on other parts (counters, memory must not count them again), and pairs move
// between parts as the plan changes. At a coarse deflection (2 mm asked, planar faces meshed
// exactly) a surface's search reach shrinks once tessellated: every part must use the deflection
// another part achieved (Scene::note_deflection), or its surface level differs from one process's.
TEST(SplitMerge, As1LazyTrajectory) {
  REQUIRE_AS1();
  const Model as1 = import_as1(true, 2.0);
  const InstanceId rod = rod_of(as1);
  ASSERT_NE(rod, kInvalidId);
  CollideOptions o;
  o.tolerance = 0.01;
  for (int parts : {2, 3, 4}) {
    Model single_model = as1;
    Scene single(single_model);
    Split split(as1, parts);
    for (int step = 0; step < 6; ++step) {
      const Pose p = rod_at_step(as1.instances[rod].pose, step);
      single.set_pose(rod, p);
      split.set_pose(rod, p);
      const Report expected = single.check(o);
      const Report got = split.check(o);
      ASSERT_EQ(first_difference(report_text(split.model(), got), report_text(single_model, expected)), "")
          << parts << " parts, step " << step;
    }
  }
}

// Faces that cannot be meshed (lazily, so during the check), reached by pairs on several parts: each
// error once, in one process's order (by part, then first need).
TEST(SplitMerge, UnmeshableFacesOnceInOrder) {
  const std::string cad = std::string(CADCLASH_DATA_DIR) + "/cad/";
  std::vector<std::string> files;
  for (int copy = 0; copy < 3; ++copy)
    for (const char* name : {"mesh_fail_degenerate.step", "mesh_fail_bowtie.brep"}) files.push_back(cad + name);
  ImportOptions io;
  io.lazy = true;
  const ImportResult r = import_files(files, io);
  ASSERT_GE(r.model.instances.size(), 6u);
  for (int parts : {2, 3, 4}) expect_same_as_one_process(r.model, CollideOptions{}, parts);
  Model m = r.model;
  Scene scene(m);
  EXPECT_GE(scene.check().diagnostics.size(), 6u);  // the scene does reach the failing faces
}

// 56 copies of as1 (1008 instances) split over 4 parts.
TEST(SplitMerge, ThousandInstances) {
  REQUIRE_AS1();
  const Model many = truth::grid_copies(import_as1(false), 56, 1.0);
  ASSERT_GE(many.instances.size(), 1000u);
  CollideOptions o;
  o.tolerance = 0.01;
  expect_same_as_one_process(many, o, 4);
}

// Part meshing (distributed.h) as the ranks do it, without MPI: each replica a lazy import of its own
// (meshing writes into the B-rep, which copies of a Model would share), its owned parts meshed and
// their facts given to every replica, then per query the parts its run reaches meshed (and the
// owned ones it does not reach released). The merged report must be one eager process's.
class PartSplit {
 public:
  PartSplit(const std::function<Model()>& import_lazy, int parts, const CollideOptions& o)
      : history_(0, {}), pm_(static_cast<std::size_t>(parts)) {
    std::vector<CheckPlan> plans;
    for (int r = 0; r < parts; ++r) {
      models_.push_back(std::make_unique<Model>(import_lazy()));
      Model& m = *models_.back();
      for (const Surface& s : m.surfaces) EXPECT_FALSE(s.has_triangles && m.parts[s.part].source);
      PartMeshing& pm = pm_[static_cast<std::size_t>(r)];
      pm.mesher.mesh = [&m](std::span<const PartId> ps) {
        std::vector<Diagnostic> ds;
        bool complete = true;
        tessellate_parts(m, ps, ds, complete);
        return ds.empty() && complete;
      };
      pm.mesher.release = [&m](std::span<const PartId> ps) { release_part_triangles(m, ps); };
      Scene boxes(m);
      plans.push_back(boxes.plan(o));
    }
    const Model& m0 = *models_[0];
    const std::vector<int> owners = mesh_owners(m0, plans[0], parts);
    std::vector<std::vector<PartId>> owned(static_cast<std::size_t>(parts));
    for (PartId p = 0; p < owners.size(); ++p) owned[static_cast<std::size_t>(owners[p])].push_back(p);
    for (int r = 0; r < parts; ++r) {
      EXPECT_EQ(mesh_owners(*models_[r], plans[r], parts), owners) << "replica " << r;
      PartMeshing& pm = pm_[static_cast<std::size_t>(r)];
      Model& m = *models_[r];
      pm.held.assign(m.parts.size(), 0);
      pm.facts_only.assign(m.parts.size(), 0);
      pm.facts.assign(m.surfaces.size(), SurfaceFacts{});
      const std::uint64_t before = held_triangles(m);
      EXPECT_TRUE(pm.mesher.mesh(owned[static_cast<std::size_t>(r)]));
      for (PartId p : owned[static_cast<std::size_t>(r)]) pm.held[p] = pm.facts_only[p] = 1;
      pm.meshed_triangles = held_triangles(m) - before;
    }
    for (int r = 0; r < parts; ++r) {  // the facts every rank sends to every rank
      const std::vector<SurfaceFacts> facts = surface_facts(*models_[r], owned[static_cast<std::size_t>(r)]);
      for (int q = 0; q < parts; ++q)
        apply_surface_facts(*models_[q], owned[static_cast<std::size_t>(r)], facts, pm_[static_cast<std::size_t>(q)]);
    }
    for (int r = 0; r < parts; ++r) {
      scenes_.push_back(std::make_unique<Scene>(*models_[r]));
      note_surface_facts(*scenes_.back(), pm_[static_cast<std::size_t>(r)]);
    }
    history_ = MergeHistory(m0.surfaces.size(), scenes_[0]->memory());
  }
  const Model& model() const { return *models_[0]; }
  const PartMeshing& meshing(int r) const { return pm_[static_cast<std::size_t>(r)]; }
  const Model& model(int r) const { return *models_[static_cast<std::size_t>(r)]; }

  void set_pose(InstanceId i, const Pose& p) {
    for (auto& s : scenes_) s->set_pose(i, p);
  }

  Report check(const CollideOptions& o) {
    std::vector<CheckPlan> plans;
    for (auto& s : scenes_) plans.push_back(s->plan(o));
    const auto split = split_by_cost(plans[0], static_cast<int>(scenes_.size()));
    std::vector<PartialCheck> parts;
    for (std::size_t r = 0; r < scenes_.size(); ++r) {
      EXPECT_EQ(plans[r].pairs.size(), plans[0].pairs.size());
      EXPECT_TRUE(share_parts(*models_[r], plans[r], split[r], pm_[r]));
      for (PartId p : parts_of_pairs(*models_[r], plans[r], split[r])) EXPECT_TRUE(pm_[r].held[p]) << p;
      through_bytes(scenes_[r]->check_part(o, plans[r], split[r]), parts);
    }
    MergedCheck m = merge_parts(plans[0], parts, *models_[0], history_);
    EXPECT_TRUE(m.new_deflections.empty());  // every reached surface was meshed before its check
    return std::move(m.report);
  }

 private:
  std::vector<std::unique_ptr<Model>> models_;
  std::vector<std::unique_ptr<Scene>> scenes_;
  MergeHistory history_;
  std::vector<PartMeshing> pm_;
};

TEST(SplitMerge, As1PartMeshingIsTheEagerProcess) {
  REQUIRE_AS1();
  for (DecisionMode mode : {DecisionMode::Certified, DecisionMode::Exact}) {
    CollideOptions o;
    o.decision = mode;
    o.tolerance = 0.01;
    o.clearance = 2.0;
    Model eager = import_as1(false);
    Scene single(eager);
    const std::string expected = report_text(eager, single.check(o));
    for (int parts : {1, 2, 3}) {
      SCOPED_TRACE(std::string(decision_mode_name(mode)) + ", " + std::to_string(parts) + " parts");
      PartSplit split([] { return import_as1(true); }, parts, o);
      EXPECT_EQ(first_difference(report_text(split.model(), split.check(o)), expected), "");
      // Every part meshed by some replica first; none meshes more than the model, and the one part
      // meshes exactly the model.
      std::uint64_t meshed = 0;
      for (int r = 0; r < parts; ++r) {
        meshed += split.meshing(r).meshed_triangles;
        EXPECT_LE(split.meshing(r).meshed_triangles, split.meshing(r).model_triangles);
        EXPECT_LE(held_triangles(split.model(r)), split.meshing(r).meshed_triangles);
      }
      EXPECT_GE(meshed, split.meshing(0).model_triangles);
      EXPECT_EQ(split.meshing(0).model_triangles, triangle_count(eager));
      if (parts == 1) {
        EXPECT_EQ(split.meshing(0).meshed_triangles, triangle_count(eager));
      }
    }
  }
}

// The rod of as1 moved over six steps at a coarse deflection (achieved deflections below the asked
// 2 mm: the plan must use the facts of parts meshed elsewhere), eagerly in one process.
TEST(SplitMerge, As1PartMeshingTrajectory) {
  REQUIRE_AS1();
  Model eager = import_as1(false, 2.0);
  const InstanceId rod = rod_of(eager);
  ASSERT_NE(rod, kInvalidId);
  CollideOptions o;
  o.tolerance = 0.01;
  for (int parts : {2, 3}) {
    Model single_model = eager;
    Scene single(single_model);
    PartSplit split([] { return import_as1(true, 2.0); }, parts, o);
    for (int step = 0; step < 6; ++step) {
      const Pose p = rod_at_step(eager.instances[rod].pose, step);
      single.set_pose(rod, p);
      split.set_pose(rod, p);
      const std::string expected = report_text(single_model, single.check(o));
      ASSERT_EQ(first_difference(report_text(split.model(), split.check(o)), expected), "")
          << parts << " parts, step " << step;
    }
  }
}

TEST(SplitMerge, MeshOwnersFollowTheSplit) {
  // Five instances of five parts (one surface each), pairs (0,1), (1,2), (2,3) of equal cost: two
  // ranks get the runs {(0,1)} and {(1,2), (2,3)} (split_by_cost: a pair goes where its middle falls);
  // part 4 is in no pair.
  Model m;
  for (PartId p = 0; p < 5; ++p) {
    m.parts.push_back(Part{"p" + std::to_string(p), "", p, 1, nullptr});
    Surface s;
    s.part = p;
    m.surfaces.push_back(s);
  }
  for (InstanceId i = 0; i < 5; ++i) m.instances.push_back(Instance{"/i" + std::to_string(i), i, Pose::Identity()});
  CheckPlan plan;
  plan.pairs = {{0, 1, 10}, {1, 2, 10}, {2, 3, 10}};
  EXPECT_EQ(parts_of_pairs(m, plan, std::vector<std::uint32_t>{1, 2}), (std::vector<PartId>{1, 2, 3}));
  ASSERT_EQ(split_by_cost(plan, 2)[0], std::vector<std::uint32_t>{0});
  // Part 1 to the first run that reaches it; part 4 to the rank owning fewer surfaces (a tie: rank 0).
  EXPECT_EQ(mesh_owners(m, plan, 2), (std::vector<int>{0, 0, 1, 1, 0}));
  // Three ranks, a pair each: part 4 to rank 1, the first of those owning one surface.
  EXPECT_EQ(mesh_owners(m, plan, 3), (std::vector<int>{0, 0, 1, 2, 1}));
  EXPECT_EQ(mesh_owners(m, plan, 1), (std::vector<int>{0, 0, 0, 0, 0}));
  // With homes (the readers of the parts' files), a part no pair reaches goes home.
  const std::vector<int> home{1, 1, 1, 0, 1};
  EXPECT_EQ(mesh_owners(m, plan, 2, home), (std::vector<int>{0, 0, 1, 1, 1}));
}

TEST(SplitMerge, ReadersTakeContiguousRunsOfEqualBytes) {
  // 250 bytes in all on 2 ranks: middles at 25, 100 (< 125: rank 0), 170, 220.
  EXPECT_EQ(assign_readers(std::vector<std::uint64_t>{50, 100, 40, 60}, 2), (std::vector<int>{0, 0, 1, 1}));
  EXPECT_EQ(assign_readers(std::vector<std::uint64_t>{7, 7, 7, 7}, 4), (std::vector<int>{0, 1, 2, 3}));
  // Fewer files than ranks: spread out; an empty file still counts.
  EXPECT_EQ(assign_readers(std::vector<std::uint64_t>{10, 10}, 4), (std::vector<int>{1, 3}));
  EXPECT_EQ(assign_readers(std::vector<std::uint64_t>{0, 0, 5}, 3), (std::vector<int>{0, 0, 1}));
  EXPECT_EQ(assign_readers(std::vector<std::uint64_t>{3, 9}, 1), (std::vector<int>{0, 0}));
}

TEST(SplitMerge, SplitIsContiguousCompleteAndBalanced) {
  CheckPlan plan;
  std::uint64_t total = 0, largest = 0;
  for (std::uint32_t k = 0; k < 1000; ++k) {
    const std::uint64_t cost = (k * 7919u) % 997u + (k % 50 == 0 ? 20000u : 0u);
    plan.pairs.push_back({k, k + 1, cost});
    total += cost + 1;
    largest = std::max(largest, cost + 1);
  }
  for (int n : {1, 2, 3, 4, 7, 64, 2000}) {
    const auto parts = split_by_cost(plan, n);
    ASSERT_EQ(parts.size(), static_cast<std::size_t>(n));
    std::uint32_t next = 0;
    for (const auto& part : parts) {
      std::uint64_t cost = 0;
      for (std::uint32_t k : part) {
        EXPECT_EQ(k, next++);  // contiguous, in order, each pair once
        cost += plan.pairs[k].cost + 1;
      }
      EXPECT_LE(cost, total / static_cast<std::uint64_t>(n) + largest) << n << " parts";
    }
    EXPECT_EQ(next, plan.pairs.size());
  }
}

TEST(SplitMerge, BytesRoundTripAndRejectGarbage) {
  PartialCheck p;
  SurfacePairResult r;
  r.instance_a = 1;
  r.instance_b = 7;
  r.surface_a = 3;
  r.surface_b = 40;
  r.contact = ContactClass::Undecided;
  r.distance = 0.1 + 0.2;
  r.distance_hi = std::numeric_limits<double>::infinity();
  r.exact_distance = 1e-300;
  r.triangle_pairs = {{1, 2}, {3, 4}};
  p.report.pairs.push_back(r);
  p.report.counters.witness_queries = 12345678901234ull;
  p.report.unexamined_pairs = {{2, 9}};
  p.report.complete = false;
  p.report.stopped_by = "time budget";
  SurfaceWork w;
  w.surface = 40;
  w.asked = true;
  w.error = Diagnostic{Severity::Error, "f.step", 0, 42, "face failed"};
  p.surfaces.push_back(w);
  const std::vector<std::uint8_t> bytes = partial_check_bytes(p);
  std::string error;
  const std::optional<PartialCheck> back = partial_check_from_bytes(bytes, error);
  ASSERT_TRUE(back.has_value()) << error;
  EXPECT_EQ(partial_check_bytes(*back), bytes);
  EXPECT_TRUE(std::isinf(back->report.pairs[0].distance_hi));
  EXPECT_EQ(back->surfaces[0].error->message, "face failed");
  const std::vector<std::uint8_t> garbage = {0xff, 0x00, 0x13};
  EXPECT_FALSE(partial_check_from_bytes(garbage, error).has_value());
  EXPECT_NE(error.find("not a partial check"), std::string::npos) << error;
}

}  // namespace
}  // namespace cadclash
