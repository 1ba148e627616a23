// triangles_intersect: Guigue–Devillers ("Fast and robust triangle-triangle overlap test using
// orientation predicates", JGT 2003) with every orientation sign made exact by stages:
//   1. double, with a static error bound (below): certifies the sign of almost every generic call;
//   2. long double, the same evaluation and bound with u = 2^-64 (side_extended): nearly degenerate
//      signs (slivers, rigid motions, 1-ulp perturbations) at a few nanoseconds;
//   3. CGAL's filtered orientation (exact_orient.h: interval arithmetic, then exact arithmetic where
//      the interval contains 0), which also gives the exact zeros of coplanar and touching
//      configurations.
// 2D signs (coplanar pairs) go double filter -> exact::orient2d_sign. Before any open 3D sign is
// resolved, two cheap special cases settle the call: a shared vertex (the closed triangles meet
// there; a shared edge is two shared vertices) and both triangles in one coordinate plane (a z = c
// contact; the 2D test below). With exact signs, zeros included, the degenerate configurations are
// decided here too: exactly coplanar triangles in any plane by a 2D closed-triangle test, vertices on
// the other plane by CGAL's own case analysis. What still goes to triangles_intersect_exact (CGAL's
// do_intersect, the "exact fallback"): degenerate triangles (collinear or repeated vertices) and
// coordinates beyond 2^48 (the static bound's range). The float-only benchmark mode
// (testing::set_float_only_for_benchmark) runs stages 1 and 2 and the special cases only: whatever
// they leave open is answered "intersect" and counted in exact_fallbacks, with no exact arithmetic.
//
// Decision (exact signs; A = (a0, a1, a2) is CGAL's t1 and B its t2, the oracle's order):
//  - da_i = orientation(b0, b1, b2, a_i). All three strictly of one sign: A lies in an open half-
//    space of B's plane, disjoint.
//  - All three zero: B is degenerate (its normal (b1-b0) x (b2-b0) is 0, so every such determinant
//    is 0) or A lies in B's plane. The normal's components are exactly the 2D orientations of B
//    projected to the coordinate planes (n_x on (y, z), n_y on (z, x), n_z on (x, y)); the first
//    axis k, by decreasing rounded |n_k|, whose exact projected orientation of B is nonzero is one
//    the plane is not parallel to, so dropping coordinate k maps the plane affinely and bijectively
//    onto the coordinate plane: incidences, convexity and "strictly outside a line" are preserved.
//    None nonzero: B is degenerate (CGAL). A's projected orientation is n_A,k = λ n_B,k with
//    n_A = λ n_B (A in B's plane), zero iff A is degenerate (CGAL). Otherwise the 2D test is the
//    separating axis theorem for closed convex polygons: the Minkowski difference A - B is a convex
//    polygon whose edge normals are those of A's edges and the reversed ones of B's, and 0 is not in
//    it iff it lies strictly outside one of its edges, i.e. iff some edge line of one triangle has
//    all three vertices of the other strictly on its outer side (exact orient2d signs; touching
//    counts as intersecting).
//  - Otherwise B is not degenerate and A has a vertex off B's plane. If all of db_i =
//    orientation(a0, a1, a2, b_i) are zero, A is degenerate (else B would lie in A's plane, the
//    planes would coincide and A would lie in B's): CGAL. Otherwise the permutation and the two
//    final non-strict tests are CGAL's Triangle_3_Triangle_3_do_intersect.h (5.5) case for case,
//    zeros included (`arrange`): the same predicates on the same points with the same (exact)
//    signs, so the same answer as CGAL's exact do_intersect on the given doubles.
//
// Error bound of stage 1 (Shewchuk-style; u = 2^-53, round to nearest, no FMA: -ffp-contract=off).
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
// the u·P spare) covers it. A certified sign is never zero.
#include "cadclash/geometry.h"
#include "cadclash/testing/benchmark_switches.h"
#include "exact_orient.h"

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

using P3 = exact::Pt3;
using P2 = exact::Pt2;

constexpr double kOrientBound = 9.0 * 0x1p-53;
constexpr double kAbsFloor = 0x1p-1000;
constexpr double kMaxCoord = 0x1p48;

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

