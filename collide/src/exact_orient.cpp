// Exact orientation signs by expansion arithmetic (see exact_orient.h for the interface).
//
// Why the sign is exact. Notation: u = 2^-53, round to nearest even, IEEE double evaluated in SSE
// registers (FLT_EVAL_METHOD == 0, checked below), no FMA contraction (-ffp-contract=off on this
// file, collide/CMakeLists.txt) and no -ffast-math (checked below), so the compiler neither fuses
// nor reorders the operations the error-free transformations rely on.
//
//  1. Error-free transformations (Shewchuk 1997, Theorems 6-7 and 17-18; Dekker 1971): Two-Sum and
//     Two-Diff give x + y == a ± b exactly with x = fl(a ± b); Two-Product with Veltkamp's split
//     (splitter 2^27 + 1) gives x + y == a * b exactly with x = fl(a * b). These theorems assume an
//     unbounded exponent range. Overflow: all coordinates have |x| <= 2^48, so differences are
//     <= 2^49, a product of three is <= 2^147, the split operand (a product of two, <= 2^98) times
//     2^27 + 1 stays far below 2^1024, and a sum of at most 192 such terms is < 2^155.
//     Underflow: a nonzero coordinate has |x| >= 2^-300, so it is an integer multiple of
//     ulp(2^-300) = 2^-352. Every exact value the transformations form (differences of coordinates
//     and their parts, the split halves, products of at most three such factors, sums of those) is
//     then an integer multiple of 2^-1056, and a rounded result of an operation whose exact value is a
//     multiple of 2^-g is itself one (rounding goes to a coarser power-of-two grid). A multiple of
//     2^-1056 below 2^-1022 has at most 35 significant bits, so it is representable in the subnormal
//     range too: every operation rounds exactly as it would with an unbounded exponent, and the
//     theorems hold as stated.
//  2. Each difference is q.x - p.x = hi + lo (Two-Diff). The determinant is multilinear in its rows,
//     so det = Σ over the 6 signed monomials ± w_i a_j b_k, and each monomial is the sum of the at
//     most 8 products of one component of each factor. A product of three doubles is four doubles
//     exactly: Two-Product(a, b) = x + y, then Two-Product(x, c) and Two-Product(y, c).
//  3. The at most 6 x 8 x 4 = 192 doubles are summed by Grow-Expansion with zero elimination
//     (Shewchuk, Theorem 10): its result h_0 .. h_{n-1} is a nonoverlapping expansion in increasing
//     magnitude whose sum is exactly the sum of the inputs. Nonoverlapping components satisfy
//     |h_0 + ... + h_{n-2}| < |h_{n-1}| (each is smaller than the lowest set bit of the next), so the
//     sign of det is the sign of h_{n-1}, and det == 0 iff n == 0.
//  4. Fast path: when every difference is exact (all lo == 0) and, for M the largest |difference| and
//     2^E <= M < 2^(E+1), every difference is an integer multiple of 2^g with g = E - 15 >= -352
//     (so |difference| < 2^(g+16)), then the plain double evaluation has no rounding at all: a 2x2
//     product is a multiple of 2^2g below 2^(2g+32), a minor below 2^(2g+33), a term w_i * minor
//     below 2^(3g+49), the sum of three below 2^(3g+51): at most 51 significant bits each, and
//     2^(3g) >= 2^-1056 keeps them out of the subnormal gaps. Its sign is the exact sign. This is
//     the common case of lattice data (small integers times a power of two, at any offset).
#include "exact_orient.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>

#if defined(__FAST_MATH__)
#error "exact_orient.cpp: expansion arithmetic needs IEEE arithmetic; do not build with -ffast-math"
#endif
static_assert(FLT_EVAL_METHOD == 0, "exact_orient.cpp: needs double evaluated in double (SSE), not x87");

