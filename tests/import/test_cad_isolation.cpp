// The isolated reader (ImportOptions::isolate_cad_readers) sends the transfer back from a child as
// its walked parts and instances; what the caller gets must be what an in-process read gives: the
// same parts, surfaces, entity ids, names, colours, triangles and instance poses, bit for bit.
#include "cadclash/import.h"
#include "../test_temp.h"
#include "readers.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace cadclash {
namespace {

void expect_same_models(const ImportResult& a, const ImportResult& b) {
  ASSERT_EQ(a.model.parts.size(), b.model.parts.size());
  ASSERT_EQ(a.model.surfaces.size(), b.model.surfaces.size());
  ASSERT_EQ(a.model.instances.size(), b.model.instances.size());
  EXPECT_EQ(a.complete, b.complete);
  ASSERT_EQ(a.diagnostics.size(), b.diagnostics.size());
  for (std::size_t i = 0; i < a.diagnostics.size(); ++i)
    EXPECT_EQ(format_diagnostic(a.diagnostics[i]), format_diagnostic(b.diagnostics[i]));
  for (std::size_t p = 0; p < a.model.parts.size(); ++p) {
    EXPECT_EQ(a.model.parts[p].name, b.model.parts[p].name);
    EXPECT_EQ(a.model.parts[p].surface_count, b.model.parts[p].surface_count);
  }
  for (std::size_t s = 0; s < a.model.surfaces.size(); ++s) {
    const Surface& x = a.model.surfaces[s];
    const Surface& y = b.model.surfaces[s];
    SCOPED_TRACE(x.name);
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.provenance.step_id, y.provenance.step_id);
    EXPECT_EQ(x.provenance.source_name, y.provenance.source_name);
    EXPECT_EQ(x.provenance.face_index, y.provenance.face_index);
    EXPECT_EQ(x.provenance.colour, y.provenance.colour);
    EXPECT_EQ(x.provenance.healed, y.provenance.healed);
    EXPECT_EQ(x.mesh.triangles, y.mesh.triangles);
    ASSERT_EQ(x.mesh.vertices.size(), y.mesh.vertices.size());
    for (std::size_t v = 0; v < x.mesh.vertices.size(); ++v) EXPECT_EQ(x.mesh.vertices[v], y.mesh.vertices[v]);
  }
  for (std::size_t i = 0; i < a.model.instances.size(); ++i) {
    EXPECT_EQ(a.model.instances[i].path, b.model.instances[i].path);
    EXPECT_EQ(a.model.instances[i].part, b.model.instances[i].part);
    EXPECT_TRUE(a.model.instances[i].pose.matrix() == b.model.instances[i].pose.matrix()) << a.model.instances[i].path;
  }
}

class CadIsolation : public ::testing::TestWithParam<const char*> {};

TEST_P(CadIsolation, SameModelAsAnInProcessRead) {
  const std::string path = std::string(CADCLASH_DATA_DIR) + "/" + GetParam();
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing: run scripts/setup.sh";
  ImportOptions isolated;
  ImportOptions here;
  here.isolate_cad_readers = false;
  const ImportResult a = import_file(path, isolated);
  const ImportResult b = import_file(path, here);
  ASSERT_TRUE(!a.model.surfaces.empty() || !a.diagnostics.empty());  // not_brep.brep: only its error
  expect_same_models(a, b);
}