// Second stage, for the signs the double filter leaves open: the same evaluation and the same bound
// in long double, where that is an IEEE format with more precision (x87 extended: u = 2^-64, so it
// certifies determinants 2^11 times smaller). The derivation above holds for any unit roundoff u;
// the floor 2^-1000 still covers underflow. Exact zeros go on to the exact stage. (On as1's real
// contacts it settles few signs and costs 0.3-0.6 % of a check; on the test families' slivers, rigid
// motions and 1-ulp perturbations it halves the time per test against going to CGAL directly.)
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

// First stage: +1 or -1, the certified sign of orientation(p, q, r, s) for the plane's p, q, r;
// 0: not certain.
inline int side_double(const Plane& pl, const P3& s) {
  const double wx = s.x - pl.p->x, wy = s.y - pl.p->y, wz = s.z - pl.p->z;
  const double det = wx * pl.nx + wy * pl.ny + wz * pl.nz;
  const double perm = std::abs(wx) * pl.px + std::abs(wy) * pl.py + std::abs(wz) * pl.pz;
  const double bound = kOrientBound * perm + kAbsFloor;
  if (det > bound) return 1;
  if (det < -bound) return -1;
  return 0;
}

// The float stages only (the float-only benchmark mode): +1 or -1 certified, 0 not certain.
inline int side_float(const Plane& pl, const P3& s, TrianglePredicateStats& st) {
  if (const int d = side_double(pl, s)) return d;
  ++st.extended_signs;
  return side_extended(*pl.p, *pl.q, *pl.r, s);
}

// The exact sign (-1, 0, +1) of a sign the double stage left open: long double, then CGAL.
[[gnu::noinline]] int resolve(const Plane& pl, const P3& s, TrianglePredicateStats& st) {
  ++st.extended_signs;
  if (const int d = side_extended(*pl.p, *pl.q, *pl.r, s)) return d;
  ++st.exact_signs;
  return exact::orient3d_sign(*pl.p, *pl.q, *pl.r, s);
}

// Both stages: the exact sign of orientation(p, q, r, s).
inline int orient_exact(const P3& p, const P3& q, const P3& r, const P3& s, TrianglePredicateStats& st) {
  const Plane pl = make_plane(p, q, r);
  if (const int d = side_double(pl, s)) return d;
  return resolve(pl, s, st);
}

inline int orient_float(const P3& p, const P3& q, const P3& r, const P3& s, TrianglePredicateStats& st) {
  return side_float(make_plane(p, q, r), s, st);
}

// The ordering Guigue–Devillers needs, as CGAL's Triangle_3_Triangle_3_do_intersect.h sets it, case
// for case including zero signs (a vertex on the other plane counts as isolated as CGAL decides):
// given the signs d[0..2] of triangle t relative to the other plane, neither all three of one strict
// sign nor all zero, returns (s_min, t_min, s_max, t_max).
struct Arranged {
  const P3 *smin, *tmin, *smax, *tmax;
};

inline Arranged arrange(const P3* t, const int* d) {
  const P3 *p = &t[0], *q = &t[1], *r = &t[2];
  if (d[0] > 0) {
    if (d[1] > 0) return {q, r, r, p};  // r isolated on the negative side
    if (d[2] > 0) return {p, q, q, r};  // q isolated on the negative side
    return {p, q, r, p};                // p isolated on the positive side
  }
  if (d[0] < 0) {
    if (d[1] < 0) return {r, p, q, r};  // r isolated on the positive side
    if (d[2] < 0) return {q, r, p, q};  // q isolated on the positive side
    return {r, p, p, q};                // p isolated on the negative side
  }
  // p on the plane
  if (d[1] > 0) return d[2] > 0 ? Arranged{r, p, p, q} : Arranged{q, r, p, q};
  if (d[1] < 0) return d[2] < 0 ? Arranged{p, q, r, p} : Arranged{p, q, q, r};
  return d[2] > 0 ? Arranged{r, p, q, r} : Arranged{q, r, r, p};  // p, q on the plane, r not
}

