#include "narrow_phase.h"

#include "cadclash/geometry.h"

#include <array>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace cadclash::detail {
namespace {

// The normal of P's plane, unnormalised, as straddle measures heights with it.
inline Vec3 facet_normal(const Vec3& p0, const Vec3& p1, const Vec3& p2) { return (p1 - p0).cross(p2 - p0); }

// False when straddle(T, P) is 0 without clipping: P has no normal, or T's vertices, as their heights
// are computed, do not lie strictly on both sides of P's plane. Clipping only shrinks the straddle,
// so a triangle wholly on one side needs none. `n` = facet_normal(P), p0 its first vertex.
inline bool may_straddle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& p0, const Vec3& n) {
  double up = 0.0, down = 0.0;
  for (const Vec3* v : {&v0, &v1, &v2}) {
    const double h = n.dot(*v - p0);
    up = std::max(up, h);
    down = std::max(down, -h);
  }
  return up > 0.0 && down > 0.0 && n.squaredNorm() > 0.0;  // the length, its root, is 0 exactly when this is
}

// straddle(T, P) for a pair may_straddle lets through (n = facet_normal(P)). Plain doubles in place
// of Eigen's expressions, with the same operations in the same order: the result is the same to the
// bit (test_crossing_depth compares it with Eigen's evaluation).
double clipped_straddle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& p0, const Vec3& p1,
                        const Vec3& p2, const Vec3& n) {
  struct P {
    double x, y, z;
  };
  const double nx = n.x(), ny = n.y(), nz = n.z();
  // Each clip adds at most one vertex: 3 + 3.
  P buf[2][6];
  buf[0][0] = {v0.x(), v0.y(), v0.z()};
  buf[0][1] = {v1.x(), v1.y(), v1.z()};
  buf[0][2] = {v2.x(), v2.y(), v2.z()};
  P* poly = buf[0];
  P* next = buf[1];
  std::size_t np = 3;
  const Vec3* corners[3] = {&p0, &p1, &p2};
  for (int e = 0; e < 3 && np > 0; ++e) {
    const Vec3& a = *corners[e];
    const Vec3& b = *corners[(e + 1) % 3];
    // The side plane through the edge, facing P: inward = n x (b - a).
    const double wx = b.x() - a.x(), wy = b.y() - a.y(), wz = b.z() - a.z();
    const double ix = ny * wz - nz * wy, iy = nz * wx - nx * wz, iz = nx * wy - ny * wx;
    double d[6];
    bool all_in = true;
    for (std::size_t k = 0; k < np; ++k) {
      d[k] = (ix * (poly[k].x - a.x()) + iy * (poly[k].y - a.y())) + iz * (poly[k].z - a.z());
      all_in = all_in && d[k] >= 0.0;
    }
    if (all_in) continue;  // every vertex kept and no edge crosses: the polygon stays as it is
    std::size_t nn = 0;
    for (std::size_t k = 0; k < np; ++k) {
      const std::size_t k1 = k + 1 == np ? 0 : k + 1;
      const P& x = poly[k];
      const P& y = poly[k1];
      const double dx = d[k], dy = d[k1];
      if (dx >= 0.0 && nn < 6) next[nn++] = x;
      if ((dx >= 0.0) != (dy >= 0.0) && nn < 6) {
        const double t = dx / (dx - dy);
        next[nn++] = {x.x + (y.x - x.x) * t, x.y + (y.y - x.y) * t, x.z + (y.z - x.z) * t};
      }
    }
    std::swap(poly, next);
    np = nn;
  }
  // Heights are divided by len once, after the maxima: division by len > 0 is monotone in IEEE
  // arithmetic, so max(h_k) / len equals max(h_k / len) (and 0 / len is 0). Not when a height
  // overflowed: then each is divided as before.
  double up = 0.0, down = 0.0;
  double h[6];
  for (std::size_t k = 0; k < np; ++k) {
    h[k] = (nx * (poly[k].x - p0.x()) + ny * (poly[k].y - p0.y())) + nz * (poly[k].z - p0.z());
    up = std::max(up, h[k]);
    down = std::max(down, -h[k]);
  }
  const double len = n.norm();
  if (up <= std::numeric_limits<double>::max() && down <= std::numeric_limits<double>::max())
    return std::min(up, down) / len;
  up = 0.0, down = 0.0;
  for (std::size_t k = 0; k < np; ++k) {
    up = std::max(up, h[k] / len);
    down = std::max(down, -h[k] / len);
  }
  return std::min(up, down);
}

