// segment_surfaces(): patch counts derived from how the soups are built, names, provenance, ids.
#include "mesh_soups.h"

#include <gtest/gtest.h>

namespace cadclash {
namespace {

using namespace cadclash::test;

Vec3 normal(const Corners& c) { return (c[1] - c[0]).cross(c[2] - c[0]).normalized(); }

// Number of distinct triangle normal directions (to 1e-9): the flat faces of a polyhedron.
std::size_t distinct_normals(const TriangleMesh& m) {
  std::vector<Vec3> seen;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const Vec3 n = normal(corners(m, t));
    bool found = false;
    for (const Vec3& s : seen) found = found || (s - n).norm() < 1e-9;
    if (!found) seen.push_back(n);
  }
  return seen.size();
}

TEST(MeshSegment, BoxSoupGivesSixFlatPatchesInInputOrder) {
  const TriangleMesh box = box_soup(Vec3(0, 0, 0), Vec3(2, 3, 4));
  ASSERT_EQ(distinct_normals(box), 6u);  // the count segmentation must reproduce
  Model model = one_part_model({box});
  const SegmentReport r = segment_surfaces(model);
  ASSERT_EQ(model.surfaces.size(), 6u);
  EXPECT_EQ(r.surfaces_split, 1u);
  EXPECT_EQ(r.patches, 6u);
  ASSERT_EQ(r.surfaces.size(), 1u);
  EXPECT_EQ(r.surfaces[0].input, 0u);
  EXPECT_EQ(r.surfaces[0].first, 0u);
  EXPECT_EQ(r.surfaces[0].count, 6u);
  EXPECT_EQ(model.parts[0].first_surface, 0u);
  EXPECT_EQ(model.parts[0].surface_count, 6u);
  for (std::uint32_t k = 0; k < 6; ++k) {
    const Surface& s = model.surfaces[k];
    EXPECT_EQ(s.name, "g0/patch-" + std::to_string(k));
    EXPECT_EQ(s.part, 0u);
    EXPECT_EQ(s.provenance.kind, SourceKind::Segment);
    EXPECT_EQ(s.provenance.parent, 0u);
    EXPECT_EQ(s.provenance.source_name, "group_0");
    EXPECT_EQ(s.provenance.step_id, 1000);
    EXPECT_EQ(s.provenance.face_index, 0);
    ASSERT_EQ(s.mesh.triangles.size(), 2u);
    // Patches are ordered by their lowest input triangle: patch k is the box's quad k.
    EXPECT_EQ(corners(s.mesh, 0), corners(box, 2 * k));
    EXPECT_EQ(corners(s.mesh, 1), corners(box, 2 * k + 1));
    EXPECT_TRUE(s.aabb.contains(s.mesh.vertices[0]));
  }
}

TEST(MeshSegment, CylinderGivesSideAndTwoCaps) {
  const int n = 32;  // 11.25 degrees between side facets, 90 at the rims
  Model model = one_part_model({cylinder_soup(5.0, 10.0, n)});
  segment_surfaces(model);
  ASSERT_EQ(model.surfaces.size(), 3u);
  EXPECT_EQ(model.surfaces[0].mesh.triangles.size(), 2u * n);  // side comes first in the soup
  EXPECT_EQ(model.surfaces[1].mesh.triangles.size(), std::size_t{n});
  EXPECT_EQ(model.surfaces[2].mesh.triangles.size(), std::size_t{n});
  EXPECT_EQ(distinct_normals(model.surfaces[1].mesh), 1u);
  EXPECT_EQ(distinct_normals(model.surfaces[2].mesh), 1u);
}

TEST(MeshSegment, SharpAngleDecides) {
  // A square prism: 90 degrees everywhere. Sharp at 60 (6 patches), smooth at 100 (kept whole).
  const TriangleMesh prism = cylinder_soup(1.0, 1.0, 4);
  Model sharp = one_part_model({prism});
  segment_surfaces(sharp);
  EXPECT_EQ(sharp.surfaces.size(), 6u);

  Model smooth = one_part_model({prism});
  SegmentOptions options;
  options.sharp_angle_degrees = 100.0;
  const SegmentReport r = segment_surfaces(smooth, options);
  ASSERT_EQ(smooth.surfaces.size(), 1u);
  EXPECT_EQ(r.surfaces_split, 0u);
  EXPECT_EQ(smooth.surfaces[0].name, "g0");
  EXPECT_EQ(smooth.surfaces[0].provenance.kind, SourceKind::ObjGroup);
  EXPECT_EQ(smooth.surfaces[0].mesh.triangles, prism.triangles);
}

TEST(MeshSegment, IdsAndPartRangesStayConsistent) {
  Model model = one_part_model({box_soup(Vec3(0, 0, 0), Vec3(1, 1, 1)), cylinder_soup(1.0, 2.0, 24)}, "a");
  Model second = one_part_model({box_soup(Vec3(5, 0, 0), Vec3(6, 1, 1))}, "b");
  TriangleMesh flat;
  add_soup_quad(flat, Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0));
  second.surfaces.push_back(second.surfaces[0]);
  second.surfaces[1].name = "flat";
  second.surfaces[1].mesh = flat;
  second.parts[0].surface_count = 2;
  append_model(model, second);
  ASSERT_EQ(model.surfaces.size(), 4u);

