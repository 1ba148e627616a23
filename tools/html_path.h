// The path of `cadclash check --path --continuous --html`, as the page's time slider plays it.
#pragma once

#include "cadclash/collide.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace cadclash::cli {

// What the page needs to place the moving instances at any time of the path and colour the
// surfaces in contact then: each checked step's poses of the instances the path moves, and the
// timeline with ids (the JSON report names its surfaces; the page needs them by id).
struct HtmlPath {
  std::vector<std::int64_t> steps;       // the steps checked, ascending (PathResult::steps)
  std::vector<InstanceId> moving;        // every instance a row of those steps places, ascending
  std::vector<std::vector<Pose>> poses;  // poses[k][i]: where moving[i] is after step k's rows
  std::vector<PairMotion> pairs;         // PathResult::pairs: spans in path time
  double resolution = 0.0;               // MotionOptions::resolution
  bool complete = true;                  // PathResult::complete
};

// The poses of `checked` (the step numbers checked, in order: a prefix of the distinct steps of
// `rows`) as replay_continuous placed them: an instance keeps its model pose until a row places it,
// and each step's rows place their instances (rows naming no instance of `scene` are skipped, as
// the replay skips them). `pairs`, `resolution` and `complete` are left for the caller.
HtmlPath html_path(const Model& model, const Scene& scene, std::span<const TrajectoryRow> rows,
                   std::span<const std::int64_t> checked);

// The page's "path" record (docs/viewer.md, "How it is built"): steps, per step each moving
// instance's pose as [tx, ty, tz, qw, qx, qy, qz] (the rotation as interpolate_pose reads it), and
// the timeline's pairs by instance and surface id (-1: the whole part) with spans [t0, t1, ends].
nlohmann::json path_json(const HtmlPath& path);

}  // namespace cadclash::cli
