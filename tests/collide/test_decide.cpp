// The certified decision's pieces: the round-off bound against a long-double reference under large
// rigid motions, the triangles' interval and verdict, and the analytic lower bounds.
#include "decide.h"
#include "surface_bvh.h"
#include "cadclash/geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace cadclash {
namespace {

using detail::analytic_gap;
using detail::Interval;
using detail::mesh_interval;
using detail::pair_roundoff;
using detail::PairOutcome;
using detail::Verdict;
using detail::verdict;
using detail::build_surface_bvh;
using detail::point_mesh_distance;
using detail::point_near_mesh;
using detail::SurfaceBvh;

Pose random_pose(std::mt19937_64& rng, double offset) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vec3 axis(u(rng), u(rng), u(rng));
  axis.normalize();
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(3.0 * u(rng), axis).toRotationMatrix();
  p.translation() = Vec3(u(rng), u(rng), u(rng)) * offset;
  return p;
}

// A's triangle lies in its plane z = 0; B's small triangle is placed (by its pose) above A's interior
// at height h, so the exact distance of the placed triangles is B's lowest vertex height, computed
// here in long double from the stored doubles (R_a inverted, not transposed).
TEST(PairRoundoff, BoundsTheDistanceErrorUnderLargeRigidMotions) {
  std::mt19937_64 rng(7);
  const Vec3 a0(-50, -50, 0), a1(50, -50, 0), a2(0, 60, 0);
  const Vec3 b0(-1, -1, 0), b1(1, -1, 0.5), b2(0, 1.2, 0.25);
  const double mag_a = Vec3(50, 60, 0).norm(), mag_b = Vec3(1, 1.2, 0.5).norm();
  double worst_ratio = 0.0;
  for (double offset : {0.0, 1e3, 1e6, 1e9}) {
    for (int k = 0; k < 2000; ++k) {
      const Pose pa = random_pose(rng, offset);
      // Heights from well above the rounding of composing the poses at this offset to 0.1.
      std::uniform_real_distribution<double> hh(std::log10(std::max(1e-9, 1e-12 * offset)), -1.0);
      Pose rel = random_pose(rng, 0.0);
      rel.linear() = Eigen::AngleAxisd(0.3 * (k % 7), Vec3::UnitZ()).toRotationMatrix();
      rel.translation() = Vec3(0.1 * (k % 5), -0.2, std::pow(10.0, hh(rng)));
      const Pose pb = pa * rel;  // B's pose as a user's assembly would store it: rounded doubles
      const Pose t_ab = detail::relative_pose(pa, pb);  // as the query maps B into its frame
      const double got = triangle_distance(a0, a1, a2, t_ab * b0, t_ab * b1, t_ab * b2);
      // pose_a⁻¹·pose_b = (R_a⁻¹R_b, R_a⁻¹(t_b - t_a)): the difference of the stored translations is
      // exact in long double, and R_a⁻¹ of a near-rotation is well conditioned (a 4x4 inverse with a
      // 1e9 translation would itself be off by 1e-11).
      using Mat3L = Eigen::Matrix<long double, 3, 3>;
      using Vec3L = Eigen::Matrix<long double, 3, 1>;
      const Mat3L ra_inv = Mat3L(pa.linear().cast<long double>()).inverse();
      const Mat3L rel_r = ra_inv * pb.linear().cast<long double>();
      const Vec3L rel_t = ra_inv * (pb.translation().cast<long double>() - pa.translation().cast<long double>());
      long double ref = 1e300L;
      for (const Vec3& v : {b0, b1, b2}) ref = std::min(ref, (rel_r * v.cast<long double>() + rel_t)(2));
      ASSERT_GT(ref, 0.0L);
      const double r = pair_roundoff(pa, pb, mag_a, mag_b);
      const double err = static_cast<double>(std::fabs(static_cast<long double>(got) - ref));
      ASSERT_LE(err, r) << "offset " << offset << " case " << k;
      worst_ratio = std::max(worst_ratio, err / r);
    }
    // Useful, not only safe: for neighbours 1e6 mm from the origin, far below the smallest model
    // uncertainty (1e-7 mm).
    const Pose pa = random_pose(rng, offset);
    Pose pb = pa;
    pb.translation() += Vec3(3, 4, 5);
    if (offset <= 1e6) {
      EXPECT_LT(pair_roundoff(pa, pb, mag_a, mag_b), 1e-8) << "offset " << offset;
    }
  }
  std::printf("worst error / bound: %.3g\n", worst_ratio);
}

