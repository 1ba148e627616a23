// cadclash check: which surfaces of which instances penetrate, touch, come close or contain each other.
#include "check_print.h"
#include "check_options.h"
#include "check_review.h"
#include "cli_common.h"
#include "cmd_check_mpi.h"
#include "html_path.h"
#include "html_report.h"
#include "import_stages.h"
#include "mpi_inputs.h"
#include "progress_line.h"

#include "cadclash/report.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <streambuf>
#include <optional>
#include <sstream>

namespace cadclash::cli {
namespace {

bool path_under(const std::string& path, const std::string& prefix) {
  return path.compare(0, prefix.size(), prefix) == 0 &&
         (path.size() == prefix.size() || path[prefix.size()] == '/' || prefix.back() == '/');
}

std::vector<InstanceId> select(const Model& m, const std::vector<std::string>& prefixes) {
  std::vector<InstanceId> out;
  for (InstanceId i = 0; i < m.instances.size(); ++i)
    for (const std::string& p : prefixes)
      if (path_under(m.instances[i].path, p)) {
        out.push_back(i);
        break;
      }
  return out;
}

// Every name of E, for CLI11's IsMember.
template <class E>
std::vector<std::string> names_of() {
  std::vector<std::string> out;
  for (E e : EnumNames<E>::values) out.emplace_back(EnumNames<E>::name(e));
  return out;
}

}  // namespace

CollideOptions collide_options(const CheckOptions& o) {
  CollideOptions c;
  c.tolerance = o.tolerance;
  c.clearance = o.clearance;
  c.threads = o.threads;
  c.mode = o.all_triangles ? CollideMode::AllTrianglePairs : CollideMode::EarlyExit;
  // CLI11 checks the names against the same lists (EnumNames, cadclash/report.h).
  c.version = enum_from_name<ParallelVersion>(o.parallel).value_or(ParallelVersion::V1);
  c.schedule = enum_from_name<Schedule>(o.schedule).value_or(Schedule::Guided);
  c.triangle_level = enum_from_name<TriangleLevel>(o.triangle_level).value_or(TriangleLevel::Auto);
  c.use_oaabb = !o.brute_force;
  c.detect_containment = !o.no_containment;
  c.decision = o.exact ? DecisionMode::Exact : o.fast ? DecisionMode::Fast : DecisionMode::Certified;
  c.time_budget_seconds = o.time_budget;
  c.memory_budget_bytes = static_cast<std::size_t>(o.memory_budget_mb * 1024.0 * 1024.0);
  if (o.memory_budget_mb > 0.0 && c.memory_budget_bytes == 0) c.memory_budget_bytes = 1;  // a budget, however small
  return c;
}

// The report's settings: the query's options, and the tessellation and selection as given.
ReportSettings report_settings_of(const CheckOptions& o, const CollideOptions& c) {
  ReportSettings s = report_settings(c);
  const TessellationOptions tess = effective_tessellation(o.in);
  s.preset = o.in.preset;
  s.deflection = tess.linear_deflection;
  s.relative_deflection = tess.relative;
  s.angular_deflection = tess.angular_deflection;
  s.lazy = o.in.lazy;
  s.exclude_under = o.exclude_under;
  s.select_a = o.select_a;
  s.select_b = o.select_b;
  s.memory_budget_mb = o.memory_budget_mb;  // as given, not rounded through bytes
  return s;
}

// The --path trajectory's rows; std::nullopt, after saying why on stderr, when the file cannot be
// read or has errors.
std::optional<std::vector<TrajectoryRow>> read_trajectory(const std::string& csv) {
  std::ifstream f(csv, std::ios::binary);
  if (!f) {
    std::cerr << csv << ": error: cannot open trajectory\n";
    return std::nullopt;
  }
  std::stringstream text;
  text << f.rdbuf();
  std::vector<Diagnostic> ds;
  std::vector<TrajectoryRow> rows = parse_trajectory(text.str(), csv, ds);
  print_diagnostics(ds);
  if (has_error(ds)) {
    std::cerr << "cadclash check: the trajectory has errors; nothing checked\n";
    return std::nullopt;
  }
  return rows;
}

// The instances --select-a/-b name and the sub-assemblies --exclude-under leaves out; std::nullopt,
// after saying so on stderr, when a --select matches no instance.
std::optional<SceneSelection> scene_selection(const Model& m, const CheckOptions& o) {
  SceneSelection sel;
  sel.set_a = select(m, o.select_a);
  sel.set_b = select(m, o.select_b);
  if ((!o.select_a.empty() && sel.set_a.empty()) || (!o.select_b.empty() && sel.set_b.empty())) {
    std::cerr << "cadclash check: --select-a/--select-b match no instance path\n";
    return std::nullopt;
  }
  sel.excluded_subassemblies = o.exclude_under;
  return sel;
}

namespace {

// What the query (or every step of the trajectory) found, beyond what went into the CheckReport.
struct CheckOutcome {
  bool collision = false;
  std::string stopped_by;               // first budget that ran out; empty when every query finished
  std::vector<Diagnostic> diagnostics;  // the queries' own
  Report shown;                         // what --html shows: the query, or a trajectory's last step
  std::optional<HtmlPath> path;         // --continuous with --html: what the page's time slider plays
  bool unreadable = false;              // an input file could not be read again for --volume
  bool bad_path = false;                // the path has an error (--continuous: steps not ascending)
};

// How the queries run: in this process, or split over the ranks of an MPI job (cmd_check_mpi.h).
struct Runner {
  std::function<Report(const CollideOptions&)> check;
  std::function<std::vector<StepResult>(std::span<const TrajectoryRow>, const CollideOptions&, std::vector<Diagnostic>&,
                                        const std::string&)>
      replay;
  // Each makes the model ready, when it may not be, and returns false (after saying why on stderr) when
  // it cannot: every part whole for the 3D view; the parts of the clashes --volume measures given
  // their exact faces.
  std::function<bool()> before_html;
  std::function<bool(const ClashReview&)> before_volume;
  // The path checked continuously (--continuous); empty where it cannot run (under mpirun).
  std::function<PathResult(std::span<const TrajectoryRow>, const CollideOptions&, const MotionOptions&,
                           std::vector<Diagnostic>&, const std::string&)>
      path;
};

// One query of the prepared scene (run --repeat times, the last kept): the table and summary on
// stdout, the results into `report`.
CheckOutcome check_once(const CheckOptions& o, const Model& m, const Runner& run, const CollideOptions& copt,
                        const ReviewInputs& review, CheckReport& report) {
  CheckOutcome out;
  Report r = run.check(copt);
  for (int k = 1; k < o.repeat; ++k) r = run.check(copt);  // a prepared scene: BVHs already built
  out.diagnostics = r.diagnostics;
  report.query = query_report(m, r);
  ReviewOptions ro = review.options;
  if (ro.group_by == "space") {  // where each pair meets: the boxes the clusters are made of
    std::vector<Pose> poses;
    for (const Instance& i : m.instances) poses.push_back(i.pose);
    ro.pair_boxes = contact_boxes(m, poses, r);
  }
  report.review = review_query(*report.query, review.baseline ? &*review.baseline : nullptr, review.approvals, ro);
  if (o.review.volume) {
    if (run.before_volume && !run.before_volume(*report.review)) out.unreadable = true;
    measure_clashes(m, *report.review);
  }
  out.collision = unapproved_collision(*report.review);  // approved clashes never fail the audit
  if (!r.complete) std::cout << "PARTIAL REPORT: stopped by " << stopped_text(r.stopped_by) << " (what was not examined: at the end)\n";
  if (r.pairs.empty()) std::cout << "no colliding, touching or close surface pairs\n";
  print_table(m, r, *report.review, collapse_clashes(o.review), std::cout);
  print_summary(r, !o.no_timings, std::cout);
  print_review(*report.review, std::cout);
  if (o.fast) std::cout << "fast mode: classes from the triangles' deflection band, not certified on the exact faces\n";
  print_partial(m, r, std::cout);
  if (!r.complete) out.stopped_by = r.stopped_by;
  out.shown = std::move(r);
  return out;
}

// A contact span of the path's timeline as a person reads it.
std::string span_text(const MotionSpan& s) {
  std::ostringstream t;
  t.precision(6);
  t << '[' << s.s0 << ", " << s.s1 << ']';
  return s.contact_at_ends ? "in contact at both ends of " + t.str() : "may touch within " + t.str();
}

// The path's timeline (--continuous) on stdout: each instance pair that may touch between the steps.
void print_timeline(const CheckOptions& o, const Model& m, const PathResult& p) {
  std::cout << "\nbetween the steps (continuous, spans " << o.time_resolution << " of a stretch wide where a contact "
            << "begins or ends; " << p.checks << " checks): ";
  if (p.pairs.empty()) {
    std::cout << "no instance pair comes into contact\n";
  } else {
    std::cout << p.pairs.size() << " instance pair" << (p.pairs.size() == 1 ? "" : "s")
              << (o.clearance > 0.0 ? " may touch or come within the clearance\n" : " may touch\n");
    for (const PairMotion& pm : p.pairs) {
      std::cout << "  " << m.instances[pm.a].path << " x " << m.instances[pm.b].path << " (" << pm.surfaces.size()
                << " surface pair" << (pm.surfaces.size() == 1 ? "" : "s") << "):";
      for (const MotionSpan& s : pm.spans) std::cout << ' ' << span_text(s) << ';';
      if (pm.closest)
        std::cout << " closest " << pm.closest->hi << " mm (at least " << pm.closest->lo << ") within ["
                  << pm.closest->s0 << ", " << pm.closest->s1 << "]";
      std::cout << '\n';
    }
  }
  if (!p.complete) std::cout << "PARTIAL TIMELINE: a stretch ran out of its --motion-checks, or the path was cut short; "
                                "its open spans are listed whole\n";
}

// The trajectory replayed on the prepared scene: one line per step on stdout, each step into `report`;
// with --continuous the motion between the steps too.
CheckOutcome check_trajectory(const CheckOptions& o, const Model& m, const Scene& scene, const Runner& run,
                              const std::vector<TrajectoryRow>& rows, const CollideOptions& copt, CheckReport& report) {
  CheckOutcome out;
  std::vector<Diagnostic> ds;
  std::optional<PathResult> path;
  std::vector<StepResult> steps;
  if (o.continuous) {
    MotionOptions mo;
    mo.resolution = o.time_resolution;
    mo.max_checks = o.motion_checks;
    path = run.path(rows, copt, mo, ds, o.path_csv);
    steps = std::move(path->steps);
    report.timeline = timeline_report(m, *path, o.time_resolution);
    // A pair that may touch between the steps is a finding; one that only comes within the clearance not.
    out.collision = std::any_of(path->pairs.begin(), path->pairs.end(), [](const PairMotion& p) { return !p.spans.empty(); });
  } else {
    steps = run.replay(rows, copt, ds, o.path_csv);
  }
  print_diagnostics(ds);
  out.bad_path = has_error(ds);
  report.trajectory = o.path_csv;
  for (const StepResult& s : steps) {
    ClassCounts n;
    n.add(s.report);
    out.collision = out.collision || n.collision();
    out.diagnostics.insert(out.diagnostics.end(), s.report.diagnostics.begin(), s.report.diagnostics.end());
    std::cout << "step " << s.step << ": " << n.c[0] << " penetrating, " << n.c[1] << " touching, " << n.c[2]
              << " clearance, " << n.c[3] << " containment, " << n.c[4] << " undecided";
    if (!o.no_timings) std::cout << "  (" << fmt(s.report.timings.total * 1e3) << " ms)";
    if (!s.report.complete) {
      std::cout << "  PARTIAL: stopped by " << stopped_text(s.report.stopped_by) << ", " << s.report.unexamined_pairs.size()
                << " of " << s.report.counters.instance_pairs << " instance pairs not examined";
      if (out.stopped_by.empty()) out.stopped_by = s.report.stopped_by;
    }
    std::cout << '\n';
    report.steps.push_back({s.step, query_report(m, s.report)});
  }
  std::size_t distinct_steps = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) distinct_steps += (k == 0 || rows[k].step != rows[k - 1].step);
  const std::size_t not_checked = distinct_steps - steps.size();
  report.steps_not_checked = not_checked;
  if (not_checked > 0 && out.bad_path) {
    std::cout << "\nPARTIAL REPORT: " << not_checked << " of " << distinct_steps
              << " steps not checked (the path's error above)\n";
  } else if (not_checked > 0) {
    std::cout << "\nPARTIAL REPORT: stopped by the time budget: " << not_checked << " of " << distinct_steps
              << " steps not checked\n";
    if (out.stopped_by.empty()) out.stopped_by = "time budget";
  }
  report.stopped_by = out.stopped_by;
  for (const Diagnostic& d : ds) report.diagnostics.push_back(format_diagnostic(d));
  if (path) print_timeline(o, m, *path);
  if (path && !o.html.empty()) {
    std::vector<std::int64_t> checked;
    for (const StepResult& s : steps) checked.push_back(s.step);
    out.path = html_path(m, scene, rows, checked);
    out.path->pairs = std::move(path->pairs);
    out.path->resolution = o.time_resolution;
    out.path->complete = path->complete;
  }
  if (!steps.empty()) out.shown = std::move(steps.back().report);
  return out;
}

// The query (or trajectory) run, printed and written: the rest of `cadclash check`. Under MPI only
// rank 0 (`primary`) writes files.
int finish_check(const CheckOptions& o, ImportResult& imported, const std::vector<TrajectoryRow>& rows,
                 const Runner& runner, Scene& scene, const CollideOptions& copt, bool primary,
                 const ReviewInputs& review) {
  Model& m = imported.model;
  CheckReport report;
  report.files = o.in.files;
  report.settings = report_settings_of(o, copt);
  CheckOutcome run = rows.empty() ? check_once(o, m, runner, copt, review, report)
                                  : check_trajectory(o, m, scene, runner, rows, copt, report);
  print_diagnostics(run.diagnostics);
  const bool input_error = has_error(imported.diagnostics) || has_error(run.diagnostics);
  for (const Diagnostic& d : imported.diagnostics) report.diagnostics.push_back(format_diagnostic(d));
  for (const Diagnostic& d : run.diagnostics) report.diagnostics.push_back(format_diagnostic(d));
  report.complete = imported.complete && !has_error(run.diagnostics) && run.stopped_by.empty() && !run.bad_path &&
                    (!report.timeline || report.timeline->complete);
  if (!run.stopped_by.empty() && run.stopped_by != kOutOfRange)
    std::cerr << "cadclash check: warning: partial report: the " << run.stopped_by << " ran out before every pair was examined\n";

  if (!o.no_timings) {
    report.import = import_report(imported);
    print_import_stages(imported, report, std::cout);
  }
  // Last, the line a person reads first (a trajectory's steps each have their own).
  if (primary && rows.empty() && report.review) std::cout << '\n' << verdict_line(*report.review, report.complete) << '\n';
  const nlohmann::json j = check_report_json(report, {.timings = !o.no_timings});
  if (primary && !o.json.empty()) {
    std::ofstream f(o.json, std::ios::binary);
    f << report_text(j);
    if (!f) {
      std::cerr << o.json << ": error: cannot write the report\n";
      return kExitInputError;
    }
  }
  if (primary && !o.html.empty() && runner.before_html && !runner.before_html()) return kExitInputError;
  if (primary && !o.html.empty() && !save_html_report(o.html, m, scene, run.shown, j, run.path ? &*run.path : nullptr))
    return kExitInputError;
  if (input_error || run.unreadable || run.bad_path) return kExitInputError;
  if (o.fail_on_collision && run.collision) return kExitCollision;  // a definite finding, partial report or not
  return run.stopped_by.empty() ? kExitOk : kExitBudget;
}

}  // namespace

