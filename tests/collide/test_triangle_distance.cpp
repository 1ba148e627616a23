// triangle_distance and triangles_within against an independent long-double reference (golden
// section over each edge pair, Ericson's closest point for each vertex–face pair, the exact oracle
// for 0), a sampled upper bound, known configurations, symmetry and rigid-motion invariance.
#include "test_triangle_cases.h"
#include "cadclash/geometry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace cadclash {
namespace {

using test::Family;
using test::Tri;
using test::TriPair;

#ifdef NDEBUG
constexpr int kPairsPerFamily = 4000;
#else
constexpr int kPairsPerFamily = 400;
#endif

using LD = long double;
struct L3 {
  LD x, y, z;
};
L3 operator-(L3 a, L3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
L3 operator+(L3 a, L3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
L3 operator*(LD s, L3 a) { return {s * a.x, s * a.y, s * a.z}; }
LD dot(L3 a, L3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
LD len(L3 a) { return std::sqrt(dot(a, a)); }

LD ref_point_segment(L3 p, L3 a, L3 b) {
  const L3 d = b - a;
  const LD dd = dot(d, d);
  LD t = dd > 0 ? dot(p - a, d) / dd : 0;
  t = std::clamp<LD>(t, 0, 1);
  return len(p - (a + t * d));
}

// min over s of dist(P(s), segment q): convex in s, so golden-section search converges.
LD ref_segment_segment(L3 p0, L3 p1, L3 q0, L3 q1) {
  auto f = [&](LD s) { return ref_point_segment(p0 + s * (p1 - p0), q0, q1); };
  LD lo = 0, hi = 1;
  const LD g = (std::sqrt(LD(5)) - 1) / 2;
  for (int it = 0; it < 120; ++it) {
    const LD m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo);
    if (f(m1) <= f(m2)) hi = m2;
    else lo = m1;
  }
  return std::min({f(lo), f(hi), f(0), f(1)});
}

// Ericson, Real-Time Collision Detection 5.1.5: closest point of triangle abc to p.
LD ref_point_triangle(L3 p, L3 a, L3 b, L3 c) {
  const L3 ab = b - a, ac = c - a, ap = p - a;
  const LD d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return len(p - a);
  const L3 bp = p - b;
  const LD d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return len(p - b);
  const LD vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return len(p - (a + (d1 / (d1 - d3)) * ab));
  const L3 cp = p - c;
  const LD d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return len(p - c);
  const LD vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return len(p - (a + (d2 / (d2 - d6)) * ac));
  const LD va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return len(p - (b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b)));
  const LD den = va + vb + vc;
  if (!(den > 0)) return std::numeric_limits<LD>::infinity();  // degenerate: edges decide
  return len(p - (a + (vb / den) * ab + (vc / den) * ac));
}

// Reference distance, coordinates taken relative to a0 (exact for nearby doubles).
double reference_distance(const TriPair& p) {
  if (test::oracle_intersect(p.a, p.b)) return 0.0;
  const Vec3 o = p.a[0];
  L3 A[3], B[3];
  for (int i = 0; i < 3; ++i) {
    A[i] = {LD(p.a[i].x()) - o.x(), LD(p.a[i].y()) - o.y(), LD(p.a[i].z()) - o.z()};
    B[i] = {LD(p.b[i].x()) - o.x(), LD(p.b[i].y()) - o.y(), LD(p.b[i].z()) - o.z()};
  }
  LD best = std::numeric_limits<LD>::infinity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      best = std::min(best, ref_segment_segment(A[i], A[(i + 1) % 3], B[j], B[(j + 1) % 3]));
  for (int i = 0; i < 3; ++i) {
    best = std::min(best, ref_point_triangle(A[i], B[0], B[1], B[2]));
    best = std::min(best, ref_point_triangle(B[i], A[0], A[1], A[2]));
  }
  return static_cast<double>(best);
}

// The scale the double computation's error is relative to: the extent of both triangles around a0.
double extent(const TriPair& p) {
  double e = 0;
  for (const Tri* t : {&p.a, &p.b})
    for (const Vec3& v : *t) e = std::max(e, (v - p.a[0]).cwiseAbs().maxCoeff());
  return e;
}

double dist(const Tri& a, const Tri& b) { return triangle_distance(a[0], a[1], a[2], b[0], b[1], b[2]); }

class DistanceFamilies : public ::testing::TestWithParam<Family> {};

TEST_P(DistanceFamilies, MatchesReferenceAndIsZeroIffIntersecting) {
  const Family f = GetParam();
  test::Rng rng(77 + static_cast<std::uint64_t>(f));
  int failures = 0, zero_mismatch = 0, asymmetric = 0, positive = 0;
  double worst = 0;
  for (int i = 0; i < kPairsPerFamily; ++i) {
    const TriPair p = test::make_case(f, rng);
    const double d = dist(p.a, p.b);
    const double ref = reference_distance(p);
    const double tol = 1e-12 * extent(p);
    positive += d > 0;
    if ((d == 0) != test::oracle_intersect(p.a, p.b)) ++zero_mismatch;
    const double err = std::abs(d - ref);
    worst = std::max(worst, err / std::max(extent(p), 1e-300));
    if (!(err <= tol) && ++failures <= 5)
      ADD_FAILURE() << test::family_name(f) << " pair " << i << ": distance " << d << " reference " << ref;
    // Symmetric up to rounding (the computation is relative to the first triangle's first vertex).
    if (!(std::abs(dist(p.b, p.a) - d) <= tol)) ++asymmetric;
  }
  EXPECT_EQ(failures, 0);
  EXPECT_EQ(zero_mismatch, 0);
  EXPECT_EQ(asymmetric, 0);
  EXPECT_GT(positive, 0);
  std::printf("[ family   ] %-15s worst |d - ref| / extent = %.2e\n",
              std::string(test::family_name(f)).c_str(), worst);
}

std::string family_test_name(const ::testing::TestParamInfo<Family>& p) {
  return std::string(test::family_name(p.param));
}

INSTANTIATE_TEST_SUITE_P(Families, DistanceFamilies,
                         ::testing::Values(Family::RandomCube, Family::RandomNear, Family::CoplanarGrid,
                                           Family::SharedFeature, Family::TouchingGrid,
                                           Family::FarOffset, Family::Sliver, Family::UlpPerturbed,
                                           Family::Degenerate, Family::RigidMotion),
                         family_test_name);

// point_triangle_distance is triangle_distance with a degenerate first triangle, to the last bit,
// on every family's B and on points spread from B's vertices, edges and interior outwards; on the
// triangle (where triangle_distance says 0) it is within rounding of 0.
TEST(PointTriangleDistance, IsTriangleDistanceOfAPointToTheLastBit) {
  test::Rng rng(31);
  int compared = 0, on_triangle = 0, mismatches = 0;
  for (int f = 0; f < static_cast<int>(Family::kCount); ++f)
    for (int i = 0; i < kPairsPerFamily / 8; ++i) {
      const TriPair c = test::make_case(static_cast<Family>(f), rng);
      const Tri& b = c.b;
      const double size = std::max({(b[1] - b[0]).norm(), (b[2] - b[0]).norm(), 1e-300});
      // A point of B (barycentric) moved off it by a random amount, or a vertex of A.
      const double w0 = rng.uniform(), w1 = rng.uniform() * (1 - w0);
      Vec3 p = w0 * b[0] + w1 * b[1] + (1 - w0 - w1) * b[2];
      switch (rng.integer(0, 3)) {
        case 0: break;                                                   // on (or rounded off) B
        case 1: p += rng.vec(-1, 1) * size * std::pow(10.0, -rng.integer(0, 12)); break;
        case 2: p += rng.vec(-1, 1) * size * 10.0; break;
        default: p = c.a[static_cast<std::size_t>(rng.integer(0, 2))];
      }
      const double want = triangle_distance(p, p, p, b[0], b[1], b[2]);
      const double got = point_triangle_distance(p, b[0], b[1], b[2]);
      if (want == 0.0) {
        ++on_triangle;
        double ext = 0;
        for (const Vec3& v : b) ext = std::max(ext, (v - p).cwiseAbs().maxCoeff());
        if (!(got > 0.0 && got <= std::max(1e-12 * ext, std::numeric_limits<double>::denorm_min())) && ++mismatches <= 5)
          ADD_FAILURE() << test::family_name(static_cast<Family>(f)) << ' ' << i << ": " << got << " on the triangle";
      } else {
        ++compared;
        if (got != want && ++mismatches <= 5)
          ADD_FAILURE() << test::family_name(static_cast<Family>(f)) << ' ' << i << ": " << got << " vs " << want;
      }
    }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(compared, 100);
  EXPECT_GT(on_triangle, 0);
  // Extreme ranges take the general path's scaling.
  const Vec3 tiny(0x1p-1060, 0, 0), big(0x1p1020, 0x1p1019, 0);
  EXPECT_EQ(point_triangle_distance(tiny, Vec3(0, 0x1p-1070, 0), Vec3(0, 0, 0x1p-1070), Vec3(0, 0x1p-1070, 0x1p-1070)),
            triangle_distance(tiny, tiny, tiny, Vec3(0, 0x1p-1070, 0), Vec3(0, 0, 0x1p-1070), Vec3(0, 0x1p-1070, 0x1p-1070)));
  EXPECT_EQ(point_triangle_distance(big, Vec3(-0x1p1020, 0, 0), Vec3(-0x1p1020, 1, 0), Vec3(-0x1p1020, 0, 1)),
            triangle_distance(big, big, big, Vec3(-0x1p1020, 0, 0), Vec3(-0x1p1020, 1, 0), Vec3(-0x1p1020, 0, 1)));
}

// No point pair sampled on the two triangles is closer than the reported distance.
TEST(TriangleDistance, NeverAboveSampledPairs) {
  test::Rng rng(5);
  for (int i = 0; i < (kPairsPerFamily / 8); ++i) {
    const TriPair p = test::make_case(rng.integer(0, 1) ? Family::RandomNear : Family::Sliver, rng);
    const double d = dist(p.a, p.b);
    double sampled = std::numeric_limits<double>::infinity();
    for (int s = 0; s < 400; ++s) {
      auto sample = [&](const Tri& t) {
        double u = rng.uniform(), v = rng.uniform();
        if (u + v > 1) u = 1 - u, v = 1 - v;
        return Vec3(t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]));
      };
      sampled = std::min(sampled, (sample(p.a) - sample(p.b)).norm());
    }
    EXPECT_LE(d, sampled + 1e-12 * extent(p)) << "pair " << i;
  }
}

