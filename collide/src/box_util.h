// Box helpers of the narrow phase: conservative transforms and margins. Internal to cadclash::collide.
#pragma once

#include "cadclash/collide.h"

#include <algorithm>
#include <cmath>

namespace cadclash::detail {

// The point of the segment [a, b] nearest `p`, by projection in plain doubles (a few roundings of the
// coordinates' magnitude).
inline Vec3 closest_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double s = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return a + s * ab;
}

// Relative padding that absorbs the rounding of mapping points between frames (a few ulps of the
// largest coordinate involved), so culling never drops what exact arithmetic would keep.
inline constexpr double kRelativePad = 1e-12;

inline double box_magnitude(const Aabb& b) {
  if (b.isEmpty()) return 0.0;
  return std::max(b.min().cwiseAbs().maxCoeff(), b.max().cwiseAbs().maxCoeff());
}

// `b` grown by `margin` plus the relative rounding pad on every side; empty stays empty.
inline Aabb pad_box(const Aabb& b, double margin) {
  if (b.isEmpty()) return b;
  const double p = margin + kRelativePad * (1.0 + box_magnitude(b));
  Aabb out = b;
  out.min().array() -= p;
  out.max().array() += p;
  return out;
}

// The AABB of `b`'s eight corners mapped by `t`, padded for rounding.
inline Aabb transform_box(const Aabb& b, const Pose& t) {
  if (b.isEmpty()) return b;
  Aabb out;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? b.max().x() : b.min().x(), (c & 2) ? b.max().y() : b.min().y(),
                      (c & 4) ? b.max().z() : b.min().z());
    out.extend(t * corner);
  }
  return pad_box(out, t.translation().cwiseAbs().maxCoeff() * kRelativePad);
}

inline bool boxes_overlap(const Aabb& a, const Aabb& b) {
  return !a.isEmpty() && !b.isEmpty() && (a.min().array() <= b.max().array()).all() &&
         (b.min().array() <= a.max().array()).all();
}

// Overlap of boxes each grown by `margin` (per axis gap <= margin).
inline bool boxes_within(const Aabb& a, const Aabb& b, double margin) {
  if (a.isEmpty() || b.isEmpty()) return false;
  for (int k = 0; k < 3; ++k) {
    if (b.min()[k] - a.max()[k] > margin) return false;
    if (a.min()[k] - b.max()[k] > margin) return false;
  }
  return true;
}

// Lower bound of the Euclidean distance between the boxes.
inline double box_distance(const Aabb& a, const Aabb& b) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double g = std::max({0.0, b.min()[k] - a.max()[k], a.min()[k] - b.max()[k]});
    s += g * g;
  }
  return std::sqrt(s);
}

}  // namespace cadclash::detail
