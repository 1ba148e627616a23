#include "test_triangle_cases.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/exceptions.h>
#include <CGAL/intersections.h>

#include <Eigen/Geometry>

#include <functional>
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

TriPair coplanar_grid_local(Rng& rng) {
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
  return {{pt(), pt(), pt()}, {pt(), pt(), pt()}};
}

TriPair coplanar_grid(Rng& rng) { return exact_scale_shift(coplanar_grid_local(rng), rng); }

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

TriPair touching_grid_local(Rng& rng) {
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
  return p;
}

TriPair touching_grid(Rng& rng) { return exact_scale_shift(touching_grid_local(rng), rng); }

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


// --- numerical extremes ---

// Offsets of 1e3..1e12 (each axis signed independently) with features of 1e-3..1e-9 of the offset.
TriPair offset_feature(Rng& rng) {
  const double offset = std::pow(10.0, rng.integer(3, 12)) * rng.uniform(1, 9.99);
  const double feature = offset * std::pow(10.0, -rng.integer(3, 9));
  Vec3 o;
  for (int k = 0; k < 3; ++k) {
    const double sign = rng.integer(0, 1) ? 1 : -1;
    o[k] = sign * offset * (k == 0 ? 1.0 : rng.uniform(0.1, 1));
  }
  TriPair p;
  switch (rng.integer(0, 3)) {
    case 0:  // two small triangles near each other
      for (Vec3& x : p.a) x = o + feature * rng.vec(-1, 1);
      for (Vec3& x : p.b) x = o + feature * (rng.vec(-1, 1) + 0.5 * rng.unit());
      break;
    case 1:  // B from affine combinations of A's vertices: coplanar up to the rounding at the offset
      for (Vec3& x : p.a) x = o + feature * rng.vec(-1, 1);
      for (Vec3& x : p.b) {
        const double s = rng.uniform(-1, 2), t = rng.uniform(-1, 2);
        x = p.a[0] + s * (p.a[1] - p.a[0]) + t * (p.a[2] - p.a[0]);
      }
      break;
    case 2: {  // a vertex of B on a point of A's edge or face (rounded), B crossing or on one side
      for (Vec3& x : p.a) x = o + feature * rng.vec(-1, 1);
      const Vec3 n = (p.a[1] - p.a[0]).cross(p.a[2] - p.a[0]).normalized();
      const double s = rng.uniform(0, 1), t = rng.integer(0, 1) ? 0.0 : rng.uniform(0, 1 - s);
      const Vec3 q = p.a[0] + s * (p.a[1] - p.a[0]) + t * (p.a[2] - p.a[0]);
      const double side = rng.integer(0, 1) ? 1 : -1;
      p.b = {q, Vec3(q + feature * (side * n + rng.vec(-1, 1))),
             Vec3(q + feature * ((rng.integer(0, 2) ? side : -side) * n + rng.vec(-1, 1)))};
      break;
    }
    default: {  // exact lattice contact at the offset: coordinates k * 2^e + offset, all representable
      // Lattice steps of 2^e <= feature / 256: offset / 2^e < 2^39 and lattice coordinates < 2^14,
      // so every coordinate is an exact double.
      const int e = static_cast<int>(std::floor(std::log2(feature))) - 8;
      const double unit = std::ldexp(1.0, e);
      const Vec3 base(std::round(o.x() / unit) * unit, std::round(o.y() / unit) * unit, std::round(o.z() / unit) * unit);
      p = rng.integer(0, 1) ? coplanar_grid_local(rng) : touching_grid_local(rng);
      for (Tri* tri : {&p.a, &p.b})
        for (Vec3& v : *tri) v = base + unit * v;
      break;
    }
  }
  return p;
}

