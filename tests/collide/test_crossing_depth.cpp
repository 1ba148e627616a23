// The narrow phase's fast path for contacts must not change a single bit of the outcome:
// - crossing_depth (plain-double clipping, one division) equals the straightforward Eigen evaluation
//   kept here as the reference, to the bit, on every family of test_triangle_cases (coplanar,
//   touching, 1-ulp, slivers, far offsets, rigid motions, ...);
// - run_pair in early-exit mode, which after the first intersecting triangle pair skips the pairs whose
//   crossing depth cannot exceed threshold (until one has) or tau (no intersection test for them;
//   most are skipped on the vertices' heights, without clipping), gives the same outcome as visiting
//   every intersecting pair in (a, b) order: crosses_threshold when one crosses deeper than
//   threshold, and the first one deeper than tau as the penetration, where it stops (0 when none). The reference list of intersecting pairs comes from
//   run_pair's AllTrianglePairs mode, which skips nothing. Scenes: coplanar contacts under rotations
//   (heights are rounding noise), nearly coplanar crossings, coaxial faceted cylinders (chords cross),
//   a plate through a plate; every tau from 0 to beyond the deepest pair; whole runs and
//   Version 2's blocks; flat loops, the candidate tree prepared, and the tree a run makes itself
//   after scanning.
#include "crossing_bound.h"
#include "narrow_phase.h"
#include "scene_fixtures.h"
#include "surface_bvh.h"
#include "test_triangle_cases.h"

#include <gtest/gtest.h>

#include <numbers>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace cadclash {
namespace {

using detail::crossing_depth;

// The reference: straddle as first written with Eigen expressions (see narrow_phase.cpp).
double reference_straddle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& p0, const Vec3& p1,
                          const Vec3& p2) {
  const Vec3 n = (p1 - p0).cross(p2 - p0);
  const double len = n.norm();
  if (!(len > 0.0)) return 0.0;
  {
    double up = 0.0, down = 0.0;
    for (const Vec3* v : {&v0, &v1, &v2}) {
      const double h = n.dot(*v - p0);
      up = std::max(up, h);
      down = std::max(down, -h);
    }
    if (!(up > 0.0 && down > 0.0)) return 0.0;
  }
  std::array<Vec3, 6> poly{v0, v1, v2}, next;
  std::size_t np = 3;
  const Vec3* corners[3] = {&p0, &p1, &p2};
  for (int e = 0; e < 3 && np > 0; ++e) {
    const Vec3& a = *corners[e];
    const Vec3 inward = n.cross(*corners[(e + 1) % 3] - a);
    std::size_t nn = 0;
    for (std::size_t k = 0; k < np; ++k) {
      const Vec3& x = poly[k];
      const Vec3& y = poly[(k + 1) % np];
      const double dx = inward.dot(x - a), dy = inward.dot(y - a);
      if (dx >= 0.0 && nn < next.size()) next[nn++] = x;
      if ((dx >= 0.0) != (dy >= 0.0) && nn < next.size()) next[nn++] = x + (y - x) * (dx / (dx - dy));
    }
    poly = next;
    np = nn;
  }
  double up = 0.0, down = 0.0;
  for (std::size_t k = 0; k < np; ++k) {
    const double h = n.dot(poly[k] - p0) / len;
    up = std::max(up, h);
    down = std::max(down, -h);
  }
  return std::min(up, down);
}

double reference_depth(const test::Tri& a, const test::Tri& b) {
  return std::min(reference_straddle(a[0], a[1], a[2], b[0], b[1], b[2]),
                  reference_straddle(b[0], b[1], b[2], a[0], a[1], a[2]));
}

TEST(CrossingDepth, EqualsTheEigenReferenceToTheBit) {
#ifdef NDEBUG
  constexpr long kPairs = 40'000;
#else
  constexpr long kPairs = 4'000;
#endif
  for (int f = 0; f < static_cast<int>(test::Family::kCount); ++f) {
    const auto family = static_cast<test::Family>(f);
    test::Rng rng(0xC0FFEE + static_cast<std::uint64_t>(f));
    long positive = 0, wrong = 0;
    for (long i = 0; i < kPairs; ++i) {
      test::TriPair p = test::make_case(family, rng);
      if (i % 2) std::swap(p.a, p.b);
      const double got = crossing_depth(p.a[0], p.a[1], p.a[2], p.b[0], p.b[1], p.b[2]);
      const double want = reference_depth(p.a, p.b);
      positive += want > 0.0;
      if (std::bit_cast<std::uint64_t>(got) != std::bit_cast<std::uint64_t>(want) && ++wrong <= 3)
        ADD_FAILURE() << test::family_name(family) << " case " << i << ": " << got << " != " << want;
    }
    EXPECT_EQ(wrong, 0) << test::family_name(family);
    std::printf("[ depth    ] %-16s %ld pairs, %ld with depth > 0\n", std::string(test::family_name(family)).c_str(),
                kPairs, positive);
  }
}

