// cadclash tessellate: write the surface-tagged model to OBJ or glTF binary.
#include "cli_common.h"
#include "progress_line.h"

#include "cadclash/export.h"

#include <iostream>
#include <memory>
#include <numeric>

namespace cadclash::cli {
namespace {

struct TessellateOptions {
  InputOptions in;
  std::string output;
  int threads = 0;  // --threads; 0 = every core
};

int run_tessellate(TessellateOptions& o) {
  // Progress: the import's line (files, parts), then this command's own steps on the same line; on a
  // terminal only and without --quiet: pipes and logs get just the result line.
  ImportResult r = import_inputs(o.in);
  ProgressLine line(show_progress(o.in.quiet), std::cerr);
  // Writing needs every triangle, so a lazy import is completed here.
  std::vector<SurfaceId> all(r.model.surfaces.size());
  std::iota(all.begin(), all.end(), SurfaceId{0});
  if (o.in.lazy) line.status("meshing " + std::to_string(r.model.surfaces.size()) + " surfaces");
  std::vector<Diagnostic> mesh_errors = require_triangles(r.model, all);
  line.clear();
  print_diagnostics(mesh_errors);
  line.status("writing " + o.output);
  std::vector<Diagnostic> written = export_model(r.model, o.output);
  line.clear();
  print_diagnostics(written);
  if (has_error(written)) return kExitInputError;
  if (!o.in.quiet)
    std::cerr << "wrote " << o.output << ": " << r.model.surfaces.size() << " surfaces, " << triangle_count(r.model)
              << " triangles\n";
  return has_error(r.diagnostics) || has_error(mesh_errors) ? kExitInputError : kExitOk;
}

}  // namespace

void register_tessellate(CLI::App& app) {
  auto o = std::make_shared<TessellateOptions>();
  CLI::App* cmd = app.add_subcommand("tessellate", "Write the surface-tagged model (.obj or .glb)");
  add_input_options(*cmd, o->in);
  add_threads_option(*cmd, o->threads, "files read at once and meshing");
  cmd->add_option("-o,--output", o->output, "Output file: .obj or .glb")->required();
  cmd->callback([o] {
    hold_threads(o->threads);
    if (int code = run_tessellate(*o); code != kExitOk) throw CLI::RuntimeError(code);
  });
}

}  // namespace cadclash::cli
