// Speed of the triangle predicates on the test generators' families. Each benchmark loops over a
// fixed set of 4096 pairs; items/s is pairs per second, `fallback` the share of calls sent to CGAL
// (triangles_intersect_exact), `exact_signs` the orientation signs settled by the exact stage (CGAL's
// filtered orientation) per call (both per pass over the set, so independent of the iteration count).
//   build-rel/bench/bench_triangle_predicates --benchmark_min_time=0.2
#include "test_triangle_cases.h"
#include "cadclash/geometry.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <string>
#include <vector>

namespace {

using cadclash::Vec3;
using cadclash::TrianglePredicateStats;
using cadclash::test::Family;
using cadclash::test::TriPair;

enum class Set { RandomDisjoint, RandomDisjointBoxesOverlap, RandomIntersecting, Adversarial };

bool boxes_overlap(const TriPair& p) {
  for (int k = 0; k < 3; ++k) {
    const double amin = std::min({p.a[0][k], p.a[1][k], p.a[2][k]}), amax = std::max({p.a[0][k], p.a[1][k], p.a[2][k]});
    const double bmin = std::min({p.b[0][k], p.b[1][k], p.b[2][k]}), bmax = std::max({p.b[0][k], p.b[1][k], p.b[2][k]});
    if (amax < bmin || bmax < amin) return false;
  }
  return true;
}

std::vector<TriPair> make_set(Set set, Family adversarial = Family::RandomCube) {
  cadclash::test::Rng rng(2024);
  std::vector<TriPair> out;
  while (out.size() < 4096) {
    const Family f = set == Set::Adversarial ? adversarial : (rng.integer(0, 1) ? Family::RandomCube : Family::RandomNear);
    const TriPair p = cadclash::test::make_case(f, rng);
    const bool hit = cadclash::test::oracle_intersect(p.a, p.b);
    switch (set) {
      case Set::RandomDisjoint: if (!hit) out.push_back(p); break;
      case Set::RandomDisjointBoxesOverlap: if (!hit && boxes_overlap(p)) out.push_back(p); break;
      case Set::RandomIntersecting: if (hit) out.push_back(p); break;
      case Set::Adversarial: out.push_back(p); break;
    }
  }
  return out;
}

template <class F>
void run(benchmark::State& state, const std::vector<TriPair>& pairs, F&& f) {
  TrianglePredicateStats stats;
  std::size_t hits = 0;
  for (auto _ : state) {
    for (const TriPair& p : pairs) hits += f(p, stats);
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * pairs.size()));
  if (stats.tests) {
    // Share of calls decided by CGAL, and exact orientation signs (exact stage) per call.
    state.counters["fallback"] = double(stats.exact_fallbacks) / double(stats.tests);
    state.counters["exact_signs"] = double(stats.exact_signs) / double(stats.tests);
  }
  // Seconds per pair, printed with an SI prefix (e.g. 21.5n = 21.5 ns).
  state.counters["per_pair"] = benchmark::Counter(double(state.iterations() * pairs.size()),
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

bool filtered(const TriPair& p, TrianglePredicateStats& s) {
  return cadclash::triangles_intersect(p.a[0], p.a[1], p.a[2], p.b[0], p.b[1], p.b[2], s);
}
bool exact(const TriPair& p, TrianglePredicateStats&) {
  return cadclash::triangles_intersect_exact(p.a[0], p.a[1], p.a[2], p.b[0], p.b[1], p.b[2]);
}
bool oracle(const TriPair& p, TrianglePredicateStats&) { return cadclash::test::oracle_intersect(p.a, p.b); }
bool distance(const TriPair& p, TrianglePredicateStats& s) {
  return cadclash::triangle_distance(p.a[0], p.a[1], p.a[2], p.b[0], p.b[1], p.b[2], s) < 0.01;
}
bool within(const TriPair& p, TrianglePredicateStats& s) {
  return cadclash::triangles_within(p.a[0], p.a[1], p.a[2], p.b[0], p.b[1], p.b[2], 0.01, s);
}

void register_all() {
  struct Named {
    std::string name;
    std::vector<TriPair> pairs;
  };
  static std::vector<Named> sets;
  sets.push_back({"random_disjoint", make_set(Set::RandomDisjoint)});
  sets.push_back({"random_disjoint_boxes_overlap", make_set(Set::RandomDisjointBoxesOverlap)});
  sets.push_back({"random_intersecting", make_set(Set::RandomIntersecting)});
  for (Family f : {Family::CoplanarGrid, Family::SharedFeature, Family::TouchingGrid, Family::FarOffset,
                   Family::Sliver, Family::UlpPerturbed, Family::Degenerate, Family::RigidMotion})
    sets.push_back({std::string(cadclash::test::family_name(f)), make_set(Set::Adversarial, f)});
  for (const Named& s : sets) {
    const auto* pairs = &s.pairs;
    benchmark::RegisterBenchmark(("intersect/" + s.name).c_str(),
                                 [pairs](benchmark::State& st) { run(st, *pairs, filtered); });
    benchmark::RegisterBenchmark(("intersect_exact_only/" + s.name).c_str(),
                                 [pairs](benchmark::State& st) { run(st, *pairs, exact); });
    benchmark::RegisterBenchmark(("oracle_epeck/" + s.name).c_str(),
                                 [pairs](benchmark::State& st) { run(st, *pairs, oracle); });
    benchmark::RegisterBenchmark(("distance/" + s.name).c_str(),
                                 [pairs](benchmark::State& st) { run(st, *pairs, distance); });
    benchmark::RegisterBenchmark(("within_0.01/" + s.name).c_str(),
                                 [pairs](benchmark::State& st) { run(st, *pairs, within); });
  }
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
