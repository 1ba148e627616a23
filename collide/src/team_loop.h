// The stages' parallel loops: on a team when there is something to share, else on the calling
// thread. Internal to cadclash::collide.
//
// Why not an OpenMP region with an if clause: a false clause still starts a team of one, ~0.34 us
// in libgomp each time, and a step of a path ran five such loops with nothing in them (plus every
// loop of a one-thread check): 1.7 us of a 0.066 ms step at 0.01 mm.
#pragma once

#include <cstddef>

namespace cadclash::detail {

// Whether a loop of n items goes to a team of `threads`: `worth` (the caller's own threshold) and
// at least two threads and two items.
inline bool use_team(std::ptrdiff_t n, int threads, bool worth) { return worth && threads > 1 && n >= 2; }

// body(i) for every i in [0, n): on a team of `threads` with OpenMP's dynamic schedule (chunks of
// one) when use_team(n, threads, worth), else in order on the calling thread.
template <class Body>
void dynamic_loop(std::ptrdiff_t n, int threads, bool worth, Body&& body) {
  if (!use_team(n, threads, worth)) {
    for (std::ptrdiff_t i = 0; i < n; ++i) body(i);
    return;
  }
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (std::ptrdiff_t i = 0; i < n; ++i) body(i);
}

// The same with the schedule of omp_set_schedule (set_schedule: CollideOptions::schedule).
template <class Body>
void runtime_loop(std::ptrdiff_t n, int threads, bool worth, Body&& body) {
  if (!use_team(n, threads, worth)) {
    for (std::ptrdiff_t i = 0; i < n; ++i) body(i);
    return;
  }
#pragma omp parallel for num_threads(threads) schedule(runtime)
  for (std::ptrdiff_t i = 0; i < n; ++i) body(i);
}

}  // namespace cadclash::detail