// ---------------------------------------------------------------------------------------------

struct PairScene {
  std::string name;
  Surface a, b;
  Pose pose_b;  // B's part frame -> A's part frame
};

// A jittered grid in the plane through `o` spanned by u, v (in-plane jitter only when `flat`).
Surface jittered_grid(const std::string& name, const Vec3& o, const Vec3& u, const Vec3& v, int n,
                      std::mt19937_64& rng, bool flat) {
  Surface s = testing::grid_surface(name, o, u, v, n);
  std::uniform_real_distribution<double> j(-0.3 / n, 0.3 / n);
  const Vec3 w = u.cross(v).normalized() * u.norm();
  for (Vec3& x : s.mesh.vertices) x += u * j(rng) + v * j(rng) + (flat ? Vec3::Zero() : Vec3(w * j(rng) * 0.01));
  return s;
}

// An annulus in the plane z = 0 between radii r and 2.5 r (chords of `segments` each, inner ring
// rotated by `phase`): a plate face with a round hole.
Surface plate_with_hole(const std::string& name, double r, int segments, double phase) {
  Surface s;
  s.name = name;
  for (int k = 0; k < segments; ++k) {
    const double a = phase + 2.0 * std::numbers::pi * k / segments;
    s.mesh.vertices.push_back(Vec3(r * std::cos(a), r * std::sin(a), 0.0));
    s.mesh.vertices.push_back(Vec3(2.5 * r * std::cos(a), 2.5 * r * std::sin(a), 0.0));
  }
  for (int k = 0; k < segments; ++k) {
    const auto i0 = static_cast<std::uint32_t>(2 * k), o0 = i0 + 1;
    const auto i1 = static_cast<std::uint32_t>(2 * ((k + 1) % segments)), o1 = i1 + 1;
    s.mesh.triangles.push_back({i0, i1, o1});
    s.mesh.triangles.push_back({i0, o1, o0});
  }
  s.analytic.shape = SurfaceShape::Plane;
  s.analytic.axis = Vec3::UnitZ();
  return s;
}

