// triangles_intersect against a brute-force exact oracle (CGAL Epeck on the same doubles), on random
// and adversarial families (including the numerical extremes: offsets 1e3..1e12 with features down to
// 1e-9 of the offset, nearly coplanar at 1e-15..1e-6 rad, T-junctions, tiny against huge, exact
// contacts on wide lattices and with rounded differences), plus hand-made cases with known answers.
// Each family also counts how often two float-only answers are wrong — the same algorithm in plain
// double with no error bound, and cadclash's filters with the exact stages switched off (undecided =
// intersect) — reported, not asserted: they show what the exact stages are for. Every call that
// reaches CGAL (exact fallback) must involve a degenerate triangle or a coordinate outside the
// exact stage's domain. One table row per family:
//   [ family   ] | name | pairs | intersecting | plain double wrong | filters only wrong |
//                  filtered wrong | exact fallbacks (CGAL) |
//
// Default run: 100 000 pairs per family, 15 families = 1.5 x 10^6 pairs (Release). Builds without
// NDEBUG (Debug, ASan) run a tenth of that to keep the sanitizer run short. The opt-in long run
// (test_triangle_predicates_slow, CTest label `slow`) checks 10^7 pairs per family with other seeds:
//   CADCLASH_SLOW_TESTS=1 ctest --test-dir build -L slow --output-on-failure
#include "test_triangle_cases.h"
#include "cadclash/geometry.h"
#include "cadclash/testing/benchmark_switches.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

namespace cadclash {
namespace {

using test::Family;
using test::Tri;
using test::TriPair;

// The long run's tests get their own names: CTest keys test properties (the `slow` label) by name.
#ifdef CADCLASH_TRIANGLE_SLOW
#define ORACLE_SUITE LongOracleAgreement
constexpr long kPairsPerFamily = 10'000'000;
constexpr std::uint64_t kSeedBase = 0x51'0000;
#elif defined(NDEBUG)
#define ORACLE_SUITE OracleAgreement
constexpr long kPairsPerFamily = 100'000;
constexpr std::uint64_t kSeedBase = 0;
#else
#define ORACLE_SUITE OracleAgreement
constexpr long kPairsPerFamily = 10'000;
constexpr std::uint64_t kSeedBase = 0;
#endif

bool intersect(const Tri& a, const Tri& b, TrianglePredicateStats& s) {
  return triangles_intersect(a[0], a[1], a[2], b[0], b[1], b[2], s);
}

std::string describe(const TriPair& p) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "A = (%a %a %a) (%a %a %a) (%a %a %a)\nB = (%a %a %a) (%a %a %a) (%a %a %a)",
                p.a[0].x(), p.a[0].y(), p.a[0].z(), p.a[1].x(), p.a[1].y(), p.a[1].z(), p.a[2].x(),
                p.a[2].y(), p.a[2].z(), p.b[0].x(), p.b[0].y(), p.b[0].z(), p.b[1].x(), p.b[1].y(),
                p.b[1].z(), p.b[2].x(), p.b[2].y(), p.b[2].z());
  return buf;
}

class ORACLE_SUITE : public ::testing::TestWithParam<Family> {};

