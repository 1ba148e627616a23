// Trajectories: CSV of per-step instance poses, replayed on a Scene.
#include "cadclash/collide.h"

#include "cadclash/internal/progress_meter.h"
#include "replay_budget.h"

#include <cassert>
#include <chrono>
#include <charconv>
#include <cmath>
#include <sstream>

namespace cadclash {
namespace {

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return std::string(s.substr(b, e - b + 1));
}

bool parse_double(const std::string& s, double& v) {
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  return r.ec == std::errc() && r.ptr == end && std::isfinite(v);
}

}  // namespace

std::vector<TrajectoryRow> parse_trajectory(const std::string& text, const std::string& file,
                                            std::vector<Diagnostic>& diagnostics) {
  std::vector<TrajectoryRow> rows;
  std::istringstream in(text);
  std::string line;
  std::int64_t number = 0;
  auto error = [&](const std::string& message) {
    diagnostics.push_back({Severity::Error, file, number, -1, message});
  };
  while (std::getline(in, line)) {
    ++number;
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    std::vector<std::string> fields;
    std::size_t start = 0;
    while (true) {
      const auto comma = t.find(',', start);
      fields.push_back(trim(std::string_view(t).substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (rows.empty() && fields[0] == "step") continue;  // header
    if (fields.size() != 9) {
      error("expected 9 fields 'step,instance_path,tx,ty,tz,qw,qx,qy,qz', found " + std::to_string(fields.size()));
      continue;
    }
    TrajectoryRow row;
    row.line = number;
    const auto r = std::from_chars(fields[0].data(), fields[0].data() + fields[0].size(), row.step);
    if (r.ec != std::errc() || r.ptr != fields[0].data() + fields[0].size()) {
      error("step '" + fields[0] + "' is not an integer");
      continue;
    }
    row.path = fields[1];
    if (row.path.empty()) {
      error("empty instance path");
      continue;
    }
    double v[7];
    bool ok = true;
    for (int k = 0; k < 7 && ok; ++k) {
      if (!parse_double(fields[static_cast<std::size_t>(k) + 2], v[k])) {
        error("field " + std::to_string(k + 3) + " '" + fields[static_cast<std::size_t>(k) + 2] + "' is not a finite number");
        ok = false;
      }
    }
    for (int k = 0; k < 3 && ok; ++k) {
      if (!in_supported_range(v[k])) {
        error("field " + std::to_string(k + 3) + " '" + fields[static_cast<std::size_t>(k) + 2] +
              "' is outside the supported range (magnitude <= 2^128, about 3.4e38 mm)");
        ok = false;
      }
    }
    if (!ok) continue;
    Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    const double n = q.norm();
    if (!(n > 1e-12)) {
      error("quaternion (qw,qx,qy,qz) is zero");
      continue;
    }
    if (!std::isfinite(n)) {
      error("quaternion (qw,qx,qy,qz) is too large to normalise");
      continue;
    }
    q.coeffs() /= n;
    row.pose = Pose::Identity();
    row.pose.linear() = q.toRotationMatrix();
    row.pose.translation() = Vec3(v[0], v[1], v[2]);
    rows.push_back(std::move(row));
  }
  return rows;
}

namespace detail {

std::map<InstanceId, Pose> step_poses(const Scene& scene, std::span<const TrajectoryRow> rows, std::size_t& k,
                                      std::vector<Diagnostic>& diagnostics, const std::string& file) {
  assert(k < rows.size());
  const std::int64_t step = rows[k].step;
  std::map<InstanceId, Pose> poses;
  for (; k < rows.size() && rows[k].step == step; ++k) {
    const InstanceId id = scene.find_instance(rows[k].path);
    if (id == kInvalidId) {
      diagnostics.push_back({Severity::Warning, file, rows[k].line, -1,
                             "no instance with path '" + rows[k].path + "'; row skipped"});
      continue;
    }
    poses[id] = rows[k].pose;
  }
  return poses;
}

}  // namespace detail

std::size_t apply_trajectory_step(Scene& scene, std::span<const TrajectoryRow> rows, std::size_t k,
                                  std::vector<Diagnostic>& diagnostics, const std::string& file) {
  for (const auto& [id, pose] : detail::step_poses(scene, rows, k, diagnostics, file)) scene.set_pose(id, pose);
  return k;
}

Diagnostic steps_not_checked(std::span<const TrajectoryRow> rows, std::size_t k, const std::string& file) {
  assert(k < rows.size());
  std::size_t steps_left = 0;
  for (std::size_t r = k; r < rows.size(); ++r) steps_left += (r == k || rows[r].step != rows[r - 1].step);
  return {Severity::Warning, file, rows[k].line, -1,
          "time budget ran out: " + std::to_string(steps_left) + " steps from step " + std::to_string(rows[k].step) +
              " on were not checked"};
}

std::vector<StepResult> replay_trajectory(Scene& scene, std::span<const TrajectoryRow> rows,
                                          const CollideOptions& options, std::vector<Diagnostic>& diagnostics,
                                          const std::string& file) {
  std::vector<StepResult> results;
  // The time budget covers the whole replay: each step gets what the earlier ones left.
  const auto start = std::chrono::steady_clock::now();
  std::size_t steps = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) steps += k == 0 || rows[k].step != rows[k - 1].step;
  detail::ProgressMeter meter(&options.progress, ProgressStage::TrajectoryStep, steps,
                              rows.empty() ? std::string() : std::to_string(rows.front().step));
  std::size_t k = 0;
  while (k < rows.size()) {
    const std::int64_t step = rows[k].step;
    CollideOptions step_options = options;
    step_options.progress = nullptr;  // the replay reports its steps, not the checks inside them
    const std::optional<double> left = detail::replay_time_left(options, start, results);
    if (!left) {
      diagnostics.push_back(steps_not_checked(rows, k, file));
      break;
    }
    step_options.time_budget_seconds = *left;
    k = apply_trajectory_step(scene, rows, k, diagnostics, file);
    results.push_back({step, scene.check(step_options)});
    if (meter.active()) meter.add(1, std::to_string(step));
  }
  meter.finish();
  return results;
}

}  // namespace cadclash
