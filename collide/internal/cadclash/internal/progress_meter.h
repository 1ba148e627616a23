// cadclash/internal/progress_meter.h — one run of a progress stage (collide.h, "Progress of long
// work") as the library's loops report it. Internal to cadclash, shared by collide and tessellate
// (their CMakeLists add collide/internal to their private include path); not installed, not API.
#pragma once

#include "cadclash/collide.h"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <string>
#include <string_view>
#include <thread>

namespace cadclash::detail {

// Made and finished on the thread that runs the stage; add() may be called on any thread, inside
// OpenMP loops too (the thread that meets a parallel loop is thread 0 of its team). The callback is
// called only on the meter's own thread, so its calls never overlap: once as the meter is made
// (done = 0), then when add() on that thread sees the whole percentage changed, and by finish();
// never again once a call had done == total (the run's end, the first call when total is 0).
// Without a callback every member returns at once.
class ProgressMeter {
 public:
  // `callback` may be null or empty: nothing is reported.
  ProgressMeter(const ProgressCallback* callback, ProgressStage stage, std::size_t total, std::string label = {})
      : callback_(callback != nullptr && *callback ? callback : nullptr), owner_(std::this_thread::get_id()) {
    if (callback_ == nullptr) return;
    progress_.stage = stage;
    progress_.total = total;
    progress_.label = std::move(label);
    (*callback_)(progress_);
  }
  ProgressMeter(const ProgressMeter&) = delete;
  ProgressMeter& operator=(const ProgressMeter&) = delete;

  bool active() const { return callback_ != nullptr; }

  // `n` more items finished; `label`, when not empty, names what finished (kept for later calls).
  void add(std::size_t n = 1, std::string_view label = {}) {
    if (callback_ == nullptr) return;
    const std::size_t done = done_.fetch_add(n, std::memory_order_relaxed) + n;
    if (std::this_thread::get_id() != owner_ || ended() || percent(done) == reported_percent_) return;
    report(done, label);
  }

  // Every item finished (or skipped): the run's last call, done = total. On the meter's thread.
  void finish(std::string_view label = {}) {
    if (callback_ != nullptr && !ended()) report(progress_.total, label);
  }

 private:
  bool ended() const { return progress_.done == progress_.total; }
  std::size_t percent(std::size_t done) const {
    return progress_.total == 0 ? 100 : std::min(done, progress_.total) * 100 / progress_.total;
  }
  void report(std::size_t done, std::string_view label) {
    progress_.done = std::min(done, progress_.total);
    reported_percent_ = percent(done);
    if (!label.empty()) progress_.label = label;
    (*callback_)(progress_);
  }

  const ProgressCallback* callback_ = nullptr;
  std::thread::id owner_;
  Progress progress_;
  std::atomic<std::size_t> done_{0};
  std::size_t reported_percent_ = 0;
};

}  // namespace cadclash::detail
