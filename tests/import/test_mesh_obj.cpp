// OBJ import: groups as surfaces, assimp's quirks, triangulation, and damaged files.
#include "readers.h"
#include "test_mesh_util.h"

#include <gtest/gtest.h>
#include "../test_temp.h"

#include <filesystem>
#include <fstream>

namespace cadclash::test {
namespace {

TEST(MeshObj, GroupsBecomeSurfacesInOrderOfFirstAppearance) {
  const std::string path = mesh_data("groups.obj");
  const ImportResult r = import_file(path);
  ASSERT_TRUE(r.complete) << all_messages(r);
  EXPECT_TRUE(r.diagnostics.empty()) << all_messages(r);
  const Model& m = r.model;
  expect_well_formed(m);
  ASSERT_EQ(m.parts.size(), 1u);
  EXPECT_EQ(m.parts[0].name, "groups");
  EXPECT_EQ(m.parts[0].source_file, path);
  ASSERT_EQ(m.instances.size(), 1u);
  EXPECT_EQ(m.instances[0].path, "/groups");
  EXPECT_TRUE(m.instances[0].pose.matrix().isIdentity(0.0));

  // Faces before any group fall in "default"; "left" and "right" recur and stay one surface each;
  // `o lid` is a surface too.
  ASSERT_EQ(m.surfaces.size(), 4u);
  const char* names[] = {"default", "left", "right", "lid"};
  const std::size_t triangles[] = {1, 3, 3, 1};
  for (std::size_t i = 0; i < 4; ++i) {
    const Surface& s = m.surfaces[i];
    EXPECT_EQ(s.name, names[i]);
    EXPECT_EQ(s.provenance.kind, SourceKind::ObjGroup);
    EXPECT_EQ(s.provenance.source_name, names[i]);
    EXPECT_EQ(s.provenance.face_index, static_cast<int>(i));
    EXPECT_EQ(s.provenance.source_file, path);
    EXPECT_EQ(s.mesh.triangles.size(), triangles[i]) << names[i];
  }
  // "left" uses file vertices 1 2 3 4 8 7: shared corners are one vertex.
  EXPECT_EQ(m.surfaces[1].mesh.vertices.size(), 6u);
  EXPECT_NEAR(area(m.surfaces[1].mesh), 1.0 + 0.5, 1e-15);
  // "right": the quad 2 5 6 3 and, through relative indices, the triangle 6 5 7.
  EXPECT_NEAR(area(m.surfaces[2].mesh), 1.0 + 0.5 * Vec3(0, -1, 0).cross(Vec3(-2, -1, 1)).norm(), 1e-15);
  EXPECT_TRUE(m.surfaces[1].aabb.contains(Vec3(0, 0, 1)));
}

TEST(MeshObj, ConcavePolygonIsTriangulatedExactly) {
  const ImportResult r = import_file(mesh_data("concave.obj"));
  ASSERT_TRUE(r.complete) << all_messages(r);
  ASSERT_EQ(r.model.surfaces.size(), 1u);
  const TriangleMesh& mesh = r.model.surfaces[0].mesh;
  ASSERT_EQ(mesh.triangles.size(), 4u);
  EXPECT_EQ(mesh.vertices.size(), 6u);
  double signed_sum = 0;
  for (const auto& t : mesh.triangles) {
    // Every triangle keeps the polygon's counter-clockwise winding.
    EXPECT_GT(signed_area_xy(mesh, t), 0.0);
    signed_sum += signed_area_xy(mesh, t);
  }
  EXPECT_DOUBLE_EQ(signed_sum, 5.0);
  EXPECT_DOUBLE_EQ(area(mesh), 5.0);
}

TEST(MeshObj, UsemtlDoesNotSplitOrRenameGroups) {
  const ImportResult r = import_file(mesh_data("usemtl.obj"));
  ASSERT_TRUE(r.complete) << all_messages(r);
  const Model& m = r.model;
  expect_well_formed(m);
  // assimp 5.2.5 alone returns five meshes here named alpha, blue, red, beta, red.
  ASSERT_EQ(m.surfaces.size(), 3u);
  EXPECT_EQ(m.surfaces[0].name, "alpha");
  EXPECT_EQ(m.surfaces[0].mesh.triangles.size(), 3u);
  EXPECT_EQ(m.surfaces[1].name, "beta");
  EXPECT_EQ(m.surfaces[1].mesh.triangles.size(), 2u);
  EXPECT_EQ(m.surfaces[2].name, "red");  // a group named like a material is still a group
  EXPECT_EQ(m.surfaces[2].mesh.triangles.size(), 1u);
}

TEST(MeshObj, MissingFileNamesTheFile) {
  const std::string path = bad_data("does_not_exist.obj");
  for (const ImportResult& r : {import_file(path), detail::read_obj(path, {})}) {
    EXPECT_FALSE(r.complete);
    EXPECT_TRUE(r.model.surfaces.empty());
    ASSERT_EQ(r.diagnostics.size(), 1u);
    EXPECT_EQ(r.diagnostics[0].file, path);
    EXPECT_NE(r.diagnostics[0].message.find("no such file"), std::string::npos);
  }
}

TEST(MeshObj, EmptyFile) {
  const ImportResult r = import_file(bad_data("empty.obj"));
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(r.model.parts.empty());
  ASSERT_TRUE(has_error(r.diagnostics));
  EXPECT_NE(all_messages(r).find("empty.obj: error: empty file"), std::string::npos) << all_messages(r);
}

TEST(MeshObj, BinaryGarbageIsRejectedWithItsLine) {
  const ImportResult r = import_file(bad_data("garbage.obj"));
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(r.model.surfaces.empty());
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_GT(r.diagnostics[0].line, 0);
  EXPECT_NE(r.diagnostics[0].message.find("binary data"), std::string::npos);
}

TEST(MeshObj, TruncatedFileKeepsWhatCameBefore) {
  const ImportResult r = import_file(bad_data("truncated.obj"));
  EXPECT_FALSE(r.complete);
  ASSERT_EQ(r.model.surfaces.size(), 2u) << all_messages(r);
  EXPECT_EQ(r.model.surfaces[0].name, "a");
  EXPECT_EQ(r.model.surfaces[1].name, "b");
  EXPECT_EQ(r.model.surfaces[1].mesh.triangles.size(), 1u);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 9, "at least 3 vertices")) << all_messages(r);
  EXPECT_NE(all_messages(r).find("truncated.obj:9: error: face dropped"), std::string::npos) << all_messages(r);
}

