// replay_trajectory: move instances along a CSV trajectory and check the prepared scene at each step.
//   replay_trajectory [--continuous] <trajectory.csv> <file> [<file> ...]
// With --continuous, the motion between two steps is checked too (cadclash::check_motion): each
// instance pair that may touch between them is listed with the stretches where it may, so a part
// that passes through another between two steps is not missed.
// Several files form one scene; their instance paths are then prefixed with "/<file name>".
// CSV rows: step,instance_path,tx,ty,tz,qw,qx,qy,qz (absolute world pose, mm). The scene builds its
// per-surface BVHs once; each step only updates the moved instances. Prints the colliding pairs per
// step. Returns 1 on a read error or a bad CSV row.
#include <cadclash/import.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

// Between consecutive steps: the instances the later step moves, from their pose before it to the
// row's pose, checked continuously on a scene of its own; the stretches where a pair may touch.
void continuous_report(cadclash::Model& model, const std::vector<cadclash::TrajectoryRow>& rows,
                       const cadclash::CollideOptions& options) {
  cadclash::Scene scene(model);
  std::map<std::string, cadclash::InstanceId> by_path;
  for (cadclash::InstanceId i = 0; i < model.instances.size(); ++i) by_path.emplace(model.instances[i].path, i);
  std::size_t k = 0;
  bool placed = false;  // the first step only places the instances
  while (k < rows.size()) {
    const std::int64_t step = rows[k].step;
    std::vector<cadclash::InstanceId> moving;
    std::vector<cadclash::Pose> from, to;
    for (; k < rows.size() && rows[k].step == step; ++k) {
      const auto it = by_path.find(rows[k].path);
      if (it == by_path.end()) continue;
      moving.push_back(it->second);
      from.push_back(scene.pose(it->second));
      to.push_back(rows[k].pose);
    }
    if (!placed) {
      for (std::size_t i = 0; i < moving.size(); ++i) scene.set_pose(moving[i], to[i]);
      placed = true;
      continue;
    }
    const cadclash::MotionResult r = cadclash::check_motion(scene, model, moving, from, to, options);
    for (const cadclash::PairMotion& p : r.pairs)
      for (const cadclash::MotionSpan& s : p.spans)
        std::printf("before step %lld: %s x %s may touch in [%.4f, %.4f] of the way%s\n", static_cast<long long>(step),
                    model.instances[p.a].path.c_str(), model.instances[p.b].path.c_str(), s.s0, s.s1,
                    s.contact_at_ends ? " (in contact at both ends)" : "");
    if (!r.complete) std::printf("before step %lld: not finished (%zu checks)\n", static_cast<long long>(step), r.checks);
  }
}

int main(int argc, char** argv) {
  const bool continuous = argc > 1 && std::string(argv[1]) == "--continuous";
  const int first = continuous ? 2 : 1;
  if (argc < first + 2) {
    std::fprintf(stderr, "usage: %s [--continuous] <trajectory.csv> <file> [<file> ...]\n", argv[0]);
    return 2;
  }
  const char* csv = argv[first];
  const std::vector<std::string> files(argv + first + 1, argv + argc);
  cadclash::ImportOptions import_options;
  import_options.lazy = true;
  cadclash::ImportResult imported = cadclash::import_files(files, import_options);
  for (const cadclash::Diagnostic& d : imported.diagnostics)
    std::fprintf(stderr, "%s\n", cadclash::format_diagnostic(d).c_str());
  if (imported.model.instances.empty()) return 1;
  const cadclash::Model& model = imported.model;

  std::ifstream in(csv, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "%s: cannot open\n", csv);
    return 1;
  }
  std::stringstream text;
  text << in.rdbuf();
  std::vector<cadclash::Diagnostic> diagnostics;
  const std::vector<cadclash::TrajectoryRow> rows = cadclash::parse_trajectory(text.str(), csv, diagnostics);

  cadclash::Scene scene(imported.model);
  cadclash::CollideOptions options;
  options.tolerance = 0.01;
  const std::vector<cadclash::StepResult> steps =
      cadclash::replay_trajectory(scene, rows, options, diagnostics, csv);
  for (const cadclash::Diagnostic& d : diagnostics)
    std::fprintf(stderr, "%s\n", cadclash::format_diagnostic(d).c_str());

  for (const cadclash::StepResult& step : steps) {
    std::printf("step %lld: %zu colliding surface pairs\n", static_cast<long long>(step.step),
                step.report.pairs.size());
    for (const cadclash::SurfacePairResult& p : step.report.pairs) {
      const auto side = [&](cadclash::InstanceId i, cadclash::SurfaceId s) {
        std::string out = model.instances[i].path;
        if (s == cadclash::kInvalidId) return out;
        out += ' ';
        out += model.surfaces[s].name;
        if (model.surfaces[s].provenance.step_id >= 0) {
          out += " #";
          out += std::to_string(model.surfaces[s].provenance.step_id);
        }
        return out;
      };
      std::printf("  %s: %s <-> %s\n", cadclash::contact_class_name(p.contact),
                  side(p.instance_a, p.surface_a).c_str(), side(p.instance_b, p.surface_b).c_str());
    }
  }
  if (continuous) continuous_report(imported.model, rows, options);
  return cadclash::has_error(diagnostics) ? 1 : 0;
}