// How far the part of triangle T inside the normal prism of triangle P straddles P's plane: the
// smaller of its largest heights above and below the plane; 0 when it stays on one side. Clipping to
// the prism keeps the measure local: a wide triangle that crosses P's plane far away from P does not
// count, only what lies over (or under) P.
double straddle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& p0, const Vec3& p1,
                const Vec3& p2) {
  const Vec3 n = facet_normal(p0, p1, p2);
  return may_straddle(v0, v1, v2, p0, n) ? clipped_straddle(v0, v1, v2, p0, p1, p2, n) : 0.0;
}

// A box of the triangle-level sweep, copied out of the Aabb in sweep order.
struct SweepBox {
  double lo[3], hi[3];
};

std::vector<SweepBox> sweep_boxes(const std::vector<Aabb>& boxes, const std::vector<std::uint32_t>& order) {
  std::vector<SweepBox> out(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    const Aabb& b = boxes[order[i]];
    out[i] = {{b.min().x(), b.min().y(), b.min().z()}, {b.max().x(), b.max().y(), b.max().z()}};
  }
  return out;
}

// boxes_within for two triangles' boxes (never empty: each holds its three finite vertices).
inline bool sweep_within(const SweepBox& a, const SweepBox& b, double margin) {
  for (int k = 0; k < 3; ++k) {
    if (b.lo[k] - a.hi[k] > margin) return false;
    if (a.lo[k] - b.hi[k] > margin) return false;
  }
  return true;
}

double max_magnitude(const std::vector<Aabb>& boxes) {
  double m = 0.0;
  for (const Aabb& b : boxes) m = std::max(m, box_magnitude(b));
  return m;
}

}  // namespace

double crossing_depth(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1,
                      const Vec3& b2) {
  return std::min(straddle(a0, a1, a2, b0, b1, b2), straddle(b0, b1, b2, a0, a1, a2));
}

double winding_number(const Vec3& p, std::span<const Surface* const> surfaces) {
  double sum = 0.0;
  for (const Surface* s : surfaces) {
    for (const auto& t : s->mesh.triangles) {
      const Vec3 a = s->mesh.vertices[t[0]] - p, b = s->mesh.vertices[t[1]] - p, c = s->mesh.vertices[t[2]] - p;
      const double la = a.norm(), lb = b.norm(), lc = c.norm();
      const double num = a.dot(b.cross(c));
      const double den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
      sum += 2.0 * std::atan2(num, den);  // solid angle (Van Oosterom & Strackee)
    }
  }
  return sum / (4.0 * std::numbers::pi);
}

void prepare_pair(const Surface& sa, const SurfaceBvh& bvh_a, const Surface& sb, const SurfaceBvh& bvh_b,
                  const Pose& t_ab, const Pose& t_ba, const CollideOptions& options, PreparedPair& out,
                  CollideCounters& counters) {
  prepare_pair_reach(sa, bvh_a, sb, bvh_b, t_ab, t_ba, options, band_threshold(sa, sb, options.tolerance), out,
                     counters);
}