TEST(MeshObj, IndexOutOfRangeDropsOnlyThatFace) {
  const ImportResult r = import_file(bad_data("index_out_of_range.obj"));
  EXPECT_FALSE(r.complete);
  expect_well_formed(r.model);
  ASSERT_EQ(r.model.surfaces.size(), 2u) << all_messages(r);
  EXPECT_EQ(r.model.surfaces[0].name, "good");
  EXPECT_EQ(r.model.surfaces[1].name, "bad");
  EXPECT_EQ(r.model.surfaces[1].mesh.triangles.size(), 1u);
  ASSERT_EQ(r.diagnostics.size(), 1u) << all_messages(r);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 8, "vertex index 9 is out of range")) << all_messages(r);
  EXPECT_NE(format_diagnostic(r.diagnostics[0]).find("index_out_of_range.obj:8:"), std::string::npos);
}

TEST(MeshObj, NonFiniteVerticesAndTheFacesUsingThemAreListed) {
  const ImportResult r = import_file(bad_data("nan_vertex.obj"));
  EXPECT_FALSE(r.complete);
  expect_well_formed(r.model);
  ASSERT_EQ(r.model.surfaces.size(), 1u) << all_messages(r);  // every face of "bad" was dropped
  EXPECT_EQ(r.model.surfaces[0].name, "good");
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 4, "not finite")) << all_messages(r);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 5, "not finite")) << all_messages(r);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 9, "vertex 4, which is bad (line 4)")) << all_messages(r);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 10, "vertex 5, which is bad (line 5)")) << all_messages(r);
}