// The check of what was imported: in this process, or split over the ranks of `mpi` when given.
// `inputs`, under mpirun with files read where needed, reads the files a rank needs and has not read.
int check_imported(const CheckOptions& o, ImportResult& imported, const std::vector<TrajectoryRow>& rows,
                   const ReviewInputs& review, [[maybe_unused]] MpiCheck* mpi,
                   [[maybe_unused]] DistributedInputs* inputs) {
  Model& m = imported.model;
  if (m.instances.empty()) {
    std::cerr << "cadclash check: no instances to check\n";
    return kExitInputError;
  }
  const std::optional<SceneSelection> sel = scene_selection(m, o);
  if (!sel) return kExitInputError;
  const CollideOptions copt = collide_options(o);
  Scene scene(m, *sel);
#if CADCLASH_HAS_MPI
  if (mpi != nullptr) mpi->note_parts(scene);
#endif
  // A progress line for each query or replay, gone before its results are printed (never under mpirun).
  const bool progress = show_progress(o.in.quiet);
  auto with_progress = [](CollideOptions c, ProgressLine& line) {
    c.progress = line.callback();
    return c;
  };
  Runner runner{[&](const CollideOptions& c) {
                  ProgressLine line(progress, std::cerr);
                  return scene.check(with_progress(c, line));
                },
                [&](std::span<const TrajectoryRow> r, const CollideOptions& c, std::vector<Diagnostic>& ds,
                    const std::string& file) {
                  ProgressLine line(progress, std::cerr);
                  return replay_trajectory(scene, r, with_progress(c, line), ds, file);
                },
                {},
                {},
                [&](std::span<const TrajectoryRow> r, const CollideOptions& c, const MotionOptions& mo,
                    std::vector<Diagnostic>& ds, const std::string& file) {
                  ProgressLine line(progress, std::cerr);
                  return replay_continuous(scene, m, r, with_progress(c, line), mo, ds, file);
                }};
  bool primary = true;
#if CADCLASH_HAS_MPI
  if (mpi != nullptr) {
    primary = mpi->rank() == 0;
    runner.check = [&](const CollideOptions& c) { return mpi->check(scene, m, c); };
    runner.replay = [&](std::span<const TrajectoryRow> r, const CollideOptions& c, std::vector<Diagnostic>& ds,
                        const std::string& file) { return mpi->replay(scene, m, r, c, ds, file); };
    // Every static check of the path split over the ranks; its pairs on every rank, so that every
    // rank halves the same stretches.
    runner.path = [&](std::span<const TrajectoryRow> r, const CollideOptions& c, const MotionOptions& mo,
                      std::vector<Diagnostic>& ds, const std::string& file) {
      MotionOptions everywhere = mo;
      everywhere.check = [&](Scene& s, const CollideOptions& co) { return mpi->check_everywhere(s, m, co); };
      return replay_continuous(scene, m, r, c, everywhere, ds, file);
    };
    runner.before_html = [&] {
      mpi->mesh_every_part(m);
      return true;
    };
    if (inputs != nullptr) {
      mpi->read_where_needed(m, *inputs);
      runner.before_html = [&] {  // the page shows every part (HTML: rank 0 only)
        std::vector<PartId> all(m.parts.size());
        for (PartId p = 0; p < all.size(); ++p) all[p] = p;
        const bool read = inputs->read_files_of(m, all);
        mpi->mesh_every_part(m);
        return read;
      };
      // Only rank 0's review holds clashes: the others read nothing here.
      runner.before_volume = [&](const ClashReview& r) { return inputs->read_files_of(m, parts_to_measure(m, r)); };
    }
  }
#endif
  return finish_check(o, imported, rows, runner, scene, copt, primary, review);
}

