#include "narrow_phase.h"

#include "crossing_bound.h"

#include "cadclash/geometry.h"

#include <array>
#include <bit>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace cadclash::detail {
namespace {

// The normal of P's plane, unnormalised, as straddle measures heights with it.
inline Vec3 facet_normal(const Vec3& p0, const Vec3& p1, const Vec3& p2) { return (p1 - p0).cross(p2 - p0); }

// The largest heights of T's vertices above and below P's plane (0 when none), as computed, in units
// of |n| (n = facet_normal(P), p0 its first vertex). Clipping only shrinks the part of T that counts,
// so min(up, down) / |n| bounds straddle(T, P) from above.
struct Heights {
  double up = 0.0, down = 0.0;
};
inline Heights heights(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& p0, const Vec3& n) {
  Heights h;
  for (const Vec3* v : {&v0, &v1, &v2}) {
    const double x = n.dot(*v - p0);
    h.up = std::max(h.up, x);
    h.down = std::max(h.down, -x);
  }
  return h;
}

// False when straddle(T, P) is 0 without clipping: P has no normal, or T's vertices, as their heights
// are computed, do not lie strictly on both sides of P's plane.
inline bool straddles(const Heights& h, const Vec3& n) {
  return h.up > 0.0 && h.down > 0.0 && n.squaredNorm() > 0.0;  // the length, its root, is 0 exactly when this is
}
inline bool may_straddle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& p0, const Vec3& n) {
  return straddles(heights(v0, v1, v2, p0, n), n);
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
                        PreparedPair& out, CollideCounters& counters, bool defer_tree) {
  // Cleared, not replaced: a caller preparing pair after pair keeps the lists' capacity.
  out.la.clear();
  out.lb.clear();
  out.box_a.clear();
  out.box_b.clear();
  out.tri_b.clear();
  out.tree_b.clear();
  out.tree_deferred = false;
  out.margin = out.slack = 0.0;
  out.tau = tau;
  out.threshold = tau;
  out.low = tau;
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
  // Appended, not resized: a resized list of arrays is zero-filled before it is written. The slack
  // needs the largest coordinate of any box: the union's (exact: min and max round nothing).
  Aabb all_a, all_b;
  out.box_a.reserve(out.la.size());
  for (std::uint32_t t : out.la) {
    out.box_a.push_back(triangle_box(sa.mesh, t));
    all_a.extend(out.box_a.back());
  }
  out.tri_b.reserve(out.lb.size());
  out.box_b.reserve(out.lb.size());
  for (std::uint32_t t : out.lb) {
    const auto& v = sb.mesh.triangles[t];
    const std::array<Vec3, 3>& m =
        out.tri_b.emplace_back(std::array<Vec3, 3>{t_ab * sb.mesh.vertices[v[0]], t_ab * sb.mesh.vertices[v[1]],
                                                   t_ab * sb.mesh.vertices[v[2]]});
    Aabb b;
    for (const Vec3& x : m) b.extend(x);
    out.box_b.push_back(b);
    all_b.extend(b);
  }
  // Slack so that rounding in box arithmetic never turns "within the margin" into "beyond it", nor a
  // height over a plane (at most a few ulps of these magnitudes) a crossing bound below its depth.
  out.slack = kRelativePad * (1.0 + std::max(box_magnitude(all_a), box_magnitude(all_b)));
  out.margin = search + out.slack;
  if (options.use_oaabb && options.triangle_level != TriangleLevel::Flat &&
      (options.triangle_level == TriangleLevel::Bvh || out.la.size() * out.lb.size() > options.flat_limit)) {
    if (defer_tree) out.tree_deferred = true;
    else out.tree_b.build(out.box_b);
  }
}

std::size_t prepared_bytes(const PreparedPair& p) {
  return (p.la.size() + p.lb.size()) * sizeof(std::uint32_t) + (p.box_a.size() + p.box_b.size()) * sizeof(Aabb) +
         p.tri_b.size() * sizeof(p.tri_b[0]) + (p.tree_deferred ? CandidateTree::bytes_for(p.lb.size()) : p.tree_b.bytes());
}