// A triangle in A's plane (overlapping A or beside it), rotated by 1e-15..1e-6 rad about an axis
// in A's plane; the rotated vertices are rounded, as a CAD kernel's output would be.
TriPair nearly_coplanar(Rng& rng) {
  const double scale = std::pow(10.0, rng.integer(-2, 3));
  const Vec3 o = rng.integer(0, 1) ? Vec3::Zero() : Vec3(std::pow(10.0, rng.integer(1, 4)) * rng.vec(-1, 1));
  TriPair p;
  for (Vec3& x : p.a) x = o + scale * rng.vec(-1, 1);
  const Vec3 e1 = p.a[1] - p.a[0], e2 = p.a[2] - p.a[0];
  const Vec3 n = e1.cross(e2).normalized();
  auto in_plane = [&](double lo, double hi) {
    const double s = rng.uniform(lo, hi), t = rng.uniform(lo, hi);
    return Vec3(p.a[0] + s * e1 + t * e2);
  };
  Tri b{in_plane(-0.5, 1.5), in_plane(-0.5, 1.5), in_plane(-0.5, 1.5)};
  const Vec3 pivot = in_plane(-0.2, 1.2);
  const Vec3 axis_dir = (rng.unit().cross(n)).normalized();
  const double angle = (rng.integer(0, 1) ? 1 : -1) * std::pow(10.0, rng.uniform(-15, -6));
  const Eigen::AngleAxisd rot(angle, axis_dir);
  for (Vec3& x : b) x = pivot + rot * (x - pivot);
  p.b = b;
  return p;
}

// A T-junction: B's vertex on the inside of an edge of A. Lattice cases are exact (the vertex is
// exactly on the edge); the rest round it onto the edge. B then lies in A's plane on the far side of
// the edge (the mesh T-junction), overlaps A, runs along the edge, or leaves the plane.
TriPair t_junction(Rng& rng) {
  TriPair p;
  Vec3 n;
  const bool lattice = rng.integer(0, 2) != 0;
  do {
    for (Vec3& x : p.a) x = lattice ? rng.ivec(-20, 20) : rng.vec(-1, 1);
    n = (p.a[1] - p.a[0]).cross(p.a[2] - p.a[0]);
  } while (n.squaredNorm() == 0);
  const int k = rng.integer(0, 2);
  const Vec3 a = p.a[k], b = p.a[(k + 1) % 3], c = p.a[(k + 2) % 3];
  // Lattice: scale A by 8 so that the points at i/8 of the edge are lattice points.
  const double s8 = lattice ? 8 : 1;
  for (Vec3& x : p.a) x *= s8;
  const int i = rng.integer(1, 7);
  const Vec3 t = lattice ? Vec3(8 * a + i * (b - a)) : Vec3(a + rng.uniform(0.05, 0.95) * (b - a));
  const Vec3 away = lattice ? Vec3(8 * (a + b) / 2 - 8 * c) : Vec3((a + b) / 2 - c);  // in-plane, across the edge
  const Vec3 along = lattice ? Vec3(b - a) : Vec3(b - a);
  const Vec3 up = lattice ? n : n.normalized();
  switch (rng.integer(0, 3)) {
    case 0:  // mesh T-junction: B across the edge, in A's plane, meeting it at t and along the edge
      p.b = {t, Vec3(t + rng.integer(1, 3) * along), Vec3(t + away)};
      break;
    case 1:  // B in A's plane, reaching back over A
      p.b = {t, Vec3(t - away), Vec3(t + away + along)};
      break;
    case 2:  // B touches the edge at t only, from above or crossing below
      p.b = {t, Vec3(t + up + away), Vec3(t + (rng.integer(0, 1) ? 1 : -1) * up - along)};
      break;
    default:  // B stands on the edge with an edge along it
      p.b = {t, Vec3(t + along), Vec3(t + up)};
      break;
  }
  if (lattice) {
    p = exact_scale_shift(p, rng);
  }
  // A third of the cases: the junction vertex moved off the edge by 1-4 ulps (rounding in a mesher).
  if (rng.integer(0, 2) == 0) {
    double& x = p.b[0][rng.integer(0, 2)];
    const double dir = rng.integer(0, 1) ? HUGE_VAL : -HUGE_VAL;
    for (int m = rng.integer(1, 4); m > 0; --m) x = std::nextafter(x, dir);
  }
  return p;
}

