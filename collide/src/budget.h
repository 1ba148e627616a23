// The time budget of a query as a shared deadline that parallel work items poll, and the
// budget-aware form of require_triangles. Internal to cadclash::collide.
#pragma once

#include "cadclash/collide.h"

#include <atomic>
#include <chrono>
#include <span>
#include <vector>

namespace cadclash::detail {

// Once expired() has returned true it keeps returning true, so a loop that skips its remaining work
// items never resumes half-way (OpenMP loops cannot break).
class Deadline {
 public:
  using Clock = std::chrono::steady_clock;
  Deadline() = default;  // never expires
  Deadline(Clock::time_point start, double seconds)
      : active_(seconds > 0.0),
        at_(start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds))) {}

  bool expired() const {
    if (!active_) return false;
    if (hit_.load(std::memory_order_relaxed)) return true;
    if (Clock::now() < at_) return false;
    hit_.store(true, std::memory_order_relaxed);
    return true;
  }

 private:
  bool active_ = false;
  Clock::time_point at_{};
  mutable std::atomic<bool> hit_{false};
};

// require_triangles (model.h) on `threads` threads (<= 0: all available) that stops asking the
// sources once `deadline` has expired; surfaces not reached keep has_triangles == false and get no
// diagnostic. `failed`, when given, receives the surface of each returned diagnostic, in order.
std::vector<Diagnostic> require_triangles(Model& model, std::span<const SurfaceId> surfaces, double deflection,
                                          int threads, const Deadline& deadline, std::vector<SurfaceId>* failed = nullptr);

}  // namespace cadclash::detail
