// cadclash/report.h — the versioned JSON report of a collision check, in the library.
//
// One writer and one reader for the report `cadclash check --json` writes (docs/report-schema.md),
// the names of every enum the report spells out, the list of counter and timing fields, and the
// surface/provenance JSON the CLI, the HTML report, the exporters and the Python bindings share.
//
// Contracts:
// - The report is held in plain structs (CheckReport): a query's results with every id resolved to
//   the names a reader of the JSON sees (instance paths, part and surface names, provenance), so a
//   report can be written, read back and written again without the model.
// - check_report_json() writes keys in sorted order and numbers in shortest round-trip form;
//   check_report_text() is the exact text of `cadclash check --json` (2-space indent, invalid UTF-8
//   replaced, one trailing newline). The same CheckReport always gives the same bytes.
// - check_report_from_json() never throws and never prints: malformed input gives a ReportError
//   naming the JSON pointer of the problem ("/pairs/3/class"). Unknown fields are ignored (adding
//   a field is not a schema break). For every text T this writer produced,
//   check_report_text(check_report_from_json(T).report) == T.
// - Non-finite numbers are written as null and read back as +infinity where the schema allows null.
// Depends on cadclash::collide and nlohmann_json only (no OpenCASCADE, no assimp).
#pragma once

#include "cadclash/collide.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cadclash {

inline constexpr std::string_view kCheckReportSchema = "cadclash-check-report";
// Bumped for any change that can break a reader (a field removed, renamed or given another meaning).
inline constexpr int kCheckReportVersion = 2;

// ---------------------------------------------------------------------------------------------
// Enum names: every value of each enum the report spells out, and its name
// ---------------------------------------------------------------------------------------------

// EnumNames<E>::values lists every value of E in declaration order; EnumNames<E>::name(e) is its
// name in the report (contact_class_name, collide_mode_name, ... of collide.h; source_kind_name of model.h).
template <class E> struct EnumNames;
template <> struct EnumNames<ContactClass> {
  static constexpr std::array values{ContactClass::Penetrating, ContactClass::Touching, ContactClass::Clearance,
                                     ContactClass::Containment, ContactClass::Undecided};
  static const char* name(ContactClass c) { return contact_class_name(c); }
};
template <> struct EnumNames<DecidedBy> {
  static constexpr std::array values{DecidedBy::Mesh,    DecidedBy::MeshExact, DecidedBy::Analytic,
                                     DecidedBy::Refined, DecidedBy::Exact,     DecidedBy::Undecided};
  static const char* name(DecidedBy d) { return decided_by_name(d); }
};
template <> struct EnumNames<ContactWithin> {
  static constexpr std::array values{ContactWithin::Unknown, ContactWithin::Tolerance, ContactWithin::ModelUncertainty};
  static const char* name(ContactWithin w) { return contact_within_name(w); }
};
template <> struct EnumNames<DecisionMode> {
  static constexpr std::array values{DecisionMode::Certified, DecisionMode::Fast, DecisionMode::Exact};
  static const char* name(DecisionMode m) { return decision_mode_name(m); }
};
template <> struct EnumNames<SourceKind> {
  static constexpr std::array values{SourceKind::StepFace, SourceKind::IgesFace,       SourceKind::BrepFace,
                                     SourceKind::ObjGroup, SourceKind::OffColourGroup, SourceKind::MeshFile,
                                     SourceKind::Segment};
  static const char* name(SourceKind k) { return source_kind_name(k); }
};
template <> struct EnumNames<UncertaintySource> {
  static constexpr std::array values{UncertaintySource::Coordinates, UncertaintySource::OcctTolerance,
                                     UncertaintySource::Declared, UncertaintySource::Given};
  static const char* name(UncertaintySource u) { return uncertainty_source_name(u); }
};
template <> struct EnumNames<CollideMode> {
  static constexpr std::array values{CollideMode::EarlyExit, CollideMode::AllTrianglePairs};
  static const char* name(CollideMode m) { return collide_mode_name(m); }
};
template <> struct EnumNames<ParallelVersion> {
  static constexpr std::array values{ParallelVersion::V1, ParallelVersion::V2};
  static const char* name(ParallelVersion v) { return parallel_version_name(v); }
};
template <> struct EnumNames<Schedule> {
  static constexpr std::array values{Schedule::Guided, Schedule::Dynamic, Schedule::Static};
  static const char* name(Schedule s) { return schedule_name(s); }
};
template <> struct EnumNames<TriangleLevel> {
  static constexpr std::array values{TriangleLevel::Auto, TriangleLevel::Flat, TriangleLevel::Bvh};
  static const char* name(TriangleLevel t) { return triangle_level_name(t); }
};