// A huge triangle (1e2..1e6) and a tiny one (1e-9..1e-3) at a point of it: crossing, touching with a
// vertex, or just above or below by a fraction of its size.
TriPair tiny_huge(Rng& rng) {
  const double big = std::pow(10.0, rng.uniform(2, 6));
  const double small = std::pow(10.0, rng.uniform(-9, -3));
  TriPair p;
  const Vec3 o = rng.integer(0, 1) ? Vec3::Zero() : Vec3(big * rng.vec(-1, 1));
  for (Vec3& x : p.a) x = o + big * rng.vec(-1, 1);
  const Vec3 n = (p.a[1] - p.a[0]).cross(p.a[2] - p.a[0]).normalized();
  // A point on the huge triangle: inside, or on an edge (barycentric 0 on one side).
  double s = rng.uniform(0, 1), t = rng.uniform(0, 1 - s);
  if (rng.integer(0, 2) == 0) t = 0;
  const Vec3 q = p.a[0] + s * (p.a[1] - p.a[0]) + t * (p.a[2] - p.a[0]);
  switch (rng.integer(0, 2)) {
    case 0:  // crossing the plane
      p.b = {Vec3(q + small * (n + 0.3 * rng.vec(-1, 1))), Vec3(q + small * (-n + 0.3 * rng.vec(-1, 1))),
             Vec3(q + small * rng.vec(-1, 1))};
      break;
    case 1:  // touching with a vertex, the rest on one side
      p.b = {q, Vec3(q + small * (n + 0.5 * rng.vec(-1, 1))), Vec3(q + small * (n + 0.5 * rng.vec(-1, 1)))};
      break;
    default: {  // just off the plane, on either side, by 1e-6..1 of its size
      const Vec3 lift = (rng.integer(0, 1) ? 1 : -1) * small * std::pow(10.0, rng.uniform(-6, 0)) * n;
      p.b = {Vec3(q + lift), Vec3(q + lift + small * rng.unit().cross(n)), Vec3(q + lift + small * rng.unit().cross(n))};
      break;
    }
  }
  if (rng.integer(0, 1)) std::swap(p.a, p.b);
  return p;
}