class MeshObjTemp : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) {
    return cadclash::testing::write_scratch_file(name, text);
  }
};

TEST_F(MeshObjTemp, ManyBadFacesAreCappedButCounted) {
  std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\ng ok\nf 1 2 3\n";
  for (int i = 0; i < 100; ++i) text += "f 1 2 99\n";
  const ImportResult r = import_file(write("many_bad.obj", text));
  EXPECT_FALSE(r.complete);
  ASSERT_EQ(r.model.surfaces.size(), 1u);
  ASSERT_EQ(r.diagnostics.size(), 21u) << all_messages(r);
  EXPECT_EQ(r.diagnostics[0].line, 6);
  EXPECT_NE(r.diagnostics.back().message.find("80 more faces dropped"), std::string::npos) << all_messages(r);
}

TEST_F(MeshObjTemp, ForwardReferencesCrLfContinuationsAndIgnoredStatements) {
  const std::string text =
      "# comment\r\ng first\r\nf 1 2 \\\r\n 3\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0 1 0 0\r\nvn 0 0 1\r\nvt 0 0\r\n"
      "s 1\r\nl 1 2\r\nf 1/1/1 2/1/1 3//1\r\ng\r\nf 3 2 1\r\n";
  const ImportResult r = import_file(write("misc.obj", text));
  EXPECT_TRUE(r.complete) << all_messages(r);
  ASSERT_EQ(r.model.surfaces.size(), 2u);
  EXPECT_EQ(r.model.surfaces[0].name, "first");
  EXPECT_EQ(r.model.surfaces[0].mesh.triangles.size(), 2u);
  EXPECT_EQ(r.model.surfaces[0].mesh.vertices.size(), 3u);
  EXPECT_EQ(r.model.surfaces[1].name, "default");
  // The one `l` element is reported, not silently dropped.
  EXPECT_TRUE(has_diagnostic(r, Severity::Warning, 0, "line/point elements")) << all_messages(r);
}

TEST_F(MeshObjTemp, CoordinatesKeepDoublePrecision) {
  // assimp stores float32; the reader must not: these differ below float precision.
  const ImportResult r = import_file(write("precise.obj", "v 1234.5678901234 0 0\nv 1234.5678901235 1 0\nv 0 0 1e-300\nf 1 2 3\n"));
  ASSERT_EQ(r.model.surfaces.size(), 1u) << all_messages(r);
  const TriangleMesh& m = r.model.surfaces[0].mesh;
  ASSERT_EQ(m.vertices.size(), 3u);
  EXPECT_EQ(m.vertices[0].x(), 1234.5678901234);
  EXPECT_EQ(m.vertices[1].x(), 1234.5678901235);
  EXPECT_EQ(m.vertices[2].z(), 1e-300);  // tiny is finite: no unit-dependent rounding to zero
}

TEST_F(MeshObjTemp, TextWithoutFacesIsAnError) {
  const ImportResult r = import_file(write("words.obj", "hello world\nthis is not a mesh\n"));
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(r.model.surfaces.empty());
  EXPECT_TRUE(has_diagnostic(r, Severity::Warning, 1, "unknown statement 'hello'")) << all_messages(r);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 0, "no usable faces")) << all_messages(r);
}

TEST_F(MeshObjTemp, ZeroIndexAndMalformedVertex) {
  const ImportResult r =
      import_file(write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 x 0\nf 0 1 2\nf 1 2 3\nf 1 2 4\nf 1 2 -9\n"));
  EXPECT_FALSE(r.complete);
  ASSERT_EQ(r.model.surfaces.size(), 1u);
  EXPECT_EQ(r.model.surfaces[0].mesh.triangles.size(), 1u);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 4, "'x' is not a number")) << all_messages(r);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 5, "index 0 is invalid")) << all_messages(r);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 7, "vertex 4, which is bad")) << all_messages(r);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 8, "index -9 is out of range")) << all_messages(r);
}

}  // namespace
}  // namespace cadclash::test
