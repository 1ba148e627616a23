// STL (and other assimp formats): one surface per mesh; real STL files checked against their own counts.
#include "readers.h"
#include "test_mesh_util.h"

#include <gtest/gtest.h>
#include "../test_temp.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace cadclash::test {
namespace {

// Triangle count and solid count read straight from an STL file, without assimp.
struct StlCounts {
  std::size_t facets = 0;
  std::size_t solids = 0;
};

StlCounts count_stl(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  StlCounts c;
  if (bytes.size() >= 84) {
    std::uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);
    if (84 + 50 * static_cast<std::uint64_t>(n) == bytes.size()) return {n, 1};  // binary
  }
  std::istringstream text(bytes);
  std::string word;
  while (text >> word) {
    for (char& ch : word) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (word == "endfacet") ++c.facets;
    if (word == "endsolid") ++c.solids;
  }
  return c;
}

// Edges used other than exactly twice, counting each undirected edge.
std::size_t open_edges(const TriangleMesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++uses[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  std::size_t open = 0;
  for (const auto& [e, n] : uses) open += n != 2;
  return open;
}

TEST(MeshStl, AsciiAndBinaryCubesAreOneClosedSurface) {
  for (const char* name : {"cube_ascii.stl", "cube_binary.stl"}) {
    SCOPED_TRACE(name);
    const std::string path = mesh_data(name);
    const ImportResult r = import_file(path);
    ASSERT_TRUE(r.complete) << all_messages(r);
    const Model& m = r.model;
    expect_well_formed(m);
    ASSERT_EQ(m.parts.size(), 1u);
    ASSERT_EQ(m.surfaces.size(), 1u);
    const Surface& s = m.surfaces[0];
    EXPECT_EQ(s.provenance.kind, SourceKind::MeshFile);
    EXPECT_EQ(s.provenance.source_file, path);
    EXPECT_FALSE(s.provenance.colour.has_value());  // not assimp's invented default material
    EXPECT_EQ(s.mesh.triangles.size(), 12u);
    EXPECT_EQ(s.mesh.vertices.size(), 8u);  // per-facet corners merged by position
    EXPECT_EQ(open_edges(s.mesh), 0u);
    EXPECT_DOUBLE_EQ(area(s.mesh), 6.0);
    EXPECT_TRUE(s.aabb.isApprox(Aabb(Vec3(0, 0, 0), Vec3(1, 1, 1))));
    EXPECT_EQ(m.instances.size(), 1u);
  }
}

TEST(MeshStl, GarbageIsAnErrorNotACrash) {
  const ImportResult r = import_file(bad_data("garbage.stl"));
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(has_error(r.diagnostics)) << all_messages(r);
  EXPECT_EQ(r.diagnostics.front().file, bad_data("garbage.stl"));
}

TEST(MeshStl, EmptyAndTruncatedBinary) {
  const std::string dir = cadclash::testing::scratch_dir();
  const std::string empty = dir + "/empty.stl";
  std::ofstream(empty, std::ios::binary).flush();
  EXPECT_TRUE(has_error(import_file(empty).diagnostics));
  // A binary header announcing 1000 facets with only one present.
  std::ifstream in(mesh_data("cube_binary.stl"), std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::uint32_t n = 1000;
  std::memcpy(bytes.data() + 80, &n, 4);
  bytes.resize(84 + 50);
  const std::string cut = dir + "/cut.stl";
  std::ofstream(cut, std::ios::binary) << bytes;
  const ImportResult r = import_file(cut);
  EXPECT_TRUE(has_error(r.diagnostics)) << all_messages(r);
  EXPECT_TRUE(r.model.surfaces.empty());
}

TEST(MeshPly, PolygonsAreTriangulated) {
  const std::string path = cadclash::testing::scratch_dir() + "/square.ply";
  std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                         "0 0 0\n3 0 0\n3 1 0\n1 1 0\n1 3 0\n0 3 0\n6 0 1 2 3 4 5\n";
  const ImportResult r = import_file(path);
  ASSERT_TRUE(r.complete) << all_messages(r);
  ASSERT_EQ(r.model.surfaces.size(), 1u);
  const TriangleMesh& m = r.model.surfaces[0].mesh;
  EXPECT_EQ(m.triangles.size(), 4u);
  EXPECT_DOUBLE_EQ(area(m), 5.0);
  for (const auto& t : m.triangles) EXPECT_GT(signed_area_xy(m, t), 0.0);
}

// Real STL files no one here wrote (data/external, from occt-misc and gmsh-doc).
class MeshStlExternal : public ::testing::TestWithParam<const char*> {};

TEST_P(MeshStlExternal, TriangleCountMatchesTheFile) {
  const std::string path = external_data(GetParam());
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing: run scripts/setup.sh";
  const StlCounts expected = count_stl(path);
  ASSERT_GT(expected.facets, 0u);
  const ImportResult r = import_file(path);
  EXPECT_TRUE(r.complete) << all_messages(r);
  expect_well_formed(r.model);
  ASSERT_EQ(r.model.parts.size(), 1u);
  EXPECT_EQ(r.model.surfaces.size(), expected.solids);
  EXPECT_EQ(triangle_count(r.model), expected.facets);
  for (const Surface& s : r.model.surfaces) {
    EXPECT_LE(s.mesh.vertices.size(), 3 * s.mesh.triangles.size());
    EXPECT_FALSE(s.aabb.isEmpty());
  }
}

INSTANTIATE_TEST_SUITE_P(Real, MeshStlExternal,
                         ::testing::Values("bearing.stl", "motor.stl", "hinge.stl", "lever.stl", "TR12J_OCC.stl",
                                           "head.stl", "sphere-surf.stl", "t13_data.stl", "propeller.stl"),
                         [](const ::testing::TestParamInfo<const char*>& param_info) {
                           std::string n = param_info.param;
                           for (char& c : n)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });

TEST(MeshStlExternal, CornersMergeIntoTheFilesDistinctPositions) {
  // Per-facet corners are merged exactly by position: the vertex count is the file's own number of
  // distinct "vertex x y z" positions, counted here from the text.
  const std::string path = external_data("bearing.stl");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing: run scripts/setup.sh";
  std::ifstream in(path);
  std::set<std::array<float, 3>> distinct;
  std::string word;
  while (in >> word) {
    if (word != "vertex") continue;
    std::array<float, 3> p{};
    for (float& c : p) {
      in >> word;
      c = std::strtof(word.c_str(), nullptr);
      if (c == 0.0f) c = 0.0f;  // -0 is +0
    }
    distinct.insert(p);
  }
  const ImportResult r = import_file(path);
  ASSERT_EQ(r.model.surfaces.size(), 1u);
  EXPECT_EQ(r.model.surfaces[0].mesh.vertices.size(), distinct.size());
}

}  // namespace
}  // namespace cadclash::test