// Exact contacts in planes whose exact orientation signs need the expansion arithmetic: (i) a wide
// lattice (plane spanned by integer vectors of up to 2^10, coordinates up to ~2^24: exact differences
// of more than 16 bits), (ii) a plane a x + z = c (a small integer, x and c on a 2^-7 grid, so z is
// exact) with y free over 2^-20..2^30 with full mantissas (differences rounded), axes permuted. B is
// coplanar with A, has one vertex on A's plane (the others on one side or across) or an edge in it.
TriPair wide_coplanar(Rng& rng) {
  TriPair p;
  // point(i, j): a point of A's plane; off(pt, k): pt moved k steps off the plane.
  std::function<Vec3()> in_plane;
  std::function<Vec3(const Vec3&, int)> off;
  Vec3 u, v, n, o;
  int a_coef = 0;
  double c = 0;
  const bool lattice = rng.integer(0, 1);
  if (lattice) {
    do {
      u = rng.ivec(-1024, 1024);
      v = rng.ivec(-1024, 1024);
      n = u.cross(v);
    } while (n.squaredNorm() == 0);
    o = rng.ivec(-(1 << 20), 1 << 20);
    in_plane = [&] { return Vec3(o + rng.integer(-8, 8) * u + rng.integer(-8, 8) * v); };
    off = [&](const Vec3& pt, int k) { return Vec3(pt + k * n + rng.integer(-8, 8) * u); };
  } else {
    a_coef = rng.integer(-3, 3);
    c = rng.integer(-4096, 4096) * 0x1p-7;
    in_plane = [&] {
      const double x = rng.integer(-1024, 1024) * 0x1p-7;
      const double y = rng.uniform(-1, 1) * std::ldexp(1.0, rng.integer(-20, 30));
      return Vec3(x, y, c - a_coef * x);
    };
    // Along the normal (a, 0, 1): a x' + z' = c + (a^2 + 1) t, exact on the 2^-7 grid.
    off = [&](const Vec3& pt, int k) {
      const double t = k * 0x1p-5;
      return Vec3(pt.x() + a_coef * t, pt.y(), pt.z() + t);
    };
  }
  p.a = {in_plane(), in_plane(), in_plane()};
  const int side = rng.integer(0, 1) ? 1 : -1;
  switch (rng.integer(0, 3)) {
    case 0:  // coplanar
      p.b = {in_plane(), in_plane(), in_plane()};
      break;
    case 1: {  // one vertex on the plane, the others on one side
      const Vec3 t = in_plane();
      p.b = {t, off(in_plane(), side * rng.integer(1, 3)), off(in_plane(), side * rng.integer(1, 3))};
      break;
    }
    case 2: {  // one vertex on the plane, the others across it
      const Vec3 t = in_plane();
      p.b = {t, off(in_plane(), side * rng.integer(1, 3)), off(in_plane(), -side * rng.integer(1, 3))};
      break;
    }
    default:  // an edge in the plane
      p.b = {in_plane(), in_plane(), off(in_plane(), side * rng.integer(1, 3))};
      break;
  }
  if (!lattice) {  // a plane along any axis, not only y
    const int r = rng.integer(0, 2);
    for (Tri* tri : {&p.a, &p.b})
      for (Vec3& x : *tri) x = Vec3(x[r], x[(r + 1) % 3], x[(r + 2) % 3]);
  }
  return p;
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
    case Family::OffsetFeature: return "offset_feature";
    case Family::NearlyCoplanar: return "nearly_coplanar";
    case Family::TJunction: return "t_junction";
    case Family::TinyHuge: return "tiny_huge";
    case Family::WideCoplanar: return "wide_coplanar";
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
    case Family::OffsetFeature: p = offset_feature(rng); break;
    case Family::NearlyCoplanar: p = nearly_coplanar(rng); break;
    case Family::TJunction: p = t_junction(rng); break;
    case Family::TinyHuge: p = tiny_huge(rng); break;
    case Family::WideCoplanar: p = wide_coplanar(rng); break;
    case Family::kCount: break;
  }
  return shuffle(p, rng);
}

// ---------------------------------------------------------------------------------------------
// Oracle
// ---------------------------------------------------------------------------------------------

namespace {
using EK = CGAL::Exact_predicates_exact_constructions_kernel;
using FK = CGAL::Simple_cartesian<double>;

// The closed point set of a triangle as kernel K sees it: a triangle, or (collinear) the segment
// between the two vertices farthest apart, or a point.
template <class K>
struct Shape {
  int dim = 2;  // 0 point, 1 segment, 2 triangle
  typename K::Point_3 p[3];
};

template <class K>
Shape<K> shape_of(const Tri& t) {
  Shape<K> s;
  for (int i = 0; i < 3; ++i) s.p[i] = typename K::Point_3(t[i].x(), t[i].y(), t[i].z());
  if (!CGAL::collinear(s.p[0], s.p[1], s.p[2])) return s;
  int bi = 0, bj = 1;
  typename K::FT best = CGAL::squared_distance(s.p[0], s.p[1]);
  for (auto [i, j] : {std::pair{0, 2}, std::pair{1, 2}}) {
    const typename K::FT d = CGAL::squared_distance(s.p[i], s.p[j]);
    if (d > best) best = d, bi = i, bj = j;
  }
  const typename K::Point_3 a = s.p[bi], b = s.p[bj];
  s.p[0] = a;
  s.p[1] = b;
  s.dim = (best == 0) ? 0 : 1;
  return s;
}

template <class K>
bool intersect_with(const Tri& ta, const Tri& tb) {
  Shape<K> a = shape_of<K>(ta), b = shape_of<K>(tb);
  if (a.dim < b.dim) std::swap(a, b);
  const typename K::Triangle_3 at(a.p[0], a.p[1], a.p[2]);
  const typename K::Segment_3 as(a.p[0], a.p[1]);
  switch (a.dim * 3 + b.dim) {
    case 8: return CGAL::do_intersect(at, typename K::Triangle_3(b.p[0], b.p[1], b.p[2]));
    case 7: return CGAL::do_intersect(at, typename K::Segment_3(b.p[0], b.p[1]));
    case 6: return CGAL::do_intersect(at, b.p[0]);
    case 4: return CGAL::do_intersect(as, typename K::Segment_3(b.p[0], b.p[1]));
    case 3: return CGAL::do_intersect(as, b.p[0]);
    default: return a.p[0] == b.p[0];
  }
}
}  // namespace

