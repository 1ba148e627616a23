// bench_accuracy computes its numbers right: the scorer on hand-made sets, and one instance pair of
// as1-tu-203.stp whose true face pairs are known, in every mode. No timing is checked.
#include "bench_accuracy_run.h"
#include "cadclash/testing/truth.h"

#include "cadclash/import.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <limits>
#include <set>
#include <string>

namespace cadclash::bench {
namespace {

using truth::compute_ground_truth;
using truth::MeasuredPair;
using truth::within;

// Tolerance 0.01 and both faces' uncertainty 1e-7: threshold 0.0100002.
GroundTruth hand_truth() {
  GroundTruth t;
  t.tolerance = 0.01;
  const double th = 0.01 + 2e-7;
  t.measured = {{0, 1, 0, 5, 0.0, th},        // touching
                {0, 1, 1, 5, 0.01, th},       // exactly at the tolerance: true
                {0, 1, 2, 5, 0.0100001, th},  // within the two uncertainties: true
                {0, 1, 3, 5, 0.0100003, th},  // beyond them: false
                {0, 2, 0, 7, 0.5, th},        // far: false
                {1, 2, 5, 7, std::numeric_limits<double>::infinity(), th}};  // not measurable: false
  return t;
}

TEST(AccuracyScore, CountsHitsMissesAndFalsePairs) {
  const GroundTruth t = hand_truth();
  // Reports one true pair twice, one false candidate and one pair the truth never measured.
  const Score s = score(t, {{0, 1, 1, 5}, {0, 1, 0, 5}, {0, 1, 0, 5}, {0, 1, 3, 5}, {3, 4, 9, 9}});
  EXPECT_EQ(s.truth, 3u);
  EXPECT_EQ(s.reported, 4u);
  EXPECT_EQ(s.hits, 2u);
  ASSERT_EQ(s.missed.size(), 1u);
  EXPECT_EQ(s.missed[0], (PairKey{0, 1, 2, 5}));
  ASSERT_EQ(s.false_pairs.size(), 2u);
  EXPECT_EQ(s.false_pairs[0], (PairKey{0, 1, 3, 5}));
  EXPECT_EQ(s.false_pairs[1], (PairKey{3, 4, 9, 9}));
  EXPECT_DOUBLE_EQ(s.recall(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.precision(), 0.5);
}

TEST(AccuracyScore, EmptySetsScorePerfect) {
  GroundTruth t;
  const Score none = score(t, {});
  EXPECT_EQ(none.recall(), 1.0);
  EXPECT_EQ(none.precision(), 1.0);
  const Score nothing_reported = score(hand_truth(), {});
  EXPECT_EQ(nothing_reported.recall(), 0.0);
  EXPECT_EQ(nothing_reported.precision(), 1.0);
  EXPECT_EQ(nothing_reported.missed.size(), 3u);
}

// One instance pair of as1: the rod and the first nut on it. The nut's bore (faces 0 and 4, two
// half cylinders) and its two threaded-end faces (6, 7) touch both halves of the rod's cylinder
// (faces 2, 3): 8 true pairs at tolerance 0. Two more face pairs pass the box prefilter and are 2.5 mm
// apart (the nut's flat ends against the rod's other half).
class AccuracyAs1 : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string path = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "needs data/external (scripts/setup.sh)";
    ImportOptions o;
    o.tessellation.linear_deflection = 0.1;
    in_ = import_file(path, o);
    Model& m = in_.model;
    for (InstanceId i = 0; i < m.instances.size(); ++i) {
      if (m.instances[i].path == "/as1/ROD-ASSEMBLY/NUT::1") nut_ = i;
      if (m.instances[i].path == "/as1/ROD-ASSEMBLY/ROD") rod_ = i;
    }
    ASSERT_NE(nut_, kInvalidId);
    ASSERT_NE(rod_, kInvalidId);
    keep_ = [this](InstanceId a, InstanceId b) {
      return std::min(nut_, rod_) == a && std::max(nut_, rod_) == b;
    };
  }
  // (nut face index, rod face index) of a pair.
  std::pair<int, int> faces(const PairKey& k) const {
    const Model& m = in_.model;
    const SurfaceId ns = k.instance_a == nut_ ? k.surface_a : k.surface_b;
    const SurfaceId rs = k.instance_a == nut_ ? k.surface_b : k.surface_a;
    return {m.surfaces[ns].provenance.face_index, m.surfaces[rs].provenance.face_index};
  }
  ImportResult in_;
  InstanceId nut_ = kInvalidId, rod_ = kInvalidId;
  std::function<bool(InstanceId, InstanceId)> keep_;
};

const std::set<std::pair<int, int>> kTrueNutRod{{0, 2}, {0, 3}, {4, 2}, {4, 3}, {6, 2}, {6, 3}, {7, 2}, {7, 3}};

TEST_F(AccuracyAs1, GroundTruthOfTheRodAndNut) {
  const GroundTruth t = compute_ground_truth(in_.model, 0.0, 1, keep_);
  EXPECT_EQ(t.instance_pairs, 1u);
  EXPECT_EQ(t.failed, 0u);
  std::set<std::pair<int, int>> real;
  for (const MeasuredPair& p : t.measured) {
    const auto f = faces({p.instance_a, p.instance_b, p.surface_a, p.surface_b});
    if (within(p)) {
      real.insert(f);
    } else {
      EXPECT_NEAR(p.distance, 2.5, 1e-6) << f.first << " " << f.second;
    }
  }
  EXPECT_EQ(real, kTrueNutRod);
  EXPECT_EQ(t.measured.size(), kTrueNutRod.size() + 2);
}

// Every mode's recall and precision equal the counts recomputed here from the raw reported pairs.
TEST_F(AccuracyAs1, ScoresMatchARecountOfTheReportedPairs) {
  const GroundTruth t = compute_ground_truth(in_.model, 0.0, 1, keep_);
  for (Mode mode : kModes) {
    const RunResult r = run_mode(in_.model, mode, 0.0, 0.1, 1, 1, keep_);
    std::set<std::pair<int, int>> got;
    for (const PairKey& k : r.reported) {
      ASSERT_TRUE((k.instance_a == nut_ && k.instance_b == rod_) || (k.instance_a == rod_ && k.instance_b == nut_));
      got.insert(faces(k));
    }
    std::size_t hits = 0;
    for (const auto& f : got) hits += kTrueNutRod.count(f);
    const Score s = score(t, r.reported);
    EXPECT_EQ(s.truth, kTrueNutRod.size()) << mode_name(mode);
    EXPECT_EQ(s.reported, got.size()) << mode_name(mode);
    EXPECT_EQ(s.hits, hits) << mode_name(mode);
    EXPECT_EQ(s.missed.size(), kTrueNutRod.size() - hits) << mode_name(mode);
    EXPECT_EQ(s.false_pairs.size(), got.size() - hits) << mode_name(mode);
    EXPECT_DOUBLE_EQ(s.recall(), double(hits) / double(kTrueNutRod.size())) << mode_name(mode);
    if (!got.empty()) {
      EXPECT_DOUBLE_EQ(s.precision(), double(hits) / double(got.size())) << mode_name(mode);
    }
    // cadclash's contract: τ includes the achieved deflections, so exact contact is never missed;
    // the certified and exact decisions report exactly the pairs in contact, none undecided.
    if (mode != Mode::OcctProximity) {
      EXPECT_EQ(s.recall(), 1.0) << mode_name(mode);
    }
    if (mode == Mode::Certified || mode == Mode::Exact) {
      EXPECT_EQ(s.precision(), 1.0) << mode_name(mode);
      EXPECT_TRUE(r.undecided.empty()) << mode_name(mode);
      EXPECT_EQ(r.counters.undecided, 0u) << mode_name(mode);
    }
  }
}

}  // namespace
}  // namespace cadclash::bench
