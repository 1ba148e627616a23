// The exact triangle–triangle decision for degenerate triangles (CGAL's filtered exact predicates,
// EPICK), which triangle_intersect.cpp falls back to, and the exact orientation signs its own
// decision asks for (exact_orient.h). Kept in its own object library because CGAL needs
// -frounding-math, which would slow down the rest of the collide module.
#include "cadclash/geometry.h"
#include "exact_orient.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Intersections_3/Point_3_Segment_3.h>
#include <CGAL/Intersections_3/Point_3_Triangle_3.h>
#include <CGAL/Intersections_3/Segment_3_Triangle_3.h>
#include <CGAL/Intersections_3/Triangle_3_Triangle_3.h>

#include <utility>

namespace cadclash {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Segment = K::Segment_3;
using Triangle = K::Triangle_3;

// The point set of a closed triangle: a point (dim 0), a segment (dim 1) or a proper triangle (dim 2).
// CGAL's do_intersect overloads require non-degenerate arguments, so degenerate triangles are
// reduced to what they are first.
struct Simplex {
  int dim = 2;
  Point p[3];
};

Simplex classify(const Vec3& a, const Vec3& b, const Vec3& c) {
  Simplex s;
  s.p[0] = Point(a.x(), a.y(), a.z());
  s.p[1] = Point(b.x(), b.y(), b.z());
  s.p[2] = Point(c.x(), c.y(), c.z());
  if (!CGAL::collinear(s.p[0], s.p[1], s.p[2])) return s;
  // The vertices lie exactly on one line, along which the lexicographic order of coordinates is
  // monotone: the extremes in that order are the ends of the segment.
  int lo = 0, hi = 0;
  for (int i = 1; i < 3; ++i) {
    if (CGAL::compare_xyz(s.p[i], s.p[lo]) == CGAL::SMALLER) lo = i;
    if (CGAL::compare_xyz(s.p[i], s.p[hi]) == CGAL::LARGER) hi = i;
  }
  const Point plo = s.p[lo], phi = s.p[hi];
  s.p[0] = plo;
  s.p[1] = phi;
  s.dim = (plo == phi) ? 0 : 1;
  return s;
}

// CGAL's Segment_3/Segment_3 do_intersect goes through Line_3 constructions, which are rounded
// with EPICK; this version uses predicates only. Precondition: p != q, r != s.
bool segments_intersect(const Point& p, const Point& q, const Point& r, const Point& s) {
  if (!CGAL::coplanar(p, q, r, s)) return false;
  const bool r_on_pq = CGAL::collinear(p, q, r);
  const bool s_on_pq = CGAL::collinear(p, q, s);
  if (r_on_pq && s_on_pq) {  // all four on one line: do the intervals overlap?
    return CGAL::collinear_are_ordered_along_line(p, r, q) ||
           CGAL::collinear_are_ordered_along_line(p, s, q) ||
           CGAL::collinear_are_ordered_along_line(r, p, s);
  }
  // Coplanar, not all collinear. Side of s with respect to line pq, measured against a point of
  // rs that is off the line (r, or s when r is on it).
  const Point& off_pq = r_on_pq ? s : r;
  const Point& other_rs = r_on_pq ? r : s;
  if (CGAL::coplanar_orientation(p, q, off_pq, other_rs) == CGAL::POSITIVE) return false;
  // Line pq meets segment rs. p and q cannot both lie on line rs (that line would then be line pq,
  // which holds a point off it), so one of them is a reference.
  const bool p_on_rs = CGAL::collinear(r, s, p);
  const Point& off_rs = p_on_rs ? q : p;
  const Point& other_pq = p_on_rs ? p : q;
  return CGAL::coplanar_orientation(r, s, off_rs, other_pq) != CGAL::POSITIVE;
}

bool simplices_intersect(const Simplex& a, const Simplex& b) {
  if (a.dim < b.dim) return simplices_intersect(b, a);
  switch (a.dim * 3 + b.dim) {
    case 2 * 3 + 2:
      return CGAL::do_intersect(Triangle(a.p[0], a.p[1], a.p[2]), Triangle(b.p[0], b.p[1], b.p[2]));
    case 2 * 3 + 1:
      return CGAL::do_intersect(Triangle(a.p[0], a.p[1], a.p[2]), Segment(b.p[0], b.p[1]));
    case 2 * 3 + 0:
      return CGAL::do_intersect(Triangle(a.p[0], a.p[1], a.p[2]), b.p[0]);
    case 1 * 3 + 1:
      return segments_intersect(a.p[0], a.p[1], b.p[0], b.p[1]);
    case 1 * 3 + 0:
      return CGAL::do_intersect(Segment(a.p[0], a.p[1]), b.p[0]);
    default:
      return a.p[0] == b.p[0];
  }
}

}  // namespace

bool triangles_intersect_exact(const Vec3& a0, const Vec3& a1, const Vec3& a2,
                               const Vec3& b0, const Vec3& b1, const Vec3& b2) {
  return simplices_intersect(classify(a0, a1, a2), classify(b0, b1, b2));
}

}  // namespace cadclash

namespace cadclash::exact {

int orient3d_sign(const Pt3& p, const Pt3& q, const Pt3& r, const Pt3& s) {
  using P = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  return static_cast<int>(CGAL::orientation(P(p.x, p.y, p.z), P(q.x, q.y, q.z), P(r.x, r.y, r.z), P(s.x, s.y, s.z)));
}

int orient2d_sign(const Pt2& a, const Pt2& b, const Pt2& c) {
  using P = CGAL::Exact_predicates_inexact_constructions_kernel::Point_2;
  return static_cast<int>(CGAL::orientation(P(a.x, a.y), P(b.x, b.y), P(c.x, c.y)));
}

}  // namespace cadclash::exact