namespace {

// A triangle's plane for the crossing bounds: n = facet_normal, its length, and n·p0.
struct Plane {
  Vec3 n;
  double length = 0.0, offset = 0.0;
};
inline Plane plane_of(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  Plane q;
  q.n = facet_normal(p0, p1, p2);
  q.length = q.n.norm();
  q.offset = q.n.dot(p0);
  return q;
}

// True when the heights of T's vertices over plane q prove straddle(T, P) <= limit (in lengths):
// min(largest height above, largest below) <= limit, with `slack` covering the rounding of heights
// taken as n·v - n·p0 here and as n·(v - p0) by the clipping. Clipping only shrinks what counts.
inline bool cannot_straddle_beyond(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Plane& q, double limit,
                                   double slack) {
  const double h0 = q.n.dot(v0) - q.offset, h1 = q.n.dot(v1) - q.offset, h2 = q.n.dot(v2) - q.offset;
  const double up = std::max(std::max(h0, h1), std::max(h2, 0.0));
  const double down = -std::min(std::min(h0, h1), std::min(h2, 0.0));
  return std::min(up, down) <= (limit - slack) * q.length;
}

// One run of the triangle level over a range of A's survivors: the state the candidate visits share.
struct TriangleRun {
  TriangleRun(const Surface& surface_a, const PreparedPair& prepared, std::size_t first, std::size_t last,
              const CollideOptions& o, PairOutcome& outcome, CollideCounters& c, const Deadline* d)
      : sa(surface_a), p(prepared), begin(first), end(last), options(o), out(outcome), counters(c), deadline(d) {}
  const Surface& sa;
  const PreparedPair& p;
  const std::size_t begin, end;  // A's survivors la[begin, end)
  const CollideOptions& options;
  PairOutcome& out;
  CollideCounters& counters;
  const Deadline* deadline;
  TrianglePredicateStats stats;
  const bool all = options.mode == CollideMode::AllTrianglePairs;
  const bool want_distance = p.margin > 0.0;
  bool done = false;
  std::uint32_t polls = 0;
  // The current triangle of A (its vertices and plane), and B's planes once the run needs them (the
  // penetration-only tests), all made at once: by then most of B's survivors take part.
  std::size_t current = ~std::size_t{0};
  Vec3 a0, a1, a2;
  bool have_plane_a = false;
  Plane plane_a;
  std::vector<Plane> planes_b;
  // Once the run has an intersecting pair (early exit): which candidates can still cross deeper than
  // the current level (crossing_bound), made at the first need and again when the level rises.
  bool bounded = false;
  double bound_level = 0.0;
  CrossingBound bound;

  bool penetration_only() const { return out.intersecting && !all; }
  // The next depth a crossing must pass to change the outcome: low, then threshold, then tau.
  double level() const {
    if (out.crosses_threshold) return p.tau;
    return out.may_cross_threshold ? p.threshold : std::min(p.low, p.threshold);
  }

  // Brings the bound to the current level; when no candidate left can cross deeper than it, the
  // outcome is settled and the run ends.
  void update_bound() {
    const double l = level();
    if (bounded && bound_level == l) return;
    bound = crossing_bound(sa.mesh, sa.analytic, p.la, begin, end, p.tri_b, l, p.slack, /*curved=*/l >= p.tau);
    bounded = true;
    bound_level = l;
    if (!bound.any) done = true;
  }

  // False when no candidate of A's survivor i can change the outcome any more (penetration-only).
  bool may_cross(std::size_t i) {
    update_bound();
    return !done && bound.steep_a[i - begin];
  }

  void load_a(std::size_t i) {
    if (current == i) return;
    const auto& ta = sa.mesh.triangles[p.la[i]];
    a0 = sa.mesh.vertices[ta[0]];
    a1 = sa.mesh.vertices[ta[1]];
    a2 = sa.mesh.vertices[ta[2]];
    have_plane_a = false;
    current = i;
  }