// It grows with the parts' magnitudes and with how far B lies from A, not with where the pair is:
// two instances 1e6 mm from the origin get the bound they get at the origin.
TEST(PairRoundoff, GrowsWithTheMagnitudesNotThePlacement) {
  const Pose id = Pose::Identity();
  Pose far = id;
  far.translation() = Vec3(1e6, 0, 0);
  Pose farther = far;
  farther.translation() = Vec3(2e6, 0, 0);
  EXPECT_EQ(pair_roundoff(far, far, 10, 10), pair_roundoff(id, id, 10, 10));
  EXPECT_EQ(pair_roundoff(far, farther, 10, 10), pair_roundoff(id, far, 10, 10));
  EXPECT_GT(pair_roundoff(id, far, 10, 10), pair_roundoff(id, id, 10, 10));
  EXPECT_GT(pair_roundoff(id, id, 1e3, 1e3), pair_roundoff(id, id, 10, 10));
  EXPECT_GT(pair_roundoff(id, id, 1, 1), 0.0);
}

TEST(MeshInterval, IntersectingDistantAndBeyondTheSearch) {
  PairOutcome o;
  o.intersecting = true;
  Interval d = mesh_interval(o, 0.1, 1.0);
  EXPECT_EQ(d.lo, 0.0);
  EXPECT_EQ(d.hi, 0.1);
  o = PairOutcome{};
  o.distance = 0.5;
  d = mesh_interval(o, 0.1, 1.0);
  EXPECT_DOUBLE_EQ(d.lo, 0.4);
  EXPECT_DOUBLE_EQ(d.hi, 0.6);
  o.distance = 0.05;
  EXPECT_EQ(mesh_interval(o, 0.1, 1.0).lo, 0.0);
  o.distance = std::numeric_limits<double>::infinity();
  d = mesh_interval(o, 0.1, 1.0);
  EXPECT_EQ(d.lo, 1.0);
  EXPECT_TRUE(std::isinf(d.hi));
}

TEST(Verdict, ThreeWays) {
  EXPECT_EQ(verdict({0.0, 1e-9}, 2e-7), Verdict::Contact);
  EXPECT_EQ(verdict({0.03, 0.2}, 2e-7), Verdict::Apart);
  EXPECT_EQ(verdict({0.0, 0.2}, 2e-7), Verdict::Ambiguous);
  EXPECT_EQ(verdict({2e-7, 2e-7}, 2e-7), Verdict::Contact);  // d* <= T touches
}

TriangleMesh one_triangle(Vec3 a, Vec3 b, Vec3 c) {
  TriangleMesh m;
  m.vertices = {a, b, c};
  m.triangles = {{0, 1, 2}};
  return m;
}

AnalyticSurface shape(SurfaceShape s, Vec3 origin, Vec3 axis, double radius) {
  AnalyticSurface a;
  a.shape = s;
  a.origin = origin;
  a.axis = axis;
  a.radius = radius;
  return a;
}

const Aabb kEverywhere(Vec3::Constant(-1e3), Vec3::Constant(1e3));

TEST(AnalyticGap, PlaneUsesSignedHeights) {
  const auto plane = shape(SurfaceShape::Plane, Vec3(0, 0, 1), Vec3::UnitZ(), 0);
  const auto above = one_triangle(Vec3(0, 0, 1.03), Vec3(1, 0, 1.05), Vec3(0, 1, 1.04));
  EXPECT_NEAR(*analytic_gap(plane, above, Pose::Identity(), kEverywhere, 1.0), 0.03, 1e-12);
  const auto below = one_triangle(Vec3(0, 0, 0.9), Vec3(1, 0, 0.95), Vec3(0, 1, 0.96));
  EXPECT_NEAR(*analytic_gap(plane, below, Pose::Identity(), kEverywhere, 1.0), 0.04, 1e-12);
  const auto crossing = one_triangle(Vec3(0, 0, 0.9), Vec3(1, 0, 1.05), Vec3(0, 1, 0.96));
  EXPECT_EQ(*analytic_gap(plane, crossing, Pose::Identity(), kEverywhere, 1.0), 0.0);
  // Mapped by a pose: the same triangle moved 1 up is 1 farther.
  Pose up = Pose::Identity();
  up.translation() = Vec3(0, 0, 0.5);
  EXPECT_NEAR(*analytic_gap(plane, above, up, kEverywhere, 1.0), 0.53, 1e-12);
  // Farther than the reach from the region: cannot matter, the reach is returned.
  const Aabb region(Vec3(100, 100, 0), Vec3(101, 101, 2));
  EXPECT_EQ(*analytic_gap(plane, crossing, Pose::Identity(), region, 1.0), 1.0);
}

