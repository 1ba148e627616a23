#include "surface_bvh.h"

#include "cadclash/geometry.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>

namespace cadclash::detail {
namespace {

constexpr std::uint32_t kLeaf = SurfaceBvh::kLeafSize;

// The grid step of one axis: the smallest power of two whose kGrid steps from the root's low end
// reach its high end as decode computes them (1 for a flat extent: every coordinate is then 0), and
// at least 2^-49 of the coordinates' magnitude: a step below their rounding would make decode flat
// over long runs of coordinates, and the encoding's corrections (grid_at_or_below) long walks.
// Normal doubles only (2^-1022 .. 2^1023); at 2^1023 the top of the grid is +inf, above any hi.
std::int16_t step_exponent(double lo, double hi) {
  if (!(hi > lo)) return 0;
  const double extent = hi - lo;
  const double magnitude = std::max(std::abs(lo), std::abs(hi));
  int e = std::isfinite(extent) ? std::ilogb(extent / SurfaceBvh::kGrid) : 1023;
  if (magnitude > 0.0 && std::isfinite(magnitude)) e = std::max(e, std::ilogb(magnitude) - 49);
  e = std::clamp(e, -1022, 1023);
  while (e < 1023 && lo + SurfaceBvh::kGrid * power_of_two(e) < hi) ++e;
  return static_cast<std::int16_t>(e);
}

// The largest grid coordinate whose decoded value is <= x (-1: none), and the smallest whose
// decoded value is >= x (kGrid + 1: none). decode is monotone, and with steps well above the
// coordinates' rounding the first guess is off by a step or two, which the walks correct.
std::int32_t grid_at_or_below(const SurfaceBvh& b, int k, double x) {
  if (!(x >= b.decode(k, 0))) return -1;
  if (x >= b.decode(k, SurfaceBvh::kGrid)) return SurfaceBvh::kGrid;
  const double guess = std::floor((x - b.root.min()[k]) / b.step(k));
  auto q = static_cast<std::int32_t>(std::clamp(guess, 0.0, double(SurfaceBvh::kGrid)));
  while (q > 0 && b.decode(k, q) > x) --q;
  while (q < SurfaceBvh::kGrid && b.decode(k, q + 1) <= x) ++q;
  return q;
}
std::int32_t grid_at_or_above(const SurfaceBvh& b, int k, double x) {
  if (!(x <= b.decode(k, SurfaceBvh::kGrid))) return SurfaceBvh::kGrid + 1;
  if (x <= b.decode(k, 0)) return 0;
  const double guess = std::ceil((x - b.root.min()[k]) / b.step(k));
  auto q = static_cast<std::int32_t>(std::clamp(guess, 0.0, double(SurfaceBvh::kGrid)));
  while (q < SurfaceBvh::kGrid && b.decode(k, q) < x) ++q;
  while (q > 0 && b.decode(k, q - 1) >= x) --q;
  return q;
}

struct Builder {
  std::span<const Aabb> boxes;
  std::vector<Vec3> centroids;
  std::vector<std::uint32_t> order;
  SurfaceBvh& bvh;
  std::uint32_t used = 1;  // nodes handed out (the root first)

