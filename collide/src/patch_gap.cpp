#include "patch_gap.h"

#include "cadclash/geometry.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

namespace cadclash::detail {
namespace {

constexpr double kUnit = 0x1p-53;  // unit round-off of a double

// A piece of a patch: homogeneous control points (w·x, w·y, w·z, w), index i * (dv + 1) + j.
struct Piece {
  int du = 0, dv = 0;
  int depth = 0;
  std::vector<Eigen::Vector4d> h;
};

Vec3 point(const Eigen::Vector4d& h) { return h.head<3>() / h[3]; }

Piece make_piece(const SurfaceSource::BezierPatch& p, const Pose& place) {
  Piece out;
  out.du = p.degree_u;
  out.dv = p.degree_v;
  out.h.reserve(p.points.size());
  for (std::size_t k = 0; k < p.points.size(); ++k) {
    const Vec3 q = place * p.points[k];
    out.h.emplace_back(p.weights[k] * q.x(), p.weights[k] * q.y(), p.weights[k] * q.z(), p.weights[k]);
  }
  return out;
}

// Halves `in` at the middle of u (along_u) or v: de Casteljau on every row of the control net.
void halve(const Piece& in, bool along_u, Piece& lo, Piece& hi) {
  lo = hi = in;
  ++lo.depth;
  ++hi.depth;
  const int n = along_u ? in.du : in.dv;
  const int rows = along_u ? in.dv + 1 : in.du + 1;
  std::vector<Eigen::Vector4d> row(static_cast<std::size_t>(n) + 1);
  for (int r = 0; r < rows; ++r) {
    auto at = [&](int k) { return static_cast<std::size_t>(along_u ? k * (in.dv + 1) + r : r * (in.dv + 1) + k); };
    for (int k = 0; k <= n; ++k) row[static_cast<std::size_t>(k)] = in.h[at(k)];
    lo.h[at(0)] = row[0];
    hi.h[at(n)] = row[static_cast<std::size_t>(n)];
    for (int level = 1; level <= n; ++level) {
      for (int k = 0; k <= n - level; ++k)
        row[static_cast<std::size_t>(k)] = 0.5 * (row[static_cast<std::size_t>(k)] + row[static_cast<std::size_t>(k) + 1]);
      lo.h[at(level)] = row[0];
      hi.h[at(n - level)] = row[static_cast<std::size_t>(n - level)];
    }
  }
}

// The piece's surface point at the middle of its parameters: de Casteljau along u on every row, then
// along v on what that leaves.
Vec3 centre(const Piece& piece) {
  std::vector<Eigen::Vector4d> column(static_cast<std::size_t>(piece.dv) + 1);
  std::vector<Eigen::Vector4d> row(static_cast<std::size_t>(piece.du) + 1);
  auto reduce = [](std::vector<Eigen::Vector4d>& v) {
    for (std::size_t n = v.size(); n > 1; --n)
      for (std::size_t k = 0; k + 1 < n; ++k) v[k] = 0.5 * (v[k] + v[k + 1]);
    return v[0];
  };
  for (int j = 0; j <= piece.dv; ++j) {
    for (int i = 0; i <= piece.du; ++i) row[static_cast<std::size_t>(i)] = piece.h[static_cast<std::size_t>(i * (piece.dv + 1) + j)];
    column[static_cast<std::size_t>(j)] = reduce(row);
  }
  return point(reduce(column));
}

// How far the net's rows along u (or v) bend away from their end points' chord: the hull's thickness
// that halving along that direction reduces.
double bend(const std::vector<Vec3>& p, const Piece& piece, bool along_u) {
  const int n = along_u ? piece.du : piece.dv;
  if (n < 2) return 0.0;
  const int rows = along_u ? piece.dv + 1 : piece.du + 1;
  double most = 0.0;
  for (int r = 0; r < rows; ++r) {
    auto at = [&](int k) { return static_cast<std::size_t>(along_u ? k * (piece.dv + 1) + r : r * (piece.dv + 1) + k); };
    const Vec3& a = p[at(0)];
    const Vec3 d = p[at(n)] - a;
    const double dd = d.squaredNorm();
    for (int k = 1; k < n; ++k) {
      const Vec3 v = p[at(k)] - a;
      const double s = dd > 0.0 ? std::clamp(v.dot(d) / dd, 0.0, 1.0) : 0.0;
      most = std::max(most, (v - s * d).norm());
    }
  }
  return most;
}

// How long the net is along u (or v): its longest row of control polygon edges.
double length(const std::vector<Vec3>& p, const Piece& piece, bool along_u) {
  const int n = along_u ? piece.du : piece.dv;
  const int rows = along_u ? piece.dv + 1 : piece.du + 1;
  double most = 0.0;
  for (int r = 0; r < rows; ++r) {
    auto at = [&](int k) { return static_cast<std::size_t>(along_u ? k * (piece.dv + 1) + r : r * (piece.dv + 1) + k); };
    double sum = 0.0;
    for (int k = 0; k < n; ++k) sum += (p[at(k + 1)] - p[at(k)]).norm();
    most = std::max(most, sum);
  }
  return most;
}

// The net's corner normal (its diagonals' cross product), zero when degenerate.
Vec3 corner_normal(const std::vector<Vec3>& p, const Piece& piece) {
  const std::size_t c00 = 0, c01 = static_cast<std::size_t>(piece.dv);
  const std::size_t c10 = static_cast<std::size_t>(piece.du * (piece.dv + 1));
  const std::size_t c11 = c10 + c01;
  return (p[c11] - p[c00]).cross(p[c01] - p[c10]);
}

// The widest gap a plane of one of a few directions puts between the two nets (negative when none
// separates them): the direction of their closest control points and each net's corner normal.
double plane_gap(const std::vector<Vec3>& pa, const Piece& a, const std::vector<Vec3>& pb, const Piece& b) {
  double best = -std::numeric_limits<double>::infinity();
  double closest = std::numeric_limits<double>::infinity();
  Vec3 between = Vec3::Zero();
  for (const Vec3& p : pa)
    for (const Vec3& q : pb)
      if (const double d = (q - p).squaredNorm(); d < closest) {
        closest = d;
        between = q - p;
      }
  for (const Vec3& dir : {between, corner_normal(pa, a), corner_normal(pb, b)}) {
    const double len = dir.norm();
    if (!(len > 0.0)) continue;
    const Vec3 n = dir / len;
    double a_lo = std::numeric_limits<double>::infinity(), a_hi = -a_lo, b_lo = a_lo, b_hi = -a_lo;
    for (const Vec3& p : pa) {
      const double h = n.dot(p);
      a_lo = std::min(a_lo, h);
      a_hi = std::max(a_hi, h);
    }
    for (const Vec3& q : pb) {
      const double h = n.dot(q);
      b_lo = std::min(b_lo, h);
      b_hi = std::max(b_hi, h);
    }
    best = std::max(best, std::max(b_lo - a_hi, a_lo - b_hi));
  }
  return best;
}

Aabb box_of(const std::vector<Vec3>& p) {
  Aabb box;
  for (const Vec3& q : p) box.extend(q);
  return box;
}

}  // namespace

PatchGap patch_gap(const SurfaceSource::BezierPatches& a, const SurfaceSource::BezierPatches& b, const Pose& t_ab,
                   const PatchGapOptions& options) {
  // What every bound below is widened by: the patches' own rounding; t_ab's (made from two poses) and
  // its application to B's points; each halving's (one rounding of a mean per level, in homogeneous
  // coordinates, so relative to the largest point times the weights' spread); the planes' dot products.
  double magnitude = options.pose_magnitude, w_lo = std::numeric_limits<double>::infinity(), w_hi = 0.0;
  std::vector<Piece> pieces_a, pieces_b;
  for (const auto& p : a.patches) {
    assert(p.points.size() == static_cast<std::size_t>((p.degree_u + 1) * (p.degree_v + 1)));
    assert(p.weights.size() == p.points.size());
    pieces_a.push_back(make_piece(p, Pose::Identity()));
  }
  for (const auto& p : b.patches) {
    assert(p.points.size() == static_cast<std::size_t>((p.degree_u + 1) * (p.degree_v + 1)));
    assert(p.weights.size() == p.points.size());
    pieces_b.push_back(make_piece(p, t_ab));
  }
  for (const auto* set : {&pieces_a, &pieces_b})
    for (const Piece& p : *set)
      for (const Eigen::Vector4d& h : p.h) {
        assert(h[3] > 0.0);
        magnitude = std::max(magnitude, point(h).norm());
        w_lo = std::min(w_lo, h[3]);
        w_hi = std::max(w_hi, h[3]);
      }
  for (const auto& p : b.patches)
    for (const Vec3& q : p.points) magnitude = std::max(magnitude, q.norm() + options.pose_magnitude);
  if (pieces_a.empty() || pieces_b.empty()) return {};
  const double spread = w_hi / w_lo;
  const double pad = a.rounding + b.rounding + 64.0 * kUnit * (magnitude + options.pose_magnitude) +
                     (8.0 * options.max_depth + 16.0) * kUnit * magnitude * spread;
  const double need = options.threshold + pad;

  struct Pair {
    Piece a, b;
  };
  std::vector<Pair> stack;
  for (const Piece& pa : pieces_a)
    for (const Piece& pb : pieces_b) stack.push_back({pa, pb});
  double least = std::numeric_limits<double>::infinity();
  int looked = 0;
  // Pairs of pieces halved as far as allowed and still not separated: the search goes on past a few
  // of them (the surfaces may cross there, or only come close) and keeps the centre of A's piece in
  // the most overlapping one (the lowest plane gap: where they cross, if anywhere) as the witness.
  constexpr int kMaxUnresolved = 8;
  int unresolved = 0;
  double worst = std::numeric_limits<double>::infinity();
  std::optional<Vec3> witness;
  std::vector<Vec3> pa, pb;
  while (!stack.empty()) {
    Pair pair = std::move(stack.back());
    stack.pop_back();
    if (++looked > options.budget) return {std::nullopt, witness ? witness : centre(pair.a)};
    pa.clear();
    pb.clear();
    for (const auto& h : pair.a.h) pa.push_back(point(h));
    for (const auto& h : pair.b.h) pb.push_back(point(h));
    const double gap = std::max(box_distance(box_of(pa), box_of(pb)), plane_gap(pa, pair.a, pb, pair.b));
    if (gap > need) {
      least = std::min(least, gap);
      continue;
    }
    // Halve the piece whose net bends most, where it bends most; nets that are flat (both straight
    // both ways) are halved where they are longest.
    const double bend_a = std::max(bend(pa, pair.a, true), bend(pa, pair.a, false));
    const double bend_b = std::max(bend(pb, pair.b, true), bend(pb, pair.b, false));
    const bool flat = std::max(bend_a, bend_b) <= pad;
    bool split_a, along_u;
    if (!flat) {
      split_a = bend_a >= bend_b;
      const std::vector<Vec3>& p = split_a ? pa : pb;
      const Piece& piece = split_a ? pair.a : pair.b;
      along_u = bend(p, piece, true) >= bend(p, piece, false);
    } else {
      const double la = std::max(length(pa, pair.a, true), length(pa, pair.a, false));
      const double lb = std::max(length(pb, pair.b, true), length(pb, pair.b, false));
      split_a = la >= lb;
      const std::vector<Vec3>& p = split_a ? pa : pb;
      const Piece& piece = split_a ? pair.a : pair.b;
      along_u = length(p, piece, true) >= length(p, piece, false);
    }
    Piece& whole = split_a ? pair.a : pair.b;
    if (whole.depth >= options.max_depth) {
      if (gap < worst) worst = gap, witness = centre(pair.a);
      if (++unresolved >= kMaxUnresolved) break;
      continue;
    }
    Piece lo, hi;
    halve(whole, along_u, lo, hi);
    if (split_a) {
      stack.push_back({std::move(lo), pair.b});
      stack.push_back({std::move(hi), std::move(pair.b)});
    } else {
      stack.push_back({pair.a, std::move(lo)});
      stack.push_back({std::move(pair.a), std::move(hi)});
    }
  }
  if (unresolved > 0) return {std::nullopt, witness};
  return {least - pad, std::nullopt};
}

}  // namespace cadclash::detail
