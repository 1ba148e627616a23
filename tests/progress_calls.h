// What the progress tests record of a ProgressCallback (collide.h, "Progress of long work") and
// how they compare reports. Shared by tests/collide/test_progress.cpp and
// tests/import/test_import_progress.cpp.
#pragma once

#include "cadclash/collide.h"
#include "cadclash/report.h"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace cadclash::testing {

// Records every call; notes two calls at once, and calls on another thread than the one that made
// the callback.
struct ProgressCalls {
  std::mutex lock;
  std::atomic<int> inside{0};
  bool overlapped = false;
  bool other_thread = false;
  std::vector<Progress> seen;

  ProgressCallback callback() {
    const std::thread::id maker = std::this_thread::get_id();
    return [this, maker](const Progress& p) {
      if (inside.fetch_add(1) != 0) overlapped = true;
      {
        const std::lock_guard<std::mutex> hold(lock);
        if (std::this_thread::get_id() != maker) other_thread = true;
        seen.push_back(p);
      }
      inside.fetch_sub(1);
    };
  }
  std::vector<Progress> of(ProgressStage stage) const {
    std::vector<Progress> out;
    for (const Progress& p : seen)
      if (p.stage == stage) out.push_back(p);
    return out;
  }
};

// The runs of one stage in `calls`: each starts at done 0, never falls and ends at its first call
// with done == total. Returns the runs' labels (at their start) and their totals.
inline std::vector<std::pair<std::string, std::size_t>> progress_runs(const std::vector<Progress>& calls,
                                                                     ProgressStage stage) {
  std::vector<std::pair<std::string, std::size_t>> out;
  bool open = false;
  std::size_t last = 0;
  for (const Progress& p : calls) {
    if (p.stage != stage) continue;
    EXPECT_LE(p.done, p.total);
    if (!open) {
      EXPECT_EQ(p.done, 0u) << p.label;
      out.emplace_back(p.label, p.total);
      open = true;
    } else {
      EXPECT_GE(p.done, last) << p.label;
      EXPECT_EQ(p.total, out.back().second);
    }
    last = p.done;
    if (p.done == p.total) open = false;
  }
  EXPECT_FALSE(open) << "a run did not end at done == total";
  return out;
}

// The JSON report of one query without timings: what must not change with a callback.
inline std::string report_bytes(const Model& m, const Report& r) {
  CheckReport c;
  c.query = query_report(m, r);
  return check_report_text(c, {.timings = false});
}

}  // namespace cadclash::testing