TEST(AnalyticGap, CylinderInsideAndOutside) {
  const auto cyl = shape(SurfaceShape::Cylinder, Vec3(0, 0, 0), Vec3::UnitZ(), 5.0);
  // A bolt's facet 0.03 inside the hole: every vertex at radius 4.97.
  const double r = 4.97;
  const auto inside = one_triangle(Vec3(r, 0, 0), Vec3(r * std::cos(0.3), r * std::sin(0.3), 0), Vec3(r, 0, 3));
  EXPECT_NEAR(*analytic_gap(cyl, inside, Pose::Identity(), kEverywhere, 1.0), 0.03, 1e-12);
  // Outside: a flat triangle tangent-ish at distance 5.03 from the axis (its nearest point is interior
  // to an edge, not a vertex).
  const auto outside = one_triangle(Vec3(5.03, -1, -1), Vec3(5.03, 1, -1), Vec3(5.03, 0, 2));
  EXPECT_NEAR(*analytic_gap(cyl, outside, Pose::Identity(), kEverywhere, 1.0), 0.03, 1e-12);
  // A chord of the cylinder itself (vertices on it, middle inside): gap 0.
  const auto chord = one_triangle(Vec3(5, 0, 0), Vec3(0, 5, 0), Vec3(5, 0, 1));
  EXPECT_EQ(*analytic_gap(cyl, chord, Pose::Identity(), kEverywhere, 1.0), 0.0);
}

TEST(AnalyticGap, SphereAndUnsupportedShapes) {
  const auto sph = shape(SurfaceShape::Sphere, Vec3(1, 2, 3), Vec3::UnitZ(), 2.0);
  const auto outside = one_triangle(Vec3(1, 2, 5.1), Vec3(2, 2, 5.1), Vec3(1, 3, 5.1));
  EXPECT_NEAR(*analytic_gap(sph, outside, Pose::Identity(), kEverywhere, 1.0), 0.1, 1e-12);
  const auto inside = one_triangle(Vec3(1, 2, 4.5), Vec3(1.5, 2, 4.5), Vec3(1, 2.5, 4.5));
  const double rmax = Vec3(0.5, 0, 1.5).norm();
  EXPECT_NEAR(*analytic_gap(sph, inside, Pose::Identity(), kEverywhere, 1.0), 2.0 - rmax, 1e-12);
  EXPECT_FALSE(analytic_gap(shape(SurfaceShape::Torus, Vec3::Zero(), Vec3::UnitZ(), 3), outside,
                            Pose::Identity(), kEverywhere, 1.0));
  EXPECT_FALSE(analytic_gap(AnalyticSurface{}, outside, Pose::Identity(), kEverywhere, 1.0));
}

TEST(AnalyticPairGap, CoaxialCylindersParallelPlanesAndTilts) {
  using detail::analytic_pair_gap;
  const Aabb region(Vec3(-6, -6, 0), Vec3(6, 6, 10));
  const auto bore = shape(SurfaceShape::Cylinder, Vec3(0, 0, 0), Vec3::UnitZ(), 5.05);
  const auto rod = shape(SurfaceShape::Cylinder, Vec3(0, 0, -3), Vec3::UnitZ(), 5.0);
  EXPECT_NEAR(*analytic_pair_gap(bore, rod, region), 0.05, 1e-12);
  EXPECT_NEAR(*analytic_pair_gap(rod, bore, region), 0.05, 1e-12);
  // Tilted by 1e-9 rad: the bound shrinks by about the tilt times the region, never grows.
  auto tilted = rod;
  tilted.axis = Vec3(1e-9, 0, 1).normalized();
  const double g = *analytic_pair_gap(bore, tilted, region);
  EXPECT_LT(g, 0.05);
  EXPECT_GT(g, 0.05 - 1e-7);
  // Offset axes: a rod 0.05 off-centre touches the bore.
  auto shifted = rod;
  shifted.origin = Vec3(0.05, 0, 0);
  EXPECT_EQ(*analytic_pair_gap(bore, shifted, region), 0.0);
  // Parallel planes 0.03 apart, and tilted by 1e-6: the height changes by at most 1e-6 x the region.
  const auto p1 = shape(SurfaceShape::Plane, Vec3(0, 0, 1), Vec3::UnitZ(), 0);
  auto p2 = shape(SurfaceShape::Plane, Vec3(0, 0, 1.03), -Vec3::UnitZ(), 0);
  EXPECT_NEAR(*analytic_pair_gap(p1, p2, region), 0.03, 1e-12);
  p2.axis = Vec3(1e-6, 0, -1).normalized();
  const double gp = *analytic_pair_gap(p1, p2, region);
  EXPECT_LT(gp, 0.03);
  EXPECT_GT(gp, 0.03 - 2e-5);
  // A rod lying 0.02 above a plane, and a ball 0.1 above it.
  auto lying = shape(SurfaceShape::Cylinder, Vec3(0, 0, 6.02), Vec3::UnitX(), 5.0);
  EXPECT_NEAR(*analytic_pair_gap(p1, lying, region), 0.02, 1e-12);
  EXPECT_NEAR(*analytic_pair_gap(lying, p1, region), 0.02, 1e-12);
  const auto ball = shape(SurfaceShape::Sphere, Vec3(0, 0, 3.1), Vec3::UnitZ(), 2.0);
  EXPECT_NEAR(*analytic_pair_gap(p1, ball, region), 0.1, 1e-12);
  // Unsupported combinations give no certificate.
  EXPECT_FALSE(analytic_pair_gap(rod, ball, region));
  EXPECT_FALSE(analytic_pair_gap(shape(SurfaceShape::Torus, Vec3::Zero(), Vec3::UnitZ(), 3), p1, region));
}