// Disjoint / Intersect: decided. Unsure: the call goes to CGAL (or, in the float-only benchmark
// mode, is answered "intersect"). Open: this test does not apply, the caller goes on.
enum class Verdict { Disjoint, Intersect, Unsure, Open };

// Orientation in a coordinate plane, with the 2D version of the bound above: each of the two
// monomials takes 4 roundings (2 differences, the product, the subtraction), so
// |fl(det) - det| <= γ4 · M <= 4u (1 + 5u) · fl(P), and 5u · fl(P) + 2^-1000 certifies the sign.
inline int orient2_filter(const P2& a, const P2& b, const P2& c) {
  const double l = (b.x - a.x) * (c.y - a.y), r = (b.y - a.y) * (c.x - a.x);
  const double det = l - r;
  const double bound = 5.0 * 0x1p-53 * (std::abs(l) + std::abs(r)) + kAbsFloor;
  return (det > bound) - (det < -bound);
}

// kExact: the exact sign; otherwise the filter's (0: not certain).
template <bool kExact>
inline int orient2(const P2& a, const P2& b, const P2& c, TrianglePredicateStats& st) {
  const int d = orient2_filter(a, b, c);
  if constexpr (kExact) {
    if (d == 0) {
      ++st.exact_signs;
      return exact::orient2d_sign(a, b, c);
    }
  }
  return d;
}

// Two closed triangles in one plane, projected to 2D (see the top of the file): disjoint iff an edge
// line of one has all three vertices of the other strictly on its outer side. oa, ob: orient2 of a
// and b. kExact: every sign is exact, so every edge either separates or not. Float-only: each edge
// certainly separates, certainly does not (a vertex certainly inside), or leaves the call open.
template <bool kExact>
Verdict coplanar_2d(const P2* a, const P2* b, int oa, int ob, TrianglePredicateStats& st) {
  if (oa == 0 || ob == 0) return Verdict::Unsure;
  bool open = false;
  for (int pass = 0; pass < 2; ++pass) {
    const P2* t = pass ? b : a;
    const P2* o = pass ? a : b;
    const int ot = pass ? ob : oa;
    for (int i = 0; i < 3; ++i) {
      const P2 &e0 = t[i], &e1 = t[(i + 1) % 3];
      if constexpr (kExact) {
        int j = 0;
        for (; j < 3; ++j) {
          if (orient2<true>(e0, e1, o[j], st) * ot >= 0) break;  // o[j] on the line or inside: this edge does not separate
        }
        if (j == 3) return Verdict::Disjoint;
      } else {
        int outside = 0;
        bool inside = false;
        for (int j = 0; j < 3; ++j) {
          const int sgn = orient2<false>(e0, e1, o[j], st) * ot;
          outside += sgn < 0;
          inside |= sgn > 0;
        }
        if (outside == 3) return Verdict::Disjoint;
        if (!inside) open = true;
      }
    }
  }
  return open ? Verdict::Unsure : Verdict::Intersect;
}

inline bool same_point(const P3& a, const P3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

// A repeated vertex: the triangle is degenerate (CGAL decides), known without any sign.
inline bool repeated_vertex(const P3* t) {
  return same_point(t[0], t[1]) || same_point(t[1], t[2]) || same_point(t[2], t[0]);
}

inline bool shared_vertex(const P3* A, const P3* B) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (A[i].x == B[j].x && A[i].y == B[j].y && A[i].z == B[j].z) return true;
  return false;
}