namespace cadclash::exact {
namespace {

inline bool supported(double x) {
  const double a = std::abs(x);
  return a <= kExactMaxCoord && (a >= kExactMinCoord || a == 0.0);  // NaN fails the first test
}

// x + y == a + b exactly, x = fl(a + b).
inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  const double br = b - bv;
  const double ar = a - av;
  y = ar + br;
}

// x + y == a - b exactly, x = fl(a - b).
inline void two_diff(double a, double b, double& x, double& y) {
  x = a - b;
  const double bv = a - x;
  const double av = x + bv;
  const double br = bv - b;
  const double ar = a - av;
  y = ar + br;
}

// a == hi + lo with hi and lo of at most 26 significant bits each (Veltkamp).
inline void split(double a, double& hi, double& lo) {
  constexpr double kSplitter = 134217729.0;  // 2^27 + 1
  const double c = kSplitter * a;
  const double abig = c - a;
  hi = c - abig;
  lo = a - hi;
}

// x + y == a * b exactly, x = fl(a * b) (Dekker).
inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  double ahi, alo, bhi, blo;
  split(a, ahi, alo);
  split(b, bhi, blo);
  const double err1 = x - ahi * bhi;
  const double err2 = err1 - alo * bhi;
  const double err3 = err2 - ahi * blo;
  y = alo * blo - err3;
}

// A nonoverlapping expansion, increasing magnitude, no zero components; its value is the exact sum
// of everything added. Capacity N >= the number of doubles added.
template <int N>
struct Expansion {
  double h[N];
  int n = 0;

  // Grow-Expansion with zero elimination (in place: h[k] is written after h[i], i >= k, is read).
  void add(double b) {
    double q = b;
    int k = 0;
    for (int i = 0; i < n; ++i) {
      double s, e;
      two_sum(q, h[i], s, e);
      q = s;
      if (e != 0.0) h[k++] = e;
    }
    if (q != 0.0) h[k++] = q;
    n = k;
  }

  // Adds a * b exactly (two doubles).
  void add_product(double a, double b) {
    double x, y;
    two_product(a, b, x, y);
    add(y);
    add(x);
  }

  // Adds a * b * c exactly (four doubles).
  void add_product(double a, double b, double c) {
    double x, y;
    two_product(a, b, x, y);
    double x1, x0;
    two_product(x, c, x1, x0);
    if (y != 0.0) {
      double y1, y0;
      two_product(y, c, y1, y0);
      add(y0);
      add(y1);
    }
    add(x0);
    add(x1);
  }

  int sign() const { return n == 0 ? 0 : (h[n - 1] > 0.0 ? 1 : -1); }
};

// A difference as hi + lo; count = 1 when lo == 0 (the components to multiply out).
struct Diff {
  double c[2];
  int count;
};

inline Diff diff(double a, double b) {
  Diff d;
  two_diff(a, b, d.c[0], d.c[1]);
  d.count = d.c[1] != 0.0 ? 2 : 1;
  return d;
}

inline int biased_exponent(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  return static_cast<int>((bits >> 52) & 0x7ff);
}

inline double power_of_two(int e) {  // 2^e, -1022 <= e <= 1023
  const std::uint64_t bits = static_cast<std::uint64_t>(e + 1023) << 52;
  double x;
  std::memcpy(&x, &bits, sizeof x);
  return x;
}

// True iff t is an integer, for |t| < 2^51: adding 1.5 * 2^52 rounds t to an integer (the sum lies
// in [2^52, 2^53), where the spacing is 1), subtracting it back is exact.
inline bool is_integer(double t) {
  constexpr double kMagic = 0x1.8p52;
  return (t + kMagic) - kMagic == t;
}

}  // namespace

