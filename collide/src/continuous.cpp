// A whole path checked continuously (trajectory.h, replay_continuous): the steps as a replay checks
// them, the motion between them by check_motion, and the spans joined into one timeline per pair.
#include "cadclash/trajectory.h"

#include "cadclash/internal/progress_meter.h"
#include "replay_budget.h"

#include <cassert>
#include <chrono>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace cadclash {
namespace {

// Appends `s` (path time, after every span already in `into`) to `into`, joining it to the last one
// when both are proved in contact at their ends and meet.
void append_span(std::vector<MotionSpan>& into, const MotionSpan& s) {
  if (!into.empty() && into.back().contact_at_ends && s.contact_at_ends && into.back().s1 == s.s0) {
    into.back().s1 = s.s1;
    return;
  }
  into.push_back(s);
}

MotionSpan to_path_time(const MotionSpan& s, double t0, double t1) {
  // Exact at the ends: s = 0 and s = 1 give t0 and t1.
  auto at = [&](double f) { return f == 1.0 ? t1 : t0 + f * (t1 - t0); };
  return {at(s.s0), at(s.s1), s.contact_at_ends};
}

}  // namespace

PathResult replay_continuous(Scene& scene, const Model& model, std::span<const TrajectoryRow> rows,
                             const CollideOptions& options, const MotionOptions& motion,
                             std::vector<Diagnostic>& diagnostics, const std::string& file) {
  assert(motion.resolution > 0.0);
  PathResult out;
  const auto start = std::chrono::steady_clock::now();
  std::size_t steps = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) steps += k == 0 || rows[k].step != rows[k - 1].step;
  detail::ProgressMeter meter(&options.progress, ProgressStage::TrajectoryStep, steps,
                              rows.empty() ? std::string() : std::to_string(rows.front().step));
  // Per instance pair, its timeline so far, and per surface pair of it.
  std::map<std::pair<InstanceId, InstanceId>, PairMotion> timeline;
  std::map<std::pair<InstanceId, InstanceId>, std::map<std::pair<SurfaceId, SurfaceId>, std::vector<MotionSpan>>> surfaces;
  // Per instance pair, its closest approach over each stretch (path time).
  std::map<std::pair<InstanceId, InstanceId>, std::vector<ClosestApproach>> closest;
  std::size_t k = 0;
  while (k < rows.size()) {
    const std::int64_t step = rows[k].step;
    CollideOptions step_options = options;
    step_options.progress = nullptr;  // the path reports its steps, not the checks inside them
    const std::optional<double> left = detail::replay_time_left(options, start, out.steps);
    if (!left) {
      diagnostics.push_back(steps_not_checked(rows, k, file));
      out.complete = false;
      break;
    }
    step_options.time_budget_seconds = *left;
    if (!out.steps.empty() && step <= out.steps.back().step) {
      diagnostics.push_back({Severity::Error, file, rows[k].line, -1,
                             "step " + std::to_string(step) + " does not follow step " +
                                 std::to_string(out.steps.back().step) +
                                 ": the motion between steps needs ascending step numbers; not checked from here on"});
      out.complete = false;
      break;
    }
    std::size_t next = k;
    const std::map<InstanceId, Pose> to = detail::step_poses(scene, rows, next, diagnostics, file);
    std::optional<Report> checked;  // the step's check
    if (out.steps.empty()) {
      for (const auto& [id, pose] : to) scene.set_pose(id, pose);
    } else {
      std::vector<InstanceId> moving;
      std::vector<Pose> a, b;
      for (const auto& [id, pose] : to) {
        moving.push_back(id);
        a.push_back(scene.pose(id));
        b.push_back(pose);
      }
      // The step's own check first (at its poses): without a clearance it is the check the motion
      // needs at the stretch's end, as the previous step's is at its start.
      for (const auto& [id, pose] : to) scene.set_pose(id, pose);
      checked.emplace(motion.check ? motion.check(scene, step_options) : scene.check(step_options));
      MotionOptions ends = motion;
      if (options.clearance == 0.0) {
        ends.at_start = &out.steps.back().report;
        ends.at_end = &*checked;
      }
      const MotionResult m = check_motion(scene, model, moving, a, b, step_options, ends);
      out.checks += m.checks;
      out.complete = out.complete && m.complete;
      const auto t0 = static_cast<double>(out.steps.back().step), t1 = static_cast<double>(step);
      for (const PairMotion& p : m.pairs) {
        PairMotion& into = timeline[{p.a, p.b}];
        into.a = p.a, into.b = p.b;
        for (const MotionSpan& s : p.spans) append_span(into.spans, to_path_time(s, t0, t1));
        for (const SurfaceMotion& sp : p.surfaces)
          for (const MotionSpan& s : sp.spans) append_span(surfaces[{p.a, p.b}][{sp.a, sp.b}], to_path_time(s, t0, t1));
        if (p.closest) {
          const MotionSpan when = to_path_time({p.closest->s0, p.closest->s1, false}, t0, t1);
          closest[{p.a, p.b}].push_back({p.closest->lo, p.closest->hi, when.s0, when.s1});
        }
      }
    }
    k = next;
    if (!checked) checked.emplace(motion.check ? motion.check(scene, step_options) : scene.check(step_options));
    out.steps.push_back({step, std::move(*checked)});
    if (meter.active()) meter.add(1, std::to_string(step));
  }
  meter.finish();
  for (auto& [key, p] : timeline) {
    for (auto& [sk, spans] : surfaces[key]) p.surfaces.push_back({sk.first, sk.second, std::move(spans)});
    // The path's minimum is the least of the stretches'; it lies where a stretch's can be below it.
    if (const auto it = closest.find(key); it != closest.end()) {
      ClosestApproach c{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
      for (const ClosestApproach& x : it->second) c.lo = std::min(c.lo, x.lo), c.hi = std::min(c.hi, x.hi);
      for (const ClosestApproach& x : it->second)
        if (x.lo <= c.hi) c.s0 = std::min(c.s0, x.s0), c.s1 = std::max(c.s1, x.s1);
      p.closest = c;
    }
    out.pairs.push_back(std::move(p));
  }
  return out;
}

}  // namespace cadclash
