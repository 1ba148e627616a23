// Exact point merging and triangle de-duplication shared by repair and segmentation (no CGAL).
#pragma once

#include "mesh_soup.h"

#include <cmath>
#include <cstring>
#include <unordered_map>
#include <unordered_set>

namespace cadclash::detail {

// Bit-exact point key; -0.0 and +0.0 are one point.
struct PointKey {
  std::array<std::uint64_t, 3> bits{};
  explicit PointKey(const Vec3& p) {
    for (int i = 0; i < 3; ++i) {
      const double v = p[i] + 0.0;  // -0.0 + 0.0 == +0.0
      std::memcpy(&bits[static_cast<std::size_t>(i)], &v, sizeof v);
    }
  }
  bool operator==(const PointKey&) const = default;
};

struct PointKeyHash {
  std::size_t operator()(const PointKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint64_t b : k.bits) h = (h ^ b) * 1099511628211ull ^ (b >> 29);
    return static_cast<std::size_t>(h);
  }
};

// Index of the first point with each coordinate triple, assigned in order of first insertion.
class PointMerger {
 public:
  std::uint32_t add(const Vec3& p, std::vector<Vec3>& points) {
    auto [it, inserted] = index_.try_emplace(PointKey(p), static_cast<std::uint32_t>(points.size()));
    if (inserted) points.push_back(p);
    return it->second;
  }

 private:
  std::unordered_map<PointKey, std::uint32_t, PointKeyHash> index_;
};

inline bool finite_point(const Vec3& p) { return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()); }

// A triangle's corners as a sorted triple: equal for the same three points in either winding.
struct TriKey {
  std::array<std::uint32_t, 3> v{};
  explicit TriKey(const Tri& t) : v(t) {
    if (v[0] > v[1]) std::swap(v[0], v[1]);
    if (v[1] > v[2]) std::swap(v[1], v[2]);
    if (v[0] > v[1]) std::swap(v[0], v[1]);
  }
  bool operator==(const TriKey&) const = default;
};

struct TriKeyHash {
  std::size_t operator()(const TriKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint32_t x : k.v) h = (h ^ x) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};

}  // namespace cadclash::detail
