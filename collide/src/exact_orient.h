// Exact orientation signs on doubles: the last stage of triangles_intersect's orientation tests
// (triangle_intersect.cpp), for the signs its double filter leaves open. They are CGAL's filtered
// predicates (Epick): a static filter, then interval arithmetic (whose bound follows the rounding
// the data actually incurs: exact products of short mantissas leave no width), then exact
// multiprecision arithmetic only where the interval still contains 0. Defined in
// triangle_exact.cpp, the one CGAL object of the collide module (CGAL needs -frounding-math there).
//
// Own expansion arithmetic (Shewchuk's Two-Sum / Two-Product, with a lattice fast path and a long
// double stage in front) was built and measured in this place: on as1's real contacts it cost +1 %
// (0.1 mm) and +2.2 % (0.001 mm) of a whole Scene::check against CGAL's whole-call fallback, while
// these predicates take -2.1 % and -4.9 %: most open signs of real contacts are certified by the
// interval stage, which a static bound cannot do.
//
// Internal to cadclash::collide (collide/src).
#pragma once

namespace cadclash::exact {

struct Pt3 {
  double x, y, z;
};

struct Pt2 {
  double x, y;
};

// Sign (-1, 0, +1) of det[q - p; r - p; s - p] = (s - p) . ((q - p) x (r - p)), exactly, for any
// finite doubles: CGAL's orientation(p, q, r, s) (positive: s on the side the normal of the
// counterclockwise p, q, r points to).
int orient3d_sign(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s);

// Sign (-1, 0, +1) of (b - a) x (c - a), exactly, for any finite doubles: CGAL's orientation(a, b, c)
// in 2D (positive: counterclockwise).
int orient2d_sign(const Pt2& a, const Pt2& b, const Pt2& c);

}  // namespace cadclash::exact
