// Synthetic models for the narrow-phase tests: boxes, faceted cylinders, random triangle soups.
#pragma once

#include "cadclash/collide.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>

namespace cadclash::testing {

// Adds a part and returns its id; surfaces are appended to the model.
inline PartId add_part(Model& m, const std::string& name, std::vector<Surface> surfaces) {
  Part p;
  p.name = name;
  p.first_surface = static_cast<SurfaceId>(m.surfaces.size());
  p.surface_count = static_cast<std::uint32_t>(surfaces.size());
  const auto id = static_cast<PartId>(m.parts.size());
  for (Surface& s : surfaces) {
    s.part = id;
    s.has_triangles = true;
    s.aabb = mesh_aabb(s.mesh);
    m.surfaces.push_back(std::move(s));
  }
  m.parts.push_back(std::move(p));
  return id;
}

inline InstanceId add_instance(Model& m, const std::string& path, PartId part, const Pose& pose = Pose::Identity()) {
  m.instances.push_back({path, part, pose});
  return static_cast<InstanceId>(m.instances.size() - 1);
}

inline Pose translation(double x, double y, double z) {
  Pose p = Pose::Identity();
  p.translation() = Vec3(x, y, z);
  return p;
}

// A quad split into n x n cells, two triangles each, counter-clockwise seen along `o + u x v`.
inline Surface grid_surface(const std::string& name, const Vec3& o, const Vec3& u, const Vec3& v, int n) {
  Surface s;
  s.name = name;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) s.mesh.vertices.push_back(o + u * (double(i) / n) + v * (double(j) / n));
  auto id = [n](int i, int j) { return static_cast<std::uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      s.mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return s;
}

// A closed box [lo, hi] with six face surfaces, outward orientation.
inline std::vector<Surface> box_surfaces(const Vec3& lo, const Vec3& hi, int n = 1) {
  const Vec3 d = hi - lo;
  const Vec3 ex(d.x(), 0, 0), ey(0, d.y(), 0), ez(0, 0, d.z());
  return {grid_surface("x-", lo, ez, ey, n), grid_surface("x+", lo + ex, ey, ez, n),
          grid_surface("y-", lo, ex, ez, n), grid_surface("y+", lo + ey, ez, ex, n),
          grid_surface("z-", lo, ey, ex, n), grid_surface("z+", lo + ez, ex, ey, n)};
}

// The lateral surface of a cylinder around z (radius r, z in [z0, z1]) with `segments` chords starting at
// angle `phase`; vertices lie on the exact circle, so the deflection is the sagitta r (1 - cos(pi/segments)).
inline Surface cylinder_surface(const std::string& name, double r, double z0, double z1, int segments,
                                double phase, bool outward = true) {
  Surface s;
  s.name = name;
  for (int k = 0; k < segments; ++k) {
    const double a = phase + 2.0 * std::numbers::pi * k / segments;
    s.mesh.vertices.push_back(Vec3(r * std::cos(a), r * std::sin(a), z0));
    s.mesh.vertices.push_back(Vec3(r * std::cos(a), r * std::sin(a), z1));
  }
  for (int k = 0; k < segments; ++k) {
    const auto b0 = static_cast<std::uint32_t>(2 * k), t0 = b0 + 1;
    const auto b1 = static_cast<std::uint32_t>(2 * ((k + 1) % segments)), t1 = b1 + 1;
    if (outward) {
      s.mesh.triangles.push_back({b0, b1, t1});
      s.mesh.triangles.push_back({b0, t1, t0});
    } else {
      s.mesh.triangles.push_back({b0, t1, b1});
      s.mesh.triangles.push_back({b0, t0, t1});
    }
  }
  s.deflection = r * (1.0 - std::cos(std::numbers::pi / segments));
  return s;
}

// A random rigid pose: rotation from a random unit quaternion, translation in [-spread, spread]^3.
inline Pose random_pose(std::mt19937_64& rng, double spread) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(-spread, spread);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  Pose p = Pose::Identity();
  p.linear() = q.toRotationMatrix();
  p.translation() = Vec3(u(rng), u(rng), u(rng));
  return p;
}