bool oracle_intersect(const Tri& ta, const Tri& tb) { return intersect_with<EK>(ta, tb); }

int oracle_compare_distance(const Tri& ta, const Tri& tb, double limit) {
  if (oracle_intersect(ta, tb)) return limit > 0.0 ? -1 : 0;
  auto point = [](const Vec3& v) { return EK::Point_3(v.x(), v.y(), v.z()); };
  const EK::FT limit2 = EK::FT(limit) * EK::FT(limit);
  // The closed triangles are disjoint: their distance is attained between a vertex and the other
  // triangle or between two edges (a degenerate triangle is the union of its edges, which the
  // edge pairs cover).
  bool below = false, equal = false;
  auto take = [&](const EK::FT& d2) {
    below = below || d2 < limit2;
    equal = equal || d2 == limit2;
  };
  for (const auto& [p, q] : {std::pair{&ta, &tb}, std::pair{&tb, &ta}}) {
    const EK::Triangle_3 face(point((*q)[0]), point((*q)[1]), point((*q)[2]));
    if (face.is_degenerate()) continue;
    for (const Vec3& v : *p) take(CGAL::squared_distance(point(v), face));
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const EK::Point_3 a0 = point(ta[i]), a1 = point(ta[(i + 1) % 3]), b0 = point(tb[j]), b1 = point(tb[(j + 1) % 3]);
      // A zero-length edge is a point: its distance to the other edge.
      if (a0 == a1 && b0 == b1) take(CGAL::squared_distance(a0, b0));
      else if (a0 == a1) take(CGAL::squared_distance(a0, EK::Segment_3(b0, b1)));
      else if (b0 == b1) take(CGAL::squared_distance(b0, EK::Segment_3(a0, a1)));
      else take(CGAL::squared_distance(EK::Segment_3(a0, a1), EK::Segment_3(b0, b1)));
    }
  return below ? -1 : equal ? 0 : 1;
}

bool may_need_cgal(const Tri& a, const Tri& b) {
  for (const Tri* t : {&a, &b}) {
    for (const Vec3& v : *t)
      for (int k = 0; k < 3; ++k) {
        const double x = std::abs(v[k]);
        if (x > 0x1p48 || (x != 0 && x < 0x1p-300)) return true;
      }
    const EK::Point_3 p((*t)[0].x(), (*t)[0].y(), (*t)[0].z()), q((*t)[1].x(), (*t)[1].y(), (*t)[1].z()),
        r((*t)[2].x(), (*t)[2].y(), (*t)[2].z());
    if (CGAL::collinear(p, q, r)) return true;
  }
  return false;
}

bool float_only_intersect(const Tri& ta, const Tri& tb, bool* failed) {
  if (failed) *failed = false;
  try {
    return intersect_with<FK>(ta, tb);
  } catch (const CGAL::Failure_exception&) {  // a precondition the rounded arithmetic broke
    if (failed) *failed = true;
    return false;
  }
}

}  // namespace cadclash::test
