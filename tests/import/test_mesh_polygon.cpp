// Polygon triangulation: every polygon kind the readers meet, checked by area and orientation.
#include "mesh_polygon.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <numeric>

namespace cadclash::detail {
namespace {

double shoelace(const std::vector<Vec3>& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) a += p[i].x() * p[(i + 1) % p.size()].y() - p[(i + 1) % p.size()].x() * p[i].y();
  return 0.5 * a;
}

// Triangulates `p` (xy plane, counter-clockwise) and checks: n-2 triangles, all counter-clockwise,
// total area = polygon area, every triangle made of corners.
void check_polygon(const std::vector<Vec3>& p) {
  std::vector<std::uint32_t> corners(p.size());
  std::iota(corners.begin(), corners.end(), 0u);
  std::vector<std::array<std::uint32_t, 3>> tris;
  EXPECT_TRUE(triangulate_polygon(p, corners, tris));
  ASSERT_EQ(tris.size(), p.size() - 2);
  double sum = 0;
  for (const auto& t : tris) {
    const Vec3 a = p[t[0]], b = p[t[1]], c = p[t[2]];
    const double s = 0.5 * ((b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x()));
    EXPECT_GT(s, 0.0) << "triangle " << t[0] << ' ' << t[1] << ' ' << t[2] << " is flipped or flat";
    sum += s;
  }
  EXPECT_NEAR(sum, shoelace(p), 1e-12 * std::abs(shoelace(p)));
}

TEST(MeshPolygon, TriangleAndConvexFan) {
  check_polygon({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  check_polygon({{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}});
  std::vector<Vec3> circle;
  for (int i = 0; i < 32; ++i) {
    const double t = 2 * std::numbers::pi * i / 32;
    circle.emplace_back(std::cos(t), std::sin(t), 0);
  }
  check_polygon(circle);
}

TEST(MeshPolygon, ConcaveLShape) { check_polygon({{0, 0, 0}, {3, 0, 0}, {3, 1, 0}, {1, 1, 0}, {1, 3, 0}, {0, 3, 0}}); }

TEST(MeshPolygon, ConcaveCombAndStar) {
  std::vector<Vec3> comb{{0, 0, 0}, {10, 0, 0}, {10, 5, 0}};
  for (int k = 9; k >= 0; --k) {  // ten teeth along the top, walked right to left
    comb.emplace_back(k + 0.5, 1, 0);
    comb.emplace_back(k, 5, 0);
  }
  check_polygon(comb);
  std::vector<Vec3> star;
  for (int i = 0; i < 10; ++i) {
    const double t = 2 * std::numbers::pi * i / 10, r = i % 2 == 0 ? 3.0 : 1.0;
    star.emplace_back(r * std::cos(t), r * std::sin(t), 0);
  }
  check_polygon(star);
}

TEST(MeshPolygon, CollinearCornersMakeNoFlatTriangles) {
  check_polygon({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}});
}

TEST(MeshPolygon, KeepsOrientationInAnyPlane) {
  // The L-shape tilted into 3D and seen from below: triangles must keep the polygon's normal.
  std::vector<Vec3> p{{0, 0, 0}, {3, 0, 0}, {3, 1, 0}, {1, 1, 0}, {1, 3, 0}, {0, 3, 0}};
  const Eigen::Matrix3d r = Eigen::AngleAxisd(2.0, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  for (Vec3& v : p) v = r * v;
  const Vec3 normal = r * Vec3::UnitZ();
  std::vector<std::uint32_t> corners{0, 1, 2, 3, 4, 5};
  std::vector<std::array<std::uint32_t, 3>> tris;
  EXPECT_TRUE(triangulate_polygon(p, corners, tris));
  double sum = 0;
  for (const auto& t : tris) {
    const Vec3 n = (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]);
    EXPECT_GT(n.dot(normal), 0.0);
    sum += 0.5 * n.norm();
  }
  EXPECT_NEAR(sum, 5.0, 1e-12);
}

TEST(MeshPolygon, DegeneratePolygonStillCovered) {
  std::vector<Vec3> p{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  std::vector<std::uint32_t> corners{0, 1, 2, 3};
  std::vector<std::array<std::uint32_t, 3>> tris;
  EXPECT_FALSE(triangulate_polygon(p, corners, tris));
  EXPECT_EQ(tris.size(), 2u);
}

}  // namespace
}  // namespace cadclash::detail
