// check_two_parts: which surfaces of two parts collide, with their STEP ids.
//   check_two_parts <file> <instance path A> <instance path B>   two instances of one assembly
//   check_two_parts <file A> <file B>                             every instance of A against every one of B
// Prints one line per colliding surface pair. Returns 1 on a read error or an unknown instance path.
#include <cadclash/import.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace {

std::string label(const cadclash::Model& model, cadclash::InstanceId i, cadclash::SurfaceId s) {
  std::string out = model.instances[i].path;
  if (s == cadclash::kInvalidId) return out + " (whole instance)";
  const cadclash::Surface& surface = model.surfaces[s];
  out += ' ';
  out += surface.name;
  if (surface.provenance.step_id >= 0) {
    out += " #";
    out += std::to_string(surface.provenance.step_id);
  }
  return out;
}

bool read(const std::string& path, cadclash::Model& into, const std::string& prefix) {
  cadclash::ImportOptions options;
  options.lazy = true;  // only surfaces that meet the other part get tessellated
  cadclash::ImportResult result = cadclash::import_file(path, options);
  for (const cadclash::Diagnostic& d : result.diagnostics)
    std::fprintf(stderr, "%s\n", cadclash::format_diagnostic(d).c_str());
  if (result.model.instances.empty()) return false;
  cadclash::append_model(into, std::move(result.model), prefix);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 && argc != 4) {
    std::fprintf(stderr, "usage: %s <file> <instance A> <instance B>\n       %s <file A> <file B>\n", argv[0],
                 argv[0]);
    return 2;
  }
  cadclash::Model model;
  cadclash::SceneSelection selection;
  if (argc == 4) {
    if (!read(argv[1], model, {})) return 1;
  } else {
    // Prefix each file's instance paths with its name so the two stay apart, then check A against B.
    if (!read(argv[1], model, "/" + std::filesystem::path(argv[1]).filename().string())) return 1;
    const auto first_b = static_cast<cadclash::InstanceId>(model.instances.size());
    if (!read(argv[2], model, "/" + std::filesystem::path(argv[2]).filename().string())) return 1;
    for (cadclash::InstanceId i = 0; i < model.instances.size(); ++i)
      (i < first_b ? selection.set_a : selection.set_b).push_back(i);
  }

  if (argc == 4) {
    for (const char* path : {argv[2], argv[3]}) {
      cadclash::InstanceId found = cadclash::kInvalidId;
      for (cadclash::InstanceId i = 0; i < model.instances.size() && found == cadclash::kInvalidId; ++i)
        if (model.instances[i].path == path) found = i;
      if (found == cadclash::kInvalidId) {
        std::fprintf(stderr, "no instance %s\n", path);
        return 1;
      }
      (path == argv[2] ? selection.set_a : selection.set_b).push_back(found);
    }
  }
  // A prepared scene checking set_a × set_b only; for one pair, cadclash::collide(model, a, b) also works.
  cadclash::Scene scene(model, selection);
  cadclash::CollideOptions options;
  options.tolerance = 0.01;  // mm: faces this close count as touching
  const cadclash::Report report = scene.check(options);
  for (const cadclash::Diagnostic& d : report.diagnostics)
    std::fprintf(stderr, "%s\n", cadclash::format_diagnostic(d).c_str());

  std::printf("%zu colliding surface pairs\n", report.pairs.size());
  for (const cadclash::SurfacePairResult& p : report.pairs)
    std::printf("%s: %s <-> %s\n", cadclash::contact_class_name(p.contact),
                label(model, p.instance_a, p.surface_a).c_str(), label(model, p.instance_b, p.surface_b).c_str());
  return cadclash::has_error(report.diagnostics) ? 1 : 0;
}
