// Inputs the fuzzers (fuzz/, docs/fuzzing.md) found to crash, hang, blow up memory or break a
// reader's contract, kept in data/fuzz-regressions/. Each must now import without a crash or an
// exception, with a diagnostic that says what is wrong, names the file and is valid UTF-8.
#include "cadclash/import.h"
#include "../test_temp.h"
#include "valid_utf8.h"

#include <gtest/gtest.h>

#include <cctype>
#include <cstdint>
#include <filesystem>
#include <ostream>
#include <string>

namespace cadclash {
namespace {

struct Regression {
  const char* file;      // in data/fuzz-regressions/
  const char* expected;  // part of the message of one diagnostic the import must give
  const char* found;     // how it was found and what went wrong before the fix
};

const Regression kRegressions[] = {
    {"off_vertex_not_utf8.off", "vertex 3: '0\\xE5\\xCC' is not a number",
     "fuzz_off: the bad coordinate was quoted raw, so the message was not UTF-8"},
    {"step_schema_not_utf8.step", "FILE_SCHEMA 'AUTOMOTIVE\\xE9DESIGN' is not",
     "hand-made, failed fuzz_step's UTF-8 check: the unknown schema name was quoted raw"},
    {"step_unit_ref_overflow.step", "GLOBAL_UNIT_ASSIGNED_CONTEXT names no LENGTH_UNIT",
     "hand-made, UBSan in fuzz_step: a 23-digit #id in a unit list overflowed int64 in the unit check"},
    {"stl_solid_name_not_utf8.stl", "cannot read the file: Validation failed",
     "fuzz_stl: assimp's error message quoted the solid's name from the file raw, not UTF-8"},
    {"obj_self_intersecting_2000_corners.obj", "self-intersecting",
     "hand-made, fuzz_obj timeout: ear clipping a self-intersecting polygon was O(n^3)"},
    {"step_axis_without_location.step", "face entity could not be read whole; dropped",
     "fuzz_step: loose-face recovery transferred a face whose AXIS2_PLACEMENT_3D has no location; "
     "OCCT dereferenced the missing point (SEGV in StepToGeom::MakeAxis2Placement)"},
    {"step_face_on_broken_placement.step", "face entity refers to #376, which could not be read whole; dropped",
     "variant of the above with a well-formed face: the broken placement is two references away"},
    {"step_cut_oriented_edge_recursion.step", "reference to #21 is unresolved: the file defines no such entity",
     "fuzz_step: a cut-up file whose ORIENTED_EDGE #330 names the vanished #194; OCCT bound it to an oriented "
     "edge and its load check recursed through EdgeStart/EdgeEnd until the stack overflowed"},
    {"step_truncated_line_without_point.step", "OCCT crashed with SIGSEGV",
     "fuzz_step: a cut-off file whose LINE #198 lost its point; the product transfer reached it and "
     "StepToGeom::MakeLine dereferenced the missing point (SEGV). Now contained by the isolated reader"},
    {"iges_solid_face_broken_by_fuzzer.igs", "while transferring this root entity on its own (in an isolated reader); dropped",
     "fuzz_iges: one byte of a face's directory entry changed; IGESToBRep_BRepEntity::TransferFace called "
     "NbLoops on a null IGESSolid_Face (SEGV). Contained; the other solid's faces are read root by root"},
};

// Names the case by its file in test listings (instead of a byte dump).
void PrintTo(const Regression& r, std::ostream* os) { *os << r.file; }

class FuzzRegression : public ::testing::TestWithParam<Regression> {};

TEST_P(FuzzRegression, ImportsWithADiagnostic) {
  const Regression& c = GetParam();
  const std::string path = std::string(CADCLASH_DATA_DIR) + "/fuzz-regressions/" + c.file;
  ASSERT_TRUE(std::filesystem::is_regular_file(path)) << path;
  ImportResult r;
  ASSERT_NO_THROW(r = import_file(path)) << c.found;
  bool expected_seen = false;
  for (const Diagnostic& d : r.diagnostics) {
    EXPECT_EQ(d.file, path);
    EXPECT_TRUE(fuzz::valid_utf8(d.message)) << format_diagnostic(d);
    expected_seen = expected_seen || d.message.find(c.expected) != std::string::npos;
  }
  std::string all;
  for (const Diagnostic& d : r.diagnostics) all += format_diagnostic(d) + "\n";
  EXPECT_TRUE(expected_seen) << "no diagnostic contains '" << c.expected << "'; got:\n" << all;
  for (const Surface& s : r.model.surfaces)
    for (const auto& t : s.mesh.triangles)
      for (std::uint32_t v : t) ASSERT_LT(v, s.mesh.vertices.size());
}

std::string case_name(const ::testing::TestParamInfo<Regression>& info) {
  std::string name = std::filesystem::path(info.param.file).stem().string();
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Files, FuzzRegression, ::testing::ValuesIn(kRegressions), case_name);

// The crash is contained and the file is then read as far as it can be: of its box's six faces, two
// were cut off, three reach the broken entities, and the remaining one (#17) is kept with its #id.
TEST(FuzzRegressionStepCrash, GoodFaceIsKeptAfterTheContainedCrash) {
  const std::string path = std::string(CADCLASH_DATA_DIR) + "/fuzz-regressions/step_truncated_line_without_point.step";
  const ImportResult r = import_file(path);
  EXPECT_FALSE(r.complete);
  ASSERT_EQ(r.model.surfaces.size(), 1u);
  EXPECT_EQ(r.model.surfaces[0].provenance.step_id, 17);
  EXPECT_FALSE(r.model.surfaces[0].mesh.triangles.empty());
  std::string all;
  for (const Diagnostic& d : r.diagnostics) all += format_diagnostic(d) + "\n";
  for (const char* dropped : {"#137: error: face entity refers to #198", "#237: error: face entity refers to #242",
                              "#284: error: face entity refers to #286", "1 of 4 face entities recovered"})
    EXPECT_NE(all.find(dropped), std::string::npos) << dropped << " not in:\n" << all;
}

// The polygon case at a size where the old O(n^3) clipping would run for hours, so a regression
// hits CTest's timeout instead of passing slowly: 20000 corners in random order in z = 0 (a fixed
// linear congruential sequence, so every run reads the same file).
TEST(FuzzRegressionPolygon, LargeSelfIntersectingPolygonIsFannedNotClippedForever) {
  constexpr int kCorners = 20000;
  std::string text;
  std::uint64_t state = 1;
  const auto next = [&state] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<int>(state >> 54);  // 0..1023
  };
  for (int i = 0; i < kCorners; ++i) text += "v " + std::to_string(next()) + ' ' + std::to_string(next()) + " 0\n";
  text += 'f';
  for (int i = 1; i <= kCorners; ++i) text += ' ' + std::to_string(i);
  text += '\n';
  const std::string path = testing::write_scratch_file("self_intersecting_20000.obj", text);
  const ImportResult r = import_file(path);
  ASSERT_EQ(r.model.surfaces.size(), 1u);
  // Still a cover of the polygon: n - 2 triangles.
  EXPECT_EQ(r.model.surfaces[0].mesh.triangles.size(), static_cast<std::size_t>(kCorners - 2));
  bool warned = false;
  for (const Diagnostic& d : r.diagnostics) warned = warned || d.message.find("self-intersecting") != std::string::npos;
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace cadclash
