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
  auto file = [&](std::string name, std::string cache, double read, double transfer, double heal, double tessellate,
                  double total) -> ReportFileImport& {
    ReportFileImport& f = import.files.emplace_back();
    f.file = std::move(name);
    f.cache = std::move(cache);
    f.read = read;
    f.transfer = transfer;
    f.heal = heal;
    f.tessellate = tessellate;
    f.total = total;
    return f;
  };
  ReportFileImport& a = file("a.step", "miss", 0.375, 0.25, 0.125, 0.0625, 0.8125);
  a.pieces = 3;
  a.pieces_cached = 1;
  a.piece_costs = ReportPieceCosts{0.03125, 0.25, 0.5, {4096, 1024, 77}, {5000, 1024, 77}, {0.375, 0.0, 1.0 / 7.0}};
  a.part_heal_seconds = {0.0625, 1.0 / 3.0};
  file("b.obj", "hit", 1.0 / 3.0, 0.0, 0.0, 0.0, 0.5);
  file("c.step", "placements", 0.125, 0.0, 0.0, 0.0, 0.25);
  r.import = import;
  return r;
}

TEST(ReportImportTimings, RoundTripAndLeftOutWithoutTimings) {
  const std::string text = check_report_text(with_import());
  EXPECT_NE(text.find("\"import_timings\""), std::string::npos);
  const ReportReadResult back = check_report_from_json(text);
  ASSERT_FALSE(back.error) << format_report_error(*back.error);
  ASSERT_TRUE(back.report.import);
  EXPECT_EQ(back.report.import->files.size(), 3u);
  EXPECT_EQ(back.report.import->files[1].cache, "hit");
  EXPECT_EQ(back.report.import->files[1].read, 1.0 / 3.0);
  EXPECT_EQ(back.report.import->files[2].cache, "placements");  // a file placed from the cache reads back
  const std::optional<ReportPieceCosts>& costs = back.report.import->files[0].piece_costs;
  ASSERT_TRUE(costs);
  EXPECT_EQ(costs->bytes, (std::vector<std::uint64_t>{4096, 1024, 77}));
  EXPECT_EQ(costs->seconds[2], 1.0 / 7.0);
  EXPECT_EQ(costs->weights[0], 5000u);
  EXPECT_EQ(costs->main_parse, 0.25);
  EXPECT_EQ(back.report.import->files[0].part_heal_seconds, (std::vector<double>{0.0625, 1.0 / 3.0}));
  EXPECT_FALSE(back.report.import->files[1].piece_costs);
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
  j["import_timings"]["files"][0]["piece_costs"]["seconds"].erase(1);
  r = check_report_from_parsed(j);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->path, "/import_timings/files/0/piece_costs/seconds");

  j = check_report_json(with_import());
  j["import_timings"]["files"][0]["part_heal_seconds"][1] = "slow";
  r = check_report_from_parsed(j);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->path, "/import_timings/files/0/part_heal_seconds/1");

  j = check_report_json(with_import());
  j["import_timings"]["seconds"] = "fast";
  r = check_report_from_parsed(j);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->path, "/import_timings/seconds");
}

}  // namespace
}  // namespace cadclash