std::vector<PairScene> scenes() {
  std::vector<PairScene> out;
  std::mt19937_64 rng(2024);
  for (int k = 0; k < 3; ++k) {
    // Coplanar contact seen through a rotation: B lies in A's plane, tilted by 1e-13 rad about an axis
    // through the overlap so that it certainly crosses A, and is stored in its own frame (pose random),
    // so the heights of either triangle over the other's plane are at the level of rounding noise.
    const Pose pose = testing::random_pose(rng, 3.0);
    const Pose inv = pose.inverse();
    const Vec3 o(0.1 * k, 0.2, 0.3), u(4.0, 0.5, 0.2), v(-0.3, 3.5, 0.7);
    Surface b = jittered_grid("b", o + u * 0.37 + v * 0.21, u, v, 11, rng, true);
    const Vec3 centre = o + u * 0.7 + v * 0.6;
    const Eigen::Matrix3d tilt = Eigen::AngleAxisd(1e-13, (u + v * 0.3 * k).normalized()).toRotationMatrix();
    for (Vec3& x : b.mesh.vertices) x = inv * (centre + tilt * (x - centre));
    out.push_back({"coplanar" + std::to_string(k), jittered_grid("a", o, u, v, 9, rng, true), std::move(b), pose});
  }
  {
    // Nearly coplanar: B tilted by 1e-9 rad about an in-plane axis, crossing A.
    const Vec3 o(0, 0, 0), u(5, 0, 0), v(0, 5, 0);
    Pose pose = Pose::Identity();
    pose.linear() = Eigen::AngleAxisd(1e-9, Vec3(1, 1, 0).normalized()).toRotationMatrix();
    out.push_back({"nearly-coplanar", jittered_grid("a", o, u, v, 10, rng, true),
                   jittered_grid("b", Vec3(0.3, 0.2, 0), u, v, 12, rng, false), pose});
  }
  {
    // Coaxial faceted cylinders of one radius, rotated against each other: chords cross by up to the sagitta.
    Pose pose = Pose::Identity();
    pose.linear() = Eigen::AngleAxisd(0.3, Vec3::UnitZ()).toRotationMatrix();
    out.push_back({"coaxial", testing::cylinder_surface("a", 2.0, 0.0, 3.0, 48, 0.0),
                   testing::cylinder_surface("b", 2.0, 1.0, 4.0, 40, 0.05), pose});
  }
  {
    // A pin through a hole of its radius (the bolt in as1's plates): the pin's chords and the hole's
    // cross by up to their sags (0.0043 and 0.0062), the pin's strips run through the plate's plane.
    // Seen from the pin (its analytic cylinder) and from the plate, the plate placed off the origin.
    Surface pin = testing::cylinder_surface("a", 2.0, -1.0, 1.5, 48, 0.0);
    pin.analytic.shape = SurfaceShape::Cylinder;
    pin.analytic.radius = 2.0;
    Pose pose = Pose::Identity();
    pose.translation() = Vec3(0.0, 0.0, 0.25);
    out.push_back({"pin-through-plate", pin, plate_with_hole("b", 2.0, 40, 0.05), pose});
    Pose back = Pose::Identity();
    back.translation() = Vec3(0.0, 0.0, -0.25);
    out.push_back({"plate-around-pin", plate_with_hole("a", 2.0, 40, 0.05), testing::cylinder_surface("b", 2.0, -1.0, 1.5, 48, 0.0), back});
    // The same with the plate tilted by 1e-6 rad and the pin's axis fitted to its chords (a shank
    // that is not an elementary face, as as1's bolts): the plate's normals are then not quite
    // across the axis, so u·ρ of its triangles is tiny but not 0, while the axis is 2 away.
    Pose tilted = pose;
    tilted.linear() = Eigen::AngleAxisd(1e-6, Vec3(1.0, 0.3, 0.0).normalized()).toRotationMatrix();
    out.push_back({"pin-through-tilted-plate", testing::cylinder_surface("a", 2.0, -1.0, 1.5, 48, 0.0),
                   plate_with_hole("b", 2.0, 40, 0.05), tilted});
    out.push_back({"tilted-plate-around-pin", plate_with_hole("a", 2.0, 40, 0.05),
                   testing::cylinder_surface("b", 2.0, -1.0, 1.5, 48, 0.0), tilted.inverse()});
  }
  {
    // A plate through a plate at 30 degrees: deep crossings, tau decides where early exit stops.
    Pose pose = Pose::Identity();
    pose.linear() = Eigen::AngleAxisd(0.5, Vec3::UnitX()).toRotationMatrix();
    pose.translation() = Vec3(0.0, 2.5, 0.0);
    out.push_back({"crossing", jittered_grid("a", Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(0, 5, 0), 10, rng, false),
                   jittered_grid("b", Vec3(0.2, -2.5, 0), Vec3(4.5, 0, 0), Vec3(0, 5, 0), 10, rng, false), pose});
  }
  return out;
}

// What early exit must give: the intersecting pairs in (a, b) order; crosses_threshold when one is
// deeper than threshold; the first one deeper than tau is the penetration, and the run stops there.
detail::PairOutcome reference_outcome(const Surface& sa, const detail::PreparedPair& p,
                                      const std::vector<std::array<std::uint32_t, 2>>& intersecting,
                                      std::size_t begin, std::size_t end) {
  detail::PairOutcome o;
  const std::uint32_t first = p.la[begin], last = end < p.la.size() ? p.la[end] : ~std::uint32_t{0};
  for (const auto& t : intersecting) {
    if (t[0] < first || t[0] >= last) continue;
    const auto j = static_cast<std::size_t>(std::lower_bound(p.lb.begin(), p.lb.end(), t[1]) - p.lb.begin());
    const auto& ta = sa.mesh.triangles[t[0]];
    const auto& tb = p.tri_b[j];
    const double depth = crossing_depth(sa.mesh.vertices[ta[0]], sa.mesh.vertices[ta[1]], sa.mesh.vertices[ta[2]],
                                        tb[0], tb[1], tb[2]);
    o.intersecting = true;
    if (depth > p.threshold) o.crosses_threshold = true;
    if (depth > p.tau) {
      o.penetration = depth;
      break;
    }
  }
  return o;
}