  // An intersecting pair's crossing depth: what the flag and the penetration keep of it.
  void note_crossing(double depth) {
    if (depth > std::min(p.low, p.threshold)) out.may_cross_threshold = true;
    if (depth > p.threshold) out.crosses_threshold = true;
    if (depth > p.tau) {
      out.penetration = std::max(out.penetration, depth);
      if (!all) done = true;
    }
  }

  // Once the run has an intersecting pair, another can change the outcome only by crossing deeper
  // than threshold (until one has) or tau. A pair whose crossing depth, computed exactly as
  // crossing_depth does, cannot is skipped without the intersection test: whether it intersects
  // changes nothing. The vertices' heights bound the depth from above (with the rounding slack), so
  // most candidates of a contact are settled by six dot products, without clipping.
  void raise_penetration(std::size_t j) {
    if (planes_b.empty()) {
      planes_b.resize(p.lb.size());
      for (std::size_t k = 0; k < p.lb.size(); ++k) planes_b[k] = plane_of(p.tri_b[k][0], p.tri_b[k][1], p.tri_b[k][2]);
    }
    const double level = this->level();
    const auto& tb = p.tri_b[j];
    if (cannot_straddle_beyond(a0, a1, a2, planes_b[j], level, p.slack)) return;
    if (!have_plane_a) {
      plane_a = plane_of(a0, a1, a2);
      have_plane_a = true;
    }
    if (cannot_straddle_beyond(tb[0], tb[1], tb[2], plane_a, level, p.slack)) return;
    // The crossing depth as crossing_depth computes it (the same operations, so the same bits).
    const Vec3& normal_b = planes_b[j].n;
    const Vec3& normal_a = plane_a.n;
    if (!may_straddle(a0, a1, a2, tb[0], normal_b) || !may_straddle(tb[0], tb[1], tb[2], a0, normal_a)) return;
    const double over_b = clipped_straddle(a0, a1, a2, tb[0], tb[1], tb[2], normal_b);
    if (!(over_b > level)) return;
    const double depth = std::min(over_b, clipped_straddle(tb[0], tb[1], tb[2], a0, a1, a2, normal_a));
    if (!(depth > level)) return;
    if (!triangles_intersect(a0, a1, a2, tb[0], tb[1], tb[2], stats)) return;
    note_crossing(depth);
  }

  // Until the run has an intersecting pair (and for every pair when all are listed): the exact
  // intersection test. The distance matters only if no pair intersects, and most pairs that reach
  // this level do: the candidates passed by are measured only then (measure_deferred), in the order
  // they were met, so the minimum, its witness and the tests made are those of measuring each one
  // as it comes. A long wait is measured in chunks, which only spends tests an intersection later
  // would have saved.
  static constexpr std::size_t kMaxDeferred = 4096;
  std::vector<std::array<std::uint32_t, 2>> deferred;  // survivor indices (i, j), visiting order

  [[gnu::noinline]] void first_phase(std::size_t i, std::size_t j) {
    const auto& tb = p.tri_b[j];
    // Boxes apart on an axis (exact: each is the min and max of its triangle's coordinates) hold
    // triangles that cannot meet; within a wide search margin most candidates are such. (Brute
    // force culls nothing: it tests every pair.)
    if (options.use_oaabb && !boxes_overlap(p.box_a[i], p.box_b[j])) {
      if (!out.intersecting && want_distance) defer(i, j);
      return;
    }
    if (triangles_intersect(a0, a1, a2, tb[0], tb[1], tb[2], stats)) {
      if (!out.intersecting) out.witness = {p.la[i], p.lb[j]};
      out.intersecting = true;
      deferred.clear();
      if (all) out.triangle_pairs.push_back({p.la[i], p.lb[j]});
      note_crossing(crossing_depth(a0, a1, a2, tb[0], tb[1], tb[2]));
    } else if (!out.intersecting && want_distance) {
      defer(i, j);
    }
  }