void prepare_pair_reach(const Surface& sa, const SurfaceBvh& bvh_a, const Surface& sb, const SurfaceBvh& bvh_b,
                        const Pose& t_ab, const Pose& t_ba, const CollideOptions& options, double tau,
                        PreparedPair& out, CollideCounters& counters) {
  out = PreparedPair{};
  out.tau = tau;
  const double search = std::max(out.tau, options.clearance);
  if (options.use_oaabb) {
    // Surface-pair OAABB in A's frame: where a triangle of one side can come within `search` of the
    // other. Built from the triangles' boxes (the BVH roots): a B-rep face's stored box may be looser.
    if (bvh_a.empty() || bvh_b.empty()) return;
    const Aabb& tri_box_a = bvh_a.root;
    const Aabb tri_box_b = transform_box(bvh_b.root, t_ab);
    ++counters.aabb_updates;
    const Aabb oaabb = pad_box(tri_box_a, search).intersection(pad_box(tri_box_b, search));
    if (oaabb.isEmpty()) return;
    query_surface_bvh(bvh_a, sa.mesh, oaabb, out.la, counters.aabb_tests);
    if (out.la.empty()) return;
    const Aabb oaabb_b = transform_box(oaabb, t_ba);  // the single update into B's frame
    ++counters.aabb_updates;
    query_surface_bvh(bvh_b, sb.mesh, oaabb_b, out.lb, counters.aabb_tests);
  } else {
    out.la.resize(sa.mesh.triangles.size());
    out.lb.resize(sb.mesh.triangles.size());
    for (std::uint32_t i = 0; i < out.la.size(); ++i) out.la[i] = i;
    for (std::uint32_t i = 0; i < out.lb.size(); ++i) out.lb[i] = i;
  }
  if (out.la.empty() || out.lb.empty()) {
    out.la.clear();
    out.lb.clear();
    return;
  }
  counters.triangles_a += out.la.size();
  counters.triangles_b += out.lb.size();
  out.box_a.resize(out.la.size());
  for (std::size_t i = 0; i < out.la.size(); ++i) out.box_a[i] = triangle_box(sa.mesh, out.la[i]);
  out.tri_b.resize(out.lb.size());
  out.box_b.resize(out.lb.size());
  for (std::size_t j = 0; j < out.lb.size(); ++j) {
    const auto& t = sb.mesh.triangles[out.lb[j]];
    Aabb b;
    for (int k = 0; k < 3; ++k) {
      out.tri_b[j][k] = t_ab * sb.mesh.vertices[t[k]];
      b.extend(out.tri_b[j][k]);
    }
    out.box_b[j] = b;
  }
  // Slack so that rounding in box arithmetic never turns "within the margin" into "beyond it".
  out.margin = search + kRelativePad * (1.0 + std::max(max_magnitude(out.box_a), max_magnitude(out.box_b)));
}

std::size_t prepared_bytes(const PreparedPair& p) {
  return (p.la.size() + p.lb.size()) * sizeof(std::uint32_t) + (p.box_a.size() + p.box_b.size()) * sizeof(Aabb) +
         p.tri_b.size() * sizeof(p.tri_b[0]);
}

namespace {

// One run of the triangle level over a range of A's survivors: the state the candidate visits share.
struct TriangleRun {
  TriangleRun(const Surface& surface_a, const PreparedPair& prepared, const CollideOptions& o, PairOutcome& outcome,
              CollideCounters& c, const Deadline* d)
      : sa(surface_a), p(prepared), options(o), out(outcome), counters(c), deadline(d) {}
  const Surface& sa;
  const PreparedPair& p;
  const CollideOptions& options;
  PairOutcome& out;
  CollideCounters& counters;
  const Deadline* deadline;
  TrianglePredicateStats stats;
  const bool all = options.mode == CollideMode::AllTrianglePairs;
  const bool want_distance = p.margin > 0.0;
  bool done = false;
  std::uint32_t polls = 0;
  // Normals for the penetration-only tests: A's is reused over the run of candidates with the same
  // triangle of A, B's are kept once computed.
  std::size_t normal_of = ~std::size_t{0};
  Vec3 normal_a;
  std::vector<Vec3> normals_b;
  std::vector<char> have_normal_b;

