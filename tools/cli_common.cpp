#include "cli_common.h"

#include <cstdio>
#include <iostream>
#include <unistd.h>

namespace cadclash::cli {

void add_input_options(CLI::App& cmd, InputOptions& in) {
  cmd.add_option("files", in.files, "Input files (STEP, IGES, BREP, OBJ, OFF, STL, PLY, glTF)")->required()->check(CLI::ExistingFile);
  cmd.add_option("--deflection", in.deflection, "Linear deflection of the tessellation, mm (or relative with --relative)")
      ->check(CLI::PositiveNumber);
  cmd.add_flag("--relative", in.relative, "Deflection is a fraction of each part's size");
  cmd.add_option("--angular", in.angular, "Angular deflection, radians")->check(CLI::PositiveNumber);
  cmd.add_option("--preset", in.preset, "Tessellation preset (overrides --deflection/--angular)")
      ->check(CLI::IsMember({"coarse", "normal", "fine", "very-fine"}));
  cmd.add_flag("--lazy", in.lazy, "Tessellate B-rep faces only when a query needs them");
}

ImportResult import_inputs(const InputOptions& in) {
  ImportOptions options;
  options.tessellation.linear_deflection = in.deflection;
  options.tessellation.relative = in.relative;
  options.tessellation.angular_deflection = in.angular;
  options.lazy = in.lazy;
  ImportResult result = import_files(in.files, options);
  print_diagnostics(result.diagnostics);
  return result;
}

void print_diagnostics(const std::vector<Diagnostic>& ds) {
  for (const Diagnostic& d : ds) std::cerr << format_diagnostic(d) << '\n';
}

bool stderr_is_terminal() { return isatty(fileno(stderr)) != 0; }

}  // namespace cadclash::cli
