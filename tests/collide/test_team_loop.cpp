// The stages' loops (team_loop.h): every index once, whether a team runs them or the calling thread
// alone, and a team only when there are two threads, two items and the caller finds it worth it.
#include "team_loop.h"

#include <gtest/gtest.h>

#include <omp.h>

#include <atomic>
#include <cstddef>
#include <vector>

namespace cadclash {
namespace {

using detail::use_team;

template <class Loop>
void expect_each_index_once(Loop loop) {
  for (int threads : {1, 2, 3})
    for (bool worth : {false, true})
      for (std::ptrdiff_t n : {0, 1, 2, 7, 100}) {
        std::vector<std::atomic<int>> seen(static_cast<std::size_t>(n));
        std::atomic<int> deepest{0};  // omp_get_level(): regions around the body, a team of one counted
        loop(n, threads, worth, [&](std::ptrdiff_t i) {
          seen[static_cast<std::size_t>(i)].fetch_add(1);
          int level = omp_get_level(), was = deepest.load();
          while (level > was && !deepest.compare_exchange_weak(was, level)) {
          }
        });
        for (std::ptrdiff_t i = 0; i < n; ++i)
          EXPECT_EQ(seen[static_cast<std::size_t>(i)].load(), 1) << "threads " << threads << " n " << n << " i " << i;
        // Without a team the body runs outside any region (a team of one is what the helper saves).
        if (n > 0) {
          EXPECT_EQ(deepest.load(), use_team(n, threads, worth) ? 1 : 0) << "threads " << threads << " n " << n;
        }
      }
}

TEST(TeamLoop, DynamicVisitsEveryIndexOnce) {
  expect_each_index_once([](auto n, int t, bool w, auto body) { detail::dynamic_loop(n, t, w, body); });
}

TEST(TeamLoop, RuntimeVisitsEveryIndexOnce) {
  omp_set_schedule(omp_sched_guided, 1);
  expect_each_index_once([](auto n, int t, bool w, auto body) { detail::runtime_loop(n, t, w, body); });
}

TEST(TeamLoop, ATeamOnlyForTwoThreadsTwoItemsAndTheCallersSay) {
  EXPECT_FALSE(use_team(100, 1, true));
  EXPECT_FALSE(use_team(1, 2, true));
  EXPECT_FALSE(use_team(0, 2, true));
  EXPECT_FALSE(use_team(100, 2, false));
  EXPECT_TRUE(use_team(2, 2, true));
}

}  // namespace
}  // namespace cadclash