  void defer(std::size_t i, std::size_t j) {
    deferred.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j)});
    if (deferred.size() == kMaxDeferred) measure_deferred();
  }

  // The distances of the deferred candidates, in their order.
  void measure_deferred() {
    for (const auto& [i, j] : deferred) {
      // A box lower bound beyond what is already known cannot lower the minimum (slack: rounding).
      const double lower = box_distance(p.box_a[i], p.box_b[j]);
      if (lower <= std::min(out.distance, p.margin) + (p.margin - std::max(p.tau, options.clearance))) {
        ++counters.distance_tests;
        load_a(i);
        const auto& tb = p.tri_b[j];
        const double d = triangle_distance(a0, a1, a2, tb[0], tb[1], tb[2]);
        if (d < out.distance) {
          out.distance = d;
          out.witness = {p.la[i], p.lb[j]};
        }
      }
    }
    deferred.clear();
  }

  // Candidate (A's survivor i, B's survivor j).
  void test(std::size_t i, std::size_t j) {
    if (deadline != nullptr && (++polls & 255u) == 0 && deadline->expired()) {
      out.cut = true;
      done = true;
      return;
    }
    if (penetration_only()) {
      if (!may_cross(i) || !bound.steep_b[j]) return;
      load_a(i);
      raise_penetration(j);
    } else {
      load_a(i);
      first_phase(i, j);
    }
  }
};

// A's survivors [begin, end) in order, each with its candidates from B's tree, visited in (a, b)
// order as the flat loops visit them, so both give the same answer. Once only deeper crossings can
// change the outcome, a triangle of A that cannot take part in one is passed over unqueried.
// Without a prepared tree the first of A's triangles scan B's boxes (the same candidates in the
// same order) until the scans have cost about what building the tree costs; most runs of a contact
// settle by then (the first intersecting pair, then the crossing bound).
void tree_candidates(TriangleRun& run) {
  const PreparedPair& p = run.p;
  CandidateTree own;
  const bool prepared = !p.tree_b.empty();
  const std::size_t nb = p.lb.size();
  std::uint64_t scan_budget = prepared ? 0 : nb * (4 + std::bit_width(nb));
  std::vector<std::uint32_t> js;
  std::uint64_t box_tests = 0;
  for (std::size_t i = run.begin; i < run.end && !run.done; ++i) {
    if (run.penetration_only() && !run.may_cross(i)) continue;
    js.clear();
    if (scan_budget >= nb) {
      scan_budget -= nb;
      box_tests += nb;
      const FlatBox a = flat_box(p.box_a[i]);
      for (std::uint32_t j = 0; j < nb; ++j)
        if (candidate_within(a, flat_box(p.box_b[j]), p.margin)) js.push_back(j);
    } else {
      if (!prepared && own.empty()) own.build(p.box_b);  // the scan budget is spent: it never grows back
      (prepared ? p.tree_b : own).query(flat_box(p.box_a[i]), p.margin, js, box_tests);
      if (js.size() > 1) std::sort(js.begin(), js.end());
    }
    for (std::size_t k = 0; k < js.size() && !run.done; ++k) run.test(i, js[k]);
  }
  run.counters.aabb_tests += box_tests;
}

}  // namespace

void run_pair(const Surface& sa, const PreparedPair& p, std::size_t begin, std::size_t end,
              const CollideOptions& options, PairOutcome& out, CollideCounters& counters,
              const Deadline* deadline) {
  TriangleRun run(sa, p, begin, end, options, out, counters, deadline);
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
    tree_candidates(run);
  }
  if (!out.intersecting && !out.cut) run.measure_deferred();
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
  into.crosses_threshold = into.crosses_threshold || later.crosses_threshold;
  into.may_cross_threshold = into.may_cross_threshold || later.may_cross_threshold;
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
