// triangles_intersect: Guigue–Devillers ("Fast and robust triangle-triangle overlap test using
// orientation predicates", JGT 2003) on doubles, with a static error bound on every orientation sign.
// A sign the double bound cannot certify is evaluated again in long double with the same kind of
// bound (side_extended); one that neither certifies (in practice: exactly zero, i.e. coplanar,
// touching or degenerate) first meets touching_special_cases (a shared vertex; both triangles in
// one coordinate plane, settled by a filtered 2D test), then sends the whole call to
// triangles_intersect_exact (CGAL).
//
// The control flow mirrors CGAL's Triangle_3_Triangle_3_do_intersect.h for the case where every
// vertex lies strictly on one side of the other triangle's plane, so the filtered answer and the
// exact answer come from the same algorithm.
//
// Error bound (Shewchuk-style; u = 2^-53, round to nearest, no FMA: -ffp-contract=off is global).
// Every orientation is evaluated as
//     det = w · ((q-p) × (r-p)),   w = s - p,
// i.e. det = Σ_k ±m_k over the 6 monomials m_k = (one coordinate of each of q-p, r-p, s-p).
// Each monomial passes through at most 8 roundings: 3 differences, the 2x2 product, the 2x2
// subtraction, the product with w_i and 2 of the additions of the final 3-term sum. Hence
//     |fl(det) - det| <= γ8 · M,   M = Σ_k |m_k|,   γ8 = 8u / (1 - 8u).
// The permanent P = Σ_i |w_i| (|a_j b_k| + |a_k b_j|) is evaluated with the same operation count,
// all on non-negative values, so fl(P) >= (1-u)^8 M >= (1 - 8u) M, and
//     |fl(det) - det| <= γ8 / (1 - 8u) · fl(P) = 8u (1 + 16u + O(u^2)) · fl(P).
// We test |fl(det)| > fl(9u · fl(P) + 2^-1000). 9u(1-u) > 8u(1+17u), so a certified sign is the
// exact sign of det, with one u·P to spare for underflow: inputs are limited to |x| <= 2^48 (larger
// coordinates go to the exact path), so differences are <= 2^49, nothing overflows, and a product
// that underflows adds at most 2^-1075 absolute error, magnified by at most 2^49 by the following
// product; the total absolute error from underflow is below 2^-1020 and the floor 2^-1000 (plus
// the u·P spare) covers it. A certified sign is never zero, so every certified configuration is the
// generic one GD handles with strict signs.
#include "cadclash/geometry.h"
#include "cadclash/testing/benchmark_switches.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>

#if defined(__FAST_MATH__)
#error "triangle_intersect.cpp: the error bounds need IEEE arithmetic; do not build with -ffast-math"
#endif

