#include "cli_common.h"
#include "progress_line.h"

#include "cadclash/tessellate.h"

#include <omp.h>

#include <cassert>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <unistd.h>

namespace cadclash::cli {

void hold_threads(int threads) {
  if (threads <= 0) return;
  omp_set_num_threads(threads);
  hold_mesher_threads(threads);
}

void add_threads_option(CLI::App& cmd, int& threads, const std::string& what) {
  cmd.add_option("--threads", threads, "Threads for the whole run: " + what + " (default: all cores)")
      ->check(CLI::NonNegativeNumber);
}

void add_input_options(CLI::App& cmd, InputOptions& in) {
  cmd.add_option("files", in.files, "Input files (STEP, IGES, BREP, OBJ, OFF, STL, PLY, glTF)")->required();  // a missing file is an input error (exit 1), reported by the importer
  cmd.add_option("--deflection", in.deflection, "Linear deflection of the tessellation, mm (or relative with --relative)")
      ->check(CLI::PositiveNumber);
  cmd.add_flag("--relative", in.relative, "Deflection is a fraction of each part's size");
  cmd.add_option("--angular", in.angular, "Angular deflection, radians")->check(CLI::PositiveNumber);
  cmd.add_option("--preset", in.preset, "Tessellation preset (overrides --deflection/--angular)")
      ->check(CLI::IsMember({"coarse", "normal", "fine", "very-fine"}));
  cmd.add_flag("--lazy", in.lazy, "Tessellate B-rep faces only when a query needs them");
  cmd.add_flag("--no-isolation", in.no_isolation,
               "Read STEP/IGES/BREP in this process, not in a child (faster import; a file that crashes OCCT then ends the program)");
  cmd.add_flag("--no-transfer-healing", in.no_transfer_healing,
               "Skip OCCT's shape healing of every STEP/IGES shape at transfer (faster import, docs/import.md "
               "\"Healing at transfer\"); faces BRepCheck finds invalid are still healed one by one, each named "
               "in a warning");
  cmd.add_option("--import-time-limit", in.import_time_limit,
                 "Seconds the isolated reader of one STEP/IGES/BREP file may take, and again its tessellation; what is not done by then is reported as not read or not tessellated (0: no limit)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--cache", in.cache,
                 "Directory of a persistent cache of imported files: a file read again with the same bytes and "
                 "settings comes back from it, the same as when it was read; a changed STEP file reads again only "
                 "the products that changed (made when missing)");
  cmd.add_option("--cache-max-mb", in.cache_max_mb,
                 "With --cache: keep the cache under this many MiB, removing the least recently used entries "
                 "(default 0: no limit)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--parallel-files", in.parallel_files, "Files read at once (default: one per core)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_flag("-q,--quiet", in.quiet,
               "No progress line (shown on a terminal) and no summary lines on stderr; errors and warnings "
               "about the input still print");
  cmd.add_option("--model-tolerance", in.model_tolerance,
                 "Uncertainty of mesh coordinates, mm: faces within tolerance + both uncertainties touch "
                 "(default: 2^-24 x the largest coordinate, the single-precision bound)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--uncertainty", in.uncertainty,
                 "Where a CAD face's model uncertainty comes from: auto (the larger of its OCCT tolerance and "
                 "the STEP file's declared uncertainty), occt (OCCT tolerances only), or a value in mm for "
                 "every surface, meshes too (a CAD face keeps its OCCT tolerance when that is larger)")
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            if (v == "auto" || v == "occt") return {};
            const std::optional<double> x = uncertainty_value(v);
            return x ? std::string() : "expected auto, occt or a length in (0, 2^128] mm, got '" + v + "'";
          },
          "auto|occt|MM"))
      ->capture_default_str();
  cmd.add_flag("--repair", in.repair,
               "Repair mesh parts: merge equal points, drop degenerate and repeated triangles, orient, stitch");
  cmd.add_flag("--fill-holes", in.fill_holes, "With --repair: also fill holes");
  cmd.add_flag("--segment", in.segment, "Cut mesh surfaces into patches at sharp edges");
  cmd.add_option("--sharp-angle", in.sharp_angle, "With --segment: dihedral angle that makes an edge sharp, degrees")
      ->check(CLI::Range(1.0, 179.0));
  cmd.add_flag("--planar", in.planar, "With --segment: also split patches into planar regions");
}

