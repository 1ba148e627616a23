// PartialCheck to bytes and back: nlohmann_json's CBOR (doubles kept as float64, so exact).
#include "cadclash/distributed.h"
#include "cadclash/report.h"

#include <nlohmann/json.hpp>

#include <cmath>

namespace cadclash {
namespace {

using nlohmann::json;

json counters_to(const CollideCounters& c) {
  json j = json::array();
  for (const CounterField& f : kCounterFields) j.push_back(c.*f.member);
  return j;
}
void counters_from(const json& j, CollideCounters& c) {
  if (!j.is_array() || j.size() != kCounterFields.size()) throw std::runtime_error("counters");
  for (std::size_t i = 0; i < kCounterFields.size(); ++i) c.*kCounterFields[i].member = j[i].get<std::uint64_t>();
}

json memory_to(const SceneMemory& m) { return {m.triangles, m.vertices, m.hierarchies, m.instances, m.triangle_count}; }
SceneMemory memory_from(const json& j) {
  return {j.at(0).get<std::uint64_t>(), j.at(1).get<std::uint64_t>(), j.at(2).get<std::uint64_t>(),
          j.at(3).get<std::uint64_t>(), j.at(4).get<std::uint64_t>()};
}

json diagnostic_to(const Diagnostic& d) {
  return {static_cast<int>(d.severity), d.file, d.line, d.step_id, d.message};
}
Diagnostic diagnostic_from(const json& j) {
  return {static_cast<Severity>(j.at(0).get<int>()), j.at(1).get<std::string>(), j.at(2).get<std::int64_t>(),
          j.at(3).get<std::int64_t>(), j.at(4).get<std::string>()};
}

json result_to(const SurfacePairResult& r) {
  json j = {r.instance_a, r.instance_b, r.surface_a, r.surface_b, static_cast<int>(r.contact), r.intersecting,
            r.distance, r.penetration, static_cast<int>(r.decided_by), r.distance_lo, r.distance_hi,
            r.exact_distance ? json(*r.exact_distance) : json(nullptr), r.triangle_pairs, r.uncertainty_a,
            r.uncertainty_b, static_cast<int>(r.within)};
  return j;
}
SurfacePairResult result_from(const json& j) {
  SurfacePairResult r;
  r.instance_a = j.at(0).get<InstanceId>();
  r.instance_b = j.at(1).get<InstanceId>();
  r.surface_a = j.at(2).get<SurfaceId>();
  r.surface_b = j.at(3).get<SurfaceId>();
  r.contact = static_cast<ContactClass>(j.at(4).get<int>());
  r.intersecting = j.at(5).get<bool>();
  r.distance = j.at(6).get<double>();
  r.penetration = j.at(7).get<double>();
  r.decided_by = static_cast<DecidedBy>(j.at(8).get<int>());
  r.distance_lo = j.at(9).get<double>();
  r.distance_hi = j.at(10).get<double>();
  if (!j.at(11).is_null()) r.exact_distance = j.at(11).get<double>();
  r.triangle_pairs = j.at(12).get<std::vector<std::array<std::uint32_t, 2>>>();
  r.uncertainty_a = j.at(13).get<double>();
  r.uncertainty_b = j.at(14).get<double>();
  r.within = static_cast<ContactWithin>(j.at(15).get<int>());
  return r;
}

json work_to(const SurfaceWork& w) {
  return {w.surface,    w.asked,     w.tessellated,      w.built, w.refined, w.deflection,
          w.mesh_bytes, w.bvh_bytes, memory_to(w.held), w.error ? diagnostic_to(*w.error) : json(nullptr)};
}
SurfaceWork work_from(const json& j) {
  SurfaceWork w;
  w.surface = j.at(0).get<SurfaceId>();
  w.asked = j.at(1).get<bool>();
  w.tessellated = j.at(2).get<bool>();
  w.built = j.at(3).get<bool>();
  w.refined = j.at(4).get<bool>();
  w.deflection = j.at(5).get<double>();
  w.mesh_bytes = j.at(6).get<std::uint64_t>();
  w.bvh_bytes = j.at(7).get<std::uint64_t>();
  w.held = memory_from(j.at(8));
  if (!j.at(9).is_null()) w.error = diagnostic_from(j.at(9));
  return w;
}

json timings_to(const CollideTimings& t) {
  json j = json::array();
  for (const TimingField& f : kTimingFields) j.push_back(t.*f.member);
  return j;
}
CollideTimings timings_from(const json& j) {
  CollideTimings t;
  for (std::size_t k = 0; k < kTimingFields.size(); ++k) t.*kTimingFields[k].member = j.at(k).get<double>();
  return t;
}

}  // namespace

std::vector<std::uint8_t> partial_check_bytes(const PartialCheck& p) {
  const Report& r = p.report;
  json pairs = json::array(), works = json::array(), unexamined = json::array(), diags = json::array();
  for (const SurfacePairResult& x : r.pairs) pairs.push_back(result_to(x));
  for (const SurfaceWork& w : p.surfaces) works.push_back(work_to(w));
  for (const auto& u : r.unexamined_pairs) unexamined.push_back({u[0], u[1]});
  for (const Diagnostic& d : r.diagnostics) diags.push_back(diagnostic_to(d));
  const json j = {{"pairs", pairs},          {"counters", counters_to(r.counters)},
                  {"timings", timings_to(r.timings)}, {"diagnostics", diags},
                  {"complete", r.complete},  {"stopped_by", r.stopped_by},
                  {"unexamined", unexamined}, {"memory_charged", r.memory_charged},
                  {"model", memory_to(r.model_memory)}, {"surfaces", works}};
  return json::to_cbor(j);
}

std::optional<PartialCheck> partial_check_from_bytes(std::span<const std::uint8_t> bytes, std::string& error) {
  try {
    const json j = json::from_cbor(bytes.begin(), bytes.end());
    PartialCheck p;
    Report& r = p.report;
    for (const json& x : j.at("pairs")) r.pairs.push_back(result_from(x));
    counters_from(j.at("counters"), r.counters);
    r.timings = timings_from(j.at("timings"));
    for (const json& d : j.at("diagnostics")) r.diagnostics.push_back(diagnostic_from(d));
    r.complete = j.at("complete").get<bool>();
    r.stopped_by = j.at("stopped_by").get<std::string>();
    for (const json& u : j.at("unexamined")) r.unexamined_pairs.push_back({u.at(0).get<InstanceId>(), u.at(1).get<InstanceId>()});
    r.memory_charged = j.at("memory_charged").get<std::uint64_t>();
    r.model_memory = memory_from(j.at("model"));
    for (const json& w : j.at("surfaces")) p.surfaces.push_back(work_from(w));
    return p;
  } catch (const std::exception& e) {  // nlohmann's parse and type errors, and ours
    error = std::string("not a partial check: ") + e.what();
    return std::nullopt;
  }
}

}  // namespace cadclash