// An assembly with colours and shared parts, a file with a healed face and a failed mesh, a file
// recovered as loose faces, IGES with directory entry numbers, and BREP (sent back in OCCT's binary
// format), healed and not a .brep at all.
INSTANTIATE_TEST_SUITE_P(Files, CadIsolation,
                         ::testing::Values("external/as1-tu-203.stp", "cad/valid_two_solids.step",
                                           "cad/mesh_fail_degenerate.step", "cad/truncated.step",
                                           "cad/dangling_ref.step", "external/bearing.iges", "external/Ball.brep",
                                           "cad/heal_unshared_vertices.brep", "cad/not_brep.brep"),
                         [](const ::testing::TestParamInfo<const char*>& param_info) {
                           std::string name = std::filesystem::path(param_info.param).stem().string();
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

// Shells whose shape representations are gone: the products give no face, so each face entity is
// transferred on its own; the same in both modes, and every face keeps its #id.
std::string file_without_shape_representations() {
  std::ifstream in(std::string(CADCLASH_DATA_DIR) + "/cad/valid_two_solids.step");
  std::string text, line;
  while (std::getline(in, line))
    if (line.find("SHAPE_DEFINITION_REPRESENTATION") == std::string::npos &&
        line.find("SHAPE_REPRESENTATION") == std::string::npos && line.find("MANIFOLD_SOLID_BREP") == std::string::npos)
      text += line + "\n";
  return testing::write_scratch_file("no_shape_representations.step", text);
}

TEST(CadIsolation, FacesOfProductsWithoutShapesAreReadAsLooseFaces) {
  const std::string path = file_without_shape_representations();
  ImportOptions here;
  here.isolate_cad_readers = false;
  const ImportResult a = import_file(path);
  const ImportResult b = import_file(path, here);
  expect_same_models(a, b);
  EXPECT_FALSE(a.complete);
  ASSERT_EQ(a.model.surfaces.size(), 9u);  // 6 + 3 faces of the two solids
  for (const Surface& s : a.model.surfaces) EXPECT_GT(s.provenance.step_id, 0);
  std::string all;
  for (const Diagnostic& d : a.diagnostics) all += format_diagnostic(d) + "\n";
  EXPECT_NE(all.find("the file's products gave no face; read again as loose faces"), std::string::npos) << all;
  EXPECT_NE(all.find("9 of 9 face entities recovered"), std::string::npos) << all;
}

// A face on which OCCT crashes when it is transferred on its own (injected: SIGSEGV in the child at
// face #137) costs that face only: the next child skips it, and it is named with the signal.
TEST(CadIsolation, FaceThatCrashesOnItsOwnIsSkippedAndNamed) {
  const std::string path = file_without_shape_representations();
  detail::set_step_crash_injection_for_testing(137);
  const ImportResult r = import_file(path);
  detail::set_step_crash_injection_for_testing(-1);
  ASSERT_EQ(r.model.surfaces.size(), 8u);
  for (const Surface& s : r.model.surfaces) EXPECT_NE(s.provenance.step_id, 137);
  bool named = false;
  for (const Diagnostic& d : r.diagnostics)
    named = named || (d.step_id == 137 && d.message.rfind("OCCT crashed with SIGSEGV", 0) == 0 &&
                      d.message.find("while transferring this face entity on its own") != std::string::npos);
  EXPECT_TRUE(named);
  EXPECT_FALSE(r.complete);
}

// A face on which the reader hangs (injected: the child pauses at face #137) is stopped by the time
// limit: an error names the file, the limit and the face, and the import returns.
TEST(CadIsolation, HangingReaderIsStoppedAtTheTimeLimitAndNamed) {
  const std::string path = file_without_shape_representations();
  ImportOptions options;
  options.reader_time_limit_seconds = 1.0;
  detail::set_step_hang_injection_for_testing(137);
  const ImportResult r = import_file(path, options);
  detail::set_step_hang_injection_for_testing(-1);
  EXPECT_FALSE(r.complete);
  bool named = false;
  for (const Diagnostic& d : r.diagnostics)
    named = named || (d.severity == Severity::Error && d.file == path && d.step_id == 137 &&
                      d.message.rfind("the isolated reader did not finish within the time limit of 1 s", 0) == 0 &&
                      d.message.find("stopped, nothing more is read from the file") != std::string::npos);
  EXPECT_TRUE(named);
  // Without a hang, the same limit leaves the read as it was.
  const ImportResult fine = import_file(path, options);
  const ImportResult unlimited = import_file(path);
  expect_same_models(fine, unlimited);
}

// A .brep is read only in the child, so the limit covers it: 3.8 MB of text cannot be parsed in the
// millisecond a spent limit leaves.
TEST(CadIsolation, BrepReaderIsStoppedAtTheTimeLimit) {
  const std::string path = std::string(CADCLASH_DATA_DIR) + "/external/Bottom.brep";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing: run scripts/setup.sh";
  ImportOptions options;
  options.reader_time_limit_seconds = 1e-6;
  const ImportResult r = import_file(path, options);
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(r.model.surfaces.empty());
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_EQ(r.diagnostics.front().message,
            "the isolated reader did not finish within the time limit of 1e-06 s while reading the file; stopped, "
            "nothing more is read from the file");
}

// Without isolation the limit cannot be applied: a warning says so, and the file is read.
TEST(CadIsolation, TimeLimitWithoutIsolationIsReportedAsNotApplied) {
  ImportOptions options;
  options.isolate_cad_readers = false;
  options.reader_time_limit_seconds = 5.0;
  const std::string data = CADCLASH_DATA_DIR;
  for (const std::string& path : {data + "/cad/valid_two_solids.step", data + "/external/bearing.iges",
                                  data + "/external/Ball.brep"}) {
    const ImportResult r = import_file(path, options);
    ASSERT_FALSE(r.diagnostics.empty()) << path;
    EXPECT_EQ(r.diagnostics.front().severity, Severity::Warning);
    EXPECT_EQ(r.diagnostics.front().message,
              "the reader time limit needs the isolated reader, which is off; not applied");
    EXPECT_FALSE(r.model.surfaces.empty()) << path;
  }
}

}  // namespace
}  // namespace cadclash