TessellationOptions effective_tessellation(const InputOptions& in) {
  TessellationOptions t;
  t.linear_deflection = in.deflection;
  t.relative = in.relative;
  t.angular_deflection = in.angular;
  if (in.preset.empty()) return t;
  const auto preset = parse_tessellation_preset(in.preset);
  assert(preset && "--preset is checked against the preset names by CLI11");
  return apply_preset(t, *preset);
}

namespace {

void print_repair_summary(const MeshRepairReport& r, bool fill_holes, double seconds) {
  std::size_t changed = 0;
  for (const SurfaceRepairStats& s : r.per_surface) changed += s.changed ? 1 : 0;
  const SurfaceRepairStats& t = r.total;
  std::cerr << "repair: " << changed << " of " << r.per_surface.size() << " mesh surfaces changed: "
            << t.merged_points << " merged points, " << t.unused_points << " unused points, " << t.degenerate_faces
            << " degenerate and " << t.duplicate_faces << " repeated triangles removed, " << t.flipped_faces
            << " flipped, " << t.stitched_edges << " edges stitched, " << t.duplicated_vertices
            << " vertices duplicated";
  if (fill_holes) std::cerr << ", " << t.filled_holes << " holes filled with " << t.hole_faces << " triangles";
  std::cerr << " (" << seconds << " s)\n";
}

}  // namespace

std::optional<double> uncertainty_value(const std::string& text) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && v > 0.0 && v <= kMaxLength) return v;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

ImportOptions import_options(const InputOptions& in) {
  ImportOptions options;
  options.tessellation = effective_tessellation(in);
  options.lazy = in.lazy;
  options.isolate_cad_readers = !in.no_isolation;
  options.transfer_healing = !in.no_transfer_healing;
  options.reader_time_limit_seconds = in.import_time_limit;
  options.model_tolerance = in.model_tolerance;
  if (in.uncertainty == "occt") options.uncertainty = UncertaintyChoice::OcctTolerance;
  else if (const std::optional<double> v = uncertainty_value(in.uncertainty)) {
    options.uncertainty = UncertaintyChoice::Value;
    options.uncertainty_value = *v;
  }
  options.tessellation.time_limit_seconds = in.import_time_limit;
  options.cache_dir = in.cache;
  options.cache_max_bytes = static_cast<std::uint64_t>(in.cache_max_mb * 1024.0 * 1024.0);
  options.parallel_files = in.parallel_files;
  return options;
}

ImportResult import_inputs(const InputOptions& in, MeshRepairReport* repair_report, SegmentReport* segment_report) {
  ProgressLine line(show_progress(in.quiet), std::cerr);
  ImportOptions options = import_options(in);
  options.progress = line.callback();
  ImportResult result = import_files(in.files, options);
  line.clear();
  return finish_inputs(in, std::move(result), repair_report, segment_report);
}

ImportResult finish_inputs(const InputOptions& in, ImportResult result, MeshRepairReport* repair_report,
                           SegmentReport* segment_report) {
  print_diagnostics(result.diagnostics);
  if (in.repair) {
    MeshRepairOptions repair_options;
    repair_options.fill_holes = in.fill_holes;
    const auto start = std::chrono::steady_clock::now();
    MeshRepairReport r = repair_meshes(result.model, repair_options);
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    print_diagnostics(r.diagnostics);
    if (!in.quiet) print_repair_summary(r, in.fill_holes, took.count());
    if (repair_report) *repair_report = std::move(r);
  }
  if (in.segment) {
    SegmentOptions segment_options;
    segment_options.sharp_angle_degrees = in.sharp_angle;
    segment_options.planar = in.planar;
    const auto start = std::chrono::steady_clock::now();
    SegmentReport r = segment_surfaces(result.model, segment_options);
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    print_diagnostics(r.diagnostics);
    if (!in.quiet)
      std::cerr << "segment: " << r.surfaces_split << " of " << r.surfaces.size() << " surfaces split into " << r.patches
              << " patches (" << took.count() << " s)\n";
    if (segment_report) *segment_report = std::move(r);
  }
  return result;
}

void print_diagnostics(const std::vector<Diagnostic>& ds) {
  // One write per line, newline included: under mpirun the ranks share one stderr, and a line
  // written in two pieces lets another rank's line land between them. (std::cerr, not stderr:
  // the MPI check silences ranks by swapping its buffer.)
  for (const Diagnostic& d : ds) std::cerr << format_diagnostic(d) + '\n';
}

bool stderr_is_terminal() { return isatty(fileno(stderr)) != 0; }

}  // namespace cadclash::cli
