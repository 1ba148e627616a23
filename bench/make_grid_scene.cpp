// make_grid_scene: a large instanced scene for the MPI scaling runs (docs/results.md, "Distributed
// checks"): COPIES copies of a CAD file's instances on a grid, tessellated at DEFLECTION, written as
// one .glb (parts stored once, one node per instance) that `cadclash check` reads back exactly.
//   make_grid_scene FILE COPIES DEFLECTION OUT.glb
#include "cadclash/export.h"
#include "cadclash/import.h"
#include "cadclash/testing/scenes.h"

#include <cstdio>
#include <cstdlib>
#include <string>

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: make_grid_scene FILE COPIES DEFLECTION OUT.glb\n");
    return 2;
  }
  cadclash::ImportOptions io;
  io.tessellation.linear_deflection = std::atof(argv[3]);
  const cadclash::ImportResult in = cadclash::import_file(argv[1], io);
  for (const cadclash::Diagnostic& d : in.diagnostics) std::fprintf(stderr, "%s\n", cadclash::format_diagnostic(d).c_str());
  if (cadclash::has_error(in.diagnostics)) return 1;
  const cadclash::Model grid = cadclash::truth::grid_copies(in.model, std::atoi(argv[2]), 0.5);
  std::size_t triangles = 0;
  for (const cadclash::Instance& i : grid.instances) {
    const cadclash::Part& p = grid.parts[i.part];
    for (std::uint32_t s = p.first_surface; s < p.first_surface + p.surface_count; ++s)
      triangles += grid.surfaces[s].mesh.triangles.size();
  }
  for (const cadclash::Diagnostic& d : cadclash::export_model(grid, argv[4])) {
    std::fprintf(stderr, "%s\n", cadclash::format_diagnostic(d).c_str());
    if (d.severity == cadclash::Severity::Error) return 1;
  }
  std::printf("%s: %zu instances, %zu parts, %zu triangles over instances (%zu stored)\n", argv[4],
              grid.instances.size(), grid.parts.size(), triangles, cadclash::triangle_count(grid));
  return 0;
}
