// limit_mesher_threads: OCCT's parallel loops, which BRepMesh meshes a part's faces with, run on at
// most as many threads as asked. Its own binary: the limit is process-wide.
#include "cadclash/tessellate.h"

#include <gtest/gtest.h>

#include <OSD_Parallel.hxx>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

namespace {

// The most iterations of an OSD_Parallel::For that ran at once (each sleeps, so that any threads
// the loop has overlap).
int most_at_once() {
  std::atomic<int> running{0}, most{0};
  OSD_Parallel::For(0, 32, [&](int) {
    const int now = ++running;
    int seen = most.load();
    while (now > seen && !most.compare_exchange_weak(seen, now)) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    --running;
  });
  return most.load();
}

TEST(MesherThreads, OcctLoopsRunOnTheThreadsAsked) {
  ASSERT_EQ(cadclash::limit_mesher_threads(1), 1);
  EXPECT_TRUE(OSD_Parallel::ToUseOcctThreads());
  EXPECT_EQ(most_at_once(), 1);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  ASSERT_EQ(cadclash::limit_mesher_threads(2), 2);  // resized after use
  const int most = most_at_once();
  EXPECT_LE(most, 2);
  if (cores >= 2) {
    EXPECT_EQ(most, 2);  // sleeping iterations on two threads overlap
  }
  // 0: back on OCCT's default, TBB's scheduler on every core.
  EXPECT_EQ(cadclash::limit_mesher_threads(0), OSD_Parallel::NbLogicalProcessors());
  EXPECT_FALSE(OSD_Parallel::ToUseOcctThreads());
  EXPECT_EQ(most_at_once(), std::min(OSD_Parallel::NbLogicalProcessors(), 32));
}

// A whole run on N threads: OCCT's pool of N below the machine's cores, TBB's (every core) from there.
TEST(MesherThreads, HoldForARunPoolsOnlyBelowTheCores) {
  const int cores = OSD_Parallel::NbLogicalProcessors();
  EXPECT_EQ(cadclash::hold_mesher_threads(1), 1);
  EXPECT_EQ(OSD_Parallel::ToUseOcctThreads(), cores > 1);
  EXPECT_EQ(cadclash::hold_mesher_threads(cores), cores);
  EXPECT_FALSE(OSD_Parallel::ToUseOcctThreads());
  EXPECT_EQ(cadclash::hold_mesher_threads(0), cores);
  EXPECT_FALSE(OSD_Parallel::ToUseOcctThreads());
}

}  // namespace
