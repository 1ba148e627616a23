// The report's writer: the model + query → QueryReport resolution, and the JSON.
#include "cadclash/report.h"

#include <cmath>
#include <limits>

namespace cadclash {

ReportSettings report_settings(const CollideOptions& o) {
  ReportSettings s;
  s.tolerance = o.tolerance;
  s.clearance = o.clearance;
  s.mode = o.mode;
  s.parallel = o.version;
  s.schedule = o.schedule;
  s.triangle_level = o.triangle_level;
  s.oaabb = o.use_oaabb;
  s.containment = o.detect_containment;
  s.decision = o.decision;
  s.time_budget = o.time_budget_seconds;
  s.memory_budget_mb = static_cast<double>(o.memory_budget_bytes) / (1024.0 * 1024.0);
  return s;
}

namespace {

ReportSide side(const Model& m, InstanceId i, SurfaceId s) {
  const Instance& inst = m.instances[i];
  ReportSide out;
  out.instance = inst.path;
  out.part = m.parts[inst.part].name;
  out.whole_part = s == kInvalidId;
  if (out.whole_part) return out;
  const Surface& surf = m.surfaces[s];
  out.surface = surf.name;
  out.kind = surf.provenance.kind;
  out.face_index = surf.provenance.face_index;
  out.step_id = surf.provenance.step_id;
  out.source_name = surf.provenance.source_name;
  out.deflection = surf.deflection;
  return out;
}

ReportSide side(const Model& m, InstanceId i, SurfaceId s, double uncertainty) {
  ReportSide out = side(m, i, s);
  out.uncertainty = uncertainty;
  if (!out.whole_part) out.uncertainty_source = uncertainty_source(m.surfaces[s]);
  return out;
}

double or_infinity(double v) { return std::isfinite(v) ? v : std::numeric_limits<double>::infinity(); }

nlohmann::json side_json(const ReportSide& s) {
  nlohmann::json j{{"instance", s.instance}, {"part", s.part}};
  if (s.whole_part) return j;
  j["surface"] = s.surface;
  j["kind"] = source_kind_name(s.kind);
  j["face_index"] = s.face_index;
  if (s.step_id >= 0) j["step_id"] = s.step_id;
  if (!s.source_name.empty()) j["source_name"] = s.source_name;
  j["deflection"] = s.deflection;
  j["uncertainty"] = s.uncertainty;
  if (s.uncertainty_source) j["uncertainty_source"] = uncertainty_source_name(*s.uncertainty_source);
  return j;
}

nlohmann::json string_or_null(const std::string& s) { return s.empty() ? nlohmann::json(nullptr) : nlohmann::json(s); }

nlohmann::json settings_json(const ReportSettings& s) {
  return {{"tolerance", s.tolerance},
          {"clearance", s.clearance},
          {"preset", string_or_null(s.preset)},
          {"deflection", s.deflection},
          {"relative_deflection", s.relative_deflection},
          {"angular_deflection", s.angular_deflection},
          {"lazy", s.lazy},
          {"mode", collide_mode_name(s.mode)},
          {"parallel", parallel_version_name(s.parallel)},
          {"schedule", schedule_name(s.schedule)},
          {"triangle_level", triangle_level_name(s.triangle_level)},
          {"oaabb", s.oaabb},
          {"containment", s.containment},
          {"decision", decision_mode_name(s.decision)},
          {"exclude_under", s.exclude_under},
          {"select_a", s.select_a},
          {"select_b", s.select_b},
          {"time_budget", s.time_budget},
          {"memory_budget_mb", s.memory_budget_mb}};
}

// The fields of one query, into `j` (the top level, or a step).
void put_query(const QueryReport& q, const ReportWriteOptions& o, nlohmann::json& j) {
  nlohmann::json pairs = nlohmann::json::array();
  for (const ReportPair& p : q.pairs) pairs.push_back(pair_json(p));
  j["pairs"] = std::move(pairs);
  j["summary"] = summary_json(q.pairs);
  j["counters"] = counters_json(q.counters);
  if (o.timings && q.timings) j["timings"] = timings_json(*q.timings);
  j["stopped_by"] = string_or_null(q.stopped_by);
  nlohmann::json u = nlohmann::json::array();
  for (const auto& [a, b] : q.unexamined_pairs) u.push_back({{"a", a}, {"b", b}});
  j["unexamined_pairs"] = std::move(u);
  j["memory_charged_bytes"] = q.memory_charged_bytes;
  j["model"] = {{"bytes",
                 {{"triangles", q.model.triangles},
                  {"vertices", q.model.vertices},
                  {"hierarchies", q.model.hierarchies},
                  {"instances", q.model.instances},
                  {"total", q.model.total()}}},
                {"triangles", q.model.triangle_count}};
}

}  // namespace

QueryReport query_report(const Model& model, const Report& r) {
  QueryReport q;
  q.pairs.reserve(r.pairs.size());
  for (const SurfacePairResult& p : r.pairs) {
    ReportPair out;
    out.a = side(model, p.instance_a, p.surface_a, p.uncertainty_a);
    out.b = side(model, p.instance_b, p.surface_b, p.uncertainty_b);
    out.within = p.within;
    out.contact = p.contact;
    out.decided_by = p.decided_by;
    out.distance_lo = or_infinity(p.distance_lo);
    out.distance_hi = or_infinity(p.distance_hi);
    out.intersecting = p.intersecting;
    out.distance = or_infinity(p.distance);
    out.penetration = p.penetration;
    if (p.exact_distance) out.exact_distance = or_infinity(*p.exact_distance);
    out.triangle_pairs = p.triangle_pairs;
    q.pairs.push_back(std::move(out));
  }
  q.counters = r.counters;
  q.timings = r.timings;
  if (!r.complete) q.stopped_by = r.stopped_by;
  for (const auto& [a, b] : r.unexamined_pairs) q.unexamined_pairs.push_back({model.instances[a].path, model.instances[b].path});
  q.memory_charged_bytes = r.memory_charged;
  q.model = r.model_memory;
  return q;
}

nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json summary_json(const std::vector<ReportPair>& pairs) {
  std::array<std::size_t, EnumNames<ContactClass>::values.size()> by_class{};
  std::array<std::size_t, EnumNames<DecidedBy>::values.size()> by_decision{};
  std::array<std::size_t, EnumNames<ContactWithin>::values.size()> by_within{};
  for (const ReportPair& p : pairs) {
    ++by_class[static_cast<std::size_t>(p.contact)];
    if (p.contact == ContactClass::Penetrating || p.contact == ContactClass::Touching)
      ++by_within[static_cast<std::size_t>(p.within)];
    if (p.contact != ContactClass::Containment) ++by_decision[static_cast<std::size_t>(p.decided_by)];
  }
  nlohmann::json j{{"pairs", pairs.size()}};
  for (ContactClass c : EnumNames<ContactClass>::values) j[contact_class_name(c)] = by_class[static_cast<std::size_t>(c)];
  nlohmann::json by = nlohmann::json::object();
  for (DecidedBy d : EnumNames<DecidedBy>::values) by[decided_by_name(d)] = by_decision[static_cast<std::size_t>(d)];
  j["decided_by"] = std::move(by);
  nlohmann::json within = nlohmann::json::object();
  for (ContactWithin w : EnumNames<ContactWithin>::values)
    within[contact_within_name(w)] = by_within[static_cast<std::size_t>(w)];
  j["contact_within"] = std::move(within);
  return j;
}

nlohmann::json counters_json(const CollideCounters& c) {
  nlohmann::json j = nlohmann::json::object();
  for (const CounterField& f : kCounterFields) j[f.name] = c.*f.member;
  return j;
}

nlohmann::json timings_json(const CollideTimings& t) {
  nlohmann::json j = nlohmann::json::object();
  for (const TimingField& f : kTimingFields) j[f.name] = t.*f.member;
  return j;
}

nlohmann::json pair_json(const ReportPair& p, bool sides) {
  nlohmann::json j{{"class", contact_class_name(p.contact)},
                   {"decided_by", decided_by_name(p.decided_by)},
                   {"distance_interval", {number_or_null(p.distance_lo), number_or_null(p.distance_hi)}},
                   {"contact_within", p.within == ContactWithin::Unknown ? nlohmann::json(nullptr)
                                                                         : nlohmann::json(contact_within_name(p.within))},
                   {"intersecting", p.intersecting},
                   {"distance", number_or_null(p.distance)},
                   {"penetration", p.penetration}};
  if (p.exact_distance) j["exact_distance"] = number_or_null(*p.exact_distance);
  if (!sides) return j;
  j["a"] = side_json(p.a);
  j["b"] = side_json(p.b);
  if (!p.triangle_pairs.empty()) j["triangle_pairs"] = p.triangle_pairs;
  return j;
}

nlohmann::json surface_json(const Surface& s) {
  ReportSide side;
  side.kind = s.provenance.kind;
  side.face_index = s.provenance.face_index;
  side.step_id = s.provenance.step_id;
  side.source_name = s.provenance.source_name;
  side.deflection = s.deflection;
  nlohmann::json j = side_json(side);
  j.erase("instance");
  j.erase("part");
  j.erase("surface");
  return j;
}

nlohmann::json provenance_json(const Surface& s) {
  const Provenance& p = s.provenance;
  nlohmann::json j{{"name", s.name},
                   {"kind", source_kind_name(p.kind)},
                   {"step_id", p.step_id},
                   {"face_index", p.face_index},
                   {"source_name", p.source_name},
                   {"source_file", p.source_file},
                   {"deflection", s.deflection},
                   {"healed", p.healed},
                   {"repaired", p.repaired}};
  if (p.parent != kInvalidId) j["parent"] = p.parent;
  if (p.colour) j["colour"] = *p.colour;
  // B-rep surfaces carry a box around the exact surface, larger than their triangles' box.
  if (!s.aabb.isEmpty())
    j["aabb"] = {s.aabb.min().x(), s.aabb.min().y(), s.aabb.min().z(), s.aabb.max().x(), s.aabb.max().y(), s.aabb.max().z()};
  return j;
}

const char* clash_status_name(ClashStatus s) {
  switch (s) {
    case ClashStatus::Active: return "active";
    case ClashStatus::Changed: return "changed";
    case ClashStatus::Resolved: return "resolved";
    case ClashStatus::Unexamined: return "unexamined";
    case ClashStatus::New: break;
  }
  return "new";
}

nlohmann::json approval_json(const Approval& a) {
  nlohmann::json j = nlohmann::json::object();
  if (!a.id.empty()) {
    j["id"] = a.id;
  } else {
    j["a"] = a.a.empty() ? std::string("**") : a.a;
    j["b"] = a.b.empty() ? std::string("**") : a.b;
    if (!a.part_a.empty()) j["part_a"] = a.part_a;
    if (!a.part_b.empty()) j["part_b"] = a.part_b;
  }
  if (!a.classes.empty()) {
    nlohmann::json c = nlohmann::json::array();
    for (ContactClass k : a.classes) c.push_back(contact_class_name(k));
    j["classes"] = std::move(c);
  }
  j["reason"] = a.reason;
  j["by"] = a.by;
  j["date"] = a.date;
  if (!a.expires.empty()) j["expires"] = a.expires;
  return j;
}

static nlohmann::json interference_json(const std::optional<ClashInterference>& i) {
  if (!i) return nullptr;
  return {{"measured", i->measured},
          {"note", string_or_null(i->note)},
          {"volume", i->volume},
          {"depth", i->depth},
          {"centroid", i->volume > 0 ? nlohmann::json(i->centroid) : nlohmann::json(nullptr)}};
}

nlohmann::json clashes_json(const ClashReview& r) {
  nlohmann::json out = nlohmann::json::array();
  for (const ReportClash& c : r.clashes) {
    nlohmann::json sp = nlohmann::json::array();
    for (const ClashSurfacePair& p : c.surface_pairs)
      sp.push_back({{"key", p.key},
                    {"pair", p.pair < 0 ? nlohmann::json(nullptr) : nlohmann::json(p.pair)},
                    {"class", contact_class_name(p.contact)},
                    {"penetration", p.penetration},
                    {"distance", number_or_null(p.distance)}});
    nlohmann::json j{{"id", c.id},
                     {"status", clash_status_name(c.status)},
                     {"a", {{"instance", c.instance_a}, {"part", c.part_a}}},
                     {"b", {{"instance", c.instance_b}, {"part", c.part_b}}},
                     {"class", contact_class_name(c.worst)},
                     {"max_penetration", c.max_penetration},
                     {"min_distance", number_or_null(c.min_distance)},
                     {"group", c.group},
                     {"box", c.box ? nlohmann::json(*c.box) : nlohmann::json(nullptr)},
                     {"interference", interference_json(c.interference)},
                     {"approval", c.approval < 0 ? nlohmann::json(nullptr) : nlohmann::json(c.approval)},
                     {"surface_pairs", std::move(sp)}};
    out.push_back(std::move(j));
  }
  return out;
}

nlohmann::json review_json(const ClashReview& r) {
  nlohmann::json counts = nlohmann::json::object();
  for (ClashStatus s : EnumNames<ClashStatus>::values) counts[clash_status_name(s)] = 0;
  std::size_t approved = 0;
  for (const ReportClash& c : r.clashes) {
    counts[clash_status_name(c.status)] = counts[clash_status_name(c.status)].get<std::size_t>() + 1;
    approved += c.approval >= 0;
  }
  counts["approved"] = approved;
  counts["clashes"] = r.clashes.size();
  nlohmann::json approvals = nlohmann::json::array();
  std::size_t stale = 0, expired = 0;
  for (const ApprovalUse& u : r.approvals) {
    const char* state = u.expired ? "expired" : u.matched == 0 ? "stale" : "used";
    stale += !u.expired && u.matched == 0;
    expired += u.expired;
    approvals.push_back({{"approval", approval_json(u.approval)},
                         {"source", u.source},
                         {"state", state},
                         {"matched", u.matched}});
  }
  counts["stale_approvals"] = stale;
  counts["expired_approvals"] = expired;
  return {{"baseline", string_or_null(r.baseline)},
          {"approvals_file", string_or_null(r.approvals_file)},
          {"today", string_or_null(r.today)},
          {"group_by", r.group_by},
          {"cluster_distance", r.cluster_distance},
          {"summary", std::move(counts)},
          {"approvals", std::move(approvals)}};
}

ReportTimeline timeline_report(const Model& model, const PathResult& r, double resolution) {
  ReportTimeline t;
  t.resolution = resolution;
  t.checks = r.checks;
  t.complete = r.complete;
  auto spans_of = [](const std::vector<MotionSpan>& v) {
    std::vector<ReportSpan> out;
    for (const MotionSpan& s : v) out.push_back({s.s0, s.s1, s.contact_at_ends});
    return out;
  };
  for (const PairMotion& p : r.pairs) {
    ReportPairTimeline rp{model.instances[p.a].path, model.instances[p.b].path, spans_of(p.spans), {}, {}};
    if (p.closest) rp.closest = ReportClosest{p.closest->lo, p.closest->hi, p.closest->s0, p.closest->s1};
    for (const SurfaceMotion& s : p.surfaces)
      rp.surfaces.push_back({side(model, p.a, s.a), side(model, p.b, s.b), spans_of(s.spans)});
    t.pairs.push_back(std::move(rp));
  }
  return t;
}

namespace {

nlohmann::json spans_json(const std::vector<ReportSpan>& v) {
  nlohmann::json out = nlohmann::json::array();
  for (const ReportSpan& s : v) out.push_back({{"t0", s.t0}, {"t1", s.t1}, {"contact_at_ends", s.contact_at_ends}});
  return out;
}

nlohmann::json timeline_json(const ReportTimeline& t) {
  nlohmann::json pairs = nlohmann::json::array();
  for (const ReportPairTimeline& p : t.pairs) {
    nlohmann::json surfaces = nlohmann::json::array();
    for (const ReportSurfaceTimeline& s : p.surfaces) {
      nlohmann::json a = side_json(s.a), b = side_json(s.b);
      for (nlohmann::json* j : {&a, &b}) j->erase("uncertainty");  // not the decision's: not known here
      surfaces.push_back({{"a", std::move(a)}, {"b", std::move(b)}, {"spans", spans_json(s.spans)}});
    }
    nlohmann::json jp{{"a", p.a}, {"b", p.b}, {"spans", spans_json(p.spans)}, {"surfaces", std::move(surfaces)}};
    if (p.closest)
      jp["closest"] = {{"lo", p.closest->lo}, {"hi", p.closest->hi}, {"t0", p.closest->t0}, {"t1", p.closest->t1}};
    pairs.push_back(std::move(jp));
  }
  return {{"resolution", t.resolution}, {"checks", t.checks}, {"complete", t.complete}, {"pairs", std::move(pairs)}};
}

}  // namespace

nlohmann::json check_report_json(const CheckReport& r, const ReportWriteOptions& o) {
  nlohmann::json j;
  j["schema"] = kCheckReportSchema;
  j["version"] = r.version;
  j["files"] = r.files;
  j["settings"] = settings_json(r.settings);
  if (r.query) {
    put_query(*r.query, o, j);
  } else {
    j["trajectory"] = r.trajectory;
    nlohmann::json steps = nlohmann::json::array();
    for (const StepReport& s : r.steps) {
      nlohmann::json js{{"step", s.step}};
      put_query(s.query, o, js);
      steps.push_back(std::move(js));
    }
    j["steps"] = std::move(steps);
    j["steps_not_checked"] = r.steps_not_checked;
    j["stopped_by"] = string_or_null(r.stopped_by);
    if (r.timeline) j["timeline"] = timeline_json(*r.timeline);
  }
  if (r.review) {
    j["clashes"] = clashes_json(*r.review);
    j["review"] = review_json(*r.review);
  }
  j["diagnostics"] = r.diagnostics;
  j["complete"] = r.complete;
  if (o.timings && r.import) {
    nlohmann::json files = nlohmann::json::array();
    for (const ReportFileImport& f : r.import->files) {
      nlohmann::json costs = nullptr;
      if (const auto& c = f.piece_costs)
        costs = {{"split", c->split}, {"main_parse", c->main_parse}, {"workers", c->workers}, {"bytes", c->bytes}, {"weights", c->weights},
                 {"seconds", c->seconds}};
      files.push_back({{"file", f.file}, {"cache", f.cache}, {"read", f.read}, {"transfer", f.transfer},
                       {"heal", f.heal}, {"tessellate", f.tessellate}, {"total", f.total}, {"processes", f.processes},
                       {"pieces", f.pieces}, {"pieces_cached", f.pieces_cached}, {"parts_cached", f.parts_cached},
                       {"piece_costs", std::move(costs)}, {"part_heal_seconds", f.part_heal_seconds}});
    }
    j["import_timings"] = {{"seconds", r.import->seconds}, {"files", std::move(files)}};
  }
  return j;
}

std::string report_text(const nlohmann::json& j) {
  // File text quoted in names and messages need not be UTF-8; never abort on it.
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + '\n';
}

std::string check_report_text(const CheckReport& r, const ReportWriteOptions& o) {
  return report_text(check_report_json(r, o));
}

}  // namespace cadclash
