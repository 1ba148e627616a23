// replay_trajectory: move instances along a CSV trajectory and check the prepared scene at each step.
//   replay_trajectory <trajectory.csv> <file> [<file> ...]
// Several files form one scene; their instance paths are then prefixed with "/<file name>".
// CSV rows: step,instance_path,tx,ty,tz,qw,qx,qy,qz (absolute world pose, mm). The scene builds its
// per-surface BVHs once; each step only updates the moved instances. Prints the colliding pairs per
// step. Returns 1 on a read error or a bad CSV row.
#include <cadclash/import.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s <trajectory.csv> <file> [<file> ...]\n", argv[0]);
    return 2;
  }
  const char* csv = argv[1];
  const std::vector<std::string> files(argv + 2, argv + argc);
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
  return cadclash::has_error(diagnostics) ? 1 : 0;
}