// A part of `surfaces` random surfaces, each a small patch of `tris` triangles near a random centre
// in [-size, size]^3 (jittered grid so neighbours share vertices and edges).
inline std::vector<Surface> random_surfaces(std::mt19937_64& rng, int surfaces, int grid, double size) {
  std::uniform_real_distribution<double> u(-size, size);
  std::uniform_real_distribution<double> j(-0.1, 0.1);
  std::vector<Surface> out;
  for (int k = 0; k < surfaces; ++k) {
    const Vec3 c(u(rng), u(rng), u(rng));
    const Vec3 a = Vec3(u(rng), u(rng), u(rng)).normalized() * size * 0.5;
    const Vec3 b = Vec3(u(rng), u(rng), u(rng)).normalized() * size * 0.5;
    Surface s = grid_surface(std::string("r").append(std::to_string(k)), c, a, b, grid);
    for (Vec3& v : s.mesh.vertices) v += Vec3(j(rng), j(rng), j(rng)) * size * 0.1;
    out.push_back(std::move(s));
  }
  return out;
}

// Every counter equal except aabb_updates (a fresh scene's first check updates every instance's box;
// a scene followed along moves only some).
inline void expect_same_counters(const CollideCounters& x, const CollideCounters& y) {
  EXPECT_EQ(x.instance_pairs, y.instance_pairs);
  EXPECT_EQ(x.aabb_tests, y.aabb_tests);
  EXPECT_EQ(x.surfaces_a, y.surfaces_a);
  EXPECT_EQ(x.surfaces_b, y.surfaces_b);
  EXPECT_EQ(x.surface_pairs, y.surface_pairs);
  EXPECT_EQ(x.triangles_a, y.triangles_a);
  EXPECT_EQ(x.triangles_b, y.triangles_b);
  EXPECT_EQ(x.triangle_tests, y.triangle_tests);
  EXPECT_EQ(x.exact_fallbacks, y.exact_fallbacks);
  EXPECT_EQ(x.distance_tests, y.distance_tests);
  EXPECT_EQ(x.intersecting_pairs, y.intersecting_pairs);
  EXPECT_EQ(x.tessellated_surfaces, y.tessellated_surfaces);
  EXPECT_EQ(x.decided_mesh, y.decided_mesh);
  EXPECT_EQ(x.decided_mesh_exact, y.decided_mesh_exact);
  EXPECT_EQ(x.decided_analytic, y.decided_analytic);
  EXPECT_EQ(x.decided_refined, y.decided_refined);
  EXPECT_EQ(x.decided_exact, y.decided_exact);
  EXPECT_EQ(x.undecided, y.undecided);
  EXPECT_EQ(x.ambiguous_pairs, y.ambiguous_pairs);
  EXPECT_EQ(x.refined_surfaces, y.refined_surfaces);
  EXPECT_EQ(x.exact_queries, y.exact_queries);
  EXPECT_EQ(x.witness_queries, y.witness_queries);
  EXPECT_EQ(x.dismissed_pairs, y.dismissed_pairs);
}

// Every reported field equal (doubles compared exactly).
inline void expect_same_pairs(const Report& x, const Report& y, bool compare_triangles = true) {
  ASSERT_EQ(x.pairs.size(), y.pairs.size());
  for (std::size_t k = 0; k < x.pairs.size(); ++k) {
    const SurfacePairResult& a = x.pairs[k];
    const SurfacePairResult& b = y.pairs[k];
    SCOPED_TRACE("pair " + std::to_string(k));
    EXPECT_EQ(a.instance_a, b.instance_a);
    EXPECT_EQ(a.instance_b, b.instance_b);
    EXPECT_EQ(a.surface_a, b.surface_a);
    EXPECT_EQ(a.surface_b, b.surface_b);
    EXPECT_EQ(a.contact, b.contact);
    EXPECT_EQ(a.intersecting, b.intersecting);
    EXPECT_EQ(a.distance, b.distance);
    EXPECT_EQ(a.penetration, b.penetration);
    if (compare_triangles) {
      EXPECT_EQ(a.triangle_pairs, b.triangle_pairs);
    }
  }
}

}  // namespace cadclash::testing
