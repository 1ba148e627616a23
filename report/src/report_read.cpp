// The report's reader: JSON back into CheckReport, with the JSON pointer of the first problem.
#include "cadclash/report.h"
#include "cadclash/review.h"

#include <algorithm>
#include <limits>
#include <utility>

namespace cadclash {
namespace {

using Json = nlohmann::json;

// Thrown inside this file only; the public functions turn it into a ReportError.
struct ReadFailure {
  ReportError error;
};

[[noreturn]] void fail(const std::string& path, std::string message) { throw ReadFailure{{path, std::move(message)}}; }

const Json& object(const Json& j, const std::string& path) {
  if (!j.is_object()) fail(path, "expected an object");
  return j;
}

const Json& array(const Json& j, const std::string& path) {
  if (!j.is_array()) fail(path, "expected an array");
  return j;
}

// The member `key` of the object `j` at `path`.
const Json& field(const Json& j, const std::string& path, const char* key) {
  object(j, path);
  const auto it = j.find(key);
  if (it == j.end()) fail(path + "/" + key, "is missing");
  return *it;
}

std::string text(const Json& j, const std::string& path) {
  if (!j.is_string()) fail(path, "expected a string");
  return j.get<std::string>();
}

bool boolean(const Json& j, const std::string& path) {
  if (!j.is_boolean()) fail(path, "expected true or false");
  return j.get<bool>();
}

// A number; null (a non-finite value when written) reads as +infinity where `null_ok`.
double number(const Json& j, const std::string& path, bool null_ok = false) {
  if (null_ok && j.is_null()) return std::numeric_limits<double>::infinity();
  if (!j.is_number()) fail(path, null_ok ? "expected a number or null" : "expected a number");
  return j.get<double>();
}

std::int64_t integer(const Json& j, const std::string& path, std::int64_t lo, std::int64_t hi) {
  if (!j.is_number_integer()) fail(path, "expected an integer");
  if (j.is_number_unsigned() ? j.get<std::uint64_t>() > static_cast<std::uint64_t>(hi) : j.get<std::int64_t>() < lo ||
                                                                                             j.get<std::int64_t>() > hi)
    fail(path, "is out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return j.get<std::int64_t>();
}

std::uint64_t count(const Json& j, const std::string& path) {
  if (!j.is_number_unsigned()) fail(path, "expected a non-negative integer");
  return j.get<std::uint64_t>();
}

std::string string_or_null(const Json& j, const std::string& path) { return j.is_null() ? std::string() : text(j, path); }

std::vector<std::string> strings(const Json& j, const std::string& path) {
  std::vector<std::string> out;
  for (std::size_t k = 0; k < array(j, path).size(); ++k) out.push_back(text(j[k], path + "/" + std::to_string(k)));
  return out;
}

template <class E>
E named(const Json& j, const std::string& path, const char* what) {
  const std::string name = text(j, path);
  if (const std::optional<E> e = enum_from_name<E>(name)) return *e;
  std::string known;
  for (E e : EnumNames<E>::values) known += std::string(known.empty() ? "" : ", ") + EnumNames<E>::name(e);
  fail(path, "unknown " + std::string(what) + " '" + name + "' (one of " + known + ")");
}

ReportSettings read_settings(const Json& j, const std::string& p) {
  ReportSettings s;
  s.tolerance = number(field(j, p, "tolerance"), p + "/tolerance");
  s.clearance = number(field(j, p, "clearance"), p + "/clearance");
  s.preset = string_or_null(field(j, p, "preset"), p + "/preset");
  s.deflection = number(field(j, p, "deflection"), p + "/deflection");
  s.relative_deflection = boolean(field(j, p, "relative_deflection"), p + "/relative_deflection");
  s.angular_deflection = number(field(j, p, "angular_deflection"), p + "/angular_deflection");
  s.lazy = boolean(field(j, p, "lazy"), p + "/lazy");
  s.mode = named<CollideMode>(field(j, p, "mode"), p + "/mode", "mode");
  s.parallel = named<ParallelVersion>(field(j, p, "parallel"), p + "/parallel", "parallel version");
  s.schedule = named<Schedule>(field(j, p, "schedule"), p + "/schedule", "schedule");
  s.triangle_level = named<TriangleLevel>(field(j, p, "triangle_level"), p + "/triangle_level", "triangle level");
  s.oaabb = boolean(field(j, p, "oaabb"), p + "/oaabb");
  s.containment = boolean(field(j, p, "containment"), p + "/containment");
  s.decision = named<DecisionMode>(field(j, p, "decision"), p + "/decision", "decision");
  s.exclude_under = strings(field(j, p, "exclude_under"), p + "/exclude_under");
  s.select_a = strings(field(j, p, "select_a"), p + "/select_a");
  s.select_b = strings(field(j, p, "select_b"), p + "/select_b");
  s.time_budget = number(field(j, p, "time_budget"), p + "/time_budget");
  s.memory_budget_mb = number(field(j, p, "memory_budget_mb"), p + "/memory_budget_mb");
  return s;
}

ReportSide read_side(const Json& j, const std::string& p) {
  ReportSide s;
  s.instance = text(field(j, p, "instance"), p + "/instance");
  s.part = text(field(j, p, "part"), p + "/part");
  s.whole_part = !j.contains("surface");
  if (s.whole_part) return s;
  s.surface = text(field(j, p, "surface"), p + "/surface");
  s.kind = named<SourceKind>(field(j, p, "kind"), p + "/kind", "surface kind");
  s.face_index = static_cast<std::int32_t>(integer(field(j, p, "face_index"), p + "/face_index", INT32_MIN, INT32_MAX));
  if (j.contains("step_id")) s.step_id = integer(j["step_id"], p + "/step_id", 0, INT64_MAX);
  if (j.contains("source_name")) s.source_name = text(j["source_name"], p + "/source_name");
  s.deflection = number(field(j, p, "deflection"), p + "/deflection");
  if (j.contains("uncertainty")) s.uncertainty = number(j["uncertainty"], p + "/uncertainty");
  if (j.contains("uncertainty_source"))
    s.uncertainty_source =
        named<UncertaintySource>(j["uncertainty_source"], p + "/uncertainty_source", "uncertainty source");
  return s;
}

ReportPair read_pair(const Json& j, const std::string& p) {
  ReportPair r;
  r.a = read_side(field(j, p, "a"), p + "/a");
  r.b = read_side(field(j, p, "b"), p + "/b");
  r.contact = named<ContactClass>(field(j, p, "class"), p + "/class", "contact class");
  r.decided_by = named<DecidedBy>(field(j, p, "decided_by"), p + "/decided_by", "decided_by value");
  if ((r.contact == ContactClass::Containment) != (r.a.whole_part && r.b.whole_part) || r.a.whole_part != r.b.whole_part)
    fail(p, "the sides name surfaces exactly when the class is not containment");
  const std::string pi = p + "/distance_interval";
  const Json& interval = array(field(j, p, "distance_interval"), pi);
  if (interval.size() != 2) fail(pi, "expected [lo, hi]");
  r.distance_lo = number(interval[0], pi + "/0", true);
  r.distance_hi = number(interval[1], pi + "/1", true);
  if (j.contains("contact_within") && !j["contact_within"].is_null())
    r.within = named<ContactWithin>(j["contact_within"], p + "/contact_within", "contact_within value");
  r.intersecting = boolean(field(j, p, "intersecting"), p + "/intersecting");
  r.distance = number(field(j, p, "distance"), p + "/distance", true);
  r.penetration = number(field(j, p, "penetration"), p + "/penetration");
  if (j.contains("exact_distance")) r.exact_distance = number(j["exact_distance"], p + "/exact_distance", true);
  if (j.contains("triangle_pairs")) {
    const std::string pt = p + "/triangle_pairs";
    const Json& t = array(j["triangle_pairs"], pt);
    for (std::size_t k = 0; k < t.size(); ++k) {
      const std::string pk = pt + "/" + std::to_string(k);
      if (!t[k].is_array() || t[k].size() != 2) fail(pk, "expected [triangle of A, triangle of B]");
      r.triangle_pairs.push_back({static_cast<std::uint32_t>(integer(t[k][0], pk + "/0", 0, UINT32_MAX)),
                                  static_cast<std::uint32_t>(integer(t[k][1], pk + "/1", 0, UINT32_MAX))});
    }
  }
  return r;
}

// Every member of `expected` is in `actual` with the same value (recursively for objects).
bool agrees(const Json& expected, const Json& actual) {
  if (!expected.is_object()) return expected == actual;
  if (!actual.is_object()) return false;
  for (const auto& [key, value] : expected.items())
    if (!actual.contains(key) || !agrees(value, actual[key])) return false;
  return true;
}

QueryReport read_query(const Json& j, const std::string& p) {
  QueryReport q;
  const Json& pairs = array(field(j, p, "pairs"), p + "/pairs");
  for (std::size_t k = 0; k < pairs.size(); ++k) q.pairs.push_back(read_pair(pairs[k], p + "/pairs/" + std::to_string(k)));
  const std::string ps = p + "/summary";
  const Json& summary = object(field(j, p, "summary"), ps);
  Json expected = summary_json(q.pairs);
  if (!summary.contains("contact_within")) expected.erase("contact_within");  // written before it
  if (!agrees(expected, summary)) fail(ps, "does not match the pairs (expected " + expected.dump() + ")");
  const std::string pc = p + "/counters";
  const Json& counters = object(field(j, p, "counters"), pc);
  for (const CounterField& f : kCounterFields) q.counters.*f.member = count(field(counters, pc, f.name), pc + "/" + f.name);
  if (j.contains("timings")) {
    const std::string pt = p + "/timings";
    CollideTimings t;
    for (std::size_t k = 0; k < kTimingFields.size(); ++k) {
      const TimingField& f = kTimingFields[k];
      if (k >= kStageTimings && !j["timings"].contains(f.name)) continue;  // written before it
      t.*f.member = number(field(j["timings"], pt, f.name), pt + "/" + f.name);
    }
    q.timings = t;
  }
  q.stopped_by = string_or_null(field(j, p, "stopped_by"), p + "/stopped_by");
  const std::string pu = p + "/unexamined_pairs";
  const Json& u = array(field(j, p, "unexamined_pairs"), pu);
  for (std::size_t k = 0; k < u.size(); ++k) {
    const std::string pk = pu + "/" + std::to_string(k);
    q.unexamined_pairs.push_back({text(field(u[k], pk, "a"), pk + "/a"), text(field(u[k], pk, "b"), pk + "/b")});
  }
  q.memory_charged_bytes = count(field(j, p, "memory_charged_bytes"), p + "/memory_charged_bytes");
  if (j.contains("model")) {  // written since the model's size was reported; older reports lack it
    const std::string pm = p + "/model";
    const Json& model = object(j["model"], pm);
    const std::string pb = pm + "/bytes";
    const Json& bytes = object(field(model, pm, "bytes"), pb);
    q.model.triangles = count(field(bytes, pb, "triangles"), pb + "/triangles");
    q.model.vertices = count(field(bytes, pb, "vertices"), pb + "/vertices");
    q.model.hierarchies = count(field(bytes, pb, "hierarchies"), pb + "/hierarchies");
    q.model.instances = count(field(bytes, pb, "instances"), pb + "/instances");
    if (count(field(bytes, pb, "total"), pb + "/total") != q.model.total())
      fail(pb + "/total", "is not the sum of the components");
    q.model.triangle_count = count(field(model, pm, "triangles"), pm + "/triangles");
  }
  return q;
}

std::string date_field(const Json& j, const std::string& path) {
  const std::string d = text(j, path);
  if (!iso_date(d)) fail(path, "expected a date YYYY-MM-DD, got '" + d + "'");
  return d;
}

Approval read_approval(const Json& j, const std::string& p) {
  Approval a;
  object(j, p);
  const bool rule = j.contains("a") || j.contains("b") || j.contains("part_a") || j.contains("part_b");
  if (j.contains("id")) {
    if (rule) fail(p, "names both a clash id and instance/part globs; give one");
    a.id = text(j["id"], p + "/id");
    if (a.id.empty()) fail(p + "/id", "is empty");
  } else if (!rule) {
    fail(p, "names neither a clash `id` nor globs `a`/`b`/`part_a`/`part_b`");
  }
  for (auto [key, member] : {std::pair{"a", &Approval::a}, {"b", &Approval::b}, {"part_a", &Approval::part_a},
                             {"part_b", &Approval::part_b}})
    if (j.contains(key)) a.*member = text(j[key], p + "/" + key);
  if (a.a == "**") a.a.clear();
  if (a.b == "**") a.b.clear();
  if (j.contains("classes")) {
    const Json& c = array(j["classes"], p + "/classes");
    for (std::size_t k = 0; k < c.size(); ++k)
      a.classes.push_back(named<ContactClass>(c[k], p + "/classes/" + std::to_string(k), "contact class"));
  }
  a.reason = text(field(j, p, "reason"), p + "/reason");
  a.by = text(field(j, p, "by"), p + "/by");
  a.date = date_field(field(j, p, "date"), p + "/date");
  if (j.contains("expires")) a.expires = date_field(j["expires"], p + "/expires");
  return a;
}

ReportClash read_clash(const Json& j, const std::string& p) {
  ReportClash c;
  c.id = text(field(j, p, "id"), p + "/id");
  c.status = named<ClashStatus>(field(j, p, "status"), p + "/status", "clash status");
  const Json& a = field(j, p, "a");
  const Json& b = field(j, p, "b");
  c.instance_a = text(field(a, p + "/a", "instance"), p + "/a/instance");
  c.part_a = text(field(a, p + "/a", "part"), p + "/a/part");
  c.instance_b = text(field(b, p + "/b", "instance"), p + "/b/instance");
  c.part_b = text(field(b, p + "/b", "part"), p + "/b/part");
  c.worst = named<ContactClass>(field(j, p, "class"), p + "/class", "contact class");
  c.max_penetration = number(field(j, p, "max_penetration"), p + "/max_penetration");
  c.min_distance = number(field(j, p, "min_distance"), p + "/min_distance", true);
  c.group = text(field(j, p, "group"), p + "/group");
  const Json& box = field(j, p, "box");
  if (!box.is_null()) {
    if (!box.is_array() || box.size() != 6) fail(p + "/box", "expected [min x, y, z, max x, y, z] or null");
    std::array<double, 6> v{};
    for (std::size_t k = 0; k < 6; ++k) v[k] = number(box[k], p + "/box/" + std::to_string(k));
    c.box = v;
  }
  const Json& measure = field(j, p, "interference");
  if (!measure.is_null()) {
    const std::string pi = p + "/interference";
    ClashInterference i;
    i.measured = boolean(field(measure, pi, "measured"), pi + "/measured");
    i.note = string_or_null(field(measure, pi, "note"), pi + "/note");
    i.volume = number(field(measure, pi, "volume"), pi + "/volume");
    i.depth = number(field(measure, pi, "depth"), pi + "/depth");
    const Json& centroid = field(measure, pi, "centroid");
    if (!centroid.is_null()) {
      if (!centroid.is_array() || centroid.size() != 3) fail(pi + "/centroid", "expected [x, y, z] or null");
      for (std::size_t k = 0; k < 3; ++k) i.centroid[k] = number(centroid[k], pi + "/centroid/" + std::to_string(k));
    }
    if (centroid.is_null() != (i.volume <= 0)) fail(pi + "/centroid", "is null exactly when the volume is 0");
    c.interference = i;
  }
  const Json& approval = field(j, p, "approval");
  if (!approval.is_null()) c.approval = integer(approval, p + "/approval", 0, INT64_MAX);
  const std::string ps = p + "/surface_pairs";
  const Json& sp = array(field(j, p, "surface_pairs"), ps);
  for (std::size_t k = 0; k < sp.size(); ++k) {
    const std::string pk = ps + "/" + std::to_string(k);
    ClashSurfacePair s;
    s.key = text(field(sp[k], pk, "key"), pk + "/key");
    const Json& pair = field(sp[k], pk, "pair");
    if (!pair.is_null()) s.pair = integer(pair, pk + "/pair", 0, INT64_MAX);
    s.contact = named<ContactClass>(field(sp[k], pk, "class"), pk + "/class", "contact class");
    s.penetration = number(field(sp[k], pk, "penetration"), pk + "/penetration");
    s.distance = number(field(sp[k], pk, "distance"), pk + "/distance", true);
    c.surface_pairs.push_back(std::move(s));
  }
  return c;
}

// `clashes` and `review` (written together); their pair indices must name pairs of `query`.
ClashReview read_review(const Json& j, const QueryReport& query) {
  ClashReview r;
  const Json& rv = object(field(j, "", "review"), "/review");
  r.baseline = string_or_null(field(rv, "/review", "baseline"), "/review/baseline");
  r.approvals_file = string_or_null(field(rv, "/review", "approvals_file"), "/review/approvals_file");
  r.today = string_or_null(field(rv, "/review", "today"), "/review/today");
  r.group_by = text(field(rv, "/review", "group_by"), "/review/group_by");
  if (std::find(kGroupBy.begin(), kGroupBy.end(), r.group_by) == kGroupBy.end())
    fail("/review/group_by", "unknown grouping '" + r.group_by + "' (one of instance, part, subassembly, space)");
  r.cluster_distance = number(field(rv, "/review", "cluster_distance"), "/review/cluster_distance");
  const Json& approvals = array(field(rv, "/review", "approvals"), "/review/approvals");
  for (std::size_t k = 0; k < approvals.size(); ++k) {
    const std::string pk = "/review/approvals/" + std::to_string(k);
    ApprovalUse u;
    u.approval = read_approval(field(approvals[k], pk, "approval"), pk + "/approval");
    u.source = text(field(approvals[k], pk, "source"), pk + "/source");
    const std::string state = text(field(approvals[k], pk, "state"), pk + "/state");
    u.expired = state == "expired";
    u.matched = count(field(approvals[k], pk, "matched"), pk + "/matched");
    if (state != (u.expired ? "expired" : u.matched == 0 ? "stale" : "used"))
      fail(pk + "/state", "does not match `matched` and the expiry");
    r.approvals.push_back(std::move(u));
  }
  const Json& clashes = array(field(j, "", "clashes"), "/clashes");
  for (std::size_t k = 0; k < clashes.size(); ++k) {
    const std::string pk = "/clashes/" + std::to_string(k);
    ReportClash c = read_clash(clashes[k], pk);
    if (c.approval >= static_cast<std::int64_t>(r.approvals.size()))
      fail(pk + "/approval", "names no entry of /review/approvals");
    for (std::size_t s = 0; s < c.surface_pairs.size(); ++s)
      if (c.surface_pairs[s].pair >= static_cast<std::int64_t>(query.pairs.size()))
        fail(pk + "/surface_pairs/" + std::to_string(s) + "/pair", "names no entry of /pairs");
    r.clashes.push_back(std::move(c));
  }
  if (!agrees(review_json(r), rv)) fail("/review", "does not match the clashes and approvals");
  return r;
}

ReportImport read_import(const Json& j, const std::string& p) {
  ReportImport out;
  out.seconds = number(field(j, p, "seconds"), p + "/seconds");
  const Json& files = array(field(j, p, "files"), p + "/files");
  for (std::size_t k = 0; k < files.size(); ++k) {
    const std::string pk = p + "/files/" + std::to_string(k);
    ReportFileImport f;
    f.file = text(field(object(files[k], pk), pk, "file"), pk + "/file");
    f.cache = text(field(files[k], pk, "cache"), pk + "/cache");
    if (f.cache != "off" && f.cache != "hit" && f.cache != "miss" && f.cache != "rebuilt" && f.cache != "placements")
      fail(pk + "/cache", "expected \"off\", \"hit\", \"miss\", \"rebuilt\" or \"placements\"");
    for (auto [name, member] : {std::pair{"read", &ReportFileImport::read}, {"transfer", &ReportFileImport::transfer},
                                {"heal", &ReportFileImport::heal}, {"tessellate", &ReportFileImport::tessellate},
                                {"total", &ReportFileImport::total}})
      f.*member = number(field(files[k], pk, name), pk + "/" + name);
    if (files[k].contains("processes")) f.processes = count(files[k]["processes"], pk + "/processes");  // since 2026-11
    for (auto [name, member] : {std::pair{"pieces", &ReportFileImport::pieces}, {"pieces_cached", &ReportFileImport::pieces_cached},
                                {"parts_cached", &ReportFileImport::parts_cached}})
      if (files[k].contains(name)) f.*member = count(files[k][name], pk + "/" + name);  // since 2026-11-27
    // Since 2026-11-29.
    if (files[k].contains("piece_costs") && !files[k]["piece_costs"].is_null()) {
      const std::string pc = pk + "/piece_costs";
      const Json& c = object(files[k]["piece_costs"], pc);
      ReportPieceCosts& costs = f.piece_costs.emplace();
      costs.split = number(field(c, pc, "split"), pc + "/split");
      costs.main_parse = number(field(c, pc, "main_parse"), pc + "/main_parse");
      costs.workers = number(field(c, pc, "workers"), pc + "/workers");
      const Json& bytes = array(field(c, pc, "bytes"), pc + "/bytes");
      const Json& weights = array(field(c, pc, "weights"), pc + "/weights");
      const Json& seconds = array(field(c, pc, "seconds"), pc + "/seconds");
      if (bytes.size() != seconds.size()) fail(pc + "/seconds", "expected one per piece, as many as bytes");
      if (bytes.size() != weights.size()) fail(pc + "/weights", "expected one per piece, as many as bytes");
      for (std::size_t i = 0; i < bytes.size(); ++i) {
        costs.bytes.push_back(count(bytes[i], pc + "/bytes/" + std::to_string(i)));
        costs.weights.push_back(count(weights[i], pc + "/weights/" + std::to_string(i)));
        costs.seconds.push_back(number(seconds[i], pc + "/seconds/" + std::to_string(i)));
      }
    }
    if (files[k].contains("part_heal_seconds")) {
      const Json& heal = array(files[k]["part_heal_seconds"], pk + "/part_heal_seconds");
      for (std::size_t i = 0; i < heal.size(); ++i)
        f.part_heal_seconds.push_back(number(heal[i], pk + "/part_heal_seconds/" + std::to_string(i)));
    }
    out.files.push_back(std::move(f));
  }
  return out;
}

std::vector<ReportSpan> read_spans(const Json& j, const std::string& p) {
  std::vector<ReportSpan> out;
  const Json& a = array(j, p);
  for (std::size_t k = 0; k < a.size(); ++k) {
    const std::string pk = p + "/" + std::to_string(k);
    out.push_back({number(field(a[k], pk, "t0"), pk + "/t0"), number(field(a[k], pk, "t1"), pk + "/t1"),
                   boolean(field(a[k], pk, "contact_at_ends"), pk + "/contact_at_ends")});
  }
  return out;
}

ReportTimeline read_timeline(const Json& j, const std::string& p) {
  ReportTimeline t;
  t.resolution = number(field(j, p, "resolution"), p + "/resolution");
  t.checks = count(field(j, p, "checks"), p + "/checks");
  t.complete = boolean(field(j, p, "complete"), p + "/complete");
  const Json& pairs = array(field(j, p, "pairs"), p + "/pairs");
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const std::string pk = p + "/pairs/" + std::to_string(k);
    ReportPairTimeline rp;
    rp.a = text(field(pairs[k], pk, "a"), pk + "/a");
    rp.b = text(field(pairs[k], pk, "b"), pk + "/b");
    rp.spans = read_spans(field(pairs[k], pk, "spans"), pk + "/spans");
    const Json& surfaces = array(field(pairs[k], pk, "surfaces"), pk + "/surfaces");
    for (std::size_t i = 0; i < surfaces.size(); ++i) {
      const std::string si = pk + "/surfaces/" + std::to_string(i);
      rp.surfaces.push_back({read_side(field(surfaces[i], si, "a"), si + "/a"), read_side(field(surfaces[i], si, "b"), si + "/b"),
                             read_spans(field(surfaces[i], si, "spans"), si + "/spans")});
    }
    if (pairs[k].contains("closest")) {  // with --clearance
      const Json& c = object(pairs[k]["closest"], pk + "/closest");
      const std::string pc = pk + "/closest";
      rp.closest = ReportClosest{number(field(c, pc, "lo"), pc + "/lo"), number(field(c, pc, "hi"), pc + "/hi"),
                                 number(field(c, pc, "t0"), pc + "/t0"), number(field(c, pc, "t1"), pc + "/t1")};
    }
    t.pairs.push_back(std::move(rp));
  }
  return t;
}

CheckReport read_report(const Json& j) {
  CheckReport r;
  object(j, "");
  if (text(field(j, "", "schema"), "/schema") != kCheckReportSchema)
    fail("/schema", "expected \"" + std::string(kCheckReportSchema) + "\"");
  r.version = static_cast<int>(integer(field(j, "", "version"), "/version", 0, INT32_MAX));
  if (r.version != kCheckReportVersion)
    fail("/version", "version " + std::to_string(r.version) + " is not supported (this reader reads version " +
                         std::to_string(kCheckReportVersion) + ")");
  r.files = strings(field(j, "", "files"), "/files");
  r.settings = read_settings(object(field(j, "", "settings"), "/settings"), "/settings");
  if (j.contains("steps")) {
    r.trajectory = text(field(j, "", "trajectory"), "/trajectory");
    const Json& steps = array(j["steps"], "/steps");
    for (std::size_t k = 0; k < steps.size(); ++k) {
      const std::string pk = "/steps/" + std::to_string(k);
      r.steps.push_back({integer(field(steps[k], pk, "step"), pk + "/step", INT64_MIN, INT64_MAX), read_query(steps[k], pk)});
    }
    r.steps_not_checked = count(field(j, "", "steps_not_checked"), "/steps_not_checked");
    r.stopped_by = string_or_null(field(j, "", "stopped_by"), "/stopped_by");
    if (j.contains("timeline")) r.timeline = read_timeline(object(j["timeline"], "/timeline"), "/timeline");  // --continuous
  } else {
    r.query = read_query(j, "");
  }
  if (j.contains("clashes") || j.contains("review")) {
    if (!r.query) fail("/clashes", "a report with a trajectory has no clashes");
    r.review = read_review(j, *r.query);
  }
  r.diagnostics = strings(field(j, "", "diagnostics"), "/diagnostics");
  r.complete = boolean(field(j, "", "complete"), "/complete");
  if (j.contains("import_timings")) r.import = read_import(object(j["import_timings"], "/import_timings"), "/import_timings");
  return r;
}

}  // namespace

std::string format_report_error(const ReportError& e) { return e.path.empty() ? e.message : e.path + ": " + e.message; }

ReportReadResult check_report_from_parsed(const nlohmann::json& j) {
  ReportReadResult out;
  try {
    out.report = read_report(j);
  } catch (const ReadFailure& f) {
    out.error = f.error;
  }
  return out;
}

ReportReadResult check_report_from_json(std::string_view text) {
  Json j = Json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) {
    ReportReadResult out;
    out.error = ReportError{"", "not valid JSON"};
    return out;
  }
  return check_report_from_parsed(j);
}

