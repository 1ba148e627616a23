// cadclash::report's reader on malformed input: a status naming the JSON pointer of the problem,
// never an exception, and unknown fields ignored.
#include "cadclash/report.h"

#include <gtest/gtest.h>

#include <string>

namespace cadclash {
namespace {

ReportSide side(const std::string& instance, const std::string& surface) {
  ReportSide s;
  s.instance = instance;
  s.part = "part of " + instance;
  s.whole_part = surface.empty();
  s.surface = surface;
  s.face_index = 0;
  return s;
}

// A small valid report as JSON: one touching pair and one containment.
nlohmann::json valid() {
  CheckReport r;
  r.files = {"a.obj"};
  QueryReport q;
  ReportPair p;
  p.a = side("/a", "s0");
  p.b = side("/b", "s1");
  q.pairs.push_back(p);
  ReportPair c;
  c.a = side("/a", "");
  c.b = side("/b", "");
  c.contact = ContactClass::Containment;
  q.pairs.push_back(c);
  r.query = q;
  return check_report_json(r);
}

// Reads `j` and returns the error's path; "(none)" when it was read.
std::string error_path(const nlohmann::json& j) {
  const ReportReadResult r = check_report_from_parsed(j);
  if (!r.error) return "(none)";
  EXPECT_FALSE(r.error->message.empty());
  return r.error->path;
}

TEST(ReportMalformed, TheValidReportReads) { EXPECT_EQ(error_path(valid()), "(none)"); }

TEST(ReportMalformed, NotJsonOrNotAnObject) {
  const ReportReadResult r = check_report_from_json(std::string_view("{\"schema\": "));
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->path, "");
  EXPECT_EQ(format_report_error(*r.error), "not valid JSON");
  EXPECT_EQ(error_path(nlohmann::json::array()), "");
}

TEST(ReportMalformed, SchemaAndVersion) {
  nlohmann::json j = valid();
  j["schema"] = "cadclash-html-report";
  EXPECT_EQ(error_path(j), "/schema");
  j = valid();
  j["version"] = 3;
  const ReportReadResult r = check_report_from_parsed(j);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(format_report_error(*r.error), "/version: version 3 is not supported (this reader reads version 2)");
  j = valid();
  j.erase("version");
  EXPECT_EQ(error_path(j), "/version");
}

TEST(ReportMalformed, NamesTheOffendingValue) {
  struct Case {
    const char* pointer;  // value replaced
    nlohmann::json value;
    const char* expected_path;
  };
  const Case cases[] = {
      {"/pairs/0/class", "scraping", "/pairs/0/class"},
      {"/pairs/0/decided_by", 3, "/pairs/0/decided_by"},
      {"/pairs/0/a/kind", "hologram", "/pairs/0/a/kind"},
      {"/pairs/0/distance_interval", {1.0}, "/pairs/0/distance_interval"},
      {"/pairs/0/distance_interval/1", "far", "/pairs/0/distance_interval/1"},
      {"/pairs/0/penetration", nullptr, "/pairs/0/penetration"},
      {"/pairs/0/b/face_index", 1.5, "/pairs/0/b/face_index"},
      {"/pairs/0/b/step_id", -4, "/pairs/0/b/step_id"},
      {"/pairs/0/triangle_pairs", {{1, 2, 3}}, "/pairs/0/triangle_pairs/0"},
      {"/counters/aabb_tests", -1, "/counters/aabb_tests"},
      {"/settings/mode", "sometimes", "/settings/mode"},
      {"/settings/select_a", nlohmann::json::array({"/a", 2}), "/settings/select_a/1"},
      {"/summary/touching", 5, "/summary"},
      {"/unexamined_pairs", {{{"a", "/a"}}}, "/unexamined_pairs/0/b"},
      {"/diagnostics", "x", "/diagnostics"},
      {"/complete", "yes", "/complete"},
      {"/memory_charged_bytes", 1e3, "/memory_charged_bytes"},
      {"/model/bytes/hierarchies", -2, "/model/bytes/hierarchies"},
      {"/model/bytes/total", 1, "/model/bytes/total"},
      {"/model/triangles", "many", "/model/triangles"},
      {"/model", 3, "/model"},
  };
  for (const Case& c : cases) {
    nlohmann::json j = valid();
    j[nlohmann::json::json_pointer(c.pointer)] = c.value;
    EXPECT_EQ(error_path(j), c.expected_path) << c.pointer << " = " << c.value.dump();
  }
}

TEST(ReportMalformed, MissingFieldsAndInconsistentSides) {
  nlohmann::json j = valid();
  j["counters"].erase("witness_queries");
  EXPECT_EQ(error_path(j), "/counters/witness_queries");
  j = valid();
  j["pairs"][0]["a"].erase("surface");  // one side a whole part, the other a surface
  EXPECT_EQ(error_path(j), "/pairs/0");
  j = valid();
  j["pairs"][1]["class"] = "touching";  // containment sides on a surface pair
  j["summary"]["touching"] = 2;
  j["summary"]["containment"] = 0;
  j["summary"]["decided_by"]["mesh"] = 2;
  EXPECT_EQ(error_path(j), "/pairs/1");
  j = valid();
  j["steps"] = nlohmann::json::array();  // a trajectory report must name its CSV
  EXPECT_EQ(error_path(j), "/trajectory");
}

TEST(ReportMalformed, UnknownFieldsAreIgnored) {
  nlohmann::json j = valid();
  j["future_field"] = {1, 2};
  j["pairs"][0]["a"]["colour"] = "red";
  j["summary"]["extra"] = 1;
  const ReportReadResult r = check_report_from_parsed(j);
  ASSERT_FALSE(r.error) << format_report_error(*r.error);
  EXPECT_EQ(check_report_json(r.report), valid());
}

}  // namespace
}  // namespace cadclash