// The witness step orders and filters vertices by their distance to the other face's triangles
// through its tree: the tree must give the brute-force minimum whenever that is within the reach,
// and +inf (never a smaller value) when no triangle comes within it.
TEST(PointMeshDistance, EqualsBruteForceWithinTheReach) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  TriangleMesh mesh;
  for (int i = 0; i < 300; ++i) {
    const Vec3 c(u(rng), u(rng), 0.1 * u(rng));
    const auto v = static_cast<std::uint32_t>(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), {c, c + Vec3(0.7, 0.1, 0.2), c + Vec3(0.2, 0.8, -0.1)});
    mesh.triangles.push_back({v, v + 1, v + 2});
  }
  const SurfaceBvh bvh = build_surface_bvh(mesh);
  int within = 0, beyond = 0;
  for (int k = 0; k < 400; ++k) {
    const Vec3 p(u(rng), u(rng), 0.5 * u(rng));
    double brute = std::numeric_limits<double>::infinity();
    for (const auto& t : mesh.triangles)
      brute = std::min(brute, triangle_distance(p, p, p, mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]));
    for (double reach : {0.05, 0.5, 3.0}) {
      const double d = point_mesh_distance(bvh, mesh, p, reach);
      if (brute <= reach) {
        EXPECT_EQ(d, brute) << k << ' ' << reach;
        ++within;
      } else {
        EXPECT_GT(d, reach) << k << ' ' << reach;
        ++beyond;
      }
    }
  }
  EXPECT_GT(within, 100);
  EXPECT_GT(beyond, 100);
  EXPECT_EQ(point_mesh_distance(SurfaceBvh{}, TriangleMesh{}, Vec3::Zero(), 1.0), std::numeric_limits<double>::infinity());
}

