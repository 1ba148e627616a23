// Mesh readers and the supported range (model.h): a coordinate past kMaxLength is an error naming
// the line and the value, the faces that use it are dropped and the rest of the file is kept; tiny
// faces that have area are not called degenerate.
#include "cadclash/import.h"
#include "test_mesh_util.h"
#include "../test_temp.h"

#include <gtest/gtest.h>

#include <string>

namespace cadclash {
namespace {

TEST(MeshRange, ObjCoordinatePastTheRangeDropsItsFacesAndNamesLineAndValue) {
  const std::string file = testing::write_scratch_file("far.obj",
                                                        "v 0 0 0\n"
                                                        "v 1 0 0\n"
                                                        "v 0 1 0\n"
                                                        "v 1e155 1 0\n"  // line 4
                                                        "g near\n"
                                                        "f 1 2 3\n"
                                                        "g far\n"
                                                        "f 2 4 3\n");
  const ImportResult r = import_file(file);
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(test::has_diagnostic(r, Severity::Error, 4, "outside the supported range")) << test::all_messages(r);
  EXPECT_NE(test::all_messages(r).find("1e155"), std::string::npos) << test::all_messages(r);
  // The good face is kept; nothing in the model lies past the range.
  ASSERT_NE(test::find_surface(r.model, "near"), nullptr) << test::all_messages(r);
  std::size_t triangles = 0;
  for (const Surface& s : r.model.surfaces) {
    triangles += s.mesh.triangles.size();
    for (const Vec3& v : s.mesh.vertices) EXPECT_LE(v.cwiseAbs().maxCoeff(), kMaxLength);
  }
  EXPECT_EQ(triangles, 1u);
}

TEST(MeshRange, ObjCoordinateAtTheRangeIsRead) {
  const std::string file = testing::write_scratch_file("edge.obj",
                                                        "v 0 0 0\n"
                                                        "v 340282366920938463463374607431768211456 0 0\n"  // 2^128
                                                        "v 0 -340282366920938463463374607431768211456 0\n"
                                                        "f 1 2 3\n");
  const ImportResult r = import_file(file);
  EXPECT_TRUE(r.complete) << test::all_messages(r);
  EXPECT_FALSE(has_error(r.diagnostics)) << test::all_messages(r);
}

TEST(MeshRange, OffCoordinatePastTheRangeIsAnErrorNamingTheLine) {
  const std::string file = testing::write_scratch_file("far.off",
                                                        "OFF\n"
                                                        "4 2 0\n"
                                                        "0 0 0\n"
                                                        "1 0 0\n"
                                                        "0 1 0\n"
                                                        "1 1 -7e38\n"  // line 6
                                                        "3 0 1 2\n"
                                                        "3 1 3 2\n");
  const ImportResult r = import_file(file);
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(test::has_diagnostic(r, Severity::Error, 6, "outside the supported range")) << test::all_messages(r);
  std::size_t triangles = 0;
  for (const Surface& s : r.model.surfaces) triangles += s.mesh.triangles.size();
  EXPECT_EQ(triangles, 1u);
}

// A float cross product of 1e-200 mm edges underflows to zero; the face has area all the same.
TEST(MeshRange, TinyFacesWithAreaAreNotCalledDegenerate) {
  const std::string file = testing::write_scratch_file("tiny.obj",
                                                        "v 0 0 0\n"
                                                        "v 1e-200 0 0\n"
                                                        "v 0 1e-200 0\n"
                                                        "v 2e-200 0 0\n"
                                                        "g area\n"
                                                        "f 1 2 3\n"
                                                        "g line\n"
                                                        "f 1 2 4\n");  // line 8: collinear
  const ImportResult r = import_file(file);
  EXPECT_FALSE(test::has_diagnostic(r, Severity::Warning, 6, "zero area")) << test::all_messages(r);
  EXPECT_TRUE(test::has_diagnostic(r, Severity::Warning, 8, "zero area")) << test::all_messages(r);
}

}  // namespace
}  // namespace cadclash