namespace {

int run_check(const CheckOptions& o, const Launch& launch) {
  if (!o.html.empty() && !html_report_available()) {
    std::cerr << "cadclash check: --html needs a build with the viewer (CMake option CADCLASH_HTML_VIEWER=ON)\n";
    return kExitUsage;
  }
  if (o.continuous && o.path_csv.empty()) {
    std::cerr << "cadclash check: --continuous checks the motion between the steps of a --path; give one\n";
    return kExitUsage;
  }
  if (launch.by_mpirun && o.continuous && o.time_budget > 0.0) {
    std::cerr << "cadclash check: --continuous with --time-budget does not run under mpirun yet (each rank's "
                 "clock would decide where the path stops; run it in one process)\n";
    return kExitUsage;
  }
  if (launch.by_mpirun && o.memory_budget_mb > 0.0) {
    std::cerr << "cadclash check: --memory-budget keeps the longest prefix of all instance pairs that fits; it "
                 "cannot be split over MPI ranks (use --time-budget, or one process)\n";
    return kExitUsage;
  }
  // Before the import: a bad baseline or approvals file should not cost a long import first.
  const std::optional<ReviewInputs> review = load_review_inputs(o.review, !o.path_csv.empty());
  if (!review) return kExitInputError;
#if CADCLASH_HAS_MPI
  // Under mpirun each file is read (without triangles) on one rank and again where the ranks' shares
  // need it (mpi_inputs.h); an eager check meshes whole parts there (part meshing, cmd_check_mpi.h).
  if (launch.by_mpirun) return run_check_mpi(o, *review);
#endif
  ImportResult imported = import_inputs(o.in);
  std::optional<std::vector<TrajectoryRow>> rows = std::vector<TrajectoryRow>{};
  if (!o.path_csv.empty()) rows = read_trajectory(o.path_csv);
  if (!rows) return kExitInputError;
  const int code = check_imported(o, imported, *rows, *review, nullptr);
  // A lazy import through the cache: the faces this check meshed are kept for the next run.
  std::vector<Diagnostic> stored;
  store_triangles_in_cache(imported, stored);
  print_diagnostics(stored);
  // Done: the process ends here, without taking the model and OCCT's shapes apart piece by piece
  // (a tenth of a second on a 40 MB board). Every file this wrote is closed; the streams are flushed.
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::_Exit(code);
}

// `cadclash check`, in one process or as one rank of an MPI job (every rank imports, rank 0 reports).
int run_check_launched(const CheckOptions& o) {
  // --threads is the run's, not only the query's: --threads 1 (or one MPI rank per core) keeps the
  // import on that many cores too.
  hold_threads(o.threads);
  const Launch launch = mpi_launch();
  if (!launch.by_mpirun) return run_check(o, launch);
#if CADCLASH_HAS_MPI
  SilentRank quiet(launch.rank != 0);
  return run_check(o, launch);
#else
  if (launch.size == 1) return run_check(o, launch);
  if (launch.rank == 0)
    std::cerr << "cadclash check: started by mpirun with " << launch.size
              << " processes, but this cadclash was built without MPI (CMake option CADCLASH_WITH_MPI): every "
                 "process would check everything\n";
  return kExitUsage;
#endif
}

}  // namespace

