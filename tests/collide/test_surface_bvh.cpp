// The per-surface tree's grid-encoded node boxes (surface_bvh.h): every decoded node box contains
// the exact boxes of its items, and a query returns exactly the items whose exact box meets the
// query box, at any placement and scale of the coordinates (far from the origin, tiny extents, flat
// axes, huge magnitudes) and with more items than 16-bit indices hold.
#include "surface_bvh.h"

#include "cadclash/geometry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace cadclash {
namespace {

using detail::SurfaceBvh;

// Random boxes of size up to `size` in a cube of side `extent` at `offset`; axis `flat` (0..2) has
// no extent at all when given.
std::vector<Aabb> random_boxes(std::size_t n, const Vec3& offset, double extent, double size, int flat,
                               std::uint32_t seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Aabb> boxes(n);
  for (auto& b : boxes) {
    Vec3 lo(u(gen), u(gen), u(gen));
    lo = offset + extent * lo;
    Vec3 hi = lo + size * Vec3(u(gen), u(gen), u(gen));
    if (flat >= 0) lo[flat] = hi[flat] = offset[flat];
    b = Aabb(lo, hi);
  }
  return boxes;
}

// Walks the whole tree: every leaf item's exact box lies in the decoded box of every node above it,
// and every item is reached once.
void expect_nodes_contain_items(const SurfaceBvh& bvh, const std::vector<Aabb>& boxes) {
  ASSERT_GT(bvh.node_count, 0u);
  std::vector<int> seen(boxes.size(), 0);
  struct Entry {
    std::uint32_t node;
    std::vector<Aabb> above;
  };
  std::vector<Entry> stack{{0, {}}};
  while (!stack.empty()) {
    Entry e = std::move(stack.back());
    stack.pop_back();
    const SurfaceBvh::Node& n = bvh.nodes[e.node];
    e.above.push_back(bvh.node_box(n));
    if (n.count() > 0) {
      for (std::uint32_t i = n.first(); i < n.first() + n.count(); ++i) {
        const std::uint32_t item = bvh.item(i);
        ASSERT_LT(item, boxes.size());
        ++seen[item];
        for (const Aabb& box : e.above) ASSERT_TRUE(box.contains(boxes[item])) << "item " << item;
      }
    } else {
      stack.push_back({n.first(), e.above});
      stack.push_back({n.first() + 1, e.above});
    }
  }
  for (std::size_t i = 0; i < seen.size(); ++i) ASSERT_EQ(seen[i], 1) << "item " << i;
}

// The same answer as testing every item's exact box, for query boxes around and between items.
void expect_queries_exact(const SurfaceBvh& bvh, const std::vector<Aabb>& boxes, std::uint32_t seed) {
  std::mt19937 gen(seed);
  std::uniform_int_distribution<std::size_t> pick(0, boxes.size() - 1);
  for (int q = 0; q < 200; ++q) {
    Aabb query = boxes[pick(gen)];
    query.extend(boxes[pick(gen)].center());
    if (q % 3 == 0) query = Aabb(boxes[pick(gen)].max());  // a point: touching boxes count
    std::vector<std::uint32_t> expected;
    for (std::uint32_t i = 0; i < boxes.size(); ++i)
      if (boxes_overlap(boxes[i], query)) expected.push_back(i);
    std::vector<std::uint32_t> got;
    bool stop = false;
    const detail::GridBox grid = detail::grid_box(bvh, query);
    detail::walk_bvh(
        bvh, [&](const SurfaceBvh::Node& n) { return detail::node_meets(n, grid); },
        [&](std::uint32_t i) {
          if (boxes_overlap(boxes[i], query)) got.push_back(i);
          return stop;
        });
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, expected) << "query " << q;
  }
}

struct GridCase {
  const char* name;
  Vec3 offset;
  double extent, size;
  int flat;
  std::size_t items;
};

TEST(SurfaceBvh, DecodedNodeBoxesContainTheirItemsAndQueriesAreExact) {
  const GridCase cases[] = {
      {"unit", Vec3(0, 0, 0), 100.0, 1.0, -1, 1000},
      {"far from the origin", Vec3(1e6, -2e6, 3e5), 10.0, 0.1, -1, 1000},
      {"tiny extent far away (below float resolution)", Vec3(1e6, 1e6, 1e6), 1e-6, 1e-8, -1, 500},
      {"extent near the coordinates' rounding", Vec3(1e3, 1e3, 1e3), 1e-11, 1e-12, -1, 300},
      {"a flat axis", Vec3(-5, 7, 3.25), 50.0, 0.5, 2, 800},
      {"huge magnitudes", Vec3(-1e300, 1e300, 0), 1e299, 1e297, -1, 500},
      {"more items than 16-bit indices", Vec3(0.5, 0.25, -3), 1000.0, 0.2, -1, 70000},
  };
  for (const GridCase& c : cases) {
    SCOPED_TRACE(c.name);
    const std::vector<Aabb> boxes = random_boxes(c.items, c.offset, c.extent, c.size, c.flat, 7);
    const SurfaceBvh bvh = detail::build_box_bvh(boxes);
    EXPECT_EQ(bvh.wide, c.items > 65536);
    expect_nodes_contain_items(bvh, boxes);
    expect_queries_exact(bvh, boxes, 11);
  }
}

