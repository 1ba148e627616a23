// Broken STEP input (files in data/cad/ made from valid_two_solids.step, a box and a cylinder with 9
// ADVANCED_FACEs): a clear error naming the file and the entity, every readable face kept.
#include "cadclash/import.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

namespace cadclash {
namespace {

const std::string kCad = std::string(CADCLASH_DATA_DIR) + "/cad/";

bool has_error_about(const ImportResult& r, const std::string& file, std::int64_t step_id, const std::string& words) {
  return std::any_of(r.diagnostics.begin(), r.diagnostics.end(), [&](const Diagnostic& d) {
    return d.severity == Severity::Error && d.file == file && (step_id < 0 || d.step_id == step_id) &&
           d.message.find(words) != std::string::npos;
  });
}

std::set<std::int64_t> step_ids(const Model& m) {
  std::set<std::int64_t> ids;
  for (const Surface& s : m.surfaces) ids.insert(s.provenance.step_id);
  return ids;
}

TEST(CadBroken, ValidBaselineHasNineFaces) {
  const ImportResult r = import_file(kCad + "valid_two_solids.step");
  for (const Diagnostic& d : r.diagnostics) ADD_FAILURE() << format_diagnostic(d);
  EXPECT_TRUE(r.complete);
  EXPECT_EQ(r.model.surfaces.size(), 9u);
  EXPECT_EQ(r.model.instances.size(), 2u);
  EXPECT_EQ(step_ids(r.model), (std::set<std::int64_t>{17, 137, 237, 284, 331, 338, 361, 449, 453}));
}

TEST(CadBroken, DanglingReferenceNamesTheEntityAndKeepsTheOtherFaces) {
  const std::string path = kCad + "dangling_ref.step";  // #449's surface is #9999, which does not exist
  const ImportResult r = import_file(path);
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(has_error_about(r, path, 449, "unresolved"));
  EXPECT_EQ(r.model.surfaces.size(), 8u);
  EXPECT_EQ(step_ids(r.model), (std::set<std::int64_t>{17, 137, 237, 284, 331, 338, 361, 453}));
  for (const Surface& s : r.model.surfaces) EXPECT_TRUE(s.has_triangles);
}

TEST(CadBroken, TruncatedFileKeepsTheFacesBeforeTheCut) {
  const std::string path = kCad + "truncated.step";  // cut at byte 14000, inside #326
  const ImportResult r = import_file(path);
  EXPECT_FALSE(r.complete);
  const auto truncated = std::find_if(r.diagnostics.begin(), r.diagnostics.end(), [](const Diagnostic& d) {
    return d.message.find("truncated") != std::string::npos;
  });
  ASSERT_NE(truncated, r.diagnostics.end());
  EXPECT_EQ(truncated->file, path);
  EXPECT_EQ(truncated->line, 383);  // "#325 = LINE(...);", the last complete entity
  // Entities whose references point past the cut are named.
  EXPECT_TRUE(has_error_about(r, path, 325, "unresolved"));
  // The ADVANCED_FACEs before the cut (#17, #137, #237, #284) are kept.
  EXPECT_EQ(step_ids(r.model), (std::set<std::int64_t>{17, 137, 237, 284}));
}

TEST(CadBroken, WrongSchemaIsAnErrorOnItsLine) {
  const std::string path = kCad + "wrong_schema.step";  // FILE_SCHEMA(('IFC2X3'))
  const ImportResult r = import_file(path);
  EXPECT_FALSE(r.complete);
  ASSERT_TRUE(has_error_about(r, path, -1, "IFC2X3"));
  const auto it = std::find_if(r.diagnostics.begin(), r.diagnostics.end(),
                               [](const Diagnostic& d) { return d.message.find("IFC2X3") != std::string::npos; });
  EXPECT_EQ(it->line, 7);
  EXPECT_EQ(r.model.surfaces.size(), 9u);  // the data is still AP214 and is kept
}

TEST(CadBroken, EmptyDataSectionIsAnError) {
  const std::string path = kCad + "empty_data.step";
  const ImportResult r = import_file(path);
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(has_error_about(r, path, -1, "empty DATA"));
  EXPECT_TRUE(r.model.surfaces.empty());
  EXPECT_TRUE(r.model.instances.empty());
}

TEST(CadBroken, NotStepAtAll) {
  const std::string path = kCad + "not_step.step";
  const ImportResult r = import_file(path);
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(has_error(r.diagnostics));
  EXPECT_TRUE(r.model.parts.empty());
}

TEST(CadBroken, BadBrepFile) {
  const std::string path = kCad + "not_brep.brep";
  const ImportResult r = import_file(path);
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(has_error_about(r, path, -1, "BREP"));
}

}  // namespace
}  // namespace cadclash