  const std::size_t triangles_before = triangle_count(model);
  const SegmentReport r = segment_surfaces(model);
  // a: box 6 + cylinder 3; b: box 6 + the flat quad kept whole.
  ASSERT_EQ(model.surfaces.size(), 16u);
  EXPECT_EQ(triangle_count(model), triangles_before);
  EXPECT_EQ(model.parts[0].first_surface, 0u);
  EXPECT_EQ(model.parts[0].surface_count, 9u);
  EXPECT_EQ(model.parts[1].first_surface, 9u);
  EXPECT_EQ(model.parts[1].surface_count, 7u);
  ASSERT_EQ(r.surfaces.size(), 4u);
  const std::uint32_t firsts[] = {0, 6, 9, 15}, counts[] = {6, 3, 6, 1};
  for (SurfaceId s = 0; s < 4; ++s) {
    EXPECT_EQ(r.surfaces[s].input, s);
    EXPECT_EQ(r.surfaces[s].first, firsts[s]);
    EXPECT_EQ(r.surfaces[s].count, counts[s]);
  }
  for (SurfaceId s = 0; s < 15; ++s) {
    const Surface& patch = model.surfaces[s];
    const SurfaceId parent = s < 6 ? 0 : s < 9 ? 1 : 2;
    EXPECT_EQ(patch.provenance.parent, parent);
    EXPECT_EQ(patch.part, s < 9 ? 0u : 1u);
  }
  EXPECT_EQ(model.surfaces[15].name, "flat");
  EXPECT_EQ(model.surfaces[15].provenance.parent, kInvalidId);
  EXPECT_EQ(model.surfaces[10].name, "g0/patch-1");
  EXPECT_EQ(model.surfaces[7].name, "g1/patch-1");
  EXPECT_EQ(model.instances.size(), 2u);
}

TEST(MeshSegment, DeterministicAndIndependentOfRepair) {
  TriangleMesh m = cylinder_soup(3.0, 4.0, 48);
  for (std::size_t t = 0; t < m.triangles.size(); t += 5) flip(m, t);  // a soup with mixed windings
  Model a = one_part_model({m});
  Model b = a;
  segment_surfaces(a);
  segment_surfaces(b);
  ASSERT_EQ(a.surfaces.size(), 3u);
  ASSERT_EQ(b.surfaces.size(), 3u);
  for (std::size_t s = 0; s < 3; ++s) {
    EXPECT_EQ(a.surfaces[s].name, b.surfaces[s].name);
    EXPECT_EQ(a.surfaces[s].mesh.triangles, b.surfaces[s].mesh.triangles);
    EXPECT_EQ(a.surfaces[s].mesh.vertices, b.surfaces[s].mesh.vertices);
  }
  // Repair first: same patches (windings aside).
  Model c = one_part_model({m});
  repair_meshes(c);
  segment_surfaces(c);
  ASSERT_EQ(c.surfaces.size(), 3u);
  for (std::size_t s = 0; s < 3; ++s) EXPECT_EQ(triangle_sets(c.surfaces[s].mesh), triangle_sets(a.surfaces[s].mesh));
}

