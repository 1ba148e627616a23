// Internal interface between the Model plumbing of mesh repair / segmentation (plain C++) and the
// one translation unit that instantiates CGAL (mesh_repair_cgal.cpp), so CGAL compiles only once.
#pragma once

#include "cadclash/tessellate.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace cadclash::detail {

using Tri = std::array<std::uint32_t, 3>;

// A cleaned triangle soup: points pairwise distinct, no triangle with a repeated corner, no two
// triangles on the same three points. tags[i] is the (part-local) surface of triangles[i].
struct TaggedSoup {
  std::vector<Vec3> points;
  std::vector<Tri> triangles;
  std::vector<std::uint32_t> tags;
};

// Per-tag counters filled by the CGAL stage.
struct TagCounts {
  std::uint32_t flipped_faces = 0;
  std::uint32_t stitched_edges = 0;
  std::uint32_t duplicated_vertices = 0;
  std::uint32_t removed_component_faces = 0;
  std::uint32_t filled_holes = 0;
  std::uint32_t hole_faces = 0;
};

struct MeshStageResult {
  bool ok = false;
  std::string error;                   // why the soup could not become a mesh (ok == false)
  std::vector<Vec3> points;
  std::vector<Tri> triangles;          // surviving input triangles in input order, then hole triangles
  std::vector<std::uint32_t> tags;
  std::vector<std::int64_t> origin;    // input triangle index, -1 for hole triangles
  std::vector<TagCounts> counts;       // indexed by tag
};

// Steps 3-5 of repair_meshes() on a cleaned soup. `tag_count` > every tag.
MeshStageResult repair_soup_cgal(const TaggedSoup& soup, std::uint32_t tag_count, const MeshRepairOptions& options);

// Patch id per triangle of a cleaned soup (ids are 0..n-1 in no particular order), from
// sharp_edges_segmentation on the oriented mesh, optionally split further by planar region growing.
// Returns false with `error` when the soup cannot become a mesh.
// True when the three points lie on one line, decided exactly (CGAL's filtered predicate).
bool collinear_exact(const Vec3& a, const Vec3& b, const Vec3& c);

bool segment_soup_cgal(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                       const SegmentOptions& options, std::vector<std::uint32_t>& patch, std::string& error);

}  // namespace cadclash::detail