// point_near_mesh (the "inside a face" tests' question) answers what the brute-force minimum says,
// also when points come one after another near each other (its hints: the triangle found last per
// mesh) and alternate between two meshes, and when a hint's mesh is replaced by a smaller one.
TEST(PointNearMesh, AgreesWithTheBruteForceMinimum) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  auto soup = [&](int n) {
    TriangleMesh mesh;
    for (int i = 0; i < n; ++i) {
      const Vec3 c(u(rng), u(rng), 0.1 * u(rng));
      const auto v = static_cast<std::uint32_t>(mesh.vertices.size());
      mesh.vertices.insert(mesh.vertices.end(), {c, c + Vec3(3.0, 0.1, 0.2), c + Vec3(0.2, 2.5, -0.1)});
      mesh.triangles.push_back({v, v + 1, v + 2});
    }
    return mesh;
  };
  std::vector<TriangleMesh> meshes{soup(300), soup(40)};
  auto brute = [](const TriangleMesh& mesh, const Vec3& p) {
    double d = std::numeric_limits<double>::infinity();
    for (const auto& t : mesh.triangles)
      d = std::min(d, triangle_distance(p, p, p, mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]));
    return d;
  };
  int yes = 0, no = 0;
  for (int round = 0; round < 2; ++round) {
    std::vector<SurfaceBvh> trees;
    for (const TriangleMesh& mesh : meshes) trees.push_back(build_surface_bvh(mesh));
    for (int k = 0; k < 300; ++k) {
      // A walk: each point near the last, asked of both meshes in turn.
      const Vec3 start(u(rng), u(rng), 0.3 * u(rng));
      for (int step = 0; step < 6; ++step) {
        const Vec3 p = start + 0.05 * step * Vec3(1.0, 0.5, 0.1);
        for (std::size_t m = 0; m < meshes.size(); ++m)
          for (double reach : {0.02, 0.3}) {
            const bool near = point_near_mesh(trees[m], meshes[m], p, reach);
            EXPECT_EQ(near, brute(meshes[m], p) <= reach) << round << ' ' << k << ' ' << step << ' ' << m;
            ++(near ? yes : no);
          }
      }
    }
    // The same addresses, fewer triangles: stale hints must not be read past the end.
    meshes[0] = soup(5);
  }
  EXPECT_GT(yes, 500);
  EXPECT_GT(no, 500);
  EXPECT_FALSE(point_near_mesh(SurfaceBvh{}, TriangleMesh{}, Vec3::Zero(), 1.0));
}

// The outline's tree answers what a scan over every segment answers, near and far from the origin,
// for margins from far below the segments' length to far above, including points at the margin.
TEST(NearOutline, AgreesWithAScanOverEverySegment) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (double offset : {0.0, 1e3, 1e6}) {
    // A wavy grid patch with two holes: its outline is the rim and the holes' rims.
    TriangleMesh mesh;
    const int n = 24;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        mesh.vertices.push_back(Vec3(offset + i, offset - 0.5 * j, offset + 0.3 * std::sin(0.7 * i + 0.4 * j)));
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        if ((i >= 5 && i < 9 && j >= 5 && j < 8) || (i >= 14 && i < 20 && j >= 12 && j < 21)) continue;
        const auto v = static_cast<std::uint32_t>(j * (n + 1) + i);
        mesh.triangles.push_back({v, v + 1, v + n + 2});
        mesh.triangles.push_back({v, v + n + 2, v + n + 1});
      }
    const detail::Outline outline = detail::make_outline(mesh);
    ASSERT_EQ(outline.segments.size(), detail::boundary_edges(mesh).size());
    ASSERT_EQ(outline.segments.size(), std::size_t{4 * n + 2 * (4 + 3) + 2 * (6 + 9)});
    int near = 0, far = 0;
    for (int k = 0; k < 3000; ++k) {
      const Vec3 p = Vec3(offset, offset, offset) + Vec3(-2 + 28 * u(rng), -14 + 16 * u(rng), -1 + 2 * u(rng));
      double scan2 = std::numeric_limits<double>::infinity();
      for (const auto& [a, b] : outline.segments) scan2 = std::min(scan2, (closest_on_segment(p, a, b) - p).squaredNorm());
      for (double margin : {1e-3, 0.1, 0.7, 3.0, std::sqrt(scan2)}) {
        const bool want = scan2 <= margin * margin;
        EXPECT_EQ(detail::near_outline(outline, p, margin), want) << offset << ' ' << k << ' ' << margin;
        (want ? near : far) += 1;
      }
    }
    EXPECT_GT(near, 1000);
    EXPECT_GT(far, 1000);
    // Points walking round the rim (each answer may come from the segments next to the last one
    // found), interleaved with another outline's queries (a hint from the wrong outline).
    TriangleMesh other;
    for (int j = 0; j <= 3; ++j)
      for (int i = 0; i <= 3; ++i) other.vertices.push_back(Vec3(offset + i, offset - j, offset));
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        const auto v = static_cast<std::uint32_t>(j * 4 + i);
        other.triangles.push_back({v, v + 1, v + 5});
        other.triangles.push_back({v, v + 5, v + 4});
      }
    const detail::Outline small = detail::make_outline(other);
    for (int k = 0; k < 2000; ++k) {
      const double s = 4.0 * n * k / 2000.0;  // along the rim: top, right, bottom, left
      const Vec3 rim = s < n ? Vec3(s, 0, 0) : s < 2 * n ? Vec3(n, -0.5 * (s - n), 0) : s < 3 * n ? Vec3(3 * n - s, -0.5 * n, 0)
                                                                                         : Vec3(0, -0.5 * (4 * n - s), 0);
      for (const detail::Outline* o : {&outline, &small}) {
        const Vec3 p = Vec3(offset, offset, offset) + rim + Vec3(0.3 * u(rng) - 0.15, 0.3 * u(rng) - 0.15, 0.6 * u(rng) - 0.3);
        double scan2 = std::numeric_limits<double>::infinity();
        for (const auto& [a, b] : o->segments) scan2 = std::min(scan2, (closest_on_segment(p, a, b) - p).squaredNorm());
        for (double margin : {0.05, 0.3, std::sqrt(scan2)}) {
          const bool want = scan2 <= margin * margin;
          EXPECT_EQ(detail::near_outline(*o, p, margin), want) << offset << " rim " << k << ' ' << margin;
          (want ? near : far) += 1;
        }
      }
    }
  }
  EXPECT_FALSE(detail::near_outline(detail::Outline{}, Vec3::Zero(), 1e9));
}

