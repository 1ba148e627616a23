// cadclash._cadclash's report pieces: the JSON report document (cadclash/report.h) and the name
// tables the pure-Python package takes its counter fields and enum names from.
#include "convert.h"

#include "cadclash/review.h"

#include <algorithm>
#include <optional>

#include <pybind11/stl.h>

namespace cadclash::py {
namespace {

// {name: pybind enum value} for an enum the options take by name.
template <class E>
pyb::dict names_to_values() {
  pyb::dict d;
  for (E e : EnumNames<E>::values) d[EnumNames<E>::name(e)] = pyb::cast(e);
  return d;
}

template <class E>
pyb::tuple names() {
  pyb::list out;
  for (E e : EnumNames<E>::values) out.append(EnumNames<E>::name(e));
  return pyb::tuple(out);
}

pyb::object side_tuple(const ReportSide& s) {
  if (s.whole_part) return pyb::make_tuple(s.instance, s.part, pyb::none(), pyb::none());
  return pyb::make_tuple(s.instance, s.part, s.surface, s.step_id >= 0 ? pyb::object(pyb::int_(s.step_id)) : pyb::none());
}

// (pairs, counters, timings|None, stopped_by, unexamined [(a, b)], memory_charged, model bytes) with each pair
// (class, decided_by, lo, hi, intersecting, distance, penetration, exact|None, triangle_pairs,
//  (instance, part, surface|None, step_id|None) of a, the same of b, contact_within|None).
pyb::tuple query_tuple(const QueryReport& q) {
  pyb::list pairs;
  for (const ReportPair& p : q.pairs) {
    pyb::object exact = p.exact_distance ? pyb::object(pyb::float_(*p.exact_distance)) : pyb::object(pyb::none());
    pairs.append(pyb::make_tuple(contact_class_name(p.contact), decided_by_name(p.decided_by), p.distance_lo,
                                 p.distance_hi, p.intersecting, p.distance, p.penetration, exact,
                                 triangle_pairs_array(p.triangle_pairs), side_tuple(p.a), side_tuple(p.b),
                                 within_or_none(p.within)));
  }
  pyb::list unexamined;
  for (const auto& [a, b] : q.unexamined_pairs) unexamined.append(pyb::make_tuple(a, b));
  pyb::object timings = q.timings ? pyb::object(timings_to_dict(*q.timings)) : pyb::object(pyb::none());
  return pyb::make_tuple(pairs, counters_to_dict(q.counters), timings, q.stopped_by, unexamined, q.memory_charged_bytes,
                         model_memory_to_dict(q.model));
}

}  // namespace

void bind_report(pyb::module_& m) {
  m.attr("REPORT_SCHEMA") = std::string(kCheckReportSchema);
  m.attr("REPORT_VERSION") = kCheckReportVersion;
  pyb::list counters, timings;
  for (const CounterField& f : kCounterFields) counters.append(f.name);
  for (const TimingField& f : kTimingFields) timings.append(f.name);
  m.attr("COUNTER_FIELDS") = pyb::tuple(counters);
  m.attr("TIMING_FIELDS") = pyb::tuple(timings);
  m.attr("CONTACT_CLASSES") = names<ContactClass>();
  m.attr("DECIDED_BY") = names<DecidedBy>();
  m.attr("SOURCE_KINDS") = names<SourceKind>();
  m.attr("PARALLEL_VERSIONS") = names_to_values<ParallelVersion>();
  m.attr("SCHEDULES") = names_to_values<Schedule>();
  m.attr("TRIANGLE_LEVELS") = names_to_values<TriangleLevel>();

  pyb::class_<QueryReport>(m, "QueryRecord", "One query's results as the JSON report holds them (names resolved).");
  pyb::class_<ReportSettings>(m, "ReportSettings", "The report's `settings` (cadclash::ReportSettings).");

  m.def(
      "report_settings",
      [](const CollideOptions& o, const ModelCore& model, std::vector<std::string> select_a,
         std::vector<std::string> select_b, std::vector<std::string> exclude_under) {
        const ModelState& st = *model.state;  // the load settings are fixed after load
        ReportSettings s = report_settings(o);
        s.preset = st.preset;
        s.deflection = st.tessellation.linear_deflection;
        s.relative_deflection = st.tessellation.relative;
        s.angular_deflection = st.tessellation.angular_deflection;
        s.lazy = st.lazy;
        s.select_a = std::move(select_a);
        s.select_b = std::move(select_b);
        s.exclude_under = std::move(exclude_under);
        return s;
      },
      pyb::arg("options"), pyb::arg("model"), pyb::arg("select_a"), pyb::arg("select_b"), pyb::arg("exclude_under"),
      "The report's settings for a query with these options on this model (as `cadclash check` writes them).");

  pyb::class_<ReportTimeline>(m, "ReportTimeline", "A continuous path's timeline (cadclash::ReportTimeline), opaque.");
  pyb::class_<CheckReport>(m, "ReportDocument", "A `cadclash check --json` report (cadclash::CheckReport).")
      .def(pyb::init([](std::vector<std::string> files, ReportSettings settings, QueryReport query,
                        std::vector<std::string> diagnostics, bool complete) {
             CheckReport r;
             r.files = std::move(files);
             r.settings = std::move(settings);
             r.query = std::move(query);
             r.diagnostics = std::move(diagnostics);
             r.complete = complete;
             r.review = review_query(*r.query, nullptr, {}, {});  // as `cadclash check` without review options
             return r;
           }),
           pyb::arg("files"), pyb::arg("settings"), pyb::arg("query"), pyb::arg("diagnostics"), pyb::arg("complete"))
      .def(
          "reviewed",
          [](const CheckReport& r, const CheckReport* baseline, const std::optional<std::string>& approvals_text,
             const std::string& approvals_file, const std::string& baseline_file, const std::string& today,
             const std::string& group_by, double depth_change) {
            if (!r.query) throw pyb::value_error("a trajectory report has no clashes to review");
            if (baseline && !baseline->query) throw pyb::value_error("a trajectory report cannot be a baseline");
            if (group_by == "space")
              throw pyb::value_error("group_by='space' needs the model's geometry: use `cadclash check --group-by space`");
            if (std::find(kGroupBy.begin(), kGroupBy.end(), group_by) == kGroupBy.end())
              throw pyb::value_error("group_by must be 'instance', 'part' or 'subassembly', not '" + group_by + "'");
            if (depth_change < 0) throw pyb::value_error("depth_change must be >= 0");
            std::vector<Approval> approvals;
            ReviewOptions o;
            o.group_by = group_by;
            o.depth_change = depth_change;
            o.baseline_file = baseline_file;
            if (approvals_text) {
              ApprovalsReadResult read = approvals_from_json(*approvals_text);
              if (read.error)
                throw pyb::value_error((approvals_file.empty() ? std::string("approvals") : approvals_file) + ": " +
                                       format_report_error(*read.error));
              approvals = std::move(read.approvals);
              if (!iso_date(today)) throw pyb::value_error("today must be a date YYYY-MM-DD, not '" + today + "'");
              o.approvals_file = approvals_file;
              o.today = today;
            }
            CheckReport out = r;
            out.review = review_query(*r.query, baseline ? &*baseline->query : nullptr, approvals, o);
            return out;
          },
          pyb::arg("baseline"), pyb::arg("approvals_text"), pyb::arg("approvals_file"), pyb::arg("baseline_file"),
          pyb::arg("today"), pyb::arg("group_by"), pyb::arg("depth_change"),
          "A copy with the clash review redone (cadclash/review.h: review_query).")
      .def("_review_json",
           [](const CheckReport& r) -> pyb::object {
             if (!r.review) return pyb::none();
             return pyb::str(nlohmann::json{{"clashes", clashes_json(*r.review)}, {"review", review_json(*r.review)}}.dump());
           })
      .def_static(
          "trajectory",
          [](std::vector<std::string> files, ReportSettings settings, std::string trajectory,
             std::vector<std::pair<std::int64_t, QueryReport>> steps, std::uint64_t steps_not_checked,
             std::string stopped_by, std::vector<std::string> diagnostics, bool complete,
             std::optional<ReportTimeline> timeline) {
            CheckReport r;
            r.files = std::move(files);
            r.settings = std::move(settings);
            r.trajectory = std::move(trajectory);
            for (auto& [step, query] : steps) r.steps.push_back({step, std::move(query)});
            r.steps_not_checked = steps_not_checked;
            r.stopped_by = std::move(stopped_by);
            r.diagnostics = std::move(diagnostics);
            r.complete = complete && (!timeline || timeline->complete);
            r.timeline = std::move(timeline);
            return r;
          },
          pyb::arg("files"), pyb::arg("settings"), pyb::arg("trajectory"), pyb::arg("steps"),
          pyb::arg("steps_not_checked"), pyb::arg("stopped_by"), pyb::arg("diagnostics"), pyb::arg("complete"),
          pyb::arg("timeline") = pyb::none(),
          "A `cadclash check --path` report: one (step, QueryRecord) per step checked, and with --continuous "
          "the path's timeline.")
      .def(
          "to_json",
          [](const CheckReport& r, bool with_timings) { return check_report_text(r, {.timings = with_timings}); },
          pyb::arg("timings"), "The report's JSON text, byte for byte as `cadclash check --json` writes it.")
      .def_static(
          "from_json",
          [](const std::string& text) {
            ReportReadResult read = check_report_from_json(text);
            if (read.error) throw pyb::value_error("not a cadclash check report: " + format_report_error(*read.error));
            return std::move(read.report);
          },
          pyb::arg("text"), "Parses a report; ValueError naming the JSON path of the first problem.")
      .def_readonly("files", &CheckReport::files)
      .def_readonly("diagnostics", &CheckReport::diagnostics)
      .def_readonly("complete", &CheckReport::complete)
      .def_property_readonly("is_trajectory", [](const CheckReport& r) { return !r.query.has_value(); })
      .def("_query", [](const CheckReport& r) {
        if (!r.query) throw pyb::value_error("a trajectory report (--path) holds steps, not one query: read it with Replay.from_json");
        return query_tuple(*r.query);
      })
      // (resolution, checks, complete, [(a, b, spans, [(side a, side b, spans)], closest|None)]) with each span
      // (t0, t1, contact_at_ends) and each side as in query_tuple; None without a timeline.
      .def("_timeline", [](const CheckReport& r) -> pyb::object {
        if (!r.timeline) return pyb::none();
        auto spans = [](const std::vector<ReportSpan>& v) {
          pyb::list out;
          for (const ReportSpan& s : v) out.append(pyb::make_tuple(s.t0, s.t1, s.contact_at_ends));
          return out;
        };
        pyb::list pairs;
        for (const ReportPairTimeline& p : r.timeline->pairs) {
          pyb::list surfaces;
          for (const ReportSurfaceTimeline& s : p.surfaces)
            surfaces.append(pyb::make_tuple(side_tuple(s.a), side_tuple(s.b), spans(s.spans)));
          pyb::object closest = p.closest ? pyb::object(pyb::make_tuple(p.closest->lo, p.closest->hi, p.closest->t0, p.closest->t1))
                                          : pyb::object(pyb::none());
          pairs.append(pyb::make_tuple(p.a, p.b, spans(p.spans), surfaces, closest));
        }
        return pyb::make_tuple(r.timeline->resolution, r.timeline->checks, r.timeline->complete, pairs);
      })
      .def("_steps", [](const CheckReport& r) {
        if (r.query) throw pyb::value_error("a report of one query holds no steps (no --path trajectory): read it with Report.from_json");
        pyb::list steps;
        for (const StepReport& s : r.steps) steps.append(pyb::make_tuple(s.step, query_tuple(s.query)));
        return pyb::make_tuple(r.trajectory, steps, r.steps_not_checked, r.stopped_by);
      });
}

}  // namespace cadclash::py
