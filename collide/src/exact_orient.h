// Exact orientation signs on doubles: the last stage of triangles_intersect's orientation tests
// (triangle_intersect.cpp), after the double and long-double filters. Our own small implementation
// of Shewchuk's error-free transformations ("Adaptive Precision Floating-Point Arithmetic and Fast
// Robust Geometric Predicates", 1997): Two-Diff, Two-Sum, and Two-Product by Dekker/Veltkamp
// splitting (no FMA: the file is compiled with -ffp-contract=off and std::fma is not used), summed
// into a nonoverlapping expansion whose largest component carries the sign.
//
// The answer is the exact sign of the determinant of the given doubles, including 0, on the domain
// below; outside it the functions return kUnsupported (the caller asks CGAL instead). The domain
// keeps every intermediate value of the expansion arithmetic a representable double: no overflow
// (|x| <= 2^48 bounds every product by 2^150 and every split operand by 2^100) and no underflow
// (a nonzero |x| >= 2^-300 is a multiple of 2^-352, so every exact product of three differences is
// a multiple of 2^-1056, above the subnormal spacing 2^-1074; see exact_orient.cpp).
//
// Internal to cadclash::collide (collide/src), exposed to the white-box tests only.
#pragma once

namespace cadclash::exact {

struct Pt3 {
  double x, y, z;
};

struct Pt2 {
  double x, y;
};

// Returned instead of a sign when a coordinate is outside the supported domain.
inline constexpr int kUnsupported = 2;
// Returned by orient3d_fast_sign when its fast path does not apply.
inline constexpr int kNoFastPath = 3;

// The supported domain of one coordinate: 0, or 2^-300 <= |x| <= 2^48 (NaN is outside).
inline constexpr double kExactMaxCoord = 0x1p48;
inline constexpr double kExactMinCoord = 0x1p-300;

// Sign (-1, 0, +1) of det[q - p; r - p; s - p] = (s - p) . ((q - p) x (r - p)), the sign CGAL's
// orientation(p, q, r, s) gives (positive: s on the side the normal of the counterclockwise p, q, r
// points to); kUnsupported outside the domain. Tries, in order: an exact double evaluation when the
// differences are exact and lie on a common grid of at most 16 bits (lattice data), then the
// expansion of the determinant with exact differences (24 products), then the general expansion
// where the differences themselves need two doubles (at most 192 products).
int orient3d_exact_sign(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s);

// The stages of orient3d_exact_sign on their own. orient3d_fast_sign: the exact sign when the
// lattice fast path applies (or when all four points coincide), kNoFastPath otherwise (cheap: 9
// Two-Diffs and 9 integer tests; triangles_intersect tries it before its long-double stage, which it
// is cheaper than). orient3d_expansion_sign: the expansion alone, never the fast path (exact
// everywhere in the domain; used by tests to check each stage against the other).
int orient3d_fast_sign(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s);
int orient3d_expansion_sign(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s);

// Sign (-1, 0, +1) of (b - a) x (c - a) = (b.x - a.x)(c.y - a.y) - (b.y - a.y)(c.x - a.x), CGAL's
// orientation(a, b, c) in 2D (positive: counterclockwise); kUnsupported outside the domain.
int orient2d_exact_sign(const Pt2& a, const Pt2& b, const Pt2& c);

}  // namespace cadclash::exact