std::optional<ReportError> approval_from_json(const nlohmann::json& j, const std::string& path, Approval& out) {
  try {
    out = read_approval(j, path);
  } catch (const ReadFailure& f) {
    return f.error;
  }
  return std::nullopt;
}

std::optional<ReportError> provenance_from_json(const nlohmann::json& j, Surface& s) {
  try {
    Provenance& p = s.provenance;
    s.name = text(field(j, "", "name"), "/name");
    p.kind = named<SourceKind>(field(j, "", "kind"), "/kind", "surface kind");
    p.step_id = integer(field(j, "", "step_id"), "/step_id", INT64_MIN, INT64_MAX);
    p.face_index = static_cast<std::int32_t>(integer(field(j, "", "face_index"), "/face_index", INT32_MIN, INT32_MAX));
    p.source_name = text(field(j, "", "source_name"), "/source_name");
    p.source_file = text(field(j, "", "source_file"), "/source_file");
    s.deflection = number(field(j, "", "deflection"), "/deflection");
    p.healed = boolean(field(j, "", "healed"), "/healed");
    p.repaired = boolean(field(j, "", "repaired"), "/repaired");
    p.parent = j.contains("parent") ? static_cast<SurfaceId>(integer(j["parent"], "/parent", 0, UINT32_MAX)) : kInvalidId;
    p.colour.reset();
    if (j.contains("colour")) {
      const Json& c = array(j["colour"], "/colour");
      if (c.size() != 3) fail("/colour", "expected [r, g, b]");
      p.colour = std::array<float, 3>{};
      for (std::size_t k = 0; k < 3; ++k) (*p.colour)[k] = static_cast<float>(number(c[k], "/colour/" + std::to_string(k)));
    }
    s.aabb.setEmpty();
    if (j.contains("aabb")) {
      const Json& b = array(j["aabb"], "/aabb");
      if (b.size() != 6) fail("/aabb", "expected [min x, y, z, max x, y, z]");
      double v[6];
      for (std::size_t k = 0; k < 6; ++k) v[k] = number(b[k], "/aabb/" + std::to_string(k));
      s.aabb = Aabb(Vec3(v[0], v[1], v[2]), Vec3(v[3], v[4], v[5]));
    }
  } catch (const ReadFailure& f) {
    return f.error;
  }
  return std::nullopt;
}

}  // namespace cadclash
