// Whole parts meshed after a lazy import (tessellate_parts, release_part_triangles): the model must
// be the eager import's bit for bit, whatever order and grouping the parts are meshed in, and again
// after the triangles were released and meshed once more. Distributed checks rely on it.
#include "cadclash/import.h"
#include "cadclash/tessellate.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

namespace cadclash {
namespace {

std::string as1_path() { return std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp"; }
#define REQUIRE_AS1() \
  if (!std::filesystem::exists(as1_path())) GTEST_SKIP() << "needs data/external/as1-tu-203.stp (scripts/setup.sh)"

Model import_as1(bool lazy) {
  ImportOptions io;
  io.lazy = lazy;
  ImportResult r = import_file(as1_path(), io);
  EXPECT_FALSE(has_error(r.diagnostics));
  return std::move(r.model);
}

// Every surface as the eager import left it: triangles, vertices (bit for bit), deflection, box.
void expect_same_surfaces(const Model& got, const Model& eager) {
  ASSERT_EQ(got.surfaces.size(), eager.surfaces.size());
  for (SurfaceId s = 0; s < got.surfaces.size(); ++s) {
    const Surface& g = got.surfaces[s];
    const Surface& e = eager.surfaces[s];
    ASSERT_EQ(g.has_triangles, e.has_triangles) << "surface " << s;
    EXPECT_EQ(g.deflection, e.deflection) << "surface " << s;
    EXPECT_TRUE(g.aabb.min() == e.aabb.min() && g.aabb.max() == e.aabb.max()) << "surface " << s;
    ASSERT_EQ(g.mesh.triangles, e.mesh.triangles) << "surface " << s;
    ASSERT_EQ(g.mesh.vertices.size(), e.mesh.vertices.size()) << "surface " << s;
    for (std::size_t v = 0; v < g.mesh.vertices.size(); ++v)
      ASSERT_TRUE(g.mesh.vertices[v] == e.mesh.vertices[v]) << "surface " << s << " vertex " << v;
  }
}

TEST(PartMeshing, LazyImportThenWholePartsIsTheEagerImport) {
  REQUIRE_AS1();
  const Model eager = import_as1(false);
  Model lazy = import_as1(true);
  EXPECT_FALSE(brep_parts_share_edges(lazy));
  for (const Surface& s : lazy.surfaces) ASSERT_FALSE(s.has_triangles);
  // The later parts first, then the rest in two calls: order and grouping must not matter.
  std::vector<PartId> all(lazy.parts.size());
  std::iota(all.begin(), all.end(), PartId{0});
  ASSERT_GE(all.size(), 3u);
  const std::vector<PartId> late(all.rbegin(), all.rbegin() + static_cast<std::ptrdiff_t>(all.size() / 2));
  std::vector<Diagnostic> ds;
  bool complete = true;
  EXPECT_EQ(tessellate_parts(lazy, late, ds, complete), late.size());
  EXPECT_EQ(tessellate_parts(lazy, all, ds, complete), all.size() - late.size());  // held ones skipped
  EXPECT_TRUE(ds.empty());
  EXPECT_TRUE(complete);
  expect_same_surfaces(lazy, eager);

  // Released (the faces' OCCT triangulations too) and meshed again: the same model once more.
  release_part_triangles(lazy, late);
  for (PartId p : late)
    for (SurfaceId s = lazy.parts[p].first_surface; s < lazy.parts[p].first_surface + lazy.parts[p].surface_count; ++s) {
      EXPECT_FALSE(lazy.surfaces[s].has_triangles);
      EXPECT_TRUE(lazy.surfaces[s].mesh.triangles.empty());
    }
  EXPECT_EQ(tessellate_parts(lazy, late, ds, complete), late.size());
  EXPECT_TRUE(ds.empty());
  expect_same_surfaces(lazy, eager);
}

// A face that does not mesh gets the eager import's error, and the part's other faces their triangles.
TEST(PartMeshing, UnmeshableFaceGetsTheEagerError) {
  const std::string path = std::string(CADCLASH_DATA_DIR) + "/cad/mesh_fail_degenerate.step";
  ImportOptions io;
  const ImportResult eager = import_file(path, io);
  io.lazy = true;
  ImportResult lazy = import_file(path, io);
  std::vector<PartId> all(lazy.model.parts.size());
  std::iota(all.begin(), all.end(), PartId{0});
  std::vector<Diagnostic> ds;
  bool complete = true;
  tessellate_parts(lazy.model, all, ds, complete);
  EXPECT_FALSE(complete);
  ASSERT_FALSE(ds.empty());
  std::vector<std::string> eager_errors;
  for (const Diagnostic& d : eager.diagnostics)
    if (d.severity == Severity::Error && d.message.find("could not be tessellated") != std::string::npos)
      eager_errors.push_back(format_diagnostic(d));
  std::vector<std::string> got;
  for (const Diagnostic& d : ds) got.push_back(format_diagnostic(d));
  EXPECT_EQ(got, eager_errors);
  expect_same_surfaces(lazy.model, eager.model);
}

}  // namespace
}  // namespace cadclash
