// Repair and segmentation of files read by import_file: the real STL meshes occt-misc ships
// (data/external, see scripts/setup.sh) and a broken OBJ with groups written here (data/repair).
#include "cadclash/import.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <set>

namespace cadclash {
namespace {

// Each OBJ group is one surface; repair counts land on the group they were built into.
TEST(MeshRepairObj, FlippedBoxGroupsKeepTheirCounts) {
  ImportResult imported = import_file(std::string(CADCLASH_DATA_DIR) + "/repair/flipped_box.obj");
  ASSERT_FALSE(has_error(imported.diagnostics));
  Model& model = imported.model;
  ASSERT_EQ(model.surfaces.size(), 6u);
  ASSERT_EQ(triangle_count(model), 13u);
  const MeshRepairReport r = repair_meshes(model);
  ASSERT_TRUE(r.diagnostics.empty());
  ASSERT_EQ(r.per_surface.size(), 6u);
  for (const SurfaceRepairStats& s : r.per_surface) {
    const std::string& name = model.surfaces[s.surface].name;
    EXPECT_EQ(s.flipped_faces, name == "top" ? 2u : 0u) << name;
    EXPECT_EQ(s.duplicate_faces, name == "front" ? 1u : 0u) << name;
    EXPECT_EQ(s.degenerate_faces, 0u) << name;
    EXPECT_EQ(s.triangles_after, 2u) << name;
  }
  std::set<std::string> names;
  double volume6 = 0.0;
  for (const Surface& s : model.surfaces) {
    names.insert(s.name);
    EXPECT_EQ(s.provenance.kind, SourceKind::ObjGroup);
    for (const auto& t : s.mesh.triangles)
      volume6 += s.mesh.vertices[t[0]].dot(s.mesh.vertices[t[1]].cross(s.mesh.vertices[t[2]]));
  }
  EXPECT_EQ(names, (std::set<std::string>{"bottom", "top", "front", "back", "left", "right"}));
  EXPECT_DOUBLE_EQ(volume6, 6.0);  // closed unit box, outward
}

class RealStl : public ::testing::TestWithParam<const char*> {};

TEST_P(RealStl, RepairsAndSegmentsKeepingEveryTriangle) {
  const std::string path = std::string(CADCLASH_DATA_DIR) + "/external/" + GetParam();
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing: run scripts/setup.sh";
  ImportResult imported = import_file(path);
  ASSERT_FALSE(has_error(imported.diagnostics)) << format_diagnostic(imported.diagnostics.front());
  Model& model = imported.model;
  ASSERT_FALSE(model.surfaces.empty());
  const std::size_t surfaces_in = model.surfaces.size();
  const std::size_t triangles_in = triangle_count(model);
  ASSERT_GT(triangles_in, 0u);

  const MeshRepairReport repair = repair_meshes(model);
  EXPECT_TRUE(repair.diagnostics.empty()) << format_diagnostic(repair.diagnostics.front());
  ASSERT_EQ(repair.per_surface.size(), surfaces_in);
  ASSERT_EQ(model.surfaces.size(), surfaces_in);
  for (const SurfaceRepairStats& s : repair.per_surface) {
    // Without hole filling and component removal, triangles only go as degenerate, collinear or repeated.
    EXPECT_EQ(s.triangles_after, s.triangles_before - s.degenerate_faces - s.collinear_faces - s.duplicate_faces);
    EXPECT_EQ(s.hole_faces + s.filled_holes + s.removed_component_faces, 0u);
    EXPECT_EQ(model.surfaces[s.surface].mesh.triangles.size(), s.triangles_after);
    EXPECT_LE(s.vertices_after, s.vertices_before - s.merged_points - s.unused_points + s.duplicated_vertices);
  }
  const std::size_t triangles_repaired = triangle_count(model);
  EXPECT_EQ(triangles_repaired, triangles_in - repair.total.degenerate_faces - repair.total.collinear_faces -
                                    repair.total.duplicate_faces);

  const SegmentReport seg = segment_surfaces(model);
  EXPECT_TRUE(seg.diagnostics.empty()) << format_diagnostic(seg.diagnostics.front());
  EXPECT_EQ(triangle_count(model), triangles_repaired);
  ASSERT_EQ(seg.surfaces.size(), surfaces_in);
  EXPECT_EQ(model.surfaces.size(), surfaces_in - seg.surfaces_split + seg.patches);
  std::set<std::string> names;
  for (const Part& p : model.parts)
    for (SurfaceId s = p.first_surface; s < p.first_surface + p.surface_count; ++s) {
      const Surface& surface = model.surfaces[s];
      EXPECT_FALSE(surface.mesh.triangles.empty());
      EXPECT_TRUE(names.insert(p.name + "|" + surface.name).second) << surface.name;
      if (surface.provenance.kind == SourceKind::Segment) {
        EXPECT_LT(surface.provenance.parent, surfaces_in);
      }
    }
  // These are machined parts: many flat and cylindrical faces, so several patches each.
  EXPECT_GT(model.surfaces.size(), surfaces_in);
  std::cout << "[          ] " << GetParam() << ": " << triangles_in << " triangles, " << repair.total.merged_points
            << " merged points, " << repair.total.degenerate_faces << " degenerate, " << repair.total.duplicate_faces
            << " repeated, " << repair.total.flipped_faces << " flipped, " << repair.total.duplicated_vertices
            << " duplicated vertices; " << model.surfaces.size() << " patches\n";
}

INSTANTIATE_TEST_SUITE_P(OcctMisc, RealStl,
                         ::testing::Values("bearing.stl", "motor.stl", "head.stl", "propeller.stl", "TR12J_OCC.stl",
                                           "video_part.stl"),
                         [](const ::testing::TestParamInfo<const char*>& param) {
                           std::string name = param.param;
                           return name.substr(0, name.find('.'));
                         });

}  // namespace
}  // namespace cadclash
