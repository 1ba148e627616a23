// Triangle–triangle distance in double precision.
//
// The minimum distance between two disjoint closed triangles is attained between an edge of one
// and an edge of the other, or between a vertex of one and the interior of the other. Every
// candidate below is the distance between two explicit points, each (up to the rounding of its
// construction) on its closed triangle: no candidate underestimates, so ill-conditioned parts
// (the normal of a sliver, nearly parallel edges) can only lose a candidate, never report a
// distance that is too small, and the well-conditioned candidate of the same class (an edge
// endpoint against the other edge) still finds the minimum.
#include "cadclash/geometry.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace cadclash {
namespace {

struct P3 {
  double x, y, z;
};

inline P3 operator-(const P3& a, const P3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline P3 operator+(const P3& a, const P3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline P3 operator*(double s, const P3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(const P3& a, const P3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline P3 cross(const P3& a, const P3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm2(const P3& a) { return dot(a, a); }
inline P3 load(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
inline double clamp01(double t) { return t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t); }

// An edge a + t d, t in [0, 1], with 1 / |d|^2 precomputed (0 for a zero-length edge).
struct Edge {
  P3 a, d;
  double inv_dd;
};

inline Edge make_edge(const P3& a, const P3& b) {
  const P3 d = b - a;
  const double dd = norm2(d);
  return {a, d, dd > 0.0 ? 1.0 / dd : 0.0};
}

// Squared distance from p to the edge.
inline double point_edge2(const P3& p, const Edge& e) {
  const P3 w = p - e.a;
  const double t = clamp01(dot(w, e.d) * e.inv_dd);
  return norm2(w - t * e.d);
}

// Squared distance between the edges at the stationary point of the lines, when it lies inside
// both edges' parameter ranges; +inf otherwise (an endpoint–edge pair then holds the minimum).
// s comes from the cross-product form, whose error grows like 1/angle rather than the 1/angle^2 of
// the normal equations; t is then the projection of that point, so the returned value is the
// distance between two actual points of the edges and only second-order sensitive to s.
inline double edge_edge_interior2(const Edge& e, const Edge& f) {
  const P3 n = cross(e.d, f.d);
  const double nn = norm2(n);
  if (!(nn > 0.0)) return std::numeric_limits<double>::infinity();  // parallel: endpoints decide
  const P3 r = f.a - e.a;
  const double s = dot(cross(r, f.d), n) / nn;
  if (!(s > 0.0 && s < 1.0)) return std::numeric_limits<double>::infinity();
  const P3 ps = e.a + s * e.d;
  const double t = dot(ps - f.a, f.d) * f.inv_dd;
  if (!(t > 0.0 && t < 1.0)) return std::numeric_limits<double>::infinity();
  return norm2(ps - (f.a + t * f.d));
}

// A triangle o + l1 e1 + l2 e2 prepared for projecting points: l1 = (p - o) · m1, l2 = (p - o) · m2
// with m1 = (e2 x n) / |n|^2, m2 = (n x e1) / |n|^2, n = e1 x e2 (scalar triple products of the
// barycentric formulas, hoisted out of the per-vertex work).
struct Face {
  P3 o, e1, e2, m1, m2;
  bool proper;  // |n| > 0; a degenerate triangle has no interior, its edges hold the minimum
};

inline Face make_face(const P3& o, const P3& e1, const P3& e2) {
  const P3 n = cross(e1, e2);
  const double nn = norm2(n);
  if (!(nn > 0.0)) return {o, e1, e2, {}, {}, false};
  const double inv = 1.0 / nn;
  return {o, e1, e2, inv * cross(e2, n), inv * cross(n, e1), true};
}

// Squared distance from p to the face when p projects inside it; +inf otherwise (the edges then
// hold the minimum). The foot point is rebuilt from l1, l2, so the result is an actual distance.
inline double point_face2(const P3& p, const Face& f) {
  const P3 w = p - f.o;
  const double l1 = dot(w, f.m1), l2 = dot(w, f.m2);
  if (!(l1 >= 0.0 && l2 >= 0.0 && l1 + l2 <= 1.0)) return std::numeric_limits<double>::infinity();
  return norm2(w - (l1 * f.e1 + l2 * f.e2));
}

// Squared distance between the closed triangles given relative to a0 (A[0] = 0), assuming they do
// not intersect. Stops as soon as a candidate is <= stop2 (returning that candidate).
double disjoint_distance2_relative(const P3 (&A)[3], const P3 (&B)[3], double stop2) {
  const Edge ea[3] = {make_edge(A[0], A[1]), make_edge(A[1], A[2]), make_edge(A[2], A[0])};
  const Edge eb[3] = {make_edge(B[0], B[1]), make_edge(B[1], B[2]), make_edge(B[2], B[0])};
  double best = std::numeric_limits<double>::infinity();
  // Vertex–edge (covers every edge pair whose minimum has an endpoint).
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      best = std::min(best, std::min(point_edge2(A[i], eb[j]), point_edge2(B[i], ea[j])));
    }
  if (best <= stop2) return best;
  // Edge–edge interiors.
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) best = std::min(best, edge_edge_interior2(ea[i], eb[j]));
  if (best <= stop2) return best;
  // Vertex–face interiors.
  const Face fa = make_face(A[0], ea[0].d, A[2] - A[0]);
  const Face fb = make_face(B[0], eb[0].d, B[2] - B[0]);
  if (fa.proper)
    for (const P3& v : B) best = std::min(best, point_face2(v, fa));
  if (fb.proper)
    for (const P3& v : A) best = std::min(best, point_face2(v, fb));
  return best;
}

// Disjoint closed sets are at a positive distance: keep "0 iff intersecting" even if it rounds.
inline double positive(double d) { return std::max(d, std::numeric_limits<double>::denorm_min()); }

// Distance between the closed triangles, assuming they do not intersect; stops as soon as a
// candidate is clearly <= stop (see triangles_within). Works relative to a0 so that the error
// scales with the triangles' extent, not their position. The candidates square lengths and the
// face and edge–edge terms take fourth powers, so a pair whose extent is far from 1 (fuzz_triangles
// found two points 3 x 2^-1074 apart whose squared distance underflowed to 0) is first scaled by a
// power of two to an extent near 1: exact, so nothing but the range changes, and pairs already in
// range are computed exactly as before.
double disjoint_distance(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                         const Vec3& b1, const Vec3& b2, double stop) {
  const Vec3* in[6] = {&a0, &a1, &a2, &b0, &b1, &b2};
  P3 R[6];
  double ext = 0.0;
  auto relative = [&](double pre) {
    const P3 o = pre * load(a0);
    ext = 0.0;
    for (int i = 0; i < 6; ++i) {
      R[i] = pre * load(*in[i]) - o;
      ext = std::max({ext, std::abs(R[i].x), std::abs(R[i].y), std::abs(R[i].z)});
    }
  };
  // A difference of finite coordinates overflows only beyond DBL_MAX / 2; a quarter of them cannot,
  // and dividing by 4 is exact except below the normal range, where it costs nothing at that extent.
  double pre = 1.0;
  relative(pre);
  if (!(ext <= std::numeric_limits<double>::max())) relative(pre = 0.25);
  int shift = 0;  // the result is scaled by 2^shift / pre
  if (ext > 0.0 && (ext < 0x1p-200 || ext > 0x1p200)) {
    shift = std::ilogb(ext);
    // Per component: 2^-shift itself is out of range for a subnormal extent.
    for (P3& r : R) r = {std::ldexp(r.x, -shift), std::ldexp(r.y, -shift), std::ldexp(r.z, -shift)};
  }
  // Powers of two throughout, applied in an order that overflows only when the value itself does.
  const double stop_scaled = std::ldexp(stop * pre, -shift);
  const double stop2 = stop_scaled * stop_scaled * (1.0 - 0x1p-50);
  const P3 A[3] = {R[0], R[1], R[2]}, B[3] = {R[3], R[4], R[5]};
  return positive(std::ldexp(std::sqrt(disjoint_distance2_relative(A, B, stop2)), shift) / pre);
}

// True when every vertex of (q0, q1, q2) is certainly farther than d from the plane of
// (p0, p1, p2), all on one side: then so is the whole triangle, and the pair is farther than d.
// Certain means for the exact values, not just the rounded ones: det = w · n is the orientation
// determinant of triangle_intersect.cpp, whose error is below 9u · perm (see the bound there), and
// |n_exact| <= |fl(n)| + 4u·|perm_n| (each component of n takes 4 roundings). So
// |fl(det)| - 9u·perm > d · (|fl(n)| + 4u·|perm_n|) · (1 + 8u) implies |det| > d · |n_exact|.
// Inputs must satisfy |x| <= 2^48 (checked by the caller), so nothing overflows or underflows badly.
// d is widened by 64u times the pair's extent, more than triangle_distance's rounding (measured
// below 1e-15 times the extent in the tests), so the early out never contradicts
// triangle_distance(...) <= d.
bool plane_separates(const P3& p0, const P3& p1, const P3& p2, const P3& q0, const P3& q1, const P3& q2,
                     double d) {
  constexpr double u = 0x1p-53;
  const P3 a = p1 - p0, b = p2 - p0;
  double ext = std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z), std::abs(b.x), std::abs(b.y), std::abs(b.z)});
  for (const P3* q : {&q0, &q1, &q2}) {
    const P3 w = *q - p0;
    ext = std::max({ext, std::abs(w.x), std::abs(w.y), std::abs(w.z)});
  }
  d += 64 * u * ext;
  const P3 n = cross(a, b);
  const P3 pn{std::abs(a.y * b.z) + std::abs(a.z * b.y), std::abs(a.z * b.x) + std::abs(a.x * b.z),
              std::abs(a.x * b.y) + std::abs(a.y * b.x)};
  // The error bound assumes no underflow: products of a sliver's subnormal edge with a long one,
  // and the squares in the norms, lose their relative precision (fuzz_triangles found a segment
  // against such a sliver at 2^37 judged 2.4e11 apart by this test with d above the distance). Such
  // a plane cannot separate anything reliably; leave the pair to the distance computation.
  if (std::max({pn.x, pn.y, pn.z}) < 0x1p-400) return false;
  const double n_up = (std::sqrt(norm2(n)) + 4 * u * std::sqrt(norm2(pn))) * (1 + 8 * u);
  const double limit = d * n_up;
  int sign = 0;
  for (const P3* q : {&q0, &q1, &q2}) {
    const P3 w = *q - p0;
    const double det = dot(w, n);
    const double perm = std::abs(w.x) * pn.x + std::abs(w.y) * pn.y + std::abs(w.z) * pn.z;
    const double margin = std::abs(det) - 9 * u * perm - 0x1p-1000;
    if (!(margin > limit)) return false;
    const int s = det > 0 ? 1 : -1;
    if (sign != 0 && s != sign) return false;
    sign = s;
  }
  return true;
}


}  // namespace