// Cases decided before any open plane sign is resolved: a shared vertex (the closed triangles meet
// there; a shared edge has two), and both triangles in one axis-parallel plane (the 2D test on the
// other two coordinates). Open when neither applies.
template <bool kExact>
[[gnu::noinline]] Verdict touching_special_cases(const P3* A, const P3* B, TrianglePredicateStats& st) {
  if (shared_vertex(A, B)) return Verdict::Intersect;
  auto same = [&](double P3::*c) {
    const double v = A[0].*c;
    return A[1].*c == v && A[2].*c == v && B[0].*c == v && B[1].*c == v && B[2].*c == v;
  };
  double P3::*u = nullptr;
  double P3::*w = nullptr;
  if (same(&P3::z)) u = &P3::x, w = &P3::y;
  else if (same(&P3::x)) u = &P3::y, w = &P3::z;
  else if (same(&P3::y)) u = &P3::z, w = &P3::x;
  else return Verdict::Open;
  const P2 a2[3] = {{A[0].*u, A[0].*w}, {A[1].*u, A[1].*w}, {A[2].*u, A[2].*w}};
  const P2 b2[3] = {{B[0].*u, B[0].*w}, {B[1].*u, B[1].*w}, {B[2].*u, B[2].*w}};
  const int oa = orient2<kExact>(a2[0], a2[1], a2[2], st);
  const int ob = orient2<kExact>(b2[0], b2[1], b2[2], st);
  return coplanar_2d<kExact>(a2, b2, oa, ob, st);
}

// Exact stage, all three of A's vertices exactly on B's plane (see the top of the file): project
// along an axis B's plane is not parallel to and decide in 2D; Unsure if either is degenerate.
[[gnu::noinline]] Verdict coplanar_any_plane(const P3* A, const P3* B, const Plane& pb, TrianglePredicateStats& st) {
  // Axis k drops coordinate k; the kept pair (k+1, k+2) makes orient2d of B's projection equal n_k.
  static constexpr double P3::*kCoord[3] = {&P3::x, &P3::y, &P3::z};
  const double n[3] = {std::abs(pb.nx), std::abs(pb.ny), std::abs(pb.nz)};
  int order[3] = {0, 1, 2};
  if (n[order[1]] > n[order[0]]) std::swap(order[0], order[1]);
  if (n[order[2]] > n[order[1]]) std::swap(order[1], order[2]);
  if (n[order[1]] > n[order[0]]) std::swap(order[0], order[1]);
  for (const int k : order) {
    const auto u = kCoord[(k + 1) % 3], w = kCoord[(k + 2) % 3];
    const P2 b2[3] = {{B[0].*u, B[0].*w}, {B[1].*u, B[1].*w}, {B[2].*u, B[2].*w}};
    const int ob = orient2<true>(b2[0], b2[1], b2[2], st);
    if (ob == 0) continue;  // B's plane is parallel to axis k (or B is degenerate)
    const P2 a2[3] = {{A[0].*u, A[0].*w}, {A[1].*u, A[1].*w}, {A[2].*u, A[2].*w}};
    const int oa = orient2<true>(a2[0], a2[1], a2[2], st);
    return coplanar_2d<true>(a2, b2, oa, ob, st);  // Unsure when oa == 0: A is degenerate
  }
  return Verdict::Unsure;  // B's normal is exactly 0: B is degenerate
}

// The exact decision (see the top of the file); Unsure only for degenerate triangles.
Verdict decide_exact(const P3* A, const P3* B, TrianglePredicateStats& st) {
  // Signs of A's vertices relative to B's plane (orientation(b0, b1, b2, a_i)), then the reverse.
  const Plane pb = make_plane(B[0], B[1], B[2]);
  int da[3] = {side_double(pb, A[0]), side_double(pb, A[1]), side_double(pb, A[2])};
  if (da[0] == 0 || da[1] == 0 || da[2] == 0) {
    const Verdict v = touching_special_cases<true>(A, B, st);
    if (v != Verdict::Open) return v;
    // All three open is what a degenerate B gives (every sign exactly 0): a repeated vertex shows it
    // without resolving them.
    if (da[0] == 0 && da[1] == 0 && da[2] == 0 && repeated_vertex(B)) return Verdict::Unsure;
    for (int i = 0; i < 3; ++i)
      if (da[i] == 0) da[i] = resolve(pb, A[i], st);
  }
  if (da[0] == da[1] && da[1] == da[2]) return da[0] != 0 ? Verdict::Disjoint : coplanar_any_plane(A, B, pb, st);

  const Plane pa = make_plane(A[0], A[1], A[2]);
  int db[3] = {side_double(pa, B[0]), side_double(pa, B[1]), side_double(pa, B[2])};
  for (int i = 0; i < 3; ++i)
    if (db[i] == 0) db[i] = resolve(pa, B[i], st);
  if (db[0] == db[1] && db[1] == db[2]) return db[0] != 0 ? Verdict::Disjoint : Verdict::Unsure;  // 0: A degenerate

  const Arranged s1 = arrange(A, da);
  const Arranged s2 = arrange(B, db);

  // The segments in which each triangle meets the other's plane overlap iff both hold (CGAL's
  // non-strict tests: a zero is a touching contact).
  const int o1 = orient_exact(*s1.smin, *s1.tmin, *s2.smin, *s2.tmin, st);
  if (o1 > 0) return Verdict::Disjoint;
  const int o2 = orient_exact(*s1.smax, *s1.tmax, *s2.tmax, *s2.smax, st);
  if (o2 > 0) return Verdict::Disjoint;
  return Verdict::Intersect;
}

