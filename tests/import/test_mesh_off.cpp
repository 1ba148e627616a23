// OFF import: colour groups, polygons, and damaged files with their line numbers.
#include "test_mesh_util.h"

#include <gtest/gtest.h>
#include "../test_temp.h"

#include <filesystem>
#include <fstream>

namespace cadclash::test {
namespace {

TEST(MeshOff, EachFaceColourIsOneSurface) {
  const std::string path = mesh_data("colours.off");
  const ImportResult r = import_file(path);
  ASSERT_TRUE(r.complete) << all_messages(r);
  EXPECT_TRUE(r.diagnostics.empty()) << all_messages(r);
  const Model& m = r.model;
  expect_well_formed(m);
  ASSERT_EQ(m.parts.size(), 1u);
  EXPECT_EQ(m.parts[0].name, "colours");
  ASSERT_EQ(m.instances.size(), 1u);
  EXPECT_EQ(m.instances[0].path, "/colours");
  // 255 0 0 and 1.0 0.0 0.0 are the same red; 0 0 255 and 0 0 1.0 0.5 (RGBA) the same blue.
  ASSERT_EQ(m.surfaces.size(), 2u);
  const Surface& red = m.surfaces[0];
  const Surface& blue = m.surfaces[1];
  EXPECT_EQ(red.name, "colour-FF0000");
  EXPECT_EQ(blue.name, "colour-0000FF");
  EXPECT_EQ(red.provenance.kind, SourceKind::OffColourGroup);
  EXPECT_EQ(red.provenance.face_index, 0);
  EXPECT_EQ(blue.provenance.face_index, 1);
  ASSERT_TRUE(red.provenance.colour.has_value());
  EXPECT_EQ(*red.provenance.colour, (std::array<float, 3>{1, 0, 0}));
  ASSERT_TRUE(blue.provenance.colour.has_value());
  EXPECT_EQ(*blue.provenance.colour, (std::array<float, 3>{0, 0, 1}));
  EXPECT_EQ(red.mesh.triangles.size(), 3u);
  EXPECT_EQ(blue.mesh.triangles.size(), 3u);  // a triangle and a quad
  EXPECT_DOUBLE_EQ(area(red.mesh), 0.75);
  EXPECT_DOUBLE_EQ(area(blue.mesh), 1.25);
  for (const Surface& s : m.surfaces)
    for (const auto& t : s.mesh.triangles) EXPECT_GT(signed_area_xy(s.mesh, t), 0.0);
}

TEST(MeshOff, NoColoursGiveOneSurfaceOfPolygons) {
  const ImportResult r = import_file(mesh_data("plain.off"));
  ASSERT_TRUE(r.complete) << all_messages(r);
  ASSERT_EQ(r.model.surfaces.size(), 1u);
  const Surface& s = r.model.surfaces[0];
  EXPECT_EQ(s.name, "uncoloured");
  EXPECT_FALSE(s.provenance.colour.has_value());
  EXPECT_EQ(s.mesh.vertices.size(), 8u);
  EXPECT_EQ(s.mesh.triangles.size(), 12u);
  EXPECT_DOUBLE_EQ(area(s.mesh), 6.0);
  // Closed and consistently oriented: every directed edge appears once, its reverse once.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (const auto& t : s.mesh.triangles)
    for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
  for (const auto& [e, n] : edges) {
    EXPECT_EQ(n, 1);
    EXPECT_EQ(edges.count({e.second, e.first}), 1u);
  }
}

TEST(MeshOff, HeaderAnnouncingMoreVerticesThanTheFileHas) {
  const ImportResult r = import_file(bad_data("off_too_many_vertices.off"));
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(r.model.surfaces.empty());
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 7, "expected vertex 5 of 5 but found a face")) << all_messages(r);
  EXPECT_NE(all_messages(r).find("off_too_many_vertices.off:7: error:"), std::string::npos);
}

TEST(MeshOff, TruncatedFileKeepsItsFaces) {
  const ImportResult r = import_file(bad_data("off_truncated.off"));
  EXPECT_FALSE(r.complete);
  ASSERT_EQ(r.model.surfaces.size(), 1u);
  EXPECT_EQ(r.model.surfaces[0].mesh.triangles.size(), 2u);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 8, "announces 3 faces but the file ends after 2")) << all_messages(r);
}

TEST(MeshOff, IndexOutOfRangeDropsThatFace) {
  const ImportResult r = import_file(bad_data("off_bad_index.off"));
  EXPECT_FALSE(r.complete);
  ASSERT_EQ(r.model.surfaces.size(), 1u);
  EXPECT_EQ(r.model.surfaces[0].mesh.triangles.size(), 1u);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 8, "vertex index 7 is out of range")) << all_messages(r);
}

TEST(MeshOff, NanVertexDropsTheFacesUsingIt) {
  const ImportResult r = import_file(bad_data("off_nan.off"));
  EXPECT_FALSE(r.complete);
  ASSERT_EQ(r.model.surfaces.size(), 1u);
  EXPECT_EQ(r.model.surfaces[0].mesh.triangles.size(), 1u);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 6, "not finite")) << all_messages(r);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 8, "vertex 3, which is bad (line 6)")) << all_messages(r);
}

class MeshOffTemp : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) {
    return cadclash::testing::write_scratch_file(name, text);
  }
};

TEST_F(MeshOffTemp, HugeHeaderCountsDoNotAllocate) {
  // CGAL's reader would resize its arrays to these counts before reading anything.
  const ImportResult r = import_file(write("huge.off", "OFF\n2000000000 2000000000 0\n0 0 0\n1 0 0\n"));
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(r.model.surfaces.empty());
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 4, "announces 2000000000 vertices but the file ends after 2"))
      << all_messages(r);
}

TEST_F(MeshOffTemp, HeaderVariantsCommentsAndMixedColours) {
  // Counts on the keyword line, a COFF with vertex colours, comments, and faces with and without colour.
  const ImportResult r = import_file(write(
      "variants.off", "COFF 4 3 0 # counts here\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 0 255\n\n0 1 0 0 0 0 255\n"
                      "3 0 1 2\n3 0 2 3 0.2 0.4 0.6\n3 0 1 3 7\n"));
  ASSERT_TRUE(r.complete) << all_messages(r);
  ASSERT_EQ(r.model.surfaces.size(), 3u);
  EXPECT_EQ(r.model.surfaces[0].name, "uncoloured");
  EXPECT_EQ(r.model.surfaces[1].name, "colour-336699");
  EXPECT_EQ(r.model.surfaces[2].name, "colour-index-7");
  EXPECT_FALSE(r.model.surfaces[2].provenance.colour.has_value());
}

TEST_F(MeshOffTemp, NotAnOffFile) {
  const ImportResult r = import_file(write("other.off", "# comment\nPLY 3 1\n"));
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(has_diagnostic(r, Severity::Error, 2, "not an OFF file")) << all_messages(r);
  const ImportResult e = import_file(write("empty.off", ""));
  EXPECT_TRUE(has_error(e.diagnostics));
  const ImportResult t = import_file(write("trailing.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n"));
  EXPECT_FALSE(t.complete);
  EXPECT_EQ(t.model.surfaces.size(), 1u);
  EXPECT_TRUE(has_diagnostic(t, Severity::Error, 7, "counts are probably wrong")) << all_messages(t);
}

}  // namespace
}  // namespace cadclash::test
