// The path's step poses and timeline for the HTML page's time slider (html_path.h).
#include "html_path.h"

#include <map>
#include <set>

namespace cadclash::cli {

HtmlPath html_path(const Model& model, const Scene& scene, std::span<const TrajectoryRow> rows,
                   std::span<const std::int64_t> checked) {
  HtmlPath out;
  out.steps.assign(checked.begin(), checked.end());
  // The rows of each checked step, resolved to instances once (replay_continuous's own reading:
  // the later row of an instance within a step wins, unknown paths are skipped).
  std::vector<std::map<InstanceId, Pose>> placed(checked.size());
  std::set<InstanceId> moving;
  std::size_t k = 0;
  for (std::size_t s = 0; s < checked.size(); ++s) {
    while (k < rows.size() && rows[k].step != checked[s]) ++k;  // a checked step's rows come in order
    for (; k < rows.size() && rows[k].step == checked[s]; ++k) {
      const InstanceId id = scene.find_instance(rows[k].path);
      if (id == kInvalidId) continue;
      placed[s][id] = rows[k].pose;
      moving.insert(id);
    }
  }
  out.moving.assign(moving.begin(), moving.end());
  std::vector<Pose> now;
  for (InstanceId id : out.moving) now.push_back(model.instances[id].pose);
  for (std::size_t s = 0; s < checked.size(); ++s) {
    for (std::size_t i = 0; i < out.moving.size(); ++i)
      if (const auto it = placed[s].find(out.moving[i]); it != placed[s].end()) now[i] = it->second;
    out.poses.push_back(now);
  }
  return out;
}

namespace {

nlohmann::json spans_json(const std::vector<MotionSpan>& spans) {
  nlohmann::json out = nlohmann::json::array();
  for (const MotionSpan& s : spans) out.push_back({s.s0, s.s1, s.contact_at_ends});
  return out;
}

nlohmann::json signed_id(std::uint32_t id) { return id == kInvalidId ? nlohmann::json(-1) : nlohmann::json(id); }

}  // namespace

nlohmann::json path_json(const HtmlPath& path) {
  nlohmann::json steps = nlohmann::json::array();
  for (std::size_t k = 0; k < path.steps.size(); ++k) {
    nlohmann::json poses = nlohmann::json::array();
    for (const Pose& p : path.poses[k]) {
      // The rotation as interpolate_pose reads it (motion.cpp, rotation_of), so the page's slerp
      // starts from the same quaternion.
      const Eigen::Quaterniond q = Eigen::Quaterniond(p.linear()).normalized();
      const Vec3 t = p.translation();
      poses.push_back({t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z()});
    }
    steps.push_back({{"step", path.steps[k]}, {"poses", std::move(poses)}});
  }
  nlohmann::json pairs = nlohmann::json::array();
  for (const PairMotion& p : path.pairs) {
    nlohmann::json surfaces = nlohmann::json::array();
    for (const SurfaceMotion& s : p.surfaces)
      surfaces.push_back({{"surface_a", signed_id(s.a)}, {"surface_b", signed_id(s.b)}, {"spans", spans_json(s.spans)}});
    pairs.push_back({{"instance_a", p.a}, {"instance_b", p.b}, {"spans", spans_json(p.spans)},
                     {"surfaces", std::move(surfaces)}});
  }
  return {{"steps", std::move(steps)},
          {"moving", path.moving},
          {"resolution", path.resolution},
          {"complete", path.complete},
          {"pairs", std::move(pairs)}};
}

}  // namespace cadclash::cli