TEST(TriangleDistance, KnownConfigurations) {
  const Tri unit{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  auto shifted = [](const Tri& t, const Vec3& s) { return Tri{t[0] + s, t[1] + s, t[2] + s}; };
  EXPECT_DOUBLE_EQ(dist(unit, shifted(unit, Vec3(0, 0, 0.25))), 0.25);  // parallel, face over face
  EXPECT_DOUBLE_EQ(dist(unit, shifted(unit, Vec3(3, 0, 0))), 2.0);      // in plane, vertex to vertex
  // Skew edges: the x axis segment against a segment parallel to y at height 2.
  EXPECT_DOUBLE_EQ(dist(unit, Tri{Vec3(0.5, -1, 2), Vec3(0.5, 1, 2), Vec3(0.5, 0, 5)}), 2.0);
  // Vertex over the interior of the face.
  EXPECT_DOUBLE_EQ(dist(unit, Tri{Vec3(0.2, 0.2, 0.5), Vec3(0.2, 0.2, 3), Vec3(0.3, 0.2, 3)}), 0.5);
  // Edge against edge, crossing in projection, 1e-9 apart.
  EXPECT_NEAR(dist(unit, Tri{Vec3(0.5, -0.5, 1e-9), Vec3(0.5, 0.5, 1e-9), Vec3(0.5, 0, 1)}), 1e-9, 1e-20);
  // Degenerate: a point, and a segment.
  EXPECT_DOUBLE_EQ(dist(unit, Tri{Vec3(2, 0, 0), Vec3(2, 0, 0), Vec3(2, 0, 0)}), 1.0);
  EXPECT_DOUBLE_EQ(dist(unit, Tri{Vec3(0.25, 0.25, 1), Vec3(0.25, 0.25, 2), Vec3(0.25, 0.25, 3)}), 1.0);
  // Touching and crossing: 0.
  EXPECT_EQ(dist(unit, Tri{Vec3(1, 0, 0), Vec3(2, 0, 1), Vec3(2, 1, 0)}), 0.0);
  EXPECT_EQ(dist(unit, Tri{Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(3, 2, 0.5)}), 0.0);
  // Apart by the smallest possible amount: positive, so "0 iff intersecting" holds.
  const double tiny = std::nextafter(0.0, 1.0);
  EXPECT_GT(dist(unit, shifted(unit, Vec3(0, 0, tiny))), 0.0);
}

// The same pair seen from another rigid frame: equal distances up to the rounding of the motion.
TEST(TriangleDistance, InvariantUnderRigidMotion) {
  test::Rng rng(11);
  for (int i = 0; i < kPairsPerFamily; ++i) {
    const TriPair p = test::make_case(rng.integer(0, 1) ? Family::RandomNear : Family::Sliver, rng);
    const double shift = std::pow(10.0, rng.uniform(0, 6));
    const TriPair q = test::rigid_motion(p, rng, shift);
    const double scale = extent(p) + 4 * shift;  // the rounded motion moves points by ~u * |x|
    EXPECT_NEAR(dist(p.a, p.b), dist(q.a, q.b), 1e-12 * scale) << "pair " << i;
  }
}

TEST(TrianglesWithin, AgreesWithDistance) {
  test::Rng rng(13);
  int mismatches = 0, within = 0;
  const int n = kPairsPerFamily * 4;
  for (int i = 0; i < n; ++i) {
    const TriPair p = test::make_case(rng.integer(0, 1) ? Family::RandomNear : Family::TouchingGrid, rng);
    const double d = dist(p.a, p.b);
    // Thresholds below, at and above the distance, and 0.
    for (double t : {0.0, d * 0.5, d, d * 1.5 + 1e-9, rng.uniform(0, 0.3)}) {
      TrianglePredicateStats stats;
      const bool w = triangles_within(p.a[0], p.a[1], p.a[2], p.b[0], p.b[1], p.b[2], t, stats);
      within += w;
      if (w != (d <= t)) ++mismatches;
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(within, 0);
  EXPECT_LT(within, n * 5);
  TrianglePredicateStats stats;
  const Tri unit{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  EXPECT_FALSE(triangles_within(unit[0], unit[1], unit[2], unit[0], unit[1], unit[2], -1.0, stats));
}

// fuzz_triangles: two triangles collapsed to points 3 x 2^-1074 apart. The squared distance
// underflowed to 0, so the distance came out as 2^-1074 and triangles_within disagreed with it.
TEST(TriangleDistance, SubnormalPointsAreMeasuredExactly) {
  const Vec3 a(-0x0.0000000000003p-1022, -8, -8), b(0, -8, -8);
  const double d = dist(Tri{a, a, a}, Tri{b, b, b});
  EXPECT_EQ(d, 0x0.0000000000003p-1022);
  TrianglePredicateStats stats;
  EXPECT_TRUE(triangles_within(a, a, a, b, b, b, d, stats));
  EXPECT_FALSE(triangles_within(a, a, a, b, b, b, std::nextafter(d, 0.0), stats));
}

// The known configurations scaled by powers of two over the whole double range: the squares and
// fourth powers inside the distance left the range at extents below ~2^-256 or above ~2^256, losing
// candidates (too large a distance) or returning inf.
TEST(TriangleDistance, ScaleInvariantOverTheDoubleRange) {
  const Tri unit{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  struct Config {
    Tri b;
    double distance;
  };
  const Config configs[] = {
      {Tri{Vec3(0, 0, 0.25), Vec3(1, 0, 0.25), Vec3(0, 1, 0.25)}, 0.25},     // face over face
      {Tri{Vec3(3, 0, 0), Vec3(4, 0, 0), Vec3(3, 1, 0)}, 2.0},               // vertex to vertex
      {Tri{Vec3(0.5, -1, 2), Vec3(0.5, 1, 2), Vec3(0.5, 0, 5)}, 2.0},        // skew edges
      {Tri{Vec3(0.25, 0.25, 0.5), Vec3(0.25, 0.25, 3), Vec3(0.375, 0.25, 3)}, 0.5},  // vertex over face
      {Tri{Vec3(2, 0, 0), Vec3(2, 0, 0), Vec3(2, 0, 0)}, 1.0},               // a point
  };
  for (int k : {-1060, -1000, -700, -400, -200, 0, 200, 400, 700, 1000}) {
    const double s = std::ldexp(1.0, k);
    const Tri a{unit[0] * s, unit[1] * s, unit[2] * s};
    for (const Config& c : configs) {
      const Tri b{c.b[0] * s, c.b[1] * s, c.b[2] * s};
      const double expected = c.distance * s;
      const double d = dist(a, b);
      EXPECT_NEAR(d, expected, 1e-14 * expected) << "scale 2^" << k << ", expected " << expected;
      // 1e-12 away, or one ulp where the subnormal grid is coarser than that.
      const double above = std::max(expected * (1 + 1e-12), std::nextafter(expected, HUGE_VAL));
      const double below = std::min(expected * (1 - 1e-12), std::nextafter(expected, 0.0));
      TrianglePredicateStats stats;
      EXPECT_TRUE(triangles_within(a[0], a[1], a[2], b[0], b[1], b[2], above, stats)) << "scale 2^" << k;
      EXPECT_FALSE(triangles_within(a[0], a[1], a[2], b[0], b[1], b[2], below, stats)) << "scale 2^" << k;
    }
  }
}

// Coordinates near the top of the double range: their differences overflow unless scaled first.
TEST(TriangleDistance, CoordinatesNearTheLargestDouble) {
  const double big = 0x1p1022;
  const Tri a{Vec3(-big, 0, 0), Vec3(-big, big, 0), Vec3(-big, 0, big)};
  const Tri b{Vec3(big, 0, 0), Vec3(big, big, 0), Vec3(big, 0, big)};
  EXPECT_EQ(dist(a, b), 0x1p1023);
  const Tri far{Vec3(-0x1.cp1023, 0, 0), Vec3(-0x1.cp1023, 1, 0), Vec3(-0x1.cp1023, 0, 1)};
  const Tri near{Vec3(0x1p1020, 0, 0), Vec3(0x1p1020, 1, 0), Vec3(0x1p1020, 0, 1)};
  EXPECT_NEAR(dist(far, near), 0x1.cp1023 + 0x1p1020, 0x1p1000);
}

// fuzz_triangles: a segment (a0 == a1) against a sliver whose edge b0-b2 is a subnormal, at 2^37.
// The plane early out of triangles_within judged them apart for d above their distance: the sliver's
// normal underflows, and its error bound assumed it would not.
TEST(TrianglesWithin, SubnormalSliverIsNotSeparatedByItsPlane) {
  const Vec3 a0(-0x1p+37, -0x1p+36, -0x1p+36), a2(-0x1p+37, -0x1.8p+37, -0x1.8p+37);
  const Vec3 b0(0.0, 0x1.2p+39, 0x1.4p+38), b1(0x1p+37, -0x1.4p+38, -0x1.8p+37),
      b2(-0x0.0000000000003p-1022, 0x1.2p+39, 0x1.4p+38);
  TrianglePredicateStats stats;
  const double d = triangle_distance(a0, a0, a2, b0, b1, b2, stats);
  ASSERT_TRUE(std::isfinite(d));
  EXPECT_TRUE(triangles_within(a0, a0, a2, b0, b1, b2, d * (1 + 0x1p-40), stats)) << d;
  EXPECT_TRUE(triangles_within(b0, b1, b2, a0, a0, a2, d * (1 + 0x1p-40), stats)) << d;
  EXPECT_FALSE(triangles_within(a0, a0, a2, b0, b1, b2, d * (1 - 0x1p-40), stats)) << d;
}

}  // namespace
}  // namespace cadclash
