// White-box tests of the exact orientation stage of triangles_intersect (collide/src/exact_orient.h):
// orient3d_exact_sign, its two stages (the lattice fast path and the expansion) and
// orient2d_exact_sign, against CGAL's exact orientation (EPICK's filtered exact predicate and EPECK)
// on exactly coplanar / collinear inputs, 1-ulp perturbations, the extremes of the supported domain
// and >= 10^5 random nearly degenerate inputs each.
#include "exact_orient.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

namespace cadclash {
namespace {

using exact::Pt2;
using exact::Pt3;
using EpickK = CGAL::Exact_predicates_inexact_constructions_kernel;
using EpeckK = CGAL::Exact_predicates_exact_constructions_kernel;

#ifdef NDEBUG
constexpr int kRandomCases = 200'000;
#else
constexpr int kRandomCases = 20'000;
#endif

// splitmix64, as in test_triangle_cases.h (kept local: this file tests exact_orient alone).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  long integer(long lo, long hi) { return lo + static_cast<long>(next() % static_cast<std::uint64_t>(hi - lo + 1)); }

 private:
  std::uint64_t s_;
};

int cgal_sign(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s) {
  using P = EpickK::Point_3;
  return static_cast<int>(CGAL::orientation(P(p.x, p.y, p.z), P(q.x, q.y, q.z), P(r.x, r.y, r.z), P(s.x, s.y, s.z)));
}

int cgal_epeck_sign(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s) {
  using P = EpeckK::Point_3;
  return static_cast<int>(CGAL::orientation(P(p.x, p.y, p.z), P(q.x, q.y, q.z), P(r.x, r.y, r.z), P(s.x, s.y, s.z)));
}

int cgal_sign(const Pt2& a, const Pt2& b, const Pt2& c) {
  using P = EpickK::Point_2;
  return static_cast<int>(CGAL::orientation(P(a.x, a.y), P(b.x, b.y), P(c.x, c.y)));
}

std::string show(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s) {
  char buf[400];
  std::snprintf(buf, sizeof buf, "p=(%a %a %a) q=(%a %a %a) r=(%a %a %a) s=(%a %a %a)", p.x, p.y, p.z, q.x,
                q.y, q.z, r.x, r.y, r.z, s.x, s.y, s.z);
  return buf;
}

// Checks every stage against the expected sign; counts which stage the fast path took.
struct Checker {
  long cases = 0, fast = 0, wrong = 0;
  void operator()(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s, int expected) {
    ++cases;
    const int e = exact::orient3d_exact_sign(p, q, r, s);
    const int x = exact::orient3d_expansion_sign(p, q, r, s);
    const int f = exact::orient3d_fast_sign(p, q, r, s);
    if (f != exact::kNoFastPath) ++fast;
    const bool ok = e == expected && x == expected && (f == exact::kNoFastPath || f == expected);
    if (!ok && ++wrong <= 5)
      ADD_FAILURE() << "expected " << expected << ", exact " << e << ", expansion " << x << ", fast " << f
                    << "\n" << show(p, q, r, s);
  }
};

Pt3 add(const Pt3& a, double i, const Pt3& u, double j, const Pt3& v) {
  return {a.x + i * u.x + j * v.x, a.y + i * u.y + j * v.y, a.z + i * u.z + j * v.z};
}
Pt3 sub(const Pt3& a, const Pt3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Pt3 scaled(const Pt3& a, double s) { return {a.x * s, a.y * s, a.z * s}; }

// ±[1, 2) x 2^e: a random magnitude of exactly that binade (never below the domain's 2^-300).
double spread(Rng& rng, int e) { return std::ldexp((rng.integer(0, 1) ? 1.0 : -1.0) * (1.0 + rng.uniform()), e); }

double& coord(Pt3& p, int k) { return k == 0 ? p.x : k == 1 ? p.y : p.z; }

// Moves c by |ulps| ulps up or down; 0 stays 0 (its neighbours are subnormal, outside the domain).
void nudge(double& c, int ulps) {
  if (c == 0.0) return;
  for (int k = 0; k < std::abs(ulps); ++k) c = std::nextafter(c, ulps > 0 ? HUGE_VAL : -HUGE_VAL);
}

// Exactly coplanar integer points: s = p + i (q - p) + j (r - p), all exact, at every scale 2^k the
// domain allows (small lattices take the fast path, wide ones the expansion).
TEST(ExactOrient, IntegerCoplanarIsZero) {
  Rng rng(1);
  Checker check;
  for (int n = 0; n < 20000; ++n) {
    const long range = n % 2 ? 16 : (1l << 20);
    auto ipt = [&] { return Pt3{double(rng.integer(-range, range)), double(rng.integer(-range, range)), double(rng.integer(-range, range))}; };
    const Pt3 p = ipt(), q = ipt(), r = ipt();
    const Pt3 s = add(p, double(rng.integer(-1024, 1024)), sub(q, p), double(rng.integer(-1024, 1024)), sub(r, p));
    const double scale = std::ldexp(1.0, static_cast<int>(rng.integer(-250, 12)));
    const Pt3 P = scaled(p, scale), Q = scaled(q, scale), R = scaled(r, scale), S = scaled(s, scale);
    ASSERT_EQ(cgal_epeck_sign(P, Q, R, S), 0);
    check(P, Q, R, S, 0);
    check(S, P, Q, R, 0);
    check(Q, S, R, P, 0);
  }
  EXPECT_EQ(check.wrong, 0);
  EXPECT_GT(check.fast, 0);
  EXPECT_LT(check.fast, check.cases);
}

// The same coplanar quadruples with one coordinate moved by 1-4 ulps: the sign CGAL gives (EPICK's
// filtered exact predicate and EPECK agree; both are checked).
TEST(ExactOrient, UlpPerturbationsMatchCgal) {
  Rng rng(2);
  Checker check;
  long nonzero = 0;
  for (int n = 0; n < 20000; ++n) {
    const long range = n % 2 ? 64 : (1l << 24);
    auto ipt = [&] { return Pt3{double(rng.integer(-range, range)), double(rng.integer(-range, range)), double(rng.integer(-range, range))}; };
    Pt3 pts[4];
    pts[0] = ipt(), pts[1] = ipt(), pts[2] = ipt();
    pts[3] = add(pts[0], double(rng.integer(-64, 64)), sub(pts[1], pts[0]), double(rng.integer(-64, 64)), sub(pts[2], pts[0]));
    const double scale = std::ldexp(1.0, static_cast<int>(rng.integer(-200, 10)));
    for (Pt3& x : pts) x = scaled(x, scale);
    nudge(coord(pts[rng.integer(0, 3)], static_cast<int>(rng.integer(0, 2))), static_cast<int>(rng.integer(1, 4)) * (rng.integer(0, 1) ? 1 : -1));
    const int want = cgal_sign(pts[0], pts[1], pts[2], pts[3]);
    ASSERT_EQ(want, cgal_epeck_sign(pts[0], pts[1], pts[2], pts[3]));
    nonzero += want != 0;
    check(pts[0], pts[1], pts[2], pts[3], want);
  }
  EXPECT_EQ(check.wrong, 0);
  EXPECT_GT(nonzero, 10000);
}

// The ends of the domain: features of one ulp at 2^47, lattices at 2^-280, huge offsets mixed with
// tiny coordinates (differences that are not doubles), and what lies outside (kUnsupported).
TEST(ExactOrient, MagnitudeExtremes) {
  Rng rng(3);
  Checker check;
  for (int n = 0; n < 20000; ++n) {
    Pt3 pts[4];
    switch (n % 4) {
      case 0: {  // near 2^47, ulp 2^-5: points 2^47 + k 2^-5, nearly or exactly coplanar
        const double base = 0x1p47;
        for (Pt3& x : pts)
          x = {base + rng.integer(-64, 64) * 0x1p-5, base + rng.integer(-64, 64) * 0x1p-5, base - rng.integer(0, 64) * 0x1p-5};
        pts[3] = add(pts[0], 1, sub(pts[1], pts[0]), -1, sub(pts[2], pts[0]));
        if (rng.integer(0, 1)) nudge(pts[3].z, 1);
        break;
      }
      case 1: {  // tiny lattice at 2^-280 (products near 2^-840)
        for (Pt3& x : pts)
          x = {rng.integer(-1000, 1000) * 0x1p-280, rng.integer(-1000, 1000) * 0x1p-280, rng.integer(-1000, 1000) * 0x1p-280};
        if (rng.integer(0, 1)) pts[3] = add(pts[0], 2, sub(pts[1], pts[0]), -3, sub(pts[2], pts[0]));
        break;
      }
      case 2: {  // offsets near 2^46 mixed with coordinates of 2^-290..2^-200 (rounded differences)
        for (Pt3& x : pts)
          x = {rng.integer(0, 1) ? spread(rng, 45) : spread(rng, -static_cast<int>(rng.integer(200, 290))),
               rng.integer(0, 1) ? spread(rng, 45) : spread(rng, -static_cast<int>(rng.integer(200, 290))),
               spread(rng, -static_cast<int>(rng.integer(0, 3)))};
        break;
      }
      default: {  // coplanar in the plane z = x (exact) with y spread over 2^-250..2^46
        for (Pt3& x : pts) {
          const double a = spread(rng, static_cast<int>(rng.integer(-250, 46)));
          x = {a, spread(rng, static_cast<int>(rng.integer(-250, 46))), a};
        }
        break;
      }
    }
    const int want = cgal_sign(pts[0], pts[1], pts[2], pts[3]);
    if (n % 4 == 3) {
      ASSERT_EQ(want, 0);
    }
    check(pts[0], pts[1], pts[2], pts[3], want);
  }
  EXPECT_EQ(check.wrong, 0);

  const Pt3 o{0, 0, 0}, x{1, 0, 0}, y{0, 1, 0};
  EXPECT_EQ(exact::orient3d_exact_sign(o, x, y, Pt3{0, 0, 0x1p-300}), 1);
  EXPECT_EQ(exact::orient3d_exact_sign(o, x, y, Pt3{0, 0, -0x1p48}), -1);
  EXPECT_EQ(exact::orient3d_exact_sign(o, x, y, Pt3{0, 0, 0x1p-301}), exact::kUnsupported);
  EXPECT_EQ(exact::orient3d_exact_sign(o, x, y, Pt3{0, 0, 0x1.0000000000001p48}), exact::kUnsupported);
  EXPECT_EQ(exact::orient3d_exact_sign(o, x, y, Pt3{0, 0, std::numeric_limits<double>::denorm_min()}), exact::kUnsupported);
  EXPECT_EQ(exact::orient3d_exact_sign(o, x, y, Pt3{0, 0, std::numeric_limits<double>::quiet_NaN()}), exact::kUnsupported);
  EXPECT_EQ(exact::orient3d_exact_sign(o, x, y, Pt3{0, 0, HUGE_VAL}), exact::kUnsupported);
  EXPECT_EQ(exact::orient3d_fast_sign(o, x, y, Pt3{0, 0, 0x1p-301}), exact::kUnsupported);
  EXPECT_EQ(exact::orient3d_exact_sign(o, o, o, o), 0);
  EXPECT_EQ(exact::orient2d_exact_sign(Pt2{0, 0}, Pt2{1, 0}, Pt2{0, 0x1p-300}), 1);
  EXPECT_EQ(exact::orient2d_exact_sign(Pt2{0, 0}, Pt2{1, 0}, Pt2{0, -0x1p-301}), exact::kUnsupported);
  EXPECT_EQ(exact::orient2d_exact_sign(Pt2{0, 0}, Pt2{0x1p49, 0}, Pt2{0, 1}), exact::kUnsupported);
}

// >= 10^5 random nearly degenerate quadruples: s a rounded affine combination of p, q, r (so within
// a few roundings of their plane), at random scales and offsets, sometimes moved by ulps.
TEST(ExactOrient, RandomNearlyCoplanarAgreesWithCgal) {
  Rng rng(4);
  Checker check;
  long zeros = 0, inexact_differences = 0;
  for (int n = 0; n < kRandomCases; ++n) {
    const double scale = std::ldexp(1.0, static_cast<int>(rng.integer(-60, 30)));
    const double offset = rng.integer(0, 2) ? 0.0 : std::ldexp(rng.uniform(-1, 1), static_cast<int>(rng.integer(-20, 40)));
    auto rpt = [&] { return Pt3{offset + scale * rng.uniform(-1, 1), offset + scale * rng.uniform(-1, 1), offset + scale * rng.uniform(-1, 1)}; };
    Pt3 pts[4] = {rpt(), rpt(), rpt(), {}};
    pts[3] = add(pts[0], rng.uniform(-2, 2), sub(pts[1], pts[0]), rng.uniform(-2, 2), sub(pts[2], pts[0]));
    if (rng.integer(0, 3) == 0) nudge(coord(pts[3], static_cast<int>(rng.integer(0, 2))), static_cast<int>(rng.integer(-3, 3)));
    const int want = cgal_sign(pts[0], pts[1], pts[2], pts[3]);
    zeros += want == 0;
    for (int k = 0; k < 3; ++k) {
      const double a = coord(pts[1], k), b = coord(pts[0], k);
      const double d = a - b;
      if ((d + b) - a != 0.0 || (a - d) - b != 0.0) ++inexact_differences;
    }
    check(pts[0], pts[1], pts[2], pts[3], want);
  }
  EXPECT_EQ(check.wrong, 0);
  EXPECT_GT(inexact_differences, 0);
  std::printf("[ exact    ] %ld nearly coplanar quadruples, %ld exactly coplanar, %ld via the fast path\n",
              check.cases, zeros, check.fast);
}

// 2D: exactly collinear lattice triples are 0; nearly collinear random triples agree with CGAL.
TEST(ExactOrient, Orient2dAgreesWithCgal) {
  Rng rng(5);
  long wrong = 0, zeros = 0;
  for (int n = 0; n < kRandomCases; ++n) {
    Pt2 a, b, c;
    if (n % 2) {  // exactly collinear lattice points at any scale, sometimes nudged
      const double s = std::ldexp(1.0, static_cast<int>(rng.integer(-250, 20)));
      a = {rng.integer(-1 << 20, 1 << 20) * s, rng.integer(-1 << 20, 1 << 20) * s};
      const Pt2 d{rng.integer(-1000, 1000) * s, rng.integer(-1000, 1000) * s};
      const double t = double(rng.integer(-1000, 1000)), u = double(rng.integer(-1000, 1000));
      b = {a.x + t * d.x, a.y + t * d.y};
      c = {a.x + u * d.x, a.y + u * d.y};
      if (rng.integer(0, 2) == 0) nudge(rng.integer(0, 1) ? c.x : c.y, static_cast<int>(rng.integer(-2, 2)));
    } else {  // nearly collinear random points with offsets (rounded differences)
      const double scale = std::ldexp(1.0, static_cast<int>(rng.integer(-40, 30)));
      const double offset = rng.integer(0, 1) ? 0.0 : std::ldexp(rng.uniform(-1, 1), static_cast<int>(rng.integer(0, 45)));
      a = {offset + scale * rng.uniform(-1, 1), offset + scale * rng.uniform(-1, 1)};
      b = {offset + scale * rng.uniform(-1, 1), offset + scale * rng.uniform(-1, 1)};
      const double t = rng.uniform(-2, 2);
      c = {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
    }
    const int want = cgal_sign(a, b, c);
    zeros += want == 0;
    const int got = exact::orient2d_exact_sign(a, b, c);
    const int got_rot = exact::orient2d_exact_sign(b, c, a);
    if ((got != want || got_rot != want) && ++wrong <= 5)
      ADD_FAILURE() << "expected " << want << ", got " << got << " / " << got_rot << ": a=(" << a.x << "," << a.y
                    << ") b=(" << b.x << "," << b.y << ") c=(" << c.x << "," << c.y << ")";
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(zeros, kRandomCases / 10);
}

}  // namespace
}  // namespace cadclash