namespace {

bool in_domain(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s) {
  for (const Pt3* v : {&p, &q, &r, &s})
    if (!supported(v->x) || !supported(v->y) || !supported(v->z)) return false;
  return true;
}

// Rows a = q - p, b = r - p, w = s - p, each coordinate as hi + lo.
struct Rows {
  Diff d[3][3];
};

Rows rows(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s) {
  return {{{diff(q.x, p.x), diff(q.y, p.y), diff(q.z, p.z)},
           {diff(r.x, p.x), diff(r.y, p.y), diff(r.z, p.z)},
           {diff(s.x, p.x), diff(s.y, p.y), diff(s.z, p.z)}}};
}

// The fast path (4. above), or kNoFastPath when it does not apply. Cheap to reject: the grid test on
// the rounded differences fails at once on data that is not a lattice; only then is it checked that
// the differences are exact (a rounded difference can lie on the grid too).
int grid_sign(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s) {
  const double d[9] = {q.x - p.x, q.y - p.y, q.z - p.z, r.x - p.x, r.y - p.y, r.z - p.z, s.x - p.x, s.y - p.y, s.z - p.z};
  double m = 0.0;
  for (const double x : d) m = std::max(m, std::abs(x));
  if (m == 0.0) return 0;  // fl(a - b) == 0 iff a == b: all four points equal
  const int g = biased_exponent(m) - 1023 - 15;
  if (g < -352) return kNoFastPath;
  const double scale = power_of_two(-g);
  for (const double x : d)
    if (!is_integer(x * scale)) return kNoFastPath;
  const Pt3* const from[3] = {&q, &r, &s};
  for (int i = 0; i < 3; ++i) {
    double hi, lo;
    two_diff(from[i]->x, p.x, hi, lo);
    if (lo != 0.0) return kNoFastPath;
    two_diff(from[i]->y, p.y, hi, lo);
    if (lo != 0.0) return kNoFastPath;
    two_diff(from[i]->z, p.z, hi, lo);
    if (lo != 0.0) return kNoFastPath;
  }
  const double ax = d[0], ay = d[1], az = d[2], bx = d[3], by = d[4], bz = d[5], wx = d[6], wy = d[7], wz = d[8];
  const double det = wx * (ay * bz - az * by) + wy * (az * bx - ax * bz) + wz * (ax * by - ay * bx);
  return (det > 0.0) - (det < 0.0);
}

// The expansion (1.-3. above).
int expansion_sign(const Rows& o) {
  const auto& d = o.d;
  // det = w . (a x b) = Σ sign * w_i a_j b_k over the 6 permutations (i, j, k).
  struct Monomial {
    int i, j, k;
    double sign;
  };
  static constexpr Monomial kMonomials[6] = {{0, 1, 2, 1.0}, {0, 2, 1, -1.0}, {1, 2, 0, 1.0},
                                             {1, 0, 2, -1.0}, {2, 0, 1, 1.0}, {2, 1, 0, -1.0}};
  Expansion<6 * 8 * 4> e;
  for (const Monomial& mo : kMonomials) {
    const Diff &w = d[2][mo.i], &a = d[0][mo.j], &b = d[1][mo.k];
    for (int x = 0; x < w.count; ++x) {
      if (w.c[x] == 0.0) continue;
      for (int y = 0; y < a.count; ++y) {
        if (a.c[y] == 0.0) continue;
        for (int z = 0; z < b.count; ++z) {
          if (b.c[z] == 0.0) continue;
          e.add_product(mo.sign * w.c[x], a.c[y], b.c[z]);
        }
      }
    }
  }
  return e.sign();
}

}  // namespace

int orient3d_fast_sign(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s) {
  if (!in_domain(p, q, r, s)) return kUnsupported;
  return grid_sign(p, q, r, s);
}

int orient3d_exact_sign(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s) {
  if (!in_domain(p, q, r, s)) return kUnsupported;
  const int fast = grid_sign(p, q, r, s);
  return fast != kNoFastPath ? fast : expansion_sign(rows(p, q, r, s));
}

int orient3d_expansion_sign(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s) {
  if (!in_domain(p, q, r, s)) return kUnsupported;
  return expansion_sign(rows(p, q, r, s));
}

int orient2d_exact_sign(const Pt2& a, const Pt2& b, const Pt2& c) {
  for (const Pt2* v : {&a, &b, &c})
    if (!supported(v->x) || !supported(v->y)) return kUnsupported;
  // det = (b.x - a.x)(c.y - a.y) - (b.y - a.y)(c.x - a.x), each factor as hi + lo: at most
  // 2 x 4 products of two doubles, 2 doubles each (1.-3. above with two factors instead of three).
  const Diff f[2][2] = {{diff(b.x, a.x), diff(c.y, a.y)}, {diff(b.y, a.y), diff(c.x, a.x)}};
  Expansion<2 * 4 * 2> e;
  for (int m = 0; m < 2; ++m) {
    const double sign = m == 0 ? 1.0 : -1.0;
    const Diff &u = f[m][0], &v = f[m][1];
    for (int x = 0; x < u.count; ++x) {
      if (u.c[x] == 0.0) continue;
      for (int y = 0; y < v.count; ++y) {
        if (v.c[y] == 0.0) continue;
        e.add_product(sign * u.c[x], v.c[y]);
      }
    }
  }
  return e.sign();
}

}  // namespace cadclash::exact