// The scene's pair prepared for the flat loops (no candidate tree).
detail::PreparedPair prepare_flat(const PairScene& sc, const CollideOptions& o) {
  const detail::SurfaceBvh bvh_a = detail::build_surface_bvh(sc.a.mesh);
  const detail::SurfaceBvh bvh_b = detail::build_surface_bvh(sc.b.mesh);
  detail::PreparedPair p;
  CollideCounters c;
  detail::prepare_pair(sc.a, bvh_a, sc.b, bvh_b, sc.pose_b, sc.pose_b.inverse(), o, p, c);
  return p;
}

TEST(EarlyExit, SkippedPairsNeverChangeTheOutcome) {
  std::uint64_t skipped = 0, runs = 0, stopped = 0;
  for (const PairScene& sc : scenes()) {
    SCOPED_TRACE(sc.name);
    CollideOptions all;
    all.mode = CollideMode::AllTrianglePairs;
    all.triangle_level = TriangleLevel::Flat;
    const detail::PreparedPair p = prepare_flat(sc, all);
    ASSERT_FALSE(p.la.empty());
    detail::PairOutcome every;
    CollideCounters c_all;
    detail::run_pair(sc.a, p, 0, p.la.size(), all, every, c_all);
    ASSERT_TRUE(every.intersecting) << "the scene must be in contact";
    ASSERT_GT(every.triangle_pairs.size(), 10u);
    // Taus at the quantiles of the crossing depths, so early exit stops at different places.
    std::vector<double> depths;
    for (const auto& t : every.triangle_pairs) {
      const auto j = static_cast<std::size_t>(std::lower_bound(p.lb.begin(), p.lb.end(), t[1]) - p.lb.begin());
      const auto& ta = sc.a.mesh.triangles[t[0]];
      depths.push_back(crossing_depth(sc.a.mesh.vertices[ta[0]], sc.a.mesh.vertices[ta[1]],
                                      sc.a.mesh.vertices[ta[2]], p.tri_b[j][0], p.tri_b[j][1], p.tri_b[j][2]));
    }
    std::sort(depths.begin(), depths.end());
    std::vector<double> taus = {0.0, depths.back() * 2 + 1.0};
    for (double q : {0.5, 0.9, 0.99}) taus.push_back(depths[static_cast<std::size_t>(q * double(depths.size() - 1))]);
    for (double tau : taus)
    for (double threshold : taus) {
      if (threshold > tau) continue;
      detail::PreparedPair pt = p;
      pt.tau = tau;
      pt.threshold = threshold;
      // The tree level with no tree prepared (its first triangles scan B's boxes, then it builds
      // one, as Version 1 runs do) and with one built beforehand (Version 2's blocks share it).
      detail::PreparedPair built = pt;
      built.tree_b.build(built.box_b);
      for (int variant = 0; variant < 3; ++variant) {
        const TriangleLevel level = variant == 0 ? TriangleLevel::Flat : TriangleLevel::Bvh;
        const detail::PreparedPair& pt_run = variant == 2 ? built : pt;
        CollideOptions early;
        early.triangle_level = level;
        for (std::size_t block : {pt.la.size(), std::size_t{7}}) {  // one run; Version 2-like blocks
          for (std::size_t begin = 0; begin < pt.la.size(); begin += block) {
            const std::size_t end = std::min(pt.la.size(), begin + block);
            detail::PairOutcome got;
            CollideCounters cg;
            detail::run_pair(sc.a, pt_run, begin, end, early, got, cg);
            const detail::PairOutcome want = reference_outcome(sc.a, pt, every.triangle_pairs, begin, end);
            ++runs;
            ASSERT_EQ(got.intersecting, want.intersecting) << "tau " << tau << " block " << begin;
            ASSERT_EQ(got.crosses_threshold, want.crosses_threshold)
                << "tau " << tau << " threshold " << threshold << " block " << begin;
            ASSERT_EQ(std::bit_cast<std::uint64_t>(got.penetration), std::bit_cast<std::uint64_t>(want.penetration))
                << "tau " << tau << " block " << begin << ": " << got.penetration << " != " << want.penetration;
            stopped += want.penetration > tau;
            // Pairs of the run that early exit did not test (all candidates were tested before).
            CollideCounters ca;
            detail::PairOutcome unused;
            CollideOptions all_level = all;
            all_level.triangle_level = level;
            detail::run_pair(sc.a, pt_run, begin, end, all_level, unused, ca);
            if (want.penetration <= tau) skipped += ca.triangle_tests - cg.triangle_tests;
          }
        }
      }
    }
  }
  std::printf("[ skip     ] %llu runs, %llu stopped early, %llu triangle tests skipped\n",
              static_cast<unsigned long long>(runs), static_cast<unsigned long long>(stopped),
              static_cast<unsigned long long>(skipped));
  EXPECT_GT(stopped, 0u);    // early exit happened somewhere ...
  EXPECT_GT(skipped, 1000u);  // ... and the skipping was exercised, not bypassed
}

}  // namespace
}  // namespace cadclash