TEST_P(ORACLE_SUITE, ZeroDisagreements) {
#ifdef CADCLASH_TRIANGLE_SLOW
  if (!std::getenv("CADCLASH_SLOW_TESTS")) GTEST_SKIP() << "opt-in: set CADCLASH_SLOW_TESTS=1";
#endif
  const Family f = GetParam();
  test::Rng rng(kSeedBase + 1000 + static_cast<std::uint64_t>(f));
  TrianglePredicateStats stats;
  long disagreements = 0, exact_disagreements = 0, asymmetric = 0, hits = 0, float_wrong = 0, filter_only_wrong = 0;
  long unexpected_cgal = 0;
  for (long i = 0; i < kPairsPerFamily; ++i) {
    const TriPair p = test::make_case(f, rng);
    const bool expected = test::oracle_intersect(p.a, p.b);
    const std::uint64_t fallbacks_before = stats.exact_fallbacks;
    const bool got = intersect(p.a, p.b, stats);
    if (stats.exact_fallbacks != fallbacks_before && !test::may_need_cgal(p.a, p.b) && ++unexpected_cgal <= 5)
      ADD_FAILURE() << "pair " << i << " went to CGAL without a degenerate triangle\n" << describe(p);
    hits += expected;
    bool float_failed = false;
    float_wrong += test::float_only_intersect(p.a, p.b, &float_failed) != expected || float_failed;
    // cadclash's own filters without the exact stage (bench_compare's "float only" switch).
    testing::set_float_only_for_benchmark(true);
    TrianglePredicateStats filter_stats;
    filter_only_wrong += intersect(p.a, p.b, filter_stats) != expected;
    testing::set_float_only_for_benchmark(false);
    if (got != expected && ++disagreements <= 5)
      ADD_FAILURE() << "pair " << i << ": got " << got << ", oracle " << expected << "\n" << describe(p);
    const bool exact = triangles_intersect_exact(p.a[0], p.a[1], p.a[2], p.b[0], p.b[1], p.b[2]);
    if (exact != expected && ++exact_disagreements <= 5)
      ADD_FAILURE() << "exact path, pair " << i << ": got " << exact << "\n" << describe(p);
    TrianglePredicateStats unused;
    if (intersect(p.b, p.a, unused) != got) ++asymmetric;
  }
  EXPECT_EQ(disagreements, 0);
  EXPECT_EQ(exact_disagreements, 0);
  EXPECT_EQ(asymmetric, 0);
  EXPECT_EQ(unexpected_cgal, 0);
  EXPECT_EQ(stats.tests, static_cast<std::uint64_t>(kPairsPerFamily));
  // Every family must exercise both answers, or it tests less than its name says.
  EXPECT_GT(hits, 0);
  EXPECT_LT(hits, kPairsPerFamily);
  // The filters must actually filter: generic families never need the exact path, and under rigid
  // motions and on slivers the long-double stage settles most signs the double stage leaves open.
  if (f == Family::RandomCube || f == Family::RandomNear || f == Family::FarOffset) {
    EXPECT_EQ(stats.exact_fallbacks, 0u);
    EXPECT_LT(stats.exact_signs * 100, stats.tests);
  }
  if (f == Family::RigidMotion || f == Family::Sliver) {
    EXPECT_GT(stats.extended_signs, 0u);                   // the long-double stage is asked...
    EXPECT_LT(stats.exact_signs * 2, stats.extended_signs);  // ...and settles most of what it is asked
    EXPECT_LT(stats.exact_fallbacks * 10, stats.tests);
  }
  // The exact contacts are settled by the exact stage, not by CGAL: only the degenerate triangles the
  // lattice generators draw now and then (collinear lattice points) go there.
  if (f == Family::CoplanarGrid || f == Family::TouchingGrid || f == Family::UlpPerturbed ||
      f == Family::TJunction || f == Family::OffsetFeature || f == Family::WideCoplanar) {
    EXPECT_GT(stats.exact_signs, 0u);
    EXPECT_LT(stats.exact_fallbacks * 10, stats.tests);
  }
  if (f == Family::SharedFeature || f == Family::TJunction || f == Family::TinyHuge ||
      f == Family::NearlyCoplanar || f == Family::Sliver) {
    EXPECT_LT(stats.exact_fallbacks * 100, stats.tests);
  }
  // These families must stay adversarial: plain double gets a few percent of them wrong. (The lattice
  // families are not on the list: small integers times powers of two make plain double exact there.)
  if (f == Family::SharedFeature || f == Family::UlpPerturbed || f == Family::TJunction || f == Family::TinyHuge) {
    EXPECT_GT(float_wrong * 1000, kPairsPerFamily);
  }
  std::printf("[ family   ] | %s | %ld | %.1f%% | %ld (%.3f%%) | %ld (%.3f%%) | %ld | %.2f%% |\n",
              std::string(test::family_name(f)).c_str(), kPairsPerFamily, 100.0 * hits / kPairsPerFamily,
              float_wrong, 100.0 * double(float_wrong) / kPairsPerFamily, filter_only_wrong,
              100.0 * double(filter_only_wrong) / kPairsPerFamily, disagreements,
              100.0 * double(stats.exact_fallbacks) / double(stats.tests));
}

std::string family_test_name(const ::testing::TestParamInfo<Family>& p) {
  return std::string(test::family_name(p.param));
}