TEST(MeshSegment, DegenerateAndRepeatedTrianglesJoinANeighbour) {
  TriangleMesh box = box_soup(Vec3(0, 0, 0), Vec3(1, 1, 1));
  const Corners c0 = corners(box, 0), c11 = corners(box, 11);
  add_soup_triangle(box, c11[0], c11[1], c11[2]);  // repeat of the last triangle (+z face, patch 5)
  add_soup_triangle(box, c0[0], c0[0], c0[1]);     // degenerate at the -x face's corners (patch 0)
  Model model = one_part_model({box});
  segment_surfaces(model);
  ASSERT_EQ(model.surfaces.size(), 6u);
  EXPECT_EQ(model.surfaces[5].mesh.triangles.size(), 3u);
  EXPECT_EQ(model.surfaces[0].mesh.triangles.size(), 3u);
  EXPECT_EQ(triangle_count(model), 14u);
}

TEST(MeshSegment, PlanarRegionGrowingSplitsAShallowFold) {
  // Two flat 4x2 strips meeting at a 30 degree fold: not sharp at 60, but two planes.
  TriangleMesh m;
  const double c = std::cos(std::numbers::pi / 6), s = std::sin(std::numbers::pi / 6);
  auto at = [&](int i, int j) {
    return i <= 4 ? Vec3(i, j, 0) : Vec3(4 + (i - 4) * c, j, (i - 4) * s);
  };
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 8; ++i) add_soup_quad(m, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
  Model plain = one_part_model({m});
  segment_surfaces(plain);
  EXPECT_EQ(plain.surfaces.size(), 1u);

  Model planar = one_part_model({m});
  SegmentOptions options;
  options.planar = true;
  segment_surfaces(planar, options);
  ASSERT_EQ(planar.surfaces.size(), 2u);
  EXPECT_EQ(distinct_normals(planar.surfaces[0].mesh), 1u);
  EXPECT_EQ(distinct_normals(planar.surfaces[1].mesh), 1u);
  EXPECT_EQ(planar.surfaces[0].mesh.triangles.size(), 16u);
}

}  // namespace
}  // namespace cadclash

namespace cadclash {
namespace {

using namespace cadclash::test;

std::size_t total_triangles(const Model& m) {
  std::size_t n = 0;
  for (const Surface& s : m.surfaces) n += s.mesh.triangles.size();
  return n;
}

// A triangle-soup cube with one zero-area triangle (three distinct corners on one edge): repair
// removes it, decided exactly, so segmentation finds the cube's 6 faces and nothing more; left in,
// it would be a patch of its own.
TEST(MeshRepairSegment, CollinearTriangleNeverBecomesASurface) {
  TriangleMesh box = box_soup(Vec3(0, 0, 0), Vec3(2, 3, 4));
  add_soup_triangle(box, Vec3(0, 0, 0), Vec3(0.5, 0, 0), Vec3(2, 0, 0));
  Model model = one_part_model({box});
  const MeshRepairReport rep = repair_meshes(model);
  EXPECT_EQ(rep.total.collinear_faces, 1u);
  EXPECT_EQ(rep.total.degenerate_faces, 0u);
  segment_surfaces(model);
  EXPECT_EQ(model.surfaces.size(), 6u);
  EXPECT_EQ(total_triangles(model), 12u);
}

// A needle is not flat: 1e-12 off the line it covers area, and repair keeps it (no epsilon decides).
TEST(MeshRepairSegment, NeedleIsKept) {
  TriangleMesh box = box_soup(Vec3(0, 0, 0), Vec3(2, 3, 4));
  TriangleMesh needle;
  add_soup_triangle(needle, Vec3(0, 0, 10), Vec3(0.5, 1e-12, 10), Vec3(2, 0, 10));
  Model model = one_part_model({box, needle});
  const MeshRepairReport rep = repair_meshes(model);
  EXPECT_EQ(rep.total.collinear_faces, 0u);
  EXPECT_EQ(model.surfaces[1].mesh.triangles.size(), 1u);
  // Exactly collinear with coordinates far from the origin too (1e6 mm): still removed.
  TriangleMesh far;
  add_soup_triangle(far, Vec3(1e6, 1e6, 1e6), Vec3(1e6 + 0.5, 1e6, 1e6), Vec3(1e6 + 1, 1e6, 1e6));
  Model m2 = one_part_model({box, far});
  EXPECT_EQ(repair_meshes(m2).total.collinear_faces, 1u);
  EXPECT_TRUE(m2.surfaces[1].mesh.triangles.empty());
}

}  // namespace
}  // namespace cadclash
