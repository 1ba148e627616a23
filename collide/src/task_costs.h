// What each surface pair's triangle-level task cost in a scene's last check, so the next check can
// start the longest first. Internal to cadclash::collide.
//
// Why: a path step holds a handful of tasks (the moving nut of bench_scale_path: ~14, the largest a
// fifth of the step), taken one at a time by the team in task order. When a long task came last,
// one thread worked it alone while the other waited: 4-14 us of a 0.125 ms step on 2 threads. The
// tasks of consecutive steps are mostly the same pairs with about the same cost, so the last check's
// times are a good forecast, and longest-first leaves only short tasks for the end (LPT order).
// Only the order changes: each task's answer depends on it alone (stage_triangles.cpp).
#pragma once

#include "cadclash/model.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

namespace cadclash::detail {

class TaskCosts {
 public:
  // A task: its instance pair and surface pair.
  struct Key {
    std::uint64_t instances = 0, surfaces = 0;
    friend bool operator<(const Key& x, const Key& y) {
      return x.instances != y.instances ? x.instances < y.instances : x.surfaces < y.surfaces;
    }
    friend bool operator==(const Key& x, const Key& y) = default;
  };
  static Key key(InstanceId a, InstanceId b, SurfaceId sa, SurfaceId sb) {
    return {std::uint64_t{a} << 32 | b, std::uint64_t{sa} << 32 | sb};
  }

  // The indices of `tasks` by forecast cost, largest first: a task the last check did not run first
  // of all (its cost is unknown), ties in index order.
  std::vector<std::uint32_t> longest_first(std::span<const Key> tasks) const {
    std::vector<std::pair<float, std::uint32_t>> by(tasks.size());
    for (std::size_t k = 0; k < tasks.size(); ++k) by[k] = {forecast(tasks[k]), static_cast<std::uint32_t>(k)};
    std::stable_sort(by.begin(), by.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
    std::vector<std::uint32_t> order(tasks.size());
    for (std::size_t k = 0; k < by.size(); ++k) order[k] = by[k].second;
    return order;
  }

  // Forgets what it knew and keeps these tasks' costs (any unit; seconds[k] is tasks[k]'s).
  void remember(std::span<const Key> tasks, std::span<const float> seconds) {
    last_.resize(tasks.size());
    for (std::size_t k = 0; k < tasks.size(); ++k) last_[k] = {tasks[k], seconds[k]};
    std::sort(last_.begin(), last_.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  }

  void clear() { last_.clear(); }

 private:
  float forecast(const Key& k) const {
    auto it = std::lower_bound(last_.begin(), last_.end(), k, [](const auto& e, const Key& x) { return e.first < x; });
    return it != last_.end() && it->first == k ? it->second : std::numeric_limits<float>::infinity();
  }

  std::vector<std::pair<Key, float>> last_;  // sorted by key
};

}  // namespace cadclash::detail