  void node(std::uint32_t index, std::uint32_t begin, std::uint32_t end) {
    Aabb box;
    Aabb centre_box;
    for (std::uint32_t i = begin; i < end; ++i) {
      box.extend(boxes[order[i]]);
      centre_box.extend(centroids[order[i]]);
    }
    SurfaceBvh::Node& n = bvh.nodes[index];
    // The items lie in the root box, so both coordinates exist (decode(0) = root low end,
    // decode(kGrid) >= root high end).
    for (int k = 0; k < 3; ++k) {
      n.lo[k] = static_cast<std::uint16_t>(grid_at_or_below(bvh, k, box.min()[k]));
      n.hi[k] = static_cast<std::uint16_t>(grid_at_or_above(bvh, k, box.max()[k]));
    }
    if (end - begin <= kLeaf) {
      n.bits = begin << 4 | (end - begin);
      return;
    }
    int axis = 0;
    centre_box.sizes().maxCoeff(&axis);
    // The left child takes half the items rounded up to whole leaves: every leaf but the last is
    // full, so there are ceil(n / kLeafSize) leaves (the node count the byte budget rests on).
    const std::uint32_t half = (end - begin) / 2;
    const std::uint32_t mid = begin + (half + kLeaf - 1) / kLeaf * kLeaf;
    // Ties broken by index so the tree (and every counter) is the same on every run.
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) {
                       const double ca = centroids[a][axis], cb = centroids[b][axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    const std::uint32_t left = used;
    used += 2;
    assert(used <= bvh.node_count);
    n.bits = left << 4;
    node(left, begin, mid);
    node(left + 1, mid, end);
  }
};

}  // namespace

// Node n meets `query` (boxes_overlap's test on its decoded box) exactly when its grid coordinates
// reach these: decode is monotone.
GridBox grid_box(const SurfaceBvh& bvh, const Aabb& query) {
  GridBox g;
  for (int k = 0; k < 3; ++k) {
    g.lo[k] = grid_at_or_above(bvh, k, query.min()[k]);
    g.hi[k] = grid_at_or_below(bvh, k, query.max()[k]);
  }
  return g;
}

SurfaceBvh build_box_bvh(std::span<const Aabb> boxes) {
  SurfaceBvh bvh;
  const auto n = static_cast<std::uint32_t>(boxes.size());
  assert(boxes.size() < (std::size_t{1} << 28));
  bvh.items = n;
  for (const Aabb& b : boxes) bvh.root.extend(b);
  if (n <= SurfaceBvh::kFlatLimit) return bvh;
  // A binary tree with ceil(n / kLeafSize) leaves (see Builder::node) has twice that less one nodes.
  bvh.node_count = 2 * ((n + kLeaf - 1) / kLeaf) - 1;
  bvh.nodes = std::make_unique<SurfaceBvh::Node[]>(bvh.node_count);
  for (int k = 0; k < 3; ++k) bvh.step_exponent[k] = step_exponent(bvh.root.min()[k], bvh.root.max()[k]);
  Builder b{boxes, std::vector<Vec3>(n), std::vector<std::uint32_t>(n), bvh};
  for (std::uint32_t t = 0; t < n; ++t) {
    b.centroids[t] = boxes[t].center();
    b.order[t] = t;
  }
  b.node(0, 0, n);
  assert(b.used == bvh.node_count);
  bvh.wide = n > 65536;
  bvh.order = std::make_unique<std::uint16_t[]>(bvh.wide ? 2 * std::size_t{n} : n);
  for (std::uint32_t i = 0; i < n; ++i) {
    if (bvh.wide) {
      bvh.order[2 * i] = static_cast<std::uint16_t>(b.order[i] & 0xffffu);
      bvh.order[2 * i + 1] = static_cast<std::uint16_t>(b.order[i] >> 16);
    } else {
      bvh.order[i] = static_cast<std::uint16_t>(b.order[i]);
    }
  }
  return bvh;
}

SurfaceBvh build_surface_bvh(const TriangleMesh& mesh) {
  std::vector<Aabb> boxes(mesh.triangles.size());
  for (std::size_t t = 0; t < boxes.size(); ++t) boxes[t] = triangle_box(mesh, static_cast<std::uint32_t>(t));
  return build_box_bvh(boxes);
}

namespace {

// Sorts out[start, end) (distinct indices below n): a bitmap over the indices when the run is long
// against n (marking and reading n / 64 words beats k log k comparisons), else std::sort.
void sort_indices(std::vector<std::uint32_t>& out, std::size_t start, std::uint32_t n) {
  const std::size_t k = out.size() - start;
  const std::size_t words = (std::size_t{n} + 63) / 64;
  if (k < 64 || words > 4 * k) {
    std::sort(out.begin() + static_cast<std::ptrdiff_t>(start), out.end());
    return;
  }
  thread_local std::vector<std::uint64_t> bits;
  bits.assign(words, 0);
  for (std::size_t i = start; i < out.size(); ++i) bits[out[i] >> 6] |= std::uint64_t{1} << (out[i] & 63u);
  out.resize(start);
  for (std::size_t w = 0; w < words; ++w)
    for (std::uint64_t b = bits[w]; b != 0; b &= b - 1)
      out.push_back(static_cast<std::uint32_t>(64 * w + static_cast<std::size_t>(std::countr_zero(b))));
}

}  // namespace

void query_surface_bvh(const SurfaceBvh& bvh, const TriangleMesh& mesh, const Aabb& query,
                       std::vector<std::uint32_t>& out, std::uint64_t& box_tests) {
  if (bvh.empty() || query.isEmpty()) return;
  const std::size_t start = out.size();
  const GridBox grid = grid_box(bvh, query);
  walk_bvh(
      bvh,
      [&](const SurfaceBvh::Node& node) {
        ++box_tests;
        return node_meets(node, grid);
      },
      [&](std::uint32_t t) {
        ++box_tests;
        if (triangle_meets_box(mesh, t, query)) out.push_back(t);
        return false;
      });
  if (bvh.node_count > 0) sort_indices(out, start, bvh.items);  // without a tree the scan is in order
}

namespace {

// The nearest triangle's distance from p among those whose box comes within `reach`, stopping
// once one is within `enough` (then some triangle is that near, not necessarily the nearest; its
// index in `found`).
double nearest_triangle(const SurfaceBvh& bvh, const TriangleMesh& mesh, const Vec3& p, double reach, double enough,
                        std::uint32_t* found = nullptr) {
  double best = std::numeric_limits<double>::infinity();
  auto visit = [&](std::uint32_t t) {
    if (triangle_box(mesh, t).exteriorDistance(p) > std::min(best, reach)) return false;
    const auto& tri = mesh.triangles[t];
    best = std::min(best, point_triangle_distance(p, mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]));
    if (!(best <= enough)) return false;
    if (found != nullptr) *found = t;
    return true;
  };
  if (bvh.node_count == 0) {
    for (std::uint32_t t = 0; t < bvh.items; ++t)
      if (visit(t)) break;
    return best;
  }
  // Nearer child first: the best so far shrinks sooner and prunes more. The minimum is the same in
  // any order. Each node's squared distance is worked out once, when it is pushed (its square root
  // is exteriorDistance's value).
  struct Entry {
    std::uint32_t node;
    double d2;
  };
  Entry stack[64];
  int top = 0;
  stack[top++] = {0, bvh.node_box(bvh.nodes[0]).squaredExteriorDistance(p)};
  while (top > 0) {
    const Entry e = stack[--top];
    if (std::sqrt(e.d2) > std::min(best, reach)) continue;
    const SurfaceBvh::Node& node = bvh.nodes[e.node];
    if (const std::uint32_t count = node.count(); count > 0) {
      for (std::uint32_t i = node.first(); i < node.first() + count; ++i)
        if (visit(bvh.item(i))) return best;
    } else {
      const Entry left{node.first(), bvh.node_box(bvh.nodes[node.first()]).squaredExteriorDistance(p)};
      const Entry right{node.first() + 1, bvh.node_box(bvh.nodes[node.first() + 1]).squaredExteriorDistance(p)};
      const bool left_nearer = left.d2 <= right.d2;
      stack[top++] = left_nearer ? right : left;
      stack[top++] = left_nearer ? left : right;
    }
  }
  return best;
}

}  // namespace

double point_mesh_distance(const SurfaceBvh& bvh, const TriangleMesh& mesh, const Vec3& p, double reach) {
  return nearest_triangle(bvh, mesh, p, reach, -std::numeric_limits<double>::infinity());
}

bool point_near_mesh(const SurfaceBvh& bvh, const TriangleMesh& mesh, const Vec3& p, double reach) {
  // Points asked one after another often lie in one triangle (the depth step's bisection walks a
  // line across a board's long planar triangles, asking of two faces in turn): the triangle found
  // last for this mesh (among the last few meshes asked) is tried first. Any triangle within reach
  // gives the answer; a hint that misses (or is stale: only its index is kept) costs one test.
  struct Hint {
    const TriangleMesh* mesh = nullptr;
    std::uint32_t triangle = 0;
  };
  thread_local std::array<Hint, 4> hints;
  thread_local std::size_t next = 0;
  for (const Hint& h : hints) {
    if (h.mesh != &mesh || h.triangle >= mesh.triangles.size()) continue;
    const auto& tri = mesh.triangles[h.triangle];
    if (point_triangle_distance(p, mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]) <= reach)
      return true;
    break;
  }
  std::uint32_t found = 0;
  if (!(nearest_triangle(bvh, mesh, p, reach, reach, &found) <= reach)) return false;
  Hint* slot = nullptr;
  for (Hint& h : hints)
    if (h.mesh == &mesh) slot = &h;
  if (slot == nullptr) {
    slot = &hints[next];
    next = (next + 1) % hints.size();
  }
  *slot = {&mesh, found};
  return true;
}

}  // namespace cadclash::detail