INSTANTIATE_TEST_SUITE_P(Families, ORACLE_SUITE,
                         ::testing::Values(Family::RandomCube, Family::RandomNear, Family::CoplanarGrid,
                                           Family::SharedFeature, Family::TouchingGrid,
                                           Family::FarOffset, Family::Sliver, Family::UlpPerturbed,
                                           Family::Degenerate, Family::RigidMotion, Family::OffsetFeature,
                                           Family::NearlyCoplanar, Family::TJunction, Family::TinyHuge,
                                           Family::WideCoplanar),
                         family_test_name);

#ifndef CADCLASH_TRIANGLE_SLOW

// Hand-made cases with the answer known independently of any oracle.
// Which stage decides: the float filters and the special cases (shared vertex, one coordinate plane
// with certified 2D signs) without any exact sign; the exact expansion stage (at least one exact
// sign, no CGAL): touching and exactly coplanar non-degenerate triangles; kNoCgal: no CGAL, with or
// without an exact sign depending on the argument order (the exact zero is met in one order only);
// CGAL: degenerate triangles and coordinates outside the exact stage's domain.
enum Path { kFilters, kExactStage, kNoCgal, kCgal };

struct Known {
  const char* what;
  Tri a, b;
  bool intersect;
  Path path;
};

const Tri kUnit{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};