namespace cadclash {
namespace {

constexpr double kOrientBound = 9.0 * 0x1p-53;
constexpr double kAbsFloor = 0x1p-1000;
constexpr double kMaxCoord = 0x1p48;

struct P3 {
  double x, y, z;
};

inline P3 load(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

// The normal (q-p) × (r-p) of a plane through p, and the matching absolute products for the bound.
struct Plane {
  const P3 *p, *q, *r;
  double nx, ny, nz;
  double px, py, pz;  // permanent parts: |a_y b_z| + |a_z b_y|, ...
};

inline Plane make_plane(const P3& p, const P3& q, const P3& r) {
  const double ax = q.x - p.x, ay = q.y - p.y, az = q.z - p.z;
  const double bx = r.x - p.x, by = r.y - p.y, bz = r.z - p.z;
  const double aybz = ay * bz, azby = az * by;
  const double azbx = az * bx, axbz = ax * bz;
  const double axby = ax * by, aybx = ay * bx;
  return {&p, &q, &r,
          aybz - azby,
          azbx - axbz,
          axby - aybx,
          std::abs(aybz) + std::abs(azby),
          std::abs(azbx) + std::abs(axbz),
          std::abs(axby) + std::abs(aybx)};
}

// Second stage, for the few signs the double filter leaves open (nearly coplanar points, e.g. a
// coplanar contact after a rotation rounded the coordinates): the same evaluation and the same
// bound in long double, where that is an IEEE format with more precision (x87 extended: u = 2^-64,
// so it certifies determinants 2^11 times smaller). The derivation above holds for any unit
// roundoff u; the floor 2^-1000 still covers underflow. Exact zeros still reach the exact path.
[[gnu::noinline]] int side_extended(const P3& p, const P3& q, const P3& r, const P3& s) {
  using L = long double;
  if constexpr (!std::numeric_limits<L>::is_iec559 || std::numeric_limits<L>::digits <= 53) {
    return 0;
  } else {
    constexpr L u = std::numeric_limits<L>::epsilon() / 2;
    const L ax = L(q.x) - L(p.x), ay = L(q.y) - L(p.y), az = L(q.z) - L(p.z);
    const L bx = L(r.x) - L(p.x), by = L(r.y) - L(p.y), bz = L(r.z) - L(p.z);
    const L wx = L(s.x) - L(p.x), wy = L(s.y) - L(p.y), wz = L(s.z) - L(p.z);
    const L aybz = ay * bz, azby = az * by, azbx = az * bx, axbz = ax * bz, axby = ax * by, aybx = ay * bx;
    const L det = wx * (aybz - azby) + wy * (azbx - axbz) + wz * (axby - aybx);
    const L perm = std::abs(wx) * (std::abs(aybz) + std::abs(azby)) +
                   std::abs(wy) * (std::abs(azbx) + std::abs(axbz)) +
                   std::abs(wz) * (std::abs(axby) + std::abs(aybx));
    const L bound = 9 * u * perm + L(kAbsFloor);
    return (det > bound) - (det < -bound);
  }
}

// +1 or -1: the certified sign of orientation(p, q, r, s) for the plane's p, q, r; 0: not certain.
inline int side(const Plane& pl, const P3& s, std::uint64_t& extended) {
  const double wx = s.x - pl.p->x, wy = s.y - pl.p->y, wz = s.z - pl.p->z;
  const double det = wx * pl.nx + wy * pl.ny + wz * pl.nz;
  const double perm = std::abs(wx) * pl.px + std::abs(wy) * pl.py + std::abs(wz) * pl.pz;
  const double bound = kOrientBound * perm + kAbsFloor;
  if (det > bound) return 1;
  if (det < -bound) return -1;
  ++extended;
  return side_extended(*pl.p, *pl.q, *pl.r, s);
}

inline int orient(const P3& p, const P3& q, const P3& r, const P3& s, std::uint64_t& extended) {
  return side(make_plane(p, q, r), s, extended);
}

// The ordering Guigue–Devillers needs: the vertex alone on its side of the other plane first.
// Given strict signs d[0..2] of triangle t relative to the other plane, not all equal, returns
// (smin, tmin, smax, tmax) as CGAL sets them.
struct Arranged {
  const P3 *smin, *tmin, *smax, *tmax;
};

inline Arranged arrange(const P3* t, const int* d) {
  const P3 *p = &t[0], *q = &t[1], *r = &t[2];
  if (d[0] > 0) {
    if (d[1] > 0) return {q, r, r, p};  // r alone on the negative side
    if (d[2] > 0) return {p, q, q, r};  // q alone on the negative side
    return {p, q, r, p};                // p alone on the positive side
  }
  if (d[1] < 0) return {r, p, q, r};  // r alone on the positive side
  if (d[2] < 0) return {q, r, p, q};  // q alone on the positive side
  return {r, p, p, q};                // p alone on the negative side
}

enum class Verdict { Disjoint, Intersect, Unsure };

// Orientation in a coordinate plane, with the 2D version of the bound above: each of the two
// monomials takes 4 roundings (2 differences, the product, the subtraction), so
// |fl(det) - det| <= γ4 · M <= 4u (1 + 5u) · fl(P), and 5u · fl(P) + 2^-1000 certifies the sign.
struct P2 {
  double x, y;
};

inline int orient2(const P2& a, const P2& b, const P2& c) {
  const double l = (b.x - a.x) * (c.y - a.y), r = (b.y - a.y) * (c.x - a.x);
  const double det = l - r;
  const double bound = 5.0 * 0x1p-53 * (std::abs(l) + std::abs(r)) + kAbsFloor;
  return (det > bound) - (det < -bound);
}

// Both triangles lie exactly in one coordinate plane (a common CAD contact: two faces on z = c).
// Closed convex polygons are disjoint iff the line of an edge of one has the other strictly on its
// outer side (separating axis theorem), so each edge either certainly separates, certainly does
// not (a vertex certainly inside), or leaves it open.
Verdict coplanar_in_axis_plane(const P2* a, const P2* b) {
  const int oa = orient2(a[0], a[1], a[2]), ob = orient2(b[0], b[1], b[2]);
  if (oa == 0 || ob == 0) return Verdict::Unsure;  // degenerate or nearly so
  bool open = false;
  for (int pass = 0; pass < 2; ++pass) {
    const P2* t = pass ? b : a;
    const P2* o = pass ? a : b;
    const int ot = pass ? ob : oa;
    for (int i = 0; i < 3; ++i) {
      const P2 &e0 = t[i], &e1 = t[(i + 1) % 3];
      int outside = 0;
      bool inside = false;
      for (int j = 0; j < 3; ++j) {
        const int sgn = orient2(e0, e1, o[j]) * ot;
        outside += sgn < 0;
        inside |= sgn > 0;
      }
      if (outside == 3) return Verdict::Disjoint;
      if (!inside) open = true;
    }
  }
  return open ? Verdict::Unsure : Verdict::Intersect;
}

// Cases where a plane sign was left open that are still decidable without CGAL: a shared vertex
// (the closed triangles meet there), and both triangles in one axis-parallel plane.
Verdict touching_special_cases(const P3* A, const P3* B) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (A[i].x == B[j].x && A[i].y == B[j].y && A[i].z == B[j].z) return Verdict::Intersect;
  auto same = [&](double P3::*c) {
    const double v = A[0].*c;
    return A[1].*c == v && A[2].*c == v && B[0].*c == v && B[1].*c == v && B[2].*c == v;
  };
  double P3::*u = nullptr;
  double P3::*w = nullptr;
  if (same(&P3::z)) u = &P3::x, w = &P3::y;
  else if (same(&P3::x)) u = &P3::y, w = &P3::z;
  else if (same(&P3::y)) u = &P3::z, w = &P3::x;
  else return Verdict::Unsure;
  const P2 a2[3] = {{A[0].*u, A[0].*w}, {A[1].*u, A[1].*w}, {A[2].*u, A[2].*w}};
  const P2 b2[3] = {{B[0].*u, B[0].*w}, {B[1].*u, B[1].*w}, {B[2].*u, B[2].*w}};
  return coplanar_in_axis_plane(a2, b2);
}

Verdict filtered(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1,
                 const Vec3& b2, std::uint64_t& extended) {
  const P3 A[3] = {load(a0), load(a1), load(a2)};
  const P3 B[3] = {load(b0), load(b1), load(b2)};

  // Separated boxes decide exactly (comparisons of doubles are exact).
  const double amin_x = std::min({A[0].x, A[1].x, A[2].x}), amax_x = std::max({A[0].x, A[1].x, A[2].x});
  const double bmin_x = std::min({B[0].x, B[1].x, B[2].x}), bmax_x = std::max({B[0].x, B[1].x, B[2].x});
  if (amax_x < bmin_x || bmax_x < amin_x) return Verdict::Disjoint;
  const double amin_y = std::min({A[0].y, A[1].y, A[2].y}), amax_y = std::max({A[0].y, A[1].y, A[2].y});
  const double bmin_y = std::min({B[0].y, B[1].y, B[2].y}), bmax_y = std::max({B[0].y, B[1].y, B[2].y});
  if (amax_y < bmin_y || bmax_y < amin_y) return Verdict::Disjoint;
  const double amin_z = std::min({A[0].z, A[1].z, A[2].z}), amax_z = std::max({A[0].z, A[1].z, A[2].z});
  const double bmin_z = std::min({B[0].z, B[1].z, B[2].z}), bmax_z = std::max({B[0].z, B[1].z, B[2].z});
  if (amax_z < bmin_z || bmax_z < amin_z) return Verdict::Disjoint;

  // The error bound assumes |coordinates| <= 2^48. Written so that NaN also fails.
  const double lo = std::min({amin_x, amin_y, amin_z, bmin_x, bmin_y, bmin_z});
  const double hi = std::max({amax_x, amax_y, amax_z, bmax_x, bmax_y, bmax_z});
  if (!(lo >= -kMaxCoord && hi <= kMaxCoord)) return Verdict::Unsure;

  // Signs of A's vertices relative to B's plane (orientation(b0, b1, b2, a_i)), then the reverse.
  const Plane pb = make_plane(B[0], B[1], B[2]);
  const int da[3] = {side(pb, A[0], extended), side(pb, A[1], extended), side(pb, A[2], extended)};
  if (da[0] == 0 || da[1] == 0 || da[2] == 0) return touching_special_cases(A, B);
  if (da[0] == da[1] && da[1] == da[2]) return Verdict::Disjoint;

  const Plane pa = make_plane(A[0], A[1], A[2]);
  const int db[3] = {side(pa, B[0], extended), side(pa, B[1], extended), side(pa, B[2], extended)};
  if (db[0] == 0 || db[1] == 0 || db[2] == 0) return Verdict::Unsure;
  if (db[0] == db[1] && db[1] == db[2]) return Verdict::Disjoint;

  const Arranged s1 = arrange(A, da);
  const Arranged s2 = arrange(B, db);

  // The segments in which each triangle meets the other's plane overlap iff both hold.
  const int o1 = orient(*s1.smin, *s1.tmin, *s2.smin, *s2.tmin, extended);
  if (o1 > 0) return Verdict::Disjoint;
  if (o1 == 0) return Verdict::Unsure;
  const int o2 = orient(*s1.smax, *s1.tmax, *s2.tmax, *s2.smax, extended);
  if (o2 > 0) return Verdict::Disjoint;
  if (o2 == 0) return Verdict::Unsure;
  return Verdict::Intersect;
}

std::atomic<bool> float_only_for_benchmark{false};

}  // namespace

namespace testing {
void set_float_only_for_benchmark(bool on) { float_only_for_benchmark.store(on, std::memory_order_relaxed); }
}  // namespace testing

bool triangles_intersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                         const Vec3& b1, const Vec3& b2, TrianglePredicateStats& stats) {
  ++stats.tests;
  switch (filtered(a0, a1, a2, b0, b1, b2, stats.extended_signs)) {
    case Verdict::Disjoint:
      return false;
    case Verdict::Intersect:
      return true;
    case Verdict::Unsure:
      break;
  }
  ++stats.exact_fallbacks;
  if (float_only_for_benchmark.load(std::memory_order_relaxed)) return true;
  return triangles_intersect_exact(a0, a1, a2, b0, b1, b2);
}

}  // namespace cadclash
