// cadclash/trajectory.h — paths of poses replayed on a prepared Scene: a CSV of steps parsed into
// rows, each step's rows applied, and the scene checked after each (collide.h includes it).
//
// Part of cadclash::collide; the conventions are model.h's.
#pragma once

#include "cadclash/collide.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace cadclash {

// One row of a trajectory: instance `path` gets the absolute world pose at step `step`.
struct TrajectoryRow {
  std::int64_t step = 0;
  std::string path;
  Pose pose = Pose::Identity();
  std::int64_t line = 0;  // 1-based line in the CSV
};

// Parses CSV text "step,instance_path,tx,ty,tz,qw,qx,qy,qz" (optional header line starting with
// "step"; blank lines and lines starting with '#' skipped). Bad rows become diagnostics naming
// `file` and the line and are skipped; quaternions are normalised (a zero quaternion is an error);
// a translation outside the supported range (model.h) is an error.
std::vector<TrajectoryRow> parse_trajectory(const std::string& text, const std::string& file,
                                            std::vector<Diagnostic>& diagnostics);

// Applies the rows of the step that starts at rows[k] (the rows that follow with the same step
// number) to `scene`; a row naming an unknown instance becomes a warning naming `file` and its line
// and is skipped. Returns the index of the first row after the step. Precondition: k < rows.size().
std::size_t apply_trajectory_step(Scene& scene, std::span<const TrajectoryRow> rows, std::size_t k,
                                  std::vector<Diagnostic>& diagnostics, const std::string& file);

// The warning a replay gives when its time budget ran out before the step that starts at rows[k]:
// how many steps from there on were not checked, at that row's line of `file`.
// Precondition: k < rows.size().
Diagnostic steps_not_checked(std::span<const TrajectoryRow> rows, std::size_t k, const std::string& file);

struct StepResult {
  std::int64_t step = 0;
  Report report;
};

// Replays rows on `scene`: rows with equal consecutive step numbers are applied together, then the
// scene is checked. Rows naming unknown instances become diagnostics (warning) and are skipped.
// Budgets: options.time_budget_seconds covers the whole replay. When it runs out, the step being
// checked returns a partial report (Report::complete false), the later steps are not checked (not
// in the result) and a warning naming `file` and the first unchecked step's line says how many were
// left. options.memory_budget_bytes applies to each step's check() on its own.
std::vector<StepResult> replay_trajectory(Scene& scene, std::span<const TrajectoryRow> rows,
                                          const CollideOptions& options,
                                          std::vector<Diagnostic>& diagnostics, const std::string& file = {});

}  // namespace cadclash
