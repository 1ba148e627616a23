#include "mesh_polygon.h"

#include <cassert>
#include <cmath>

namespace cadclash::detail {
namespace {

struct P2 {
  double x, y;
};

double cross(const P2& o, const P2& a, const P2& b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

// Inside or on the boundary of counter-clockwise triangle abc.
bool in_triangle(const P2& p, const P2& a, const P2& b, const P2& c) {
  return cross(a, b, p) >= 0 && cross(b, c, p) >= 0 && cross(c, a, p) >= 0;
}

bool same_point(const P2& a, const P2& b) { return a.x == b.x && a.y == b.y; }

}  // namespace

bool triangulate_polygon(std::span<const Vec3> points, std::span<const std::uint32_t> corners,
                         std::vector<std::array<std::uint32_t, 3>>& out) {
  const std::size_t n = corners.size();
  assert(n >= 3);
  if (n == 3) {
    out.push_back({corners[0], corners[1], corners[2]});
    return true;
  }

  // Newell's normal: robust for non-planar and concave polygons.
  Vec3 normal = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& a = points[corners[i]];
    const Vec3& b = points[corners[(i + 1) % n]];
    normal.x() += (a.y() - b.y()) * (a.z() + b.z());
    normal.y() += (a.z() - b.z()) * (a.x() + b.x());
    normal.z() += (a.x() - b.x()) * (a.y() + b.y());
  }
  const auto fan = [&] {
    for (std::size_t i = 1; i + 1 < n; ++i) out.push_back({corners[0], corners[i], corners[i + 1]});
  };
  if (!(normal.squaredNorm() > 0)) {
    fan();
    return false;
  }

  // Project by dropping the dominant axis; choose the two kept axes so the polygon is
  // counter-clockwise in 2D (its Newell normal points towards the viewer).
  int axis = 0;
  normal.cwiseAbs().maxCoeff(&axis);
  int u = (axis + 1) % 3, v = (axis + 2) % 3;
  if (normal[axis] < 0) std::swap(u, v);
  std::vector<P2> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = {points[corners[i]][u], points[corners[i]][v]};

  // Strictly convex only: a fan over collinear corners would make zero-area triangles.
  bool convex = true;
  for (std::size_t i = 0; i < n && convex; ++i)
    if (!(cross(p[i], p[(i + 1) % n], p[(i + 2) % n]) > 0)) convex = false;
  if (convex) {
    fan();
    return true;
  }

  // Ear clipping, O(n^2): good for the polygons of mesh files, which are small.
  std::vector<std::size_t> ring(n);
  for (std::size_t i = 0; i < n; ++i) ring[i] = i;
  std::size_t guard = 0;
  std::size_t i = 0;
  while (ring.size() > 3) {
    const std::size_t m = ring.size();
    const std::size_t ia = ring[(i + m - 1) % m], ib = ring[i % m], ic = ring[(i + 1) % m];
    bool ear = cross(p[ia], p[ib], p[ic]) > 0;
    for (std::size_t k = 0; ear && k < m; ++k) {
      const std::size_t q = ring[k];
      if (q == ia || q == ib || q == ic) continue;
      if (same_point(p[q], p[ia]) || same_point(p[q], p[ib]) || same_point(p[q], p[ic])) continue;
      if (in_triangle(p[q], p[ia], p[ib], p[ic])) ear = false;
    }
    if (!ear && guard >= m) {
      // A full turn without an ear: the polygon is not simple. Fan the rest: clipping one corner
      // per full turn costs O(n^3): a random self-intersecting 3000-gon took 13 s under ASan.
      for (std::size_t k = 1; k + 1 < m; ++k) out.push_back({corners[ring[0]], corners[ring[k]], corners[ring[k + 1]]});
      return false;
    }
    if (ear) {
      out.push_back({corners[ia], corners[ib], corners[ic]});
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i % m));
      guard = 0;
      i = (i + m - 2) % (m - 1);  // step back: the previous corner may have become an ear
    } else {
      ++guard;
      i = (i + 1) % m;
    }
  }
  out.push_back({corners[ring[0]], corners[ring[1]], corners[ring[2]]});
  return true;
}

}  // namespace cadclash::detail