// The value of E named `name`; nullopt when no value has that name.
template <class E>
std::optional<E> enum_from_name(std::string_view name) {
  for (E e : EnumNames<E>::values)
    if (name == EnumNames<E>::name(e)) return e;
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------
// Counter and timing fields: the report's (and the bindings') names of each member
// ---------------------------------------------------------------------------------------------

struct CounterField {
  const char* name;
  std::uint64_t CollideCounters::*member;
};
// Every CollideCounters member, in the order the schema documents them.
inline constexpr std::array<CounterField, 24> kCounterFields{{
    {"instance_pairs", &CollideCounters::instance_pairs},
    {"aabb_tests", &CollideCounters::aabb_tests},
    {"aabb_updates", &CollideCounters::aabb_updates},
    {"surfaces_a", &CollideCounters::surfaces_a},
    {"surfaces_b", &CollideCounters::surfaces_b},
    {"surface_pairs", &CollideCounters::surface_pairs},
    {"triangles_a", &CollideCounters::triangles_a},
    {"triangles_b", &CollideCounters::triangles_b},
    {"triangle_tests", &CollideCounters::triangle_tests},
    {"exact_fallbacks", &CollideCounters::exact_fallbacks},
    {"distance_tests", &CollideCounters::distance_tests},
    {"intersecting_pairs", &CollideCounters::intersecting_pairs},
    {"tessellated_surfaces", &CollideCounters::tessellated_surfaces},
    {"decided_mesh", &CollideCounters::decided_mesh},
    {"decided_mesh_exact", &CollideCounters::decided_mesh_exact},
    {"decided_analytic", &CollideCounters::decided_analytic},
    {"decided_refined", &CollideCounters::decided_refined},
    {"decided_exact", &CollideCounters::decided_exact},
    {"undecided", &CollideCounters::undecided},
    {"ambiguous_pairs", &CollideCounters::ambiguous_pairs},
    {"refined_surfaces", &CollideCounters::refined_surfaces},
    {"witness_queries", &CollideCounters::witness_queries},
    {"exact_queries", &CollideCounters::exact_queries},
    {"dismissed_pairs", &CollideCounters::dismissed_pairs},
}};

struct TimingField {
  const char* name;
  double CollideTimings::*member;
};
// The first kStageTimings are in every report with timings; the decide_* ones since 2026-11-28.
inline constexpr std::size_t kStageTimings = 5;
inline constexpr std::array<TimingField, 10> kTimingFields{{
    {"broad", &CollideTimings::broad},
    {"surface_level", &CollideTimings::surface_level},
    {"tessellation", &CollideTimings::tessellation},
    {"triangle_level", &CollideTimings::triangle_level},
    {"total", &CollideTimings::total},
    {"decide_witness", &CollideTimings::decide_witness},
    {"decide_depth", &CollideTimings::decide_depth},
    {"decide_refine", &CollideTimings::decide_refine},
    {"decide_hull", &CollideTimings::decide_hull},
    {"decide_exact", &CollideTimings::decide_exact},
}};

// ---------------------------------------------------------------------------------------------
// The report as plain structs
// ---------------------------------------------------------------------------------------------

// `settings`: the options the report was computed with (docs/report-schema.md, "settings").
struct ReportSettings {
  double tolerance = 0.0;  // mm
  double clearance = 0.0;  // mm
  std::string preset;      // the tessellation preset's name; empty: none (null)
  double deflection = 0.1;  // in effect (the preset's when one was given): mm, or a fraction when relative
  bool relative_deflection = false;
  double angular_deflection = 0.5;  // rad
  bool lazy = false;
  CollideMode mode = CollideMode::EarlyExit;
  ParallelVersion parallel = ParallelVersion::V1;
  Schedule schedule = Schedule::Guided;
  TriangleLevel triangle_level = TriangleLevel::Auto;
  bool oaabb = true;
  bool containment = true;
  DecisionMode decision = DecisionMode::Certified;
  std::vector<std::string> exclude_under, select_a, select_b;  // path prefixes as given
  double time_budget = 0.0;       // s; 0 = none
  double memory_budget_mb = 0.0;  // MiB; 0 = none
};

// The query half of the settings from `o` (tolerance ... memory_budget_mb; memory_budget_mb =
// memory_budget_bytes / 2^20). Tessellation fields and the path prefixes keep their defaults.
ReportSettings report_settings(const CollideOptions& o);

// One side of a pair. For containment (`whole_part`) only `instance` and `part` are written.
struct ReportSide {
  std::string instance;  // instance path
  std::string part;      // part name
  bool whole_part = false;
  std::string surface;   // surface name within the part
  SourceKind kind = SourceKind::MeshFile;
  std::int32_t face_index = -1;
  std::int64_t step_id = -1;  // < 0: not written
  std::string source_name;    // empty: not written
  double deflection = 0.0;
  double uncertainty = 0.0;   // ε the decision used (SurfacePairResult::uncertainty_a/b); 0 in reports written before it
  // where ε came from (model.h, uncertainty_source(Surface)); empty in reports written before it
  std::optional<UncertaintySource> uncertainty_source;
};

struct ReportPair {
  ReportSide a, b;
  ContactClass contact = ContactClass::Touching;
  DecidedBy decided_by = DecidedBy::Mesh;
  double distance_lo = 0.0, distance_hi = 0.0;  // +infinity: unbounded (null)
  ContactWithin within = ContactWithin::Unknown;  // "contact_within"; Unknown: null
  bool intersecting = false;
  double distance = 0.0;  // +infinity: null
  double penetration = 0.0;
  std::optional<double> exact_distance;
  std::vector<std::array<std::uint32_t, 2>> triangle_pairs;  // --all-triangles only
};

// One query's results: top level of a report without a trajectory, or one step of one.
struct QueryReport {
  std::vector<ReportPair> pairs;
  CollideCounters counters;
  std::optional<CollideTimings> timings;  // absent: not written (--no-timings)
  std::string stopped_by;                 // empty: every instance pair was examined (null)
  std::vector<std::array<std::string, 2>> unexamined_pairs;  // instance paths
  std::uint64_t memory_charged_bytes = 0;
  SceneMemory model;  // "model": bytes per component and triangles (absent in reports written before it: zeros)
};

struct StepReport {
  std::int64_t step = 0;
  QueryReport query;
};

// ---------------------------------------------------------------------------------------------
// Clashes and their review (cadclash/review.h computes them; docs/report-schema.md, "Clash")
// ---------------------------------------------------------------------------------------------

// A clash's status against a baseline report: new (not in it), active (unchanged), changed (worst
// class, a surface pair's class, or the depth changed), resolved (in the baseline, gone now),
// unexamined (in the baseline, its instance pair not examined by this partial run: unknown now).
enum class ClashStatus : std::uint8_t { New, Active, Changed, Resolved, Unexamined };
// Returns "new", "active", "changed", "resolved" or "unexamined".
const char* clash_status_name(ClashStatus s);
template <> struct EnumNames<ClashStatus> {
  static constexpr std::array values{ClashStatus::New, ClashStatus::Active, ClashStatus::Changed, ClashStatus::Resolved,
                                     ClashStatus::Unexamined};
  static const char* name(ClashStatus s) { return clash_status_name(s); }
};

// One surface pair of a clash.
struct ClashSurfacePair {
  std::string key;         // stable across runs: face indices (and STEP face names) within the parts
  std::int64_t pair = -1;  // index into the query's `pairs`; -1 for a resolved clash (its last data below)
  ContactClass contact = ContactClass::Touching;
  double penetration = 0.0;
  double distance = 0.0;  // +infinity: null
};

// The Boolean common of a clash's two solids (`cadclash check --volume`; cadclash/interference.h).
struct ClashInterference {
  bool measured = false;  // false: `note` says why not (a mesh, not a closed solid, an OCCT failure)
  std::string note;
  double volume = 0.0;  // mm^3
  double depth = 0.0;   // mm: smallest extent of the common's oriented box
  std::array<double, 3> centroid{};  // world; meaningful when volume > 0
};

// One clash: an instance pair with its surface pairs, the sides in canonical order (review.h).
struct ReportClash {
  std::string id;  // 12 hex digits (review.h: clash_id)
  ClashStatus status = ClashStatus::New;
  std::string instance_a, part_a, instance_b, part_b;
  ContactClass worst = ContactClass::Clearance;  // the most severe class of its surface pairs
  double max_penetration = 0.0;
  double min_distance = 0.0;  // +infinity: null
  std::string group;          // the group it belongs to (ClashReview::group_by)
  // World box of where the two meet (review.h: contact_boxes), for the viewer and spatial groups;
  // nullopt when not known (a resolved clash, or a review without the model).
  std::optional<std::array<double, 6>> box;
  std::optional<ClashInterference> interference;  // with --volume, for penetrating and containment clashes
  std::int64_t approval = -1;  // index into ClashReview::approvals; -1: not approved
  std::vector<ClashSurfacePair> surface_pairs;
};

// One approval: a clash id, or a rule by instance-path and part-name globs (review.h: matching).
struct Approval {
  std::string id;                      // a clash id; empty: a rule by the globs below
  std::string a, b;                    // instance path globs (rule only); empty: "**"
  std::string part_a, part_b;          // part name globs (rule only); empty: any part
  std::vector<ContactClass> classes;   // worst classes it approves; empty: every class
  std::string reason, by, date;        // date: YYYY-MM-DD
  std::string expires;                 // YYYY-MM-DD, last day it applies; empty: never expires
};

// What became of one approval in this run.
struct ApprovalUse {
  Approval approval;
  std::string source;       // where it was read: "FILE#/approvals/3"
  bool expired = false;     // `expires` is before the run's `today`: not applied
  std::uint64_t matched = 0;  // current clashes it approved (0 and not expired: stale)
};

struct ClashReview {
  std::string baseline;   // the baseline report's file; empty: none (every clash is new)
  std::string approvals_file;  // empty: none
  std::string today;      // YYYY-MM-DD the expiries were judged by; empty without approvals
  std::string group_by = "instance";  // instance | part | subassembly | space
  double cluster_distance = 0.0;      // mm, with group_by "space"
  std::vector<ReportClash> clashes;   // current clashes in the order of their first pair, then resolved ones
  std::vector<ApprovalUse> approvals;
};

// `import_timings`: where reading each input file went, in seconds (cadclash/import.h, ImportTimings),
// and what the import cache did for it. Written only with timings.
// A STEP file read in pieces: what each stage cost (cadclash/import.h, PieceCosts).
struct ReportPieceCosts {
  double split = 0.0, main_parse = 0.0, workers = 0.0;
  std::vector<std::uint64_t> bytes, weights;  // per piece
  std::vector<double> seconds;                // per piece: its worker's CPU seconds (0: from the cache)
};
struct ReportFileImport {
  std::string file;           // as given
  std::string cache = "off";  // "off", "hit", "miss", "rebuilt" or "placements" (cache_use_name)
  double read = 0.0, transfer = 0.0, heal = 0.0, tessellate = 0.0, total = 0.0;
  std::uint64_t processes = 1;  // STEP: processes that read and transferred the file at once
  // STEP: the pieces its products' shapes were cut into and how many came from the cache; CAD parts
  // that came checked and healed from the cache (FileImport).
  std::uint64_t pieces = 0, pieces_cached = 0, parts_cached = 0;
  std::optional<ReportPieceCosts> piece_costs;  // a STEP file read in pieces by this process
  std::vector<double> part_heal_seconds;        // per B-rep part checked and healed here (FileImport)
};
struct ReportImport {
  double seconds = 0.0;  // wall clock of the whole import (files are read in parallel)
  std::vector<ReportFileImport> files;
};

// The whole path checked continuously (`check --path --continuous`; trajectory.h, replay_continuous):
// per instance pair that may be in contact at some time, where, in step numbers. A span is proved in
// contact at both ends (`contact_at_ends`; in between not proved either way) or at most the
// resolution wide: a contact may begin, end or hold there. A pair not listed is proved out of
// contact over the whole path.
struct ReportSpan {
  double t0 = 0.0, t1 = 0.0;
  bool contact_at_ends = false;
};
struct ReportSurfaceTimeline {
  ReportSide a, b;  // the surfaces (instance, part, surface, its STEP #id ...); uncertainty not set
  std::vector<ReportSpan> spans;
};
// With --clearance: the minimum distance over the path lies in [lo, hi] and is reached within
// [t0, t1] (step numbers).
struct ReportClosest {
  double lo = 0.0, hi = 0.0, t0 = 0.0, t1 = 0.0;
};
struct ReportPairTimeline {
  std::string a, b;  // instance paths
  std::vector<ReportSpan> spans;
  std::vector<ReportSurfaceTimeline> surfaces;
  std::optional<ReportClosest> closest;  // with --clearance, when the pair comes within it
};
struct ReportTimeline {
  double resolution = 0.0;   // the spans' width where a contact begins or ends, a fraction of a stretch
  std::uint64_t checks = 0;  // static checks the motion took (the steps' own not counted)
  bool complete = true;      // false: a stretch ran out of its checks, or the path was cut short
  std::vector<ReportPairTimeline> pairs;
};

// `r` over `model` with every id resolved to names. Precondition: every id in `r` is valid for `model`.
ReportTimeline timeline_report(const Model& model, const PathResult& r, double resolution);

struct CheckReport {
  int version = kCheckReportVersion;
  std::vector<std::string> files;  // as given
  ReportSettings settings;
  // Without a trajectory: the query (top-level pairs, summary, counters, timings, stopped_by,
  // unexamined_pairs, memory_charged_bytes). With one: nullopt, and the fields below.
  std::optional<QueryReport> query;
  std::string trajectory;  // the CSV file
  std::vector<StepReport> steps;
  std::uint64_t steps_not_checked = 0;
  std::string stopped_by;  // first budget that ran out over the steps; empty: none (null)
  std::vector<std::string> diagnostics;  // format_diagnostic() lines
  bool complete = true;
  // Without a trajectory: the query's pairs grouped into clashes, with their review (written as
  // `clashes` and `review`); nullopt: not written (reports of the library's callers that do not ask).
  std::optional<ClashReview> review;
  std::optional<ReportImport> import;    // absent: not written (and not in reports written without timings)
  std::optional<ReportTimeline> timeline;  // with --continuous: the path's timeline ("timeline")
};

// `r` over `model` with every id resolved to names: what the report says about one query.
// Timings are included; reset `timings` to leave them out.
// Precondition: every id in `r` is valid for `model`.
QueryReport query_report(const Model& model, const Report& r);

// ---------------------------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------------------------

struct ReportWriteOptions {
  bool timings = true;  // false: leave every `timings` out, as --no-timings does
};

nlohmann::json check_report_json(const CheckReport& r, const ReportWriteOptions& o = {});
// The file `cadclash check --json` writes: check_report_json(r, o) as report_text().
std::string check_report_text(const CheckReport& r, const ReportWriteOptions& o = {});
// JSON as the report files are written: 2-space indent, invalid UTF-8 replaced, a final newline.
std::string report_text(const nlohmann::json& j);

// The `clashes` list and the `review` object of a report (written at the top level with `r.review`).
nlohmann::json clashes_json(const ClashReview& r);
nlohmann::json review_json(const ClashReview& r);
// One approval as the approvals file and the report's `review.approvals` hold it.
nlohmann::json approval_json(const Approval& a);

// The pieces, for the JSON documents built around them (HTML report, `cadclash info`):
// `summary`: counts per class and per decided_by (containment excluded from decided_by).
nlohmann::json summary_json(const std::vector<ReportPair>& pairs);
nlohmann::json counters_json(const CollideCounters& c);
nlohmann::json timings_json(const CollideTimings& t);
// One pair's fields; the sides `a`/`b` only with `sides`.
nlohmann::json pair_json(const ReportPair& p, bool sides = true);
// What every JSON of cadclash says about a surface: kind, face_index, deflection, and step_id /
// source_name when it has them (the name is left to the caller: "surface" or "name").
nlohmann::json surface_json(const Surface& s);
// v when finite, else null.
nlohmann::json number_or_null(double v);

// A surface's name and complete provenance (the OBJ comment lines and the .glb extras of the
// exporters): every Provenance field, the deflection, and the part-local box when not empty.
nlohmann::json provenance_json(const Surface& s);

// ---------------------------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------------------------

struct ReportError {
  std::string path;     // JSON pointer of the offending value ("/pairs/3/class"); "" = the whole text
  std::string message;  // one sentence
};
// "path: message" (or the message alone when the path is empty).
std::string format_report_error(const ReportError& e);

struct ReportReadResult {
  CheckReport report;                // meaningful only when !error
  std::optional<ReportError> error;  // the first problem found
};

// Parses a report written by check_report_text() (schema "cadclash-check-report", version 2).
// Checks types, enum names, that `summary` matches the pairs, and the trajectory/query layout.
ReportReadResult check_report_from_json(std::string_view text);
// The same on a document already parsed.
ReportReadResult check_report_from_parsed(const nlohmann::json& j);

// Reads one approval written by approval_json() (or by hand: unknown fields are ignored); `path`
// is its JSON pointer for the error. Checks the dates (YYYY-MM-DD) and that it names an id or a rule.
std::optional<ReportError> approval_from_json(const nlohmann::json& j, const std::string& path, Approval& out);

// Reads back what provenance_json() wrote into `s` (name, provenance, deflection, box; the box is
// emptied when none was written). Returns the first problem; `s` is then partly assigned.
std::optional<ReportError> provenance_from_json(const nlohmann::json& j, Surface& s);

}  // namespace cadclash
