#include "crossing_bound.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

namespace cadclash::detail {
namespace {

Vec3 normal_of(const Vec3& p0, const Vec3& p1, const Vec3& p2) { return (p1 - p0).cross(p2 - p0); }

// The core and its r (crossing_bound.h): a plane (u unit, offset c), a line (point, unit direction)
// or a point.
struct Core {
  enum Kind { Plane, Line, Point } kind = Plane;
  Vec3 origin = Vec3::Zero(), dir = Vec3::UnitZ();
  double offset = 0.0;

  // The vector from the core to v (line: perpendicular to it; plane: unused).
  Vec3 rho(const Vec3& v) const {
    const Vec3 q = v - origin;
    return kind == Line ? Vec3(q - q.dot(dir) * dir) : q;
  }
};

// One triangle's share: the range of r over it, and c (0 when no side of it is bounded).
struct Share {
  double lo = 0.0, hi = 0.0, c = 0.0;
};

// A line or point core's share (a plane's is its vertices' heights and plane_c, in bound_for).
Share share(const Core& core, const std::array<Vec3, 3>& t) {
  Share s;
  const Vec3 n = normal_of(t[0], t[1], t[2]);
  const double len = n.norm();
  const Vec3 r0 = core.rho(t[0]), r1 = core.rho(t[1]), r2 = core.rho(t[2]);
  // The largest norm, with one square root: sqrt is correctly rounded, so monotone, and this is the
  // value of max(r0.norm(), r1.norm(), r2.norm()) to the bit.
  s.hi = std::sqrt(std::max({r0.squaredNorm(), r1.squaredNorm(), r2.squaredNorm()}));
  if (len > 0.0 && s.hi > 0.0) {
    // u·ρ is linear over the triangle, so on a side where it stays positive it bounds |ρ| = r from
    // below there too: r's minimum without a point–triangle distance.
    const Vec3 u = n / len;
    const double out = std::min({u.dot(r0), u.dot(r1), u.dot(r2)});
    const double in = std::min({-u.dot(r0), -u.dot(r1), -u.dot(r2)});
    if (out > 0.0 || in > 0.0) {
      s.lo = std::max(out, in);
      s.c = s.lo / s.hi;
      // A triangle nearly across the core's direction (a plate's face around a pin: its normal along
      // the axis) has u·ρ near 0 while r is not: its true minimum, which the other side's inward
      // bound (over_curved) needs, is the core's distance to it. c stays u·ρ's.
      if (s.c < 0.5) s.lo = std::max(s.lo, point_triangle_distance(Vec3::Zero(), r0, r1, r2));
      return s;
    }
  }
  s.lo = point_triangle_distance(Vec3::Zero(), r0, r1, r2);  // r's minimum: the core to the triangle
  return s;
}

// A line or point core: how deep triangles X whose points have r in [lo_x, hi_x] can straddle
// triangle y (share `y`) when one of them intersects y. Outward (the side y's normal ν points away
// from the core): r(f + h·ν) >= r(f) + h·c_y, so h <= (hi_x - lo_y) / c_y. Inward, at depth t:
// r(f - t·ν)^2 <= r_f^2 - 2·t·r_f·c_y + t^2 (ρ_f·ν >= r_f·c_y, |ν⊥| <= 1), which is below lo_x^2,
// so holds no point of X, for t between the roots t1 < t2 when lo_x^2 > r_f^2·(1 - c_y^2) for every
// foot f. X's triangle meets y at depth 0 and its part over y is convex, so its depths cannot jump
// that gap: they stay <= t1 = (r_f^2 - lo_x^2) / (r_f·c_y + sqrt(lo_x^2 - r_f^2·(1 - c_y^2))). Only
// intersecting pairs count (the run measures no other), so the smaller bound holds for them.
double over_curved(const Share& y, double lo_x, double hi_x, double slack) {
  if (!(y.c > 0.0)) return std::numeric_limits<double>::infinity();
  const double outward = (std::max(0.0, hi_x - y.lo) + 2.0 * slack) / y.c;
  const double gap = lo_x * lo_x - y.hi * y.hi * (1.0 - y.c * y.c);
  if (!(lo_x > 0.0 && gap > 1e-9 * lo_x * lo_x)) return outward;
  const double inward =
      (std::max(0.0, y.hi - lo_x) + 2.0 * slack) * (y.hi + lo_x + 2.0 * slack) / (y.lo * y.c + std::sqrt(gap));
  return std::min(outward, inward);
}

// Triangles per side a plane core's shell is first sampled with (bound_for).
constexpr std::size_t kSampleShell = 32;

// The range of the heights over a plane core of the vertices of every `stride`-th triangle.
std::pair<double, double> height_range(const Core& core, const std::vector<std::array<Vec3, 3>>& ts,
                                       std::size_t stride) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;  // in registers, not an array's slots
  for (std::size_t i = 0; i < ts.size(); i += stride)
    for (const Vec3& v : ts[i]) {
      const double h = core.dir.dot(v) - core.offset;
      lo = std::min(lo, h), hi = std::max(hi, h);
    }
  return {lo, hi};
}

// c of a triangle for a plane core, as share() computes it.
double plane_c(const Core& core, const std::array<Vec3, 3>& t) {
  const Vec3 n = normal_of(t[0], t[1], t[2]);
  const double len = n.norm();
  return len > 0.0 ? std::abs(n.dot(core.dir)) / len : 0.0;
}

// The steep sets for one core, or nullopt when the shell is too thick for it to say anything. Once
// one side has no steep triangle no pair can cross deeper: the other side's flags are not worked
// out (left steep, which says nothing more).
std::optional<CrossingBound> bound_for(const Core& core, const std::vector<std::array<Vec3, 3>>& ta,
                                       const std::vector<std::array<Vec3, 3>>& tb, double level, double slack) {
  // Plane: depth <= D / max(c_X, c_Y), D = min(hi_a - lo_b, hi_b - lo_a). Curved: per triangle
  // (over_curved). The shell's ends and the foot points carry the rounding of r (slack each), the
  // depth its own.
  const double room = level - slack;
  const double grow = 1.0 + 1e-9;
  CrossingBound b;
  b.steep_a.resize(ta.size());
  bool any_a = false, any_b = false;
  auto certified = [&] {  // b is not used after: moved out, not copied
    b.steep_b.assign(tb.size(), 1);
    b.any = false;
    return std::optional<CrossingBound>(std::move(b));
  };
  if (core.kind == Core::Plane) {
    // The shell of a plane is its vertices' heights (r of share()): a shell too thick for the level
    // (the common case for a plane that is not a contact's) is known without the triangles' normals.
    // kappa only grows with the triangles taken (their heights' range widens), so when a sample of
    // both sides already gives kappa >= 1 so do all of them: that answer costs the sample alone.
    auto kappa_of = [&](std::size_t stride) {  // a triangle is steep below this
      const auto [lo_a, hi_a] = height_range(core, ta, stride);
      const auto [lo_b, hi_b] = height_range(core, tb, stride);
      const double d = std::min(std::max(0.0, hi_a - lo_b), std::max(0.0, hi_b - lo_a)) + 2.0 * slack;
      return d / room * grow;
    };
    const std::size_t sample = std::max(ta.size(), tb.size()) / kSampleShell;
    if (sample > 1 && !(kappa_of(sample) < 1.0)) return std::nullopt;
    const double kappa = kappa_of(1);
    if (!(kappa < 1.0)) return std::nullopt;
    for (std::size_t i = 0; i < ta.size(); ++i) any_a |= (b.steep_a[i] = !(plane_c(core, ta[i]) >= kappa)) != 0;
    if (!any_a) return certified();
    b.steep_b.resize(tb.size());
    for (std::size_t j = 0; j < tb.size(); ++j) any_b |= (b.steep_b[j] = !(plane_c(core, tb[j]) >= kappa)) != 0;
    b.any = any_a && any_b;
    return b;
  }
  // Appended (a resized list would be filled first), into the thread's lists: a run asks for a
  // bound per pair, and these are its only scratch.
  thread_local std::vector<Share> sa, sb;
  sa.clear();
  sb.clear();
  sa.reserve(ta.size());
  sb.reserve(tb.size());
  double lo_a = std::numeric_limits<double>::infinity(), hi_a = -lo_a, lo_b = lo_a, hi_b = -lo_a;
  for (const auto& t : ta) {
    const Share& s = sa.emplace_back(share(core, t));
    lo_a = std::min(lo_a, s.lo), hi_a = std::max(hi_a, s.hi);
  }
  for (const auto& t : tb) {
    const Share& s = sb.emplace_back(share(core, t));
    lo_b = std::min(lo_b, s.lo), hi_b = std::max(hi_b, s.hi);
  }
  // x of A is steep when B's triangles may straddle it deeper than the level, and y of B when A's
  // may straddle it: a pair is deeper only if both are.
  for (std::size_t i = 0; i < ta.size(); ++i)
    any_a |= (b.steep_a[i] = !(over_curved(sa[i], lo_b, hi_b, slack) * grow <= room)) != 0;
  if (!any_a) return certified();
  b.steep_b.resize(tb.size());
  for (std::size_t j = 0; j < tb.size(); ++j)
    any_b |= (b.steep_b[j] = !(over_curved(sb[j], lo_a, hi_a, slack) * grow <= room)) != 0;
  if (any_a && any_b && std::all_of(b.steep_a.begin(), b.steep_a.end(), [](char c) { return c != 0; }) &&
      std::all_of(b.steep_b.begin(), b.steep_b.end(), [](char c) { return c != 0; }))
    return std::nullopt;
  b.any = any_a && any_b;
  return b;
}

// A plane core is the plane of one triangle, chosen among at most this many evenly spread: any plane
// is a valid core (the bound is the triangles' own), and a flat face's triangles all lie on its plane.
// (An axis fitted to a sample was worse: on as1 at 0.001 mm it held fewer pairs off, 2.5x the box tests.)
constexpr std::size_t kCoreSample = 64;
std::size_t core_stride(std::size_t n) { return std::max<std::size_t>(1, n / kCoreSample); }

// The plane of the largest of the sampled triangles (the first of equal ones); nullopt when none has
// an area.
std::optional<Core> plane_core(const std::vector<std::array<Vec3, 3>>& ta) {
  std::size_t best = 0;
  double best_area = 0.0;
  for (std::size_t i = 0; i < ta.size(); i += core_stride(ta.size())) {
    const double a = normal_of(ta[i][0], ta[i][1], ta[i][2]).squaredNorm();
    if (a > best_area) best_area = a, best = i;
  }
  if (!(best_area > 0.0)) return std::nullopt;
  Core core;
  core.dir = normal_of(ta[best][0], ta[best][1], ta[best][2]).normalized();
  core.offset = core.dir.dot(ta[best][0]);
  return core;
}

// An axis fitted to A's triangles (a face of revolution without its analytic form): the direction
// their normals avoid, through the point nearest to their normal lines. Any line is a valid core;
// a good one only makes the shell thin.
std::optional<Core> fitted_axis(const std::vector<std::array<Vec3, 3>>& ta) {
  // One pass: with n = len·u, Σ n nᵀ / len = Σ len·u uᵀ, so the point's normal equations
  // Σ len·(I - u uᵀ)·x = Σ len·(I - u uᵀ)·centroid come from the same sums as the direction's.
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  Vec3 mean = Vec3::Zero(), along = Vec3::Zero();
  double weight = 0.0;
  for (const auto& t : ta) {
    const Vec3 n = normal_of(t[0], t[1], t[2]);
    const double len = n.norm();
    if (!(len > 0.0)) continue;
    const Vec3 c = (t[0] + t[1] + t[2]) / 3.0;
    m += n * (n.transpose() / len);
    mean += len * c;
    along += n * (n.dot(c) / len);
    weight += len;
  }
  if (!(weight > 0.0)) return std::nullopt;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()(1) > 1e-3 * eig.eigenvalues()(2))) return std::nullopt;
  const Vec3 d = eig.eigenvectors().col(0).normalized();
  // weight·d dᵀ pins the point along the axis (at the weighted centroid's height).
  const Eigen::Matrix3d lhs = weight * d * d.transpose() + weight * Eigen::Matrix3d::Identity() - m;
  const Vec3 rhs = weight * d * d.dot(mean / weight) + mean - along;
  const Vec3 origin = lhs.ldlt().solve(rhs);
  if (!origin.allFinite()) return std::nullopt;
  Core core;
  core.kind = Core::Line;
  core.origin = origin;
  core.dir = d;
  return core;
}

}  // namespace