  // Once the run has an intersecting pair, another can change the outcome only by raising the
  // penetration (the maximum crossing depth; deeper than tau ends the run). A pair whose crossing
  // depth, computed exactly as crossing_depth does, does not exceed it is skipped without the
  // intersection test: whether it intersects changes nothing. Most candidates of a contact are
  // decided by the plane sides alone.
  void raise_penetration(std::size_t i, std::size_t j, const Vec3& a0, const Vec3& a1, const Vec3& a2,
                         const std::array<Vec3, 3>& tb) {
    if (normal_of != i) {
      normal_a = facet_normal(a0, a1, a2);
      normal_of = i;
    }
    if (normals_b.empty()) {
      normals_b.resize(p.lb.size());
      have_normal_b.assign(p.lb.size(), 0);
    }
    if (!have_normal_b[j]) {
      normals_b[j] = facet_normal(tb[0], tb[1], tb[2]);
      have_normal_b[j] = 1;
    }
    const Vec3& normal_b = normals_b[j];
    if (!may_straddle(a0, a1, a2, tb[0], normal_b) || !may_straddle(tb[0], tb[1], tb[2], a0, normal_a)) return;
    const double over_b = clipped_straddle(a0, a1, a2, tb[0], tb[1], tb[2], normal_b);
    if (!(over_b > out.penetration)) return;
    const double depth = std::min(over_b, clipped_straddle(tb[0], tb[1], tb[2], a0, a1, a2, normal_a));
    if (!(depth > out.penetration)) return;
    if (!triangles_intersect(a0, a1, a2, tb[0], tb[1], tb[2], stats)) return;
    out.penetration = depth;
    if (depth > p.tau) done = true;
  }

  // Candidate (A's survivor i, B's survivor j).
  void test(std::size_t i, std::size_t j) {
    if (deadline != nullptr && (++polls & 255u) == 0 && deadline->expired()) {
      out.cut = true;
      done = true;
      return;
    }
    const auto& ta = sa.mesh.triangles[p.la[i]];
    const Vec3& a0 = sa.mesh.vertices[ta[0]];
    const Vec3& a1 = sa.mesh.vertices[ta[1]];
    const Vec3& a2 = sa.mesh.vertices[ta[2]];
    const auto& tb = p.tri_b[j];
    if (out.intersecting && !all) {
      raise_penetration(i, j, a0, a1, a2, tb);
      return;
    }
    if (triangles_intersect(a0, a1, a2, tb[0], tb[1], tb[2], stats)) {
      if (!out.intersecting) out.witness = {p.la[i], p.lb[j]};
      out.intersecting = true;
      const double depth = crossing_depth(a0, a1, a2, tb[0], tb[1], tb[2]);
      out.penetration = std::max(out.penetration, depth);
      if (all) out.triangle_pairs.push_back({p.la[i], p.lb[j]});
      else if (depth > p.tau) done = true;
    } else if (!out.intersecting && want_distance) {
      // A box lower bound beyond what is already known cannot lower the minimum (slack: rounding).
      const double lower = box_distance(p.box_a[i], p.box_b[j]);
      if (lower <= std::min(out.distance, p.margin) + (p.margin - std::max(p.tau, options.clearance))) {
        ++counters.distance_tests;
        const double d = triangle_distance(a0, a1, a2, tb[0], tb[1], tb[2]);
        if (d < out.distance) {
          out.distance = d;
          out.witness = {p.la[i], p.lb[j]};
        }
      }
    }
  }
};

// Sweep over x of A's survivors [begin, end) (grown by the margin) and B's; candidates are then
// visited in the same (a, b) order as the flat loops, so both variants give the same answer. The
// boxes are copied in sweep order so that the inner loops read memory in sequence.
void sweep_candidates(TriangleRun& run, std::size_t begin, std::size_t end) {
  const PreparedPair& p = run.p;
  const std::size_t na = end - begin, nb = p.lb.size();
  std::vector<std::uint32_t> oa(na), ob(nb);
  for (std::size_t i = 0; i < na; ++i) oa[i] = static_cast<std::uint32_t>(begin + i);
  for (std::size_t j = 0; j < nb; ++j) ob[j] = static_cast<std::uint32_t>(j);
  auto by_min_a = [&](std::uint32_t x, std::uint32_t y) {
    return p.box_a[x].min().x() < p.box_a[y].min().x() || (p.box_a[x].min().x() == p.box_a[y].min().x() && x < y);
  };
  auto by_min_b = [&](std::uint32_t x, std::uint32_t y) {
    return p.box_b[x].min().x() < p.box_b[y].min().x() || (p.box_b[x].min().x() == p.box_b[y].min().x() && x < y);
  };
  std::sort(oa.begin(), oa.end(), by_min_a);
  std::sort(ob.begin(), ob.end(), by_min_b);
  const std::vector<SweepBox> sa_boxes = sweep_boxes(p.box_a, oa), sb_boxes = sweep_boxes(p.box_b, ob);
  std::vector<std::array<std::uint32_t, 2>> cand;
  std::size_t ia = 0, ib = 0;
  const double m = p.margin;
  while (ia < na && ib < nb) {
    const SweepBox& ba = sa_boxes[ia];
    const SweepBox& bb = sb_boxes[ib];
    if (ba.lo[0] - m <= bb.lo[0]) {
      for (std::size_t k = ib; k < nb && sb_boxes[k].lo[0] <= ba.hi[0] + m; ++k) {
        ++run.counters.aabb_tests;
        if (sweep_within(ba, sb_boxes[k], m)) cand.push_back({oa[ia], ob[k]});
      }
      ++ia;
    } else {
      for (std::size_t k = ia; k < na && sa_boxes[k].lo[0] - m <= bb.hi[0]; ++k) {
        ++run.counters.aabb_tests;
        if (sweep_within(sa_boxes[k], bb, m)) cand.push_back({oa[k], ob[ib]});
      }
      ++ib;
    }
  }
  // Visit in (a, b) order: a counting sort by A's triangle, then each triangle's few b's sorted.
  std::vector<std::uint32_t> first(na + 1, 0), by_a(cand.size());
  for (const auto& c : cand) ++first[c[0] - begin + 1];
  for (std::size_t i = 0; i < na; ++i) first[i + 1] += first[i];
  {
    std::vector<std::uint32_t> fill(first.begin(), first.end() - 1);
    for (const auto& c : cand) by_a[fill[c[0] - begin]++] = c[1];
  }
  for (std::size_t i = 0; i < na && !run.done; ++i) {
    const auto from = by_a.begin() + first[i], to = by_a.begin() + first[i + 1];
    std::sort(from, to);
    for (auto it = from; it != to && !run.done; ++it) run.test(begin + i, *it);
  }
}

}  // namespace

