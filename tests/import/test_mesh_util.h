// Helpers shared by the mesh import and export tests.
#pragma once

#include "cadclash/import.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

namespace cadclash::test {

inline std::string mesh_data(const std::string& name) { return std::string(CADCLASH_DATA_DIR) + "/mesh/" + name; }
inline std::string bad_data(const std::string& name) { return std::string(CADCLASH_DATA_DIR) + "/bad/" + name; }
inline std::string external_data(const std::string& name) { return std::string(CADCLASH_DATA_DIR) + "/external/" + name; }

// Signed area of a triangle projected on the xy plane (positive when counter-clockwise seen from +z).
inline double signed_area_xy(const TriangleMesh& m, const std::array<std::uint32_t, 3>& t) {
  const Vec3 a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
  return 0.5 * ((b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x()));
}

// Total unsigned 3D area.
inline double area(const TriangleMesh& m) {
  double sum = 0;
  for (const auto& t : m.triangles)
    sum += 0.5 * (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]).norm();
  return sum;
}

inline const Surface* find_surface(const Model& m, const std::string& name) {
  const auto it = std::find_if(m.surfaces.begin(), m.surfaces.end(), [&](const Surface& s) { return s.name == name; });
  return it == m.surfaces.end() ? nullptr : &*it;
}

// All diagnostics formatted, one per line, for failure messages and content checks.
inline std::string all_messages(const ImportResult& r) {
  std::string out;
  for (const Diagnostic& d : r.diagnostics) out += format_diagnostic(d) + "\n";
  return out;
}

// True if some diagnostic of the given severity is at `line` and its message contains `text`.
inline bool has_diagnostic(const ImportResult& r, Severity severity, std::int64_t line, const std::string& text) {
  return std::any_of(r.diagnostics.begin(), r.diagnostics.end(), [&](const Diagnostic& d) {
    return d.severity == severity && d.line == line && d.message.find(text) != std::string::npos;
  });
}

// Checks the structure every model must have: contiguous surfaces per part, valid indices.
inline void expect_well_formed(const Model& m) {
  SurfaceId next = 0;
  for (PartId p = 0; p < m.parts.size(); ++p) {
    EXPECT_EQ(m.parts[p].first_surface, next);
    next += m.parts[p].surface_count;
    for (SurfaceId s = m.parts[p].first_surface; s < next; ++s) EXPECT_EQ(m.surfaces[s].part, p);
  }
  EXPECT_EQ(next, m.surfaces.size());
  for (const Surface& s : m.surfaces) {
    EXPECT_TRUE(s.has_triangles);
    for (const auto& t : s.mesh.triangles)
      for (std::uint32_t v : t) ASSERT_LT(v, s.mesh.vertices.size());
    for (const Vec3& v : s.mesh.vertices) EXPECT_TRUE(v.allFinite());
  }
  for (const Instance& i : m.instances) EXPECT_LT(i.part, m.parts.size());
}

}  // namespace cadclash::test