const Known kKnown[] = {
    {"crossing", kUnit, {Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(3, 2, 0.5)}, true, kFilters},
    {"above", kUnit, {Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0, 1, 2)}, false, kFilters},
    {"plane crossed outside", kUnit, {Vec3(2, 2, -1), Vec3(2, 2, 1), Vec3(3, 2, 0)}, false, kFilters},
    {"coplanar overlapping", kUnit, {Vec3(0.2, 0.2, 0), Vec3(2, 0.2, 0), Vec3(0.2, 2, 0)}, true, kFilters},
    {"coplanar contained", kUnit, {Vec3(0.1, 0.1, 0), Vec3(0.2, 0.1, 0), Vec3(0.1, 0.2, 0)}, true, kFilters},
    {"coplanar shared vertex", kUnit, {Vec3(0, 0, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0)}, true, kFilters},
    {"coplanar shared edge", kUnit, {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)}, true, kFilters},
    {"coplanar touching edge", kUnit, {Vec3(0.5, 0.5, 0), Vec3(1, 1, 0), Vec3(0.5, 2, 0)}, true, kExactStage},
    {"coplanar apart", kUnit, {Vec3(0.6, 0.6, 0), Vec3(1, 1, 0), Vec3(0.6, 2, 0)}, false, kNoCgal},
    {"vertex on face", kUnit, {Vec3(0.25, 0.25, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)}, true, kExactStage},
    {"vertex on edge", kUnit, {Vec3(0.5, 0, 0), Vec3(0, -1, 1), Vec3(1, -1, 1)}, true, kExactStage},
    {"edge on edge crossing", kUnit, {Vec3(0.5, -0.5, 0), Vec3(0.5, 0.5, 0), Vec3(0.5, 0, 1)}, true, kExactStage},
    {"shared edge folded", kUnit, {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 1)}, true, kFilters},
    {"shared vertex only", kUnit, {Vec3(0, 0, 0), Vec3(-1, 0, 1), Vec3(0, -1, 1)}, true, kFilters},
    {"segment through face", kUnit, {Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(0.2, 0.2, 0.5)}, true, kCgal},
    {"segment beside face", kUnit, {Vec3(2, 2, -1), Vec3(2, 2, 1), Vec3(2, 2, 0)}, false, kFilters},
    {"point on face", kUnit, {Vec3(0.25, 0.5, 0), Vec3(0.25, 0.5, 0), Vec3(0.25, 0.5, 0)}, true, kCgal},
    {"point above face", kUnit, {Vec3(0.25, 0.5, 1e-300), Vec3(0.25, 0.5, 1e-300), Vec3(0.25, 0.5, 1e-300)},
     false, kFilters},
    {"collinear segments overlapping", {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2)},
     {Vec3(1.5, 1.5, 1.5), Vec3(3, 3, 3), Vec3(1.5, 1.5, 1.5)}, true, kCgal},
    {"collinear segments apart", {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(0.5, 0.5, 0.5)},
     {Vec3(1.5, 1.5, 1.5), Vec3(3, 3, 3), Vec3(2, 2, 2)}, false, kFilters},
    {"skew segments crossing", {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 0, 0)},
     {Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(1, 0.5, 0)}, true, kCgal},
    {"skew segments apart", {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 0, 0)},
     {Vec3(1, -1, 1e-200), Vec3(1, 1, 1e-200), Vec3(1, 0.5, 1e-200)}, false, kFilters},
    {"coplanar segments, end on segment", {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 0, 0)},
     {Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(1, 1, 0)}, true, kCgal},
    {"x-plane overlapping", {Vec3(3, 0, 0), Vec3(3, 1, 0), Vec3(3, 0, 1)},
     {Vec3(3, 0.25, 0.25), Vec3(3, 2, 0.25), Vec3(3, 0.25, 2)}, true, kFilters},
    {"y-plane apart", {Vec3(0, -2, 0), Vec3(1, -2, 0), Vec3(0, -2, 1)},
     {Vec3(0.6, -2, 0.6), Vec3(2, -2, 0.6), Vec3(0.6, -2, 2)}, false, kFilters},
    {"z-plane touching at a vertex on an edge", kUnit,
     {Vec3(0.5, 0.5, 0), Vec3(2, 1, 0), Vec3(1, 2, 0)}, true, kExactStage},
    {"z-plane 1 ulp apart", kUnit,
     {Vec3(0.5, std::nextafter(0.5, 1.0), 0), Vec3(2, 1, 0), Vec3(1, 2, 0)}, false, kExactStage},
    {"z-plane at 1e8", {Vec3(1e8, 1e8, 1e8), Vec3(1e8 + 1e-3, 1e8, 1e8), Vec3(1e8, 1e8 + 1e-3, 1e8)},
     {Vec3(1e8 + 4e-4, 1e8 + 4e-4, 1e8), Vec3(1e8 + 1, 1e8, 1e8), Vec3(1e8, 1e8 + 1, 1e8)}, true, kFilters},
    {"huge coordinates", {Vec3(1e300, 0, 0), Vec3(-1e300, 1e300, 0), Vec3(-1e300, -1e300, 0)},
     {Vec3(0, 0, -1e300), Vec3(0, 0, 1e300), Vec3(1, 0, 1e300)}, true, kCgal},
    // Exactly coplanar in the tilted plane z = x + y (no coordinate plane): the 2D test after projection.
    {"tilted plane, vertex on an edge", {Vec3(0, 0, 0), Vec3(4, 1, 5), Vec3(1, 4, 5)},
     {Vec3(2, 0.5, 2.5), Vec3(3, 0, 3), Vec3(4, 0.5, 4.5)}, true, kExactStage},
    {"tilted plane, just beyond an edge", {Vec3(0, 0, 0), Vec3(4, 1, 5), Vec3(1, 4, 5)},
     {Vec3(2, 0.375, 2.375), Vec3(3, 0, 3), Vec3(4, 0.5, 4.5)}, false, kExactStage},
    {"tilted plane, contained", {Vec3(0, 0, 0), Vec3(4, 1, 5), Vec3(1, 4, 5)},
     {Vec3(1, 1, 2), Vec3(2, 1, 3), Vec3(1, 2, 3)}, true, kExactStage},
    {"tilted plane, sharing an edge", {Vec3(0, 0, 0), Vec3(4, 1, 5), Vec3(1, 4, 5)},
     {Vec3(4, 1, 5), Vec3(1, 4, 5), Vec3(4, 4, 8)}, true, kFilters},
    // Coplanar in the vertical plane y = 3x with B a sliver whose differences round: B's rounded
    // normal has its largest component in z (2.7e11), where the exact one is 0. The projection must
    // take the exact check and fall back to the next axis, not hand the pair to CGAL.
    {"vertical plane, rounded normal points the wrong way",
     {Vec3(0x1p45 + 1, 3 * (0x1p45 + 1), 0), Vec3(0x3p-8, 0x9p-8, 0), Vec3(0x1p44 + 5, 3 * (0x1p44 + 5), 0x1p-10)},
     {Vec3(0x1p44, 0x3p44, -1), Vec3(0x1p44, 0x3p44, 1), Vec3(1, 3, 0)}, true, kExactStage},
    // A vertex or an edge on the other's plane, outside the other triangle (boxes overlap).
    {"vertex on plane, outside", kUnit, {Vec3(0.75, 0.75, 0), Vec3(0, 0, 1), Vec3(1, 0, 1)}, false, kExactStage},
    {"edge in plane, outside", kUnit, {Vec3(0.75, 0.75, 0), Vec3(1, 0.25, 0), Vec3(0, 0, 1)}, false, kNoCgal},
    {"edge in plane, through", kUnit, {Vec3(0.75, 0.75, 0), Vec3(-0.5, 0.25, 0), Vec3(0, 0, 1)}, true, kExactStage},
    // Touching at 2^-600: the double filter's floor leaves every sign open; the exact signs decide.
    {"tiny touching", {Vec3(0, 0, 0), Vec3(0x1p-600, 0, 0), Vec3(0, 0x1p-600, 0)},
     {Vec3(0x1p-602, 0x1p-602, 0), Vec3(0, 0, 0x1p-600), Vec3(0x1p-600, 0x1p-600, 0x1p-600)}, true, kExactStage},
};

