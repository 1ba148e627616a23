// list_surfaces: import a CAD or mesh file and list its parts, instances and surfaces.
//   list_surfaces <file.stp|.iges|.brep|.obj|...>
// Every surface is listed with its STEP #id when the file has one. Returns 1 when the file cannot be
// read at all, 0 otherwise (problems in a partly bad file are printed to stderr).
#include <cadclash/import.h>

#include <cstdio>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <file>\n", argv[0]);
    return 2;
  }
  // Lazy: surfaces get their boxes from the exact geometry now and triangles only when a query needs
  // them — listing needs none.
  cadclash::ImportOptions options;
  options.lazy = true;
  const cadclash::ImportResult result = cadclash::import_file(argv[1], options);
  for (const cadclash::Diagnostic& d : result.diagnostics)
    std::fprintf(stderr, "%s\n", cadclash::format_diagnostic(d).c_str());
  const cadclash::Model& model = result.model;
  if (model.instances.empty()) return 1;

  std::printf("%zu parts, %zu instances, %zu surfaces\n", model.parts.size(), model.instances.size(),
              model.surfaces.size());
  for (cadclash::InstanceId i = 0; i < model.instances.size(); ++i)
    std::printf("instance %u: %s (part %u)\n", i, model.instances[i].path.c_str(), model.instances[i].part);
  for (cadclash::PartId p = 0; p < model.parts.size(); ++p) {
    const cadclash::Part& part = model.parts[p];
    std::printf("part %u: %s, %u surfaces\n", p, part.name.c_str(), part.surface_count);
    for (cadclash::SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s) {
      const cadclash::Provenance& from = model.surfaces[s].provenance;
      std::printf("  surface %u: %s, %s", s, model.surfaces[s].name.c_str(), cadclash::source_kind_name(from.kind));
      char id[32] = "";
      if (from.step_id >= 0) std::snprintf(id, sizeof id, "#%lld", static_cast<long long>(from.step_id));
      if (id[0] != '\0') std::printf(" %s", id);
      // STEP faces often carry no name of their own; the importer then names them by their #id.
      if (!from.source_name.empty() && from.source_name != id) std::printf(" \"%s\"", from.source_name.c_str());
      std::printf("\n");
    }
  }
  return 0;
}