double triangle_distance(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                         const Vec3& b1, const Vec3& b2, TrianglePredicateStats& stats) {
  if (triangles_intersect(a0, a1, a2, b0, b1, b2, stats)) return 0.0;
  return disjoint_distance(a0, a1, a2, b0, b1, b2, 0.0);
}

double triangle_distance(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                         const Vec3& b1, const Vec3& b2) {
  TrianglePredicateStats stats;
  return triangle_distance(a0, a1, a2, b0, b1, b2, stats);
}

// triangle_distance(p, p, p, b0, b1, b2) without the intersection test and the terms a degenerate
// first triangle cannot contribute: the same candidates (p against B's edges and face, B's vertices
// against p), relative to p and scaled the same way, so the value agrees with it to the last bit
// wherever p is off the triangle (there a 0 becomes the smallest positive double, as there).
double point_triangle_distance(const Vec3& p, const Vec3& b0, const Vec3& b1, const Vec3& b2) {
  const P3 o = load(p);
  P3 B[3] = {load(b0) - o, load(b1) - o, load(b2) - o};
  double ext = 0.0;
  for (const P3& v : B) ext = std::max({ext, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  if (!(ext <= std::numeric_limits<double>::max()) || (ext > 0.0 && (ext < 0x1p-200 || ext > 0x1p200)))
    return triangle_distance(p, p, p, b0, b1, b2);  // rare ranges: the general path's scaling
  const P3 zero{0.0, 0.0, 0.0};
  const Edge eb[3] = {make_edge(B[0], B[1]), make_edge(B[1], B[2]), make_edge(B[2], B[0])};
  double best = std::numeric_limits<double>::infinity();
  for (int j = 0; j < 3; ++j) best = std::min({best, point_edge2(zero, eb[j]), norm2(B[j])});
  const Face fb = make_face(B[0], eb[0].d, B[2] - B[0]);
  if (fb.proper) best = std::min(best, point_face2(zero, fb));
  return positive(std::sqrt(best));
}

double triangle_distance_apart(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                               const Vec3& b1, const Vec3& b2) {
  return disjoint_distance(a0, a1, a2, b0, b1, b2, 0.0);
}

bool triangles_within(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                      const Vec3& b1, const Vec3& b2, double d, TrianglePredicateStats& stats) {
  assert(!std::isnan(d));
  if (!(d >= 0.0)) return false;
  // Boxes farther apart than d along an axis: the triangles are too.
  for (int k = 0; k < 3; ++k) {
    const double amin = std::min({a0[k], a1[k], a2[k]}), amax = std::max({a0[k], a1[k], a2[k]});
    const double bmin = std::min({b0[k], b1[k], b2[k]}), bmax = std::max({b0[k], b1[k], b2[k]});
    if (bmin - amax > d || amin - bmax > d) return false;
  }
  if (d == 0.0) return triangles_intersect(a0, a1, a2, b0, b1, b2, stats);
  // Either triangle's plane with the other wholly beyond d on one side. The bound behind it needs
  // |coordinates| <= 2^48; larger ones skip this early out.
  const P3 A[3] = {load(a0), load(a1), load(a2)}, B[3] = {load(b0), load(b1), load(b2)};
  double mag = 0.0;
  for (const P3& v : A) mag = std::max({mag, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  for (const P3& v : B) mag = std::max({mag, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  if (mag <= 0x1p48 && (plane_separates(A[0], A[1], A[2], B[0], B[1], B[2], d) ||
                        plane_separates(B[0], B[1], B[2], A[0], A[1], A[2], d)))
    return false;
  if (triangles_intersect(a0, a1, a2, b0, b1, b2, stats)) return true;
  // Stop early only when the candidate is clearly below d (squared, less 2^-50), so that the answer
  // is the one triangle_distance(...) <= d gives, to the last bit.
  return disjoint_distance(a0, a1, a2, b0, b1, b2, d) <= d;
}

}  // namespace cadclash
