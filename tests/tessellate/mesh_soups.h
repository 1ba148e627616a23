// Triangle soups with known structure for the mesh repair and segmentation tests.
#pragma once

#include "cadclash/tessellate.h"

#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

namespace cadclash::test {

using Tri = std::array<std::uint32_t, 3>;
using Corners = std::array<Vec3, 3>;

// Appends a triangle with three vertices of its own (an STL-style soup).
inline void add_soup_triangle(TriangleMesh& m, const Vec3& a, const Vec3& b, const Vec3& c) {
  const auto n = static_cast<std::uint32_t>(m.vertices.size());
  m.vertices.insert(m.vertices.end(), {a, b, c});
  m.triangles.push_back({n, n + 1, n + 2});
}

// Appends the quad a-b-c-d (counter-clockwise seen from outside) as two soup triangles.
inline void add_soup_quad(TriangleMesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  add_soup_triangle(m, a, b, c);
  add_soup_triangle(m, a, c, d);
}

// The 6 faces of the box [lo, hi] as quads, outward, in the order -x, +x, -y, +y, -z, +z.
inline std::vector<std::array<Vec3, 4>> box_quads(const Vec3& lo, const Vec3& hi) {
  auto p = [&](int x, int y, int z) { return Vec3(x ? hi.x() : lo.x(), y ? hi.y() : lo.y(), z ? hi.z() : lo.z()); };
  return {{p(0, 0, 0), p(0, 0, 1), p(0, 1, 1), p(0, 1, 0)}, {p(1, 0, 0), p(1, 1, 0), p(1, 1, 1), p(1, 0, 1)},
          {p(0, 0, 0), p(1, 0, 0), p(1, 0, 1), p(0, 0, 1)}, {p(0, 1, 0), p(0, 1, 1), p(1, 1, 1), p(1, 1, 0)},
          {p(0, 0, 0), p(0, 1, 0), p(1, 1, 0), p(1, 0, 0)}, {p(0, 0, 1), p(1, 0, 1), p(1, 1, 1), p(0, 1, 1)}};
}

// A box as one soup: 12 triangles, 36 vertices, outward.
inline TriangleMesh box_soup(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  for (const auto& q : box_quads(lo, hi)) add_soup_quad(m, q[0], q[1], q[2], q[3]);
  return m;
}

// A closed cylinder around z as one soup: `n` side quads, two caps as fans around their centres.
inline TriangleMesh cylinder_soup(double r, double h, int n) {
  TriangleMesh m;
  auto rim = [&](int k, double z) {
    const double a = 2.0 * std::numbers::pi * (k % n) / n;
    return Vec3(r * std::cos(a), r * std::sin(a), z);
  };
  for (int k = 0; k < n; ++k) add_soup_quad(m, rim(k, 0), rim(k + 1, 0), rim(k + 1, h), rim(k, h));
  for (int k = 0; k < n; ++k) add_soup_triangle(m, Vec3(0, 0, h), rim(k, h), rim(k + 1, h));
  for (int k = 0; k < n; ++k) add_soup_triangle(m, Vec3(0, 0, 0), rim(k + 1, 0), rim(k, 0));
  return m;
}

inline Corners corners(const TriangleMesh& m, std::size_t t) {
  return {m.vertices[m.triangles[t][0]], m.vertices[m.triangles[t][1]], m.vertices[m.triangles[t][2]]};
}

inline void flip(TriangleMesh& m, std::size_t t) { std::swap(m.triangles[t][1], m.triangles[t][2]); }

// A Model with one mesh part made of the given surfaces.
inline Model one_part_model(const std::vector<TriangleMesh>& surfaces, const std::string& part_name = "part") {
  Model model;
  Part part;
  part.name = part_name;
  part.source_file = part_name;
  part.source_file.append(".stl");  // append, not operator+: GCC 12 -Wrestrict false positive (PR 105329)
  part.first_surface = 0;
  part.surface_count = static_cast<std::uint32_t>(surfaces.size());
  model.parts.push_back(part);
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    Surface s;
    s.name = std::string("g").append(std::to_string(i));
    s.part = 0;
    s.provenance.kind = SourceKind::ObjGroup;
    s.provenance.source_file = part.source_file;
    s.provenance.face_index = static_cast<std::int32_t>(i);
    s.provenance.source_name = std::string("group_").append(std::to_string(i));
    s.provenance.step_id = 1000 + static_cast<std::int64_t>(i);
    s.has_triangles = true;
    s.mesh = surfaces[i];
    s.aabb = mesh_aabb(s.mesh);
    model.surfaces.push_back(std::move(s));
  }
  Instance inst;
  inst.path = std::string("/").append(part_name);
  inst.part = 0;
  model.instances.push_back(inst);
  return model;
}

// Directed edges of all triangles of a part, by exact corner coordinates.
using PointKey = std::array<double, 3>;
inline PointKey key(const Vec3& p) { return {p.x() + 0.0, p.y() + 0.0, p.z() + 0.0}; }

// True when every undirected edge of the part's triangles is used exactly twice, once each way:
// closed and consistently oriented.
inline bool closed_and_oriented(const Model& model, PartId pid) {
  std::map<std::pair<PointKey, PointKey>, int> directed;
  const Part& p = model.parts[pid];
  for (SurfaceId s = p.first_surface; s < p.first_surface + p.surface_count; ++s) {
    const TriangleMesh& m = model.surfaces[s].mesh;
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      const Corners c = corners(m, t);
      for (int i = 0; i < 3; ++i) ++directed[{key(c[i]), key(c[(i + 1) % 3])}];
    }
  }
  for (const auto& [e, n] : directed) {
    if (n != 1) return false;
    auto it = directed.find({e.second, e.first});
    if (it == directed.end() || it->second != 1) return false;
  }
  return !directed.empty();
}

// Six times the signed volume enclosed by a part's triangles.
inline double volume6(const Model& model, PartId pid) {
  double v = 0.0;
  const Part& p = model.parts[pid];
  for (SurfaceId s = p.first_surface; s < p.first_surface + p.surface_count; ++s) {
    const TriangleMesh& m = model.surfaces[s].mesh;
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      const Corners c = corners(m, t);
      v += c[0].dot(c[1].cross(c[2]));
    }
  }
  return v;
}

// The set of corner-point triples (unordered) of a mesh: what a triangle is, whatever its winding.
inline std::multiset<std::set<PointKey>> triangle_sets(const TriangleMesh& m) {
  std::multiset<std::set<PointKey>> out;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const Corners c = corners(m, t);
    out.insert({key(c[0]), key(c[1]), key(c[2])});
  }
  return out;
}

}  // namespace cadclash::test