// The float-only benchmark mode: the float stages and the special cases, no exact arithmetic; every
// sign they leave open makes the call Unsure.
[[gnu::noinline]] Verdict decide_float_only(const P3* A, const P3* B, TrianglePredicateStats& st) {
  const Plane pb = make_plane(B[0], B[1], B[2]);
  const int da[3] = {side_float(pb, A[0], st), side_float(pb, A[1], st), side_float(pb, A[2], st)};
  if (da[0] == 0 || da[1] == 0 || da[2] == 0) {
    const Verdict v = touching_special_cases<false>(A, B, st);
    return v == Verdict::Open ? Verdict::Unsure : v;
  }
  if (da[0] == da[1] && da[1] == da[2]) return Verdict::Disjoint;

  const Plane pa = make_plane(A[0], A[1], A[2]);
  const int db[3] = {side_float(pa, B[0], st), side_float(pa, B[1], st), side_float(pa, B[2], st)};
  if (db[0] == 0 || db[1] == 0 || db[2] == 0) return Verdict::Unsure;
  if (db[0] == db[1] && db[1] == db[2]) return Verdict::Disjoint;

  const Arranged s1 = arrange(A, da);
  const Arranged s2 = arrange(B, db);
  const int o1 = orient_float(*s1.smin, *s1.tmin, *s2.smin, *s2.tmin, st);
  if (o1 > 0) return Verdict::Disjoint;
  if (o1 == 0) return Verdict::Unsure;
  const int o2 = orient_float(*s1.smax, *s1.tmax, *s2.tmax, *s2.smax, st);
  if (o2 > 0) return Verdict::Disjoint;
  if (o2 == 0) return Verdict::Unsure;
  return Verdict::Intersect;
}

Verdict filtered(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1,
                 const Vec3& b2, TrianglePredicateStats& st, bool float_only) {
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

  // The error bounds assume |coordinates| <= 2^48. Written so that NaN also fails.
  const double lo = std::min({amin_x, amin_y, amin_z, bmin_x, bmin_y, bmin_z});
  const double hi = std::max({amax_x, amax_y, amax_z, bmax_x, bmax_y, bmax_z});
  if (!(lo >= -kMaxCoord && hi <= kMaxCoord)) return Verdict::Unsure;

  return float_only ? decide_float_only(A, B, st) : decide_exact(A, B, st);
}

std::atomic<bool> float_only_for_benchmark{false};

}  // namespace

namespace testing {
void set_float_only_for_benchmark(bool on) { float_only_for_benchmark.store(on, std::memory_order_relaxed); }
}  // namespace testing

bool triangles_intersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                         const Vec3& b1, const Vec3& b2, TrianglePredicateStats& stats) {
  ++stats.tests;
  const bool float_only = float_only_for_benchmark.load(std::memory_order_relaxed);
  switch (filtered(a0, a1, a2, b0, b1, b2, stats, float_only)) {
    case Verdict::Disjoint:
      return false;
    case Verdict::Intersect:
      return true;
    case Verdict::Unsure:
    case Verdict::Open:
      break;
  }
  ++stats.exact_fallbacks;
  if (float_only) return true;
  return triangles_intersect_exact(a0, a1, a2, b0, b1, b2);
}

}  // namespace cadclash