void register_check(CLI::App& app) {
  auto o = std::make_shared<CheckOptions>();
  CLI::App* cmd = app.add_subcommand("check", "Report penetrating, touching, close and contained surface pairs");
  cmd->footer(
      "Example: cadclash check assembly.step --json report.json --html report.html\n"
      "  (every penetrating and touching surface pair, certified on the exact faces; the last line is the verdict)\n"
      "Exit codes: 0 the check ran; 1 input error; 2 usage error; 3 --fail-on-collision and a collision was found\n"
      "(even in a partial report); 4 a --time-budget or --memory-budget ran out: the report (table, --json) was\n"
      "written, marked PARTIAL, listing the instance pairs not examined.\n");
  add_input_options(*cmd, o->in);
  // A check meshes only the faces its queries reach (the same report as meshing every face first);
  // --eager meshes every face at import, as `tessellate` and `info` do.
  o->in.lazy = true;
  CLI::Option* lazy = cmd->get_option("--lazy");
  lazy->description("Tessellate B-rep faces only when a query needs them (the default of check)");
  cmd->add_flag_callback("--eager", [o] { o->in.lazy = false; }, "Tessellate every B-rep face at import, not only the ones a query reaches")
      ->excludes(lazy);
  cmd->add_option("--tolerance", o->tolerance, "Contact tolerance t, mm (touching: distance <= t + both deflections)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--clearance", o->clearance, "Also report pairs closer than this, mm")->check(CLI::NonNegativeNumber);
  add_threads_option(*cmd, o->threads, "files read at once, meshing and the query");
  cmd->add_option("--path", o->path_csv, "Trajectory CSV: step,instance_path,tx,ty,tz,qw,qx,qy,qz");
  cmd->add_flag("--continuous", o->continuous,
                "With --path: check the motion between the steps too (each instance moves along the screw of "
                "the displacement between its poses); a contact that begins and ends between two steps is found, and the "
                "report gets a timeline per pair (docs/cli.md)");
  cmd->add_option("--time-resolution", o->time_resolution,
                  "With --continuous: how narrow the spans where a contact begins or ends are, as a fraction of "
                  "the stretch between two steps")
      ->check(CLI::Range(1e-9, 1.0));
  cmd->add_option("--motion-checks", o->motion_checks,
                  "With --continuous: static checks at most per stretch between two steps; past it the open spans "
                  "are listed whole and the timeline is marked partial")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--time-budget", o->time_budget,
                  "Stop after this many seconds (whole trajectory with --path) and report what was found, marked partial; exit 4")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--memory-budget", o->memory_budget_mb,
                  "Stop before the query's own structures (triangles, BVHs, lists) pass this many MiB; the partial "
                  "report is the same for any --threads; exit 4")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--repeat", o->repeat, "Run the query this many times on the prepared scene; report the last (benchmarking)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--all-triangles", o->all_triangles, "List every intersecting triangle pair (no early exit)");
  cmd->add_option("--json", o->json, "Write the JSON report (docs/report-schema.md) here");
  cmd->add_option("--html", o->html, "Write a self-contained HTML report with a 3D view here (docs/viewer.md)");
  cmd->add_flag("--no-timings", o->no_timings, "Leave timings out (the report is then identical for any thread count)");
  cmd->add_flag("--fail-on-collision", o->fail_on_collision,
                "Exit 3 when a penetrating, touching, containment or undecided pair is found (not counting approved clashes)");
  cmd->add_flag("--brute-force", o->brute_force, "Test every triangle pair, no OAABB culling (for comparison)");
  cmd->add_flag("--no-containment", o->no_containment, "Skip the point-in-part containment test");
  CLI::Option* exact = cmd->add_flag(
      "--exact", o->exact,
      "Every reported class from the exact B-rep faces (OCCT distance); pairs farther than the tolerance become "
      "clearance or leave the report");
  cmd->add_flag("--fast", o->fast,
                "Classes from the triangles' deflection band alone (not certified on the exact faces)")
      ->excludes(exact);
  cmd->add_option("--parallel", o->parallel, "Parallel version: v1 (per surface pair) or v2 (flattened)")
      ->check(CLI::IsMember(names_of<ParallelVersion>()));
  cmd->add_option("--schedule", o->schedule, "OpenMP schedule")->check(CLI::IsMember(names_of<Schedule>()));
  cmd->add_option("--triangle-level", o->triangle_level, "Candidate triangle pairs: auto, flat loops or bvh")
      ->check(CLI::IsMember(names_of<TriangleLevel>()));
  cmd->add_option("--select-a", o->select_a, "Check only instances under these paths (set A) ...");
  cmd->add_option("--select-b", o->select_b, "... against instances under these paths (set B)");
  cmd->add_option("--exclude-under", o->exclude_under, "Skip pairs whose instances are both under this sub-assembly path");
  add_review_options(*cmd, o->review);
  cmd->callback([o] {
    const int code = run_check_launched(*o);
    if (code != kExitOk) throw CLI::RuntimeError(code);
  });
}

}  // namespace cadclash::cli
