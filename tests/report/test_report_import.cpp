// The report's `import_timings` (where reading each file went, what the cache did): written only
// with timings, read back exactly, malformed values named by their JSON pointer.
#include "cadclash/report.h"

#include <gtest/gtest.h>

#include <string>

namespace cadclash {
namespace {

CheckReport with_import() {
  CheckReport r;
  r.files = {"a.step", "b.obj"};
  r.query = QueryReport{};
  r.query->timings = CollideTimings{0.5, 0.25, 0.125, 1.0 / 3.0, 2.0};
  ReportImport import;
  import.seconds = 1.25;
  import.files.push_back({"a.step", "miss", 0.375, 0.25, 0.125, 0.0625, 0.8125});
  import.files.push_back({"b.obj", "hit", 1.0 / 3.0, 0.0, 0.0, 0.0, 0.5});
  r.import = import;
  return r;
}

TEST(ReportImportTimings, RoundTripAndLeftOutWithoutTimings) {
  const std::string text = check_report_text(with_import());
  EXPECT_NE(text.find("\"import_timings\""), std::string::npos);
  const ReportReadResult back = check_report_from_json(text);
  ASSERT_FALSE(back.error) << format_report_error(*back.error);
  ASSERT_TRUE(back.report.import);
  EXPECT_EQ(back.report.import->files.size(), 2u);
  EXPECT_EQ(back.report.import->files[1].cache, "hit");
  EXPECT_EQ(back.report.import->files[1].read, 1.0 / 3.0);
  EXPECT_EQ(check_report_text(back.report), text);

  const std::string bare = check_report_text(with_import(), {.timings = false});
  EXPECT_EQ(bare.find("import_timings"), std::string::npos);
  CheckReport without = with_import();  // a report written before the field: nothing else changes
  without.import.reset();
  EXPECT_EQ(check_report_text(without, {.timings = false}), bare);
}

TEST(ReportImportTimings, MalformedValuesAreNamed) {
  nlohmann::json j = check_report_json(with_import());
  j["import_timings"]["files"][1]["cache"] = "lukewarm";
  ReportReadResult r = check_report_from_parsed(j);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->path, "/import_timings/files/1/cache");

  j = check_report_json(with_import());
  j["import_timings"]["files"][0].erase("heal");
  r = check_report_from_parsed(j);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->path, "/import_timings/files/0/heal");

  j = check_report_json(with_import());
  j["import_timings"]["seconds"] = "fast";
  r = check_report_from_parsed(j);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->path, "/import_timings/seconds");
}

}  // namespace
}  // namespace cadclash
