// cadclash/testing/benchmark_switches.h — switches for benchmarks and tests only. The library never
// turns them on; a program that does measures something other than what cadclash answers.
//
// Part of cadclash::collide.
#pragma once

namespace cadclash::testing {

// Benchmark-only switch for bench/bench_compare's "float only" rows: while on, cadclash::triangles_intersect
// answers a call its float filters cannot decide with "intersect" (a float test calls a sign within
// rounding of zero touching) instead of asking CGAL; exact_fallbacks still counts those calls.
// Process-wide, off by default; the library never turns it on. Not for concurrent toggling.
void set_float_only_for_benchmark(bool on);

}  // namespace cadclash::testing