// query_surface_bvh: the triangles whose exact box meets the query, ascending, after what `out`
// held already; for queries meeting a few triangles and most of them (the ascending order is made
// two ways), and for a surface too small for a tree.
TEST(SurfaceBvh, TriangleQueriesReturnTheMeetingTrianglesAscending) {
  for (const std::size_t n : {std::size_t{SurfaceBvh::kFlatLimit}, std::size_t{5000}, std::size_t{70000}}) {
    SCOPED_TRACE(n);
    std::mt19937 gen(static_cast<std::uint32_t>(n));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    TriangleMesh mesh;
    for (std::size_t t = 0; t < n; ++t) {
      const Vec3 c(100 * u(gen), 100 * u(gen), 100 * u(gen));
      const auto v = static_cast<std::uint32_t>(mesh.vertices.size());
      for (int k = 0; k < 3; ++k) mesh.vertices.push_back(c + Vec3(u(gen), u(gen), u(gen)));
      mesh.triangles.push_back({v, v + 1, v + 2});
    }
    const SurfaceBvh bvh = detail::build_surface_bvh(mesh);
    EXPECT_EQ(bvh.node_count == 0, n <= SurfaceBvh::kFlatLimit);
    std::size_t large = 0;
    std::uniform_int_distribution<std::uint32_t> pick(0, static_cast<std::uint32_t>(n - 1));
    for (const double side : {0.5, 3.0, 20.0, 60.0, 120.0}) {
      for (int q = 0; q < 16; ++q) {
        const Vec3 lo(100 * u(gen) - side / 2, 100 * u(gen) - side / 2, 100 * u(gen) - side / 2);
        Aabb query(lo, lo + Vec3::Constant(side));
        if (q >= 10) {
          // A query box whose face lies exactly on a face of a triangle's box (closed boxes: they meet),
          // below it on one axis for q even, above it for q odd.
          const auto& tri = mesh.triangles[pick(gen)];
          Aabb b(mesh.vertices[tri[0]]);
          b.extend(mesh.vertices[tri[1]]).extend(mesh.vertices[tri[2]]);
          const int k = q % 3;
          query = Aabb(b.center() - Vec3::Constant(side / 2), b.center() + Vec3::Constant(side / 2));
          if (q % 2 == 0) query.max()[k] = b.min()[k], query.min()[k] = b.min()[k] - side;
          else query.min()[k] = b.max()[k], query.max()[k] = b.max()[k] + side;
        }
        std::vector<std::uint32_t> expected{7, 3};  // what the caller held: kept in front, unsorted
        for (std::uint32_t t = 0; t < n; ++t) {
          const auto& tri = mesh.triangles[t];
          Aabb b(mesh.vertices[tri[0]]);
          b.extend(mesh.vertices[tri[1]]).extend(mesh.vertices[tri[2]]);
          if (boxes_overlap(b, query)) expected.push_back(t);
        }
        large += expected.size() > n / 4;
        std::vector<std::uint32_t> got{7, 3};
        std::uint64_t tests = 0;
        detail::query_surface_bvh(bvh, mesh, query, got, tests);
        ASSERT_EQ(got, expected) << "side " << side << " query " << q;
        EXPECT_GT(tests, 0u);
      }
    }
    EXPECT_GT(large, 0u);  // some queries meet most triangles
  }
}

// The tree's bytes are what the layout promises: 16 per node and 2 per item (4 past 65536 items).
TEST(SurfaceBvh, BytesPerItem) {
  const std::vector<Aabb> small = random_boxes(1000, Vec3::Zero(), 10.0, 0.1, -1, 3);
  const SurfaceBvh a = detail::build_box_bvh(small);
  EXPECT_EQ(a.node_count, 2u * 125u - 1u);
  EXPECT_EQ(detail::bvh_heap_bytes(a), 16u * a.node_count + 2u * 1000u);
  const std::vector<Aabb> flat_only = random_boxes(SurfaceBvh::kFlatLimit, Vec3::Zero(), 10.0, 0.1, -1, 3);
  EXPECT_EQ(detail::bvh_heap_bytes(detail::build_box_bvh(flat_only)), 0u);
}

}  // namespace
}  // namespace cadclash
