// What a replay (replay_trajectory, replay_continuous) has left of its time budget before a step.
// Internal to collide.
#pragma once

#include "cadclash/trajectory.h"

#include <chrono>
#include <map>
#include <span>
#include <optional>
#include <string>
#include <vector>

namespace cadclash::detail {

// The seconds `options.time_budget_seconds` leaves a replay that started at `start` for its next step
// (0: no budget), or nullopt when it has run out: none left, or the last step checked was stopped by
// the time budget.
inline std::optional<double> replay_time_left(const CollideOptions& options,
                                              std::chrono::steady_clock::time_point start,
                                              const std::vector<StepResult>& done) {
  if (options.time_budget_seconds <= 0.0) return 0.0;
  const double left =
      options.time_budget_seconds - std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const bool stopped = !done.empty() && !done.back().report.complete &&
                       done.back().report.stopped_by.find("time") != std::string::npos;
  if (left <= 0.0 || stopped) return std::nullopt;
  return left;
}

// The poses the step that starts at rows[k] gives (the last row for an instance named twice), and
// the index of the first row after it; a row naming an unknown instance becomes a warning naming
// `file` and its line and is skipped. Precondition: k < rows.size().
std::map<InstanceId, Pose> step_poses(const Scene& scene, std::span<const TrajectoryRow> rows, std::size_t& k,
                                      std::vector<Diagnostic>& diagnostics, const std::string& file);

}  // namespace cadclash::detail
