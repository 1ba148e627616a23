#include "test_triangle_cases.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/intersections.h>

#include <Eigen/Geometry>

#include <utility>

namespace cadclash::test {
namespace {

// Shuffles vertex order and swaps the triangles, so no generator favours one argument position.
TriPair shuffle(TriPair p, Rng& rng) {
  for (Tri* t : {&p.a, &p.b}) {
    const int r = rng.integer(0, 5);
    if (r & 1) std::swap((*t)[1], (*t)[2]);
    for (int k = 0; k < r / 2; ++k) std::swap((*t)[0], (*t)[1]), std::swap((*t)[1], (*t)[2]);
  }
  if (rng.integer(0, 1)) std::swap(p.a, p.b);
  return p;
}

// Multiplies by 2^k and adds an integer offset: exact for the small lattice coordinates used here.
TriPair exact_scale_shift(TriPair p, Rng& rng) {
  const double s = std::ldexp(1.0, rng.integer(-20, 20));
  const Vec3 t = rng.integer(0, 1) ? Vec3::Zero() : Vec3(rng.ivec(-100000000, 100000000));
  for (Tri* tri : {&p.a, &p.b})
    for (Vec3& v : *tri) v = v * s + t;
  return p;
}

Vec3 lattice_normal_pair(Rng& rng, Vec3& u, Vec3& v) {
  for (;;) {
    u = rng.ivec(-4, 4);
    v = rng.ivec(-4, 4);
    const Vec3 n = u.cross(v);
    if (n.squaredNorm() > 0) return n;
  }
}

TriPair coplanar_grid(Rng& rng) {
  Vec3 u, v;
  lattice_normal_pair(rng, u, v);
  // A third in a coordinate plane, the common CAD contact (faces on z = c).
  if (rng.integer(0, 2) == 0) {
    const int axis = rng.integer(0, 2);
    do {
      u = rng.ivec(-4, 4);
      v = rng.ivec(-4, 4);
      u[axis] = v[axis] = 0;
    } while (u.cross(v).squaredNorm() == 0);
  }
  const Vec3 o = rng.ivec(-100, 100);
  auto pt = [&] { return Vec3(o + rng.integer(-6, 6) * u + rng.integer(-6, 6) * v); };
  return exact_scale_shift({{pt(), pt(), pt()}, {pt(), pt(), pt()}}, rng);
}

TriPair shared_feature(Rng& rng) {
  TriPair p;
  const bool lattice = rng.integer(0, 1);
  for (Vec3& x : p.a) x = lattice ? rng.ivec(-50, 50) : rng.vec(0, 1);
  const int shared = rng.integer(1, 2);
  for (int i = 0; i < 3; ++i) {
    if (i < shared) {
      p.b[i] = p.a[i];
    } else if (lattice && rng.integer(0, 1)) {  // exactly on A's plane
      p.b[i] = p.a[0] + rng.integer(-3, 3) * (p.a[1] - p.a[0]) + rng.integer(-3, 3) * (p.a[2] - p.a[0]);
    } else {
      p.b[i] = lattice ? rng.ivec(-50, 50) : rng.vec(0, 1);
    }
  }
  if (lattice) p = exact_scale_shift(p, rng);
  // A third of the cases nearly share: one coordinate of the shared vertex moves by 1-4 ulps.
  if (rng.integer(0, 2) == 0) {
    double& c = p.b[0][rng.integer(0, 2)];
    const double dir = rng.integer(0, 1) ? HUGE_VAL : -HUGE_VAL;
    for (int k = rng.integer(1, 4); k > 0; --k) c = std::nextafter(c, dir);
  }
  return p;
}

TriPair touching_grid(Rng& rng) {
  TriPair p;
  Vec3 n;
  do {
    for (Vec3& x : p.a) x = rng.ivec(-20, 20);
    n = (p.a[1] - p.a[0]).cross(p.a[2] - p.a[0]);
  } while (n.squaredNorm() == 0);
  const Vec3 e1 = p.a[1] - p.a[0], e2 = p.a[2] - p.a[0];
  for (Vec3& x : p.a) x *= 4;
  // A point of A's plane with lattice barycentrics (i, j)/4: on an edge, inside, or just outside.
  auto on_plane = [&] {
    const int i = rng.integer(-1, 5), j = rng.integer(-1, 5 - std::max(i, 0));
    return Vec3(p.a[0] + i * e1 + j * e2);
  };
  const Vec3 t = on_plane();
  const int side = rng.integer(0, 1) ? 1 : -1;
  auto off = [&](int s) { return Vec3(t + s * rng.integer(1, 3) * n + rng.ivec(-30, 30)); };
  switch (rng.integer(0, 2)) {
    case 0:  // one vertex on the plane, both others on one side
      p.b = {t, off(side), off(side)};
      break;
    case 1:  // an edge in the plane
      p.b = {t, on_plane(), off(side)};
      break;
    default:  // crossing through the point
      p.b = {t, off(side), off(-side)};
      break;
  }
  return exact_scale_shift(p, rng);
}

TriPair far_offset(Rng& rng) {
  const Vec3 o(1e8 + rng.uniform(0, 1e3), -1e8 - rng.uniform(0, 1e3), 1e8 + rng.uniform(0, 1e3));
  TriPair p;
  for (Vec3& x : p.a) x = o + 1e-3 * rng.vec(-1, 1);
  if (rng.integer(0, 2) == 0) {  // B near A's plane: affine combinations of A's vertices, rounded
    for (Vec3& x : p.b) {
      const double s = rng.uniform(-1, 2), t = rng.uniform(-1, 2);
      x = p.a[0] + s * (p.a[1] - p.a[0]) + t * (p.a[2] - p.a[0]);
    }
  } else {
    for (Vec3& x : p.b) x = o + 1e-3 * rng.vec(-1, 1);
  }
  return p;
}

Tri sliver(Rng& rng, double len) {
  const Vec3 p = rng.vec(-1, 1);
  const Vec3 d = rng.unit();
  const Vec3 e = d.cross(rng.unit()).normalized();
  const double eps = 1e-12 * rng.uniform(0.5, 2);
  if (rng.integer(0, 1)) return {p, Vec3(p + len * d), Vec3(p + len * (d + eps * e))};  // needle
  return {p, Vec3(p + len * d), Vec3(p + 0.5 * len * d + len * eps * e)};               // cap
}

TriPair sliver_case(Rng& rng) {
  TriPair p;
  const double len = rng.uniform(0.1, 2);
  p.a = sliver(rng, len);
  const Vec3 c = p.a[0] + rng.uniform(0, 1) * (p.a[1] - p.a[0]);
  if (rng.integer(0, 3) == 0) {
    p.b = sliver(rng, len);
    const Vec3 shift = c - p.b[0] + 1e-6 * rng.vec(-1, 1);
    for (Vec3& x : p.b) x += shift;
  } else {
    for (Vec3& x : p.b) x = c + 0.5 * len * rng.vec(-1, 1);
  }
  return p;
}

TriPair ulp_perturbed(Rng& rng) {
  TriPair p = rng.integer(0, 1) ? coplanar_grid(rng) : touching_grid(rng);
  Tri& t = rng.integer(0, 1) ? p.a : p.b;
  Vec3& v = t[rng.integer(0, 2)];
  double& c = v[rng.integer(0, 2)];
  const double dir = rng.integer(0, 1) ? HUGE_VAL : -HUGE_VAL;
  for (int k = rng.integer(1, 4); k > 0; --k) c = std::nextafter(c, dir);
  return p;
}

Tri degenerate_tri(Rng& rng) {
  const Vec3 o = rng.ivec(-6, 6);
  const Vec3 u = rng.ivec(-3, 3);
  switch (rng.integer(0, 3)) {
    case 0:
      return {o, Vec3(o + rng.integer(-3, 3) * u), Vec3(o + rng.integer(-3, 3) * u)};  // collinear
    case 1:
      return {o, o, Vec3(o + u)};  // repeated vertex
    case 2:
      return {o, o, o};  // a point
    default: {  // a proper lattice triangle
      Tri t{o, rng.ivec(-6, 6), rng.ivec(-6, 6)};
      return t;
    }
  }
}

TriPair degenerate_case(Rng& rng) {
  TriPair p{degenerate_tri(rng), degenerate_tri(rng)};
  return exact_scale_shift(p, rng);
}

}  // namespace

std::string_view family_name(Family f) {
  switch (f) {
    case Family::RandomCube: return "random_cube";
    case Family::RandomNear: return "random_near";
    case Family::CoplanarGrid: return "coplanar_grid";
    case Family::SharedFeature: return "shared_feature";
    case Family::TouchingGrid: return "touching_grid";
    case Family::FarOffset: return "far_offset";
    case Family::Sliver: return "sliver";
    case Family::UlpPerturbed: return "ulp_perturbed";
    case Family::Degenerate: return "degenerate";
    case Family::RigidMotion: return "rigid_motion";
    case Family::kCount: break;
  }
  return "?";
}

TriPair rigid_motion(const TriPair& p, Rng& rng, double max_shift) {
  Eigen::Quaterniond q(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
  if (q.norm() < 1e-3) q = Eigen::Quaterniond(1, 0, 0, 0);
  q.normalize();
  const Eigen::Matrix3d r = q.toRotationMatrix();
  const Vec3 t = max_shift * rng.vec(-1, 1);
  TriPair out;
  for (int i = 0; i < 3; ++i) {
    out.a[i] = r * p.a[i] + t;
    out.b[i] = r * p.b[i] + t;
  }
  return out;
}

TriPair make_case(Family f, Rng& rng) {
  TriPair p;
  switch (f) {
    case Family::RandomCube:
      p = {{rng.vec(0, 1), rng.vec(0, 1), rng.vec(0, 1)}, {rng.vec(0, 1), rng.vec(0, 1), rng.vec(0, 1)}};
      break;
    case Family::RandomNear: {
      const Vec3 c = rng.vec(0, 1);
      const Vec3 c2 = c + 0.2 * rng.uniform() * rng.unit();
      for (Vec3& x : p.a) x = c + 0.1 * rng.vec(-1, 1);
      for (Vec3& x : p.b) x = c2 + 0.1 * rng.vec(-1, 1);
      break;
    }
    case Family::CoplanarGrid: p = coplanar_grid(rng); break;
    case Family::SharedFeature: p = shared_feature(rng); break;
    case Family::TouchingGrid: p = touching_grid(rng); break;
    case Family::FarOffset: p = far_offset(rng); break;
    case Family::Sliver: p = sliver_case(rng); break;
    case Family::UlpPerturbed: p = ulp_perturbed(rng); break;
    case Family::Degenerate: p = degenerate_case(rng); break;
    case Family::RigidMotion: {
      const auto inner = static_cast<Family>(rng.integer(0, static_cast<int>(Family::RigidMotion) - 1));
      const double shift = std::pow(10.0, rng.uniform(0, 8));
      p = rigid_motion(make_case(inner, rng), rng, shift);
      break;
    }
    case Family::kCount: break;
  }
  return shuffle(p, rng);
}

// ---------------------------------------------------------------------------------------------
// Oracle
// ---------------------------------------------------------------------------------------------

namespace {
using EK = CGAL::Exact_predicates_exact_constructions_kernel;
using EPoint = EK::Point_3;

struct EShape {
  int dim = 2;  // 0 point, 1 segment, 2 triangle
  EPoint p[3];
};

EShape exact_shape(const Tri& t) {
  EShape s;
  for (int i = 0; i < 3; ++i) s.p[i] = EPoint(t[i].x(), t[i].y(), t[i].z());
  if (!CGAL::collinear(s.p[0], s.p[1], s.p[2])) return s;
  // Collinear: the segment between the two vertices farthest apart.
  int bi = 0, bj = 1;
  EK::FT best = CGAL::squared_distance(s.p[0], s.p[1]);
  for (auto [i, j] : {std::pair{0, 2}, std::pair{1, 2}}) {
    const EK::FT d = CGAL::squared_distance(s.p[i], s.p[j]);
    if (d > best) best = d, bi = i, bj = j;
  }
  const EPoint a = s.p[bi], b = s.p[bj];
  s.p[0] = a;
  s.p[1] = b;
  s.dim = (best == 0) ? 0 : 1;
  return s;
}
}  // namespace

bool oracle_intersect(const Tri& ta, const Tri& tb) {
  EShape a = exact_shape(ta), b = exact_shape(tb);
  if (a.dim < b.dim) std::swap(a, b);
  const EK::Triangle_3 at(a.p[0], a.p[1], a.p[2]);
  const EK::Segment_3 as(a.p[0], a.p[1]);
  switch (a.dim * 3 + b.dim) {
    case 8: return CGAL::do_intersect(at, EK::Triangle_3(b.p[0], b.p[1], b.p[2]));
    case 7: return CGAL::do_intersect(at, EK::Segment_3(b.p[0], b.p[1]));
    case 6: return CGAL::do_intersect(at, b.p[0]);
    case 4: return CGAL::do_intersect(as, EK::Segment_3(b.p[0], b.p[1]));
    case 3: return CGAL::do_intersect(as, b.p[0]);
    default: return a.p[0] == b.p[0];
  }
}

}  // namespace cadclash::test
