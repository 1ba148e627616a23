// Shared pieces of the cadclash subcommands.
#pragma once

#include "cadclash/import.h"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

namespace cadclash::cli {

// Exit codes of every subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitInputError = 1;
inline constexpr int kExitUsage = 2;

// Options every subcommand that reads files shares.
struct InputOptions {
  std::vector<std::string> files;
  double deflection = 0.1;
  bool relative = false;
  double angular = 0.5;
  std::string preset;  // coarse | normal | fine | very-fine; overrides deflection/angular when set
  bool lazy = false;
  bool no_isolation = false;
  bool no_transfer_healing = false;  // ImportOptions::transfer_healing = false
  double model_tolerance = 0.0;    // mm, meshes; 0 = derived from the coordinates
  std::string uncertainty = "auto";  // auto | occt | a value in mm (ImportOptions::uncertainty)
  double import_time_limit = 0.0;  // seconds per CAD file's isolated reader, and again for its tessellation; 0 = none
  std::string cache;               // directory of the import cache (ImportOptions::cache_dir); empty = none
  double cache_max_mb = 0.0;       // ImportOptions::cache_max_bytes in MiB; 0 = no limit
  int parallel_files = 0;          // files read at once; 0 = one per core
  bool quiet = false;              // no progress line and no summary lines on stderr (progress_line.h)
  // Mesh post-processing (mesh parts only; see tessellate.h).
  bool repair = false;
  bool fill_holes = false;  // with --repair
  bool segment = false;
  double sharp_angle = 60.0;  // degrees
  bool planar = false;        // with --segment
};

// The value of --uncertainty MM: a length in (0, kMaxLength]; nullopt for anything else.
std::optional<double> uncertainty_value(const std::string& text);

// Adds FILE... and the tessellation switches to `cmd`, bound to `in`.
void add_input_options(CLI::App& cmd, InputOptions& in);

// Holds this process to `threads` threads (0 = every core), the whole run and not only a query: the
// import's loops (files read at once, parts meshed at once, lazy tessellation) through
// omp_set_num_threads, and BRepMesh's own through hold_mesher_threads (tessellate.h). Call before
// importing.
void hold_threads(int threads);
// Adds --threads N (0 = every core) to `cmd`, bound to `threads`; `what` says what it covers.
void add_threads_option(CLI::App& cmd, int& threads, const std::string& what);

// The tessellation the switches ask for: --deflection, --relative and --angular, or the preset's
// values when --preset is given (it overrides them). The one place a preset is resolved: the import
// and the report's settings both read this.
TessellationOptions effective_tessellation(const InputOptions& in);

// Imports the files (with a progress line on a terminal, show_progress), printing every diagnostic
// to stderr, then repairs and segments the mesh parts when asked (printing what changed to stderr
// unless --quiet). Returns the result; `repair_report` / `segment_report`,
// when given, receive what repair and segmentation did (left empty without --repair / --segment).
ImportResult import_inputs(const InputOptions& in, MeshRepairReport* repair_report = nullptr,
                           SegmentReport* segment_report = nullptr);
// The options the switches give the importer (no progress callback).
ImportOptions import_options(const InputOptions& in);
// What import_inputs does after import_files: `result`'s diagnostics printed, mesh parts repaired
// and segmented when asked.
ImportResult finish_inputs(const InputOptions& in, ImportResult result, MeshRepairReport* repair_report = nullptr,
                           SegmentReport* segment_report = nullptr);

// Prints diagnostics to stderr, one line each.
void print_diagnostics(const std::vector<Diagnostic>& ds);

// True when stderr is a terminal (progress is shown only then: show_progress, progress_line.h).
bool stderr_is_terminal();

void register_info(CLI::App& app);
void register_tessellate(CLI::App& app);
void register_check(CLI::App& app);

}  // namespace cadclash::cli