TEST(TrianglesIntersect, KnownCases) {
  for (const Known& k : kKnown) {
    for (int swap = 0; swap < 2; ++swap) {
      const Tri& a = swap ? k.b : k.a;
      const Tri& b = swap ? k.a : k.b;
      TrianglePredicateStats stats;
      EXPECT_EQ(intersect(a, b, stats), k.intersect) << k.what;
      EXPECT_EQ(test::oracle_intersect(a, b), k.intersect) << k.what << " (oracle)";
      EXPECT_EQ(stats.tests, 1u);
      EXPECT_EQ(stats.exact_fallbacks, k.path == kCgal ? 1u : 0u) << k.what;
      if (k.path == kFilters) {
        EXPECT_EQ(stats.exact_signs, 0u) << k.what;
      }
      if (k.path == kExactStage) {
        EXPECT_GT(stats.exact_signs, 0u) << k.what;
      }
    }
  }
}

// A vertex of B on A's plane, nudged by one ulp either way, flips between crossing, touching and
// apart; the answers must follow the nudge, and exact touching must be settled by the exact stage
// (an exact zero), without CGAL.
TEST(TrianglesIntersect, OneUlpDecides) {
  for (double base : {0.0, 1.0, 0.1, 1e8}) {
    const Tri a{Vec3(0, 0, base), Vec3(4, 0, base), Vec3(0, 4, base)};
    for (int dir : {-1, 0, 1}) {
      const double zb = dir == 0 ? base : std::nextafter(base, dir * HUGE_VAL);
      const Tri b{Vec3(1, 1, zb), Vec3(1, 2, base + 1), Vec3(2, 1, base + 1)};
      TrianglePredicateStats stats;
      EXPECT_EQ(intersect(a, b, stats), dir <= 0) << "base " << base << " dir " << dir;
      // Subnormal nudges too (base 0: ±2^-1074) are decided by the exact signs, not by CGAL's
      // whole-call fallback.
      EXPECT_EQ(stats.exact_fallbacks, 0u) << "base " << base << " dir " << dir;
      if (dir == 0) {
        EXPECT_GT(stats.exact_signs, 0u);
      }
    }
  }
}

// The exact path (CGAL, with its rounding-mode switches) runs concurrently in the narrow phase.
TEST(TrianglesIntersect, SameAnswersFromManyThreads) {
  test::Rng rng(99);
  std::vector<TriPair> pairs;
  for (int i = 0; i < 20000; ++i) pairs.push_back(test::make_case(static_cast<Family>(i % 10), rng));
  std::vector<char> serial(pairs.size()), parallel(pairs.size());
  TrianglePredicateStats stats;
  for (std::size_t i = 0; i < pairs.size(); ++i) serial[i] = intersect(pairs[i].a, pairs[i].b, stats);
  const long n = static_cast<long>(pairs.size());
#pragma omp parallel for schedule(dynamic, 64) num_threads(4)
  for (long i = 0; i < n; ++i) {
    TrianglePredicateStats local;
    parallel[i] = intersect(pairs[i].a, pairs[i].b, local);
  }
  EXPECT_EQ(serial, parallel);
  EXPECT_GT(stats.exact_fallbacks, 0u);
}

#endif  // CADCLASH_TRIANGLE_SLOW

}  // namespace
}  // namespace cadclash