// analytic_witness: of the vertices of A (mapped into B's frame, inside the region) within the limit
// of B's plane, the nearest four are tried, nearest first and in vertex order among equals; the first
// whose foot lies inside B (on its triangles, clear of their outline by twice B's deflection) gives
// the answer. A's frame is turned and moved 1e6 away from B's.
TEST(AnalyticWitness, NearestFourVerticesInVertexOrderFirstFootInsideWins) {
  Surface b;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j) b.mesh.vertices.push_back(Vec3(i, j, 0.0));
  for (std::uint32_t i = 0; i < 10; ++i)
    for (std::uint32_t j = 0; j < 10; ++j) {
      const std::uint32_t v = i * 11 + j;
      b.mesh.triangles.push_back({v, v + 11, v + 12});
      b.mesh.triangles.push_back({v, v + 12, v + 1});
    }
  AnalyticSurface plane;
  plane.shape = SurfaceShape::Plane;
  plane.origin = Vec3::Zero();
  plane.axis = Vec3::UnitZ();
  const detail::SurfaceBvh bvh = detail::build_surface_bvh(b.mesh);
  const detail::Outline outline = detail::make_outline(b.mesh);
  const double delta = 0.001;
  Pose to_b = Pose::Identity();
  to_b.rotate(Eigen::AngleAxisd(0.8, Vec3(1, -2, 0.5).normalized()));
  to_b.pretranslate(Vec3(-1e6, 2e6, 5e5));
  const Pose to_a = to_b.inverse();
  const Aabb region(Vec3(-1, -1, -1), Vec3(11, 11, 1));
  // Points given in B's frame; A holds them mapped back. Near the edge x = 0: a foot on the outline.
  auto witness = [&](const std::vector<Vec3>& in_b, bool moved = true) {
    TriangleMesh a;
    for (const Vec3& p : in_b) a.vertices.push_back(moved ? to_a * p : p);
    return detail::analytic_witness(plane, b.mesh, bvh, outline, delta, a, moved ? to_b : Pose::Identity(), region,
                                    1.0, 1e-9);
  };
  // The interior vertex at 0.1 beats the farther one; the nearer vertex on the edge does not count.
  std::optional<double> g = witness({{5, 5, 0.3}, {0.0005, 5, 0.05}, {3, 3, -0.1}, {20, 5, 0.01}});
  ASSERT_TRUE(g.has_value());
  EXPECT_NEAR(*g, 0.1, 1e-8);
  // Four nearer vertices on the edge use up the trials: the interior one is never tried.
  EXPECT_FALSE(witness({{0.0005, 1, 0.01}, {0.0005, 2, 0.02}, {0.0005, 3, 0.03}, {0.0005, 4, 0.04}, {5, 5, 0.05}}));
  // Exact ties (no mapping) keep vertex order: of two vertices at 0.04, the one listed first is tried.
  const Vec3 e1(0.0005, 1, 0.01), e2(0.0005, 2, 0.02), e3(0.0005, 3, 0.03), e4(0.0005, 4, 0.04), in(5, 5, 0.04);
  g = witness({e1, e2, e3, in, e4}, false);
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(*g, 0.04);
  EXPECT_FALSE(witness({e1, e2, e3, e4, in}, false));
  EXPECT_FALSE(witness({e4, in, e1, e2, e3}, false));
  EXPECT_TRUE(witness({in, e4, e1, e2, e3}, false));
  // Outside the region or beyond the limit: no candidate.
  EXPECT_FALSE(witness({{5, 5, 1.5}, {12, 5, 0.01}}));
}

}  // namespace
}  // namespace cadclash