void run_pair(const Surface& sa, const PreparedPair& p, std::size_t begin, std::size_t end,
              const CollideOptions& options, PairOutcome& out, CollideCounters& counters,
              const Deadline* deadline) {
  TriangleRun run(sa, p, options, out, counters, deadline);
  const std::size_t na = end - begin, nb = p.lb.size();
  if (!options.use_oaabb) {
    for (std::size_t i = begin; i < end && !run.done; ++i)
      for (std::size_t j = 0; j < nb && !run.done; ++j) run.test(i, j);
  } else if (options.triangle_level == TriangleLevel::Flat ||
             (options.triangle_level == TriangleLevel::Auto && na * nb <= options.flat_limit)) {
    for (std::size_t i = begin; i < end && !run.done; ++i)
      for (std::size_t j = 0; j < nb && !run.done; ++j) {
        ++counters.aabb_tests;
        if (boxes_within(p.box_a[i], p.box_b[j], p.margin)) run.test(i, j);
      }
  } else {
    sweep_candidates(run, begin, end);
  }
  counters.triangle_tests += run.stats.tests;
  counters.exact_fallbacks += run.stats.exact_fallbacks;
}

void merge_outcome(PairOutcome& into, PairOutcome&& later) {
  // The earlier block's witness wins ties, as the visiting order of one run would have it.
  if ((!into.intersecting && later.intersecting) ||
      (!into.intersecting && !later.intersecting && later.distance < into.distance))
    into.witness = later.witness;
  into.intersecting = into.intersecting || later.intersecting;
  into.cut = into.cut || later.cut;
  into.penetration = std::max(into.penetration, later.penetration);
  into.distance = std::min(into.distance, later.distance);
  into.triangle_pairs.insert(into.triangle_pairs.end(), later.triangle_pairs.begin(), later.triangle_pairs.end());
}

}  // namespace cadclash::detail

namespace cadclash {

namespace detail {

std::optional<ContactClass> classify(const PairOutcome& o, double tau, double clearance) {
  if (o.intersecting) return o.penetration > tau ? ContactClass::Penetrating : ContactClass::Touching;
  if (o.distance <= tau) return ContactClass::Touching;
  if (clearance > 0.0 && o.distance <= clearance) return ContactClass::Clearance;
  return std::nullopt;
}

}  // namespace detail
}  // namespace cadclash
