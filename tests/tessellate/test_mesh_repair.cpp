// repair_meshes(): exact per-surface counts on soups built here, tags kept across many groups.
#include "mesh_soups.h"

#include <gtest/gtest.h>

namespace cadclash {
namespace {

using namespace cadclash::test;

// Box [0,2]x[0,3]x[0,4] as one soup with three flipped triangles (including the first one, which
// orient_polygon_soup starts from), two repeats, two degenerate triangles and one unused vertex.
TEST(MeshRepair, CountsExactOnBrokenBox) {
  TriangleMesh m = box_soup(Vec3(0, 0, 0), Vec3(2, 3, 4));
  for (std::size_t t : {0u, 7u, 9u}) flip(m, t);
  const Corners c5 = corners(m, 5), c3 = corners(m, 3);
  add_soup_triangle(m, c5[0], c5[2], c5[1]);  // repeat of 5, reversed
  add_soup_triangle(m, c3[0], c3[1], c3[2]);  // repeat of 3
  m.triangles.push_back({0, 0, 1});           // repeated index
  add_soup_triangle(m, c3[0], c3[0], c3[1]);  // two corners at one point
  m.vertices.push_back(Vec3(9, 9, 9));        // used by nothing
  ASSERT_EQ(m.vertices.size(), 46u);
  ASSERT_EQ(m.triangles.size(), 16u);

  Model model = one_part_model({m});
  const MeshRepairReport r = repair_meshes(model);
  ASSERT_TRUE(r.diagnostics.empty());
  ASSERT_EQ(r.per_surface.size(), 1u);
  const SurfaceRepairStats& s = r.per_surface[0];
  EXPECT_EQ(s.surface, 0u);
  EXPECT_EQ(s.vertices_before, 46u);
  EXPECT_EQ(s.triangles_before, 16u);
  EXPECT_EQ(s.unused_points, 1u);
  EXPECT_EQ(s.merged_points, 45u - 8u);  // 45 used vertices on the 8 corners
  EXPECT_EQ(s.degenerate_faces, 2u);
  EXPECT_EQ(s.duplicate_faces, 2u);
  EXPECT_EQ(s.flipped_faces, 3u);
  EXPECT_EQ(s.stitched_edges, 0u);
  EXPECT_EQ(s.duplicated_vertices, 0u);
  EXPECT_EQ(s.filled_holes, 0u);
  EXPECT_EQ(s.hole_faces, 0u);
  EXPECT_EQ(s.triangles_after, 12u);
  EXPECT_EQ(s.vertices_after, 8u);
  EXPECT_TRUE(s.changed);
  EXPECT_EQ(r.parts_repaired, 1u);
  EXPECT_EQ(r.total.flipped_faces, 3u);

  const Surface& out = model.surfaces[0];
  EXPECT_TRUE(out.provenance.repaired);
  EXPECT_EQ(out.name, "g0");
  EXPECT_EQ(out.mesh.triangles.size(), 12u);
  EXPECT_TRUE(closed_and_oriented(model, 0));
  EXPECT_DOUBLE_EQ(volume6(model, 0), 6.0 * 2 * 3 * 4);  // outward
  EXPECT_TRUE(out.aabb.isApprox(Aabb(Vec3(0, 0, 0), Vec3(2, 3, 4))));
}

// A hollow box: the cavity's shell must face inward (into the cavity), so a correct one is kept
// and an outward one is flipped whole.
TEST(MeshRepair, CavityShellFacesInward) {
  const TriangleMesh outer = box_soup(Vec3(0, 0, 0), Vec3(10, 10, 10));
  TriangleMesh inner = box_soup(Vec3(2, 2, 2), Vec3(8, 8, 8));
  Model wrong = one_part_model({outer, inner});
  const MeshRepairReport r1 = repair_meshes(wrong);
  EXPECT_EQ(r1.per_surface[0].flipped_faces, 0u);
  EXPECT_EQ(r1.per_surface[1].flipped_faces, 12u);
  EXPECT_TRUE(closed_and_oriented(wrong, 0));
  EXPECT_DOUBLE_EQ(volume6(wrong, 0), 6.0 * (1000 - 216));

  for (std::size_t t = 0; t < inner.triangles.size(); ++t) flip(inner, t);
  Model right = one_part_model({outer, inner});
  EXPECT_EQ(repair_meshes(right).total.flipped_faces, 0u);
  EXPECT_DOUBLE_EQ(volume6(right, 0), 6.0 * (1000 - 216));
}

// A box whose faces are 4x4 grids, one group per grid row (24 groups of 8 soup triangles), with
// g % 3 triangles of group g flipped: every triangle stays on its group, every group keeps its
// name and source ids, and the flips are counted on the right group.
TEST(MeshRepair, ManyGroupsKeepEveryTriangleAndTag) {
  std::vector<TriangleMesh> groups;
  std::vector<std::uint32_t> flips;
  for (const auto& q : box_quads(Vec3(0, 0, 0), Vec3(10, 10, 10))) {
    auto at = [&](int i, int j) { return Vec3(q[0] + (q[1] - q[0]) * i / 4.0 + (q[3] - q[0]) * j / 4.0); };
    for (int j = 0; j < 4; ++j) {
      TriangleMesh g;
      for (int i = 0; i < 4; ++i) add_soup_quad(g, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      const std::uint32_t n = static_cast<std::uint32_t>(groups.size()) % 3;
      for (std::uint32_t t = 0; t < n; ++t) flip(g, 2 * t + 1);
      flips.push_back(n);
      groups.push_back(g);
    }
  }
  ASSERT_EQ(groups.size(), 24u);
  Model model = one_part_model(groups);
  const Model before = model;
  const MeshRepairReport r = repair_meshes(model);
  ASSERT_TRUE(r.diagnostics.empty());
  ASSERT_EQ(model.surfaces.size(), 24u);
  ASSERT_EQ(r.per_surface.size(), 24u);
  std::uint32_t total_flips = 0;
  for (SurfaceId s = 0; s < 24; ++s) {
    const Surface& a = before.surfaces[s];
    const Surface& b = model.surfaces[s];
    const SurfaceRepairStats& st = r.per_surface[s];
    EXPECT_EQ(st.surface, s);
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.part, a.part);
    EXPECT_EQ(b.provenance.kind, a.provenance.kind);
    EXPECT_EQ(b.provenance.source_name, a.provenance.source_name);
    EXPECT_EQ(b.provenance.step_id, a.provenance.step_id);
    EXPECT_EQ(b.provenance.face_index, a.provenance.face_index);
    EXPECT_EQ(triangle_sets(b.mesh), triangle_sets(a.mesh)) << "surface " << s;
    EXPECT_EQ(st.flipped_faces, flips[s]) << "surface " << s;
    EXPECT_EQ(st.merged_points, 24u - 10u);  // 8 soup triangles on a 2x5 row of grid points
    EXPECT_EQ(st.vertices_after, 10u);
    EXPECT_EQ(st.triangles_after, 8u);
    EXPECT_EQ(st.degenerate_faces + st.duplicate_faces + st.stitched_edges + st.duplicated_vertices, 0u);
    total_flips += flips[s];
  }
  EXPECT_EQ(r.total.flipped_faces, total_flips);
  EXPECT_TRUE(closed_and_oriented(model, 0));
  EXPECT_GT(volume6(model, 0), 0.0);
}

// Every box face a 3x3 grid of its own surface; one triangle of the top face's centre cell missing.
// The hole is filled only on request, and its triangle goes to the top surface.
TEST(MeshRepair, HolesFilledOnlyOnRequest) {
  std::vector<TriangleMesh> surfaces;
  for (const auto& q : box_quads(Vec3(0, 0, 0), Vec3(3, 3, 3))) {
    auto at = [&](int i, int j) { return Vec3(q[0] + (q[1] - q[0]) * i / 3.0 + (q[3] - q[0]) * j / 3.0); };
    TriangleMesh grid;
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        if (surfaces.size() == 5 && i == 1 && j == 1) {
          add_soup_triangle(grid, at(i, j), at(i + 1, j + 1), at(i, j + 1));  // half of the centre cell
          continue;
        }
        add_soup_quad(grid, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      }
    surfaces.push_back(grid);
  }

  Model plain = one_part_model(surfaces);
  const MeshRepairReport r0 = repair_meshes(plain);
  EXPECT_EQ(r0.total.filled_holes, 0u);
  EXPECT_EQ(r0.total.triangles_after, 5u * 18u + 17u);
  EXPECT_FALSE(closed_and_oriented(plain, 0));

  Model filled = one_part_model(surfaces);
  MeshRepairOptions options;
  options.fill_holes = true;
  const MeshRepairReport r1 = repair_meshes(filled, options);
  ASSERT_EQ(r1.per_surface.size(), 6u);
  EXPECT_EQ(r1.total.filled_holes, 1u);
  EXPECT_EQ(r1.per_surface[5].filled_holes, 1u);
  EXPECT_EQ(r1.per_surface[5].hole_faces, 1u);
  EXPECT_EQ(filled.surfaces[5].mesh.triangles.size(), 18u);
  EXPECT_TRUE(closed_and_oriented(filled, 0));
  EXPECT_DOUBLE_EQ(volume6(filled, 0), 6.0 * 27);
}

TEST(MeshRepair, NegligibleComponentsRemovedOnlyOnRequest) {
  const std::vector<TriangleMesh> surfaces{box_soup(Vec3(0, 0, 0), Vec3(100, 100, 100)),
                                           box_soup(Vec3(500, 500, 500), Vec3(500.1, 500.1, 500.1))};
  Model kept = one_part_model(surfaces);
  EXPECT_EQ(repair_meshes(kept).total.removed_component_faces, 0u);
  EXPECT_EQ(kept.surfaces[1].mesh.triangles.size(), 12u);

  Model cleaned = one_part_model(surfaces);
  MeshRepairOptions options;
  options.remove_negligible_components = true;
  const MeshRepairReport r = repair_meshes(cleaned, options);
  ASSERT_EQ(r.per_surface.size(), 2u);
  EXPECT_EQ(r.per_surface[0].removed_component_faces, 0u);
  EXPECT_EQ(r.per_surface[1].removed_component_faces, 12u);
  EXPECT_EQ(cleaned.surfaces[0].mesh.triangles.size(), 12u);
  EXPECT_EQ(cleaned.surfaces[1].mesh.triangles.size(), 0u);
  EXPECT_EQ(cleaned.surfaces[1].name, "g1");  // the surface stays, empty
}

TEST(MeshRepair, CleanMeshIsLeftAlone) {
  // The box as an indexed mesh: 8 shared corners, consistently outward.
  TriangleMesh soup = box_soup(Vec3(0, 0, 0), Vec3(1, 1, 1));
  Model first = one_part_model({soup});
  repair_meshes(first);
  Model model = first;
  for (Surface& s : model.surfaces) s.provenance.repaired = false;
  const MeshRepairReport r = repair_meshes(model);
  ASSERT_EQ(r.per_surface.size(), 1u);
  EXPECT_FALSE(r.per_surface[0].changed);
  EXPECT_FALSE(model.surfaces[0].provenance.repaired);
  EXPECT_EQ(model.surfaces[0].mesh.vertices, first.surfaces[0].mesh.vertices);
  EXPECT_EQ(model.surfaces[0].mesh.triangles, first.surfaces[0].mesh.triangles);
  EXPECT_EQ(r.parts_repaired, 0u);
}

TEST(MeshRepair, SurfaceOfOnlyDegenerateTrianglesEndsEmpty) {
  TriangleMesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 0)};
  m.triangles = {{0, 1, 2}, {0, 0, 1}};
  Model model = one_part_model({m, TriangleMesh{}});
  const MeshRepairReport r = repair_meshes(model);
  ASSERT_EQ(r.per_surface.size(), 2u);
  EXPECT_EQ(r.per_surface[0].degenerate_faces, 2u);
  EXPECT_EQ(r.per_surface[0].merged_points, 1u);
  EXPECT_EQ(r.per_surface[0].triangles_after, 0u);
  EXPECT_TRUE(model.surfaces[0].mesh.triangles.empty());
  EXPECT_TRUE(model.surfaces[0].provenance.repaired);
  EXPECT_FALSE(r.per_surface[1].changed);
  EXPECT_EQ(segment_surfaces(model).surfaces_split, 0u);
}