CrossingBound crossing_bound(const TriangleMesh& mesh_a, const AnalyticSurface& core_a,
                             const std::vector<std::uint32_t>& la, std::size_t begin, std::size_t end,
                             const std::vector<std::array<Vec3, 3>>& tri_b, double level, double slack,
                             bool curved) {
  // Everything may cross: what is left when no core says more.
  auto fallback = [&] {
    CrossingBound b;
    b.steep_a.assign(end - begin, 1);
    b.steep_b.assign(tri_b.size(), 1);
    b.any = end > begin && !tri_b.empty();
    return b;
  };
  if (end == begin || tri_b.empty() || !(level > slack)) return fallback();  // nothing, or no room
  thread_local std::vector<std::array<Vec3, 3>> ta;  // A's survivors' corners (the thread's list)
  ta.clear();
  ta.reserve(end - begin);
  for (std::size_t i = begin; i < end; ++i) {
    const auto& t = mesh_a.triangles[la[i]];
    ta.push_back({mesh_a.vertices[t[0]], mesh_a.vertices[t[1]], mesh_a.vertices[t[2]]});
  }
  // Cores, the likeliest first: A's own analytic axis or centre; for a plane a plane; for another
  // face a fitted axis, then the plane of its largest triangle; then B's plane and fitted axis.
  std::optional<CrossingBound> best;
  auto steep_pairs = [](const CrossingBound& b) {
    std::size_t na = 0, nb = 0;
    for (char s : b.steep_a) na += s != 0;
    for (char s : b.steep_b) nb += s != 0;
    return na * nb;
  };
  auto consider = [&](const std::optional<Core>& c) {
    if (!c || (!curved && c->kind != Core::Plane)) return false;
    std::optional<CrossingBound> b = bound_for(*c, ta, tri_b, level, slack);
    if (b && (!best || steep_pairs(*b) < steep_pairs(*best))) best = std::move(b);
    return best && !best->any;
  };
  bool done = false;
  switch (core_a.shape) {
    case SurfaceShape::Cylinder:
    case SurfaceShape::Sphere: {
      if (!curved) break;
      Core c;
      c.kind = core_a.shape == SurfaceShape::Cylinder ? Core::Line : Core::Point;
      c.origin = core_a.origin;
      c.dir = core_a.axis.normalized();
      done = consider(c);
      break;
    }
    case SurfaceShape::Plane: done = consider(plane_core(ta)); break;
    default: done = (curved && consider(fitted_axis(ta))) || consider(plane_core(ta));
  }
  // Then B's: the plane a pin stands on, the axis of a pin through a plate's hole.
  if (!done && !consider(plane_core(tri_b)) && curved) consider(fitted_axis(tri_b));
  return best ? std::move(*best) : fallback();
}

}  // namespace cadclash::detail