namespace cadclash {
namespace {

// crossing_bound must never call a pair harmless that crosses deeper than the level: every
// intersecting survivor pair (the run measures no other) with crossing_depth > level is steep on
// both sides. And it must say something where it is meant to: faces lying on each other at any
// level above their rounding, coaxial faceted cylinders (axis fitted to the chords) above both
// sagittas, a pin through a hole above the chords' sag seen from either face (the side toward the
// pin's axis bounded); the plate through a plate keeps its deep crossings.
TEST(CrossingBound, EveryDeeperCrossingIsBetweenSteepTriangles) {
  std::size_t certified = 0, checked = 0;
  for (const PairScene& sc : scenes()) {
    SCOPED_TRACE(sc.name);
    CollideOptions o;
    o.triangle_level = TriangleLevel::Flat;
    const detail::PreparedPair p = prepare_flat(sc, o);
    ASSERT_FALSE(p.la.empty());
    std::vector<double> depth(p.la.size() * p.lb.size());  // intersecting pairs; 0 for the others
    double deepest = 0.0;
    TrianglePredicateStats stats;
    for (std::size_t i = 0; i < p.la.size(); ++i) {
      const auto& ta = sc.a.mesh.triangles[p.la[i]];
      const Vec3 &a0 = sc.a.mesh.vertices[ta[0]], &a1 = sc.a.mesh.vertices[ta[1]], &a2 = sc.a.mesh.vertices[ta[2]];
      for (std::size_t j = 0; j < p.lb.size(); ++j) {
        const auto& tb = p.tri_b[j];
        if (!triangles_intersect(a0, a1, a2, tb[0], tb[1], tb[2], stats)) continue;
        const double d = detail::crossing_depth(a0, a1, a2, tb[0], tb[1], tb[2]);
        depth[i * p.lb.size() + j] = d;
        deepest = std::max(deepest, d);
      }
    }
    const bool pin = sc.name.find("pin") != std::string::npos;
    if (pin) {
      EXPECT_GT(deepest, 0.004);  // the chords cross: the bound has something to bound
      EXPECT_LT(deepest, 0.011);
    }
    for (double level : {1e-9, 1e-6, 0.011, 0.5 * deepest, 0.9 * deepest}) {
      if (!(level > 0.0)) continue;
      const detail::CrossingBound b =
          detail::crossing_bound(sc.a.mesh, sc.a.analytic, p.la, 0, p.la.size(), p.tri_b, level, p.slack);
      ASSERT_EQ(b.steep_a.size(), p.la.size());
      ASSERT_EQ(b.steep_b.size(), p.lb.size());
      certified += !b.any;
      for (std::size_t i = 0; i < p.la.size(); ++i)
        for (std::size_t j = 0; j < p.lb.size(); ++j) {
          ++checked;
          if (depth[i * p.lb.size() + j] > level) {
            ASSERT_TRUE(b.any && b.steep_a[i] && b.steep_b[j])
                << "level " << level << " pair " << i << ' ' << j << " depth " << depth[i * p.lb.size() + j];
          }
        }
      // Above the rounding of the coplanar scenes' heights (1e-14 here) the bound has room.
      if (sc.name.rfind("coplanar", 0) == 0 && level >= 1e-9) {
        EXPECT_FALSE(b.any) << "level " << level;
      }
      if ((sc.name == "coaxial" || pin) && level >= 0.011) {
        EXPECT_FALSE(b.any) << "level " << level;
      }
      if (sc.name == "crossing" && level < deepest) {
        EXPECT_TRUE(b.any) << "level " << level;
      }
    }
  }
  std::printf("[ bound    ] %zu certified (pair, level) cases, %zu triangle pairs checked\n", certified, checked);
}

}  // namespace
}  // namespace cadclash