// A part with a SurfaceSource (a B-rep part) is not a mesh part: repair leaves it alone.
class NullSource final : public SurfaceSource {
 public:
  bool triangulate(std::uint32_t, double, TriangleMesh&, double&, Diagnostic&) override { return false; }
};

TEST(MeshRepair, SkipsPartsWithASurfaceSource) {
  TriangleMesh m = box_soup(Vec3(0, 0, 0), Vec3(1, 1, 1));
  flip(m, 4);
  Model model = one_part_model({m});
  model.parts[0].source = std::make_shared<NullSource>();
  const MeshRepairReport r = repair_meshes(model);
  EXPECT_TRUE(r.per_surface.empty());
  EXPECT_EQ(model.surfaces[0].mesh.triangles, m.triangles);
  EXPECT_FALSE(model.surfaces[0].provenance.repaired);
}

TEST(MeshRepair, Deterministic) {
  TriangleMesh m = cylinder_soup(5.0, 7.0, 40);
  for (std::size_t t = 0; t < m.triangles.size(); t += 7) flip(m, t);
  Model a = one_part_model({m, box_soup(Vec3(20, 0, 0), Vec3(21, 1, 1))});
  Model b = a;
  const MeshRepairReport ra = repair_meshes(a), rb = repair_meshes(b);
  ASSERT_EQ(a.surfaces.size(), b.surfaces.size());
  for (std::size_t s = 0; s < a.surfaces.size(); ++s) {
    EXPECT_EQ(a.surfaces[s].mesh.vertices, b.surfaces[s].mesh.vertices);
    EXPECT_EQ(a.surfaces[s].mesh.triangles, b.surfaces[s].mesh.triangles);
  }
  EXPECT_EQ(ra.total.flipped_faces, rb.total.flipped_faces);
  EXPECT_EQ(ra.per_surface[0].flipped_faces, (m.triangles.size() + 6) / 7);
  EXPECT_TRUE(closed_and_oriented(a, 0));
}

}  // namespace
}  // namespace cadclash
