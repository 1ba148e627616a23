// Generators of triangle pairs for the predicate tests and benchmarks: random, coplanar, touching,
// shared features, far offsets, slivers, 1-ulp perturbations, degenerate, under rigid motions, and the
// numerical extremes (offsets 1e3..1e12 with features down to 1e-9 of the offset, nearly coplanar at
// 1e-15..1e-6 rad, T-junctions, tiny against huge); the brute-force exact oracle (CGAL Epeck, exact
// constructions) they are checked against; and the float-only answer the filters exist to avoid.
#pragma once

#include "cadclash/collide.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <string_view>

namespace cadclash::test {

using Tri = std::array<Vec3, 3>;

struct TriPair {
  Tri a, b;
};

// splitmix64: portable, so every platform generates the same cases.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int integer(int lo, int hi) {  // [lo, hi]
    return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  Vec3 vec(double lo, double hi) { return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)}; }
  Vec3 ivec(int lo, int hi) {
    return {double(integer(lo, hi)), double(integer(lo, hi)), double(integer(lo, hi))};
  }
  Vec3 unit() {
    for (;;) {
      const Vec3 v = vec(-1, 1);
      const double n = v.norm();
      if (n > 0.1 && n <= 1.0) return v / n;
    }
  }

 private:
  std::uint64_t s_;
};

enum class Family {
  RandomCube,      // vertices uniform in the unit cube (about half intersect)
  RandomNear,      // small triangles near each other (mostly disjoint, many close calls)
  CoplanarGrid,    // both triangles exactly in one plane on an integer lattice: overlap, touch, apart
  SharedFeature,   // a shared vertex or a shared edge, the rest random or on the common plane
  TouchingGrid,    // a vertex or edge of B exactly on an edge or the face of A, B otherwise off-plane
  FarOffset,       // at 1e8 from the origin with 1e-3 features
  Sliver,          // needles and caps with angles of 1e-12 against small random triangles
  UlpPerturbed,    // a coplanar or touching pair with one coordinate moved by 1-4 ulps
  Degenerate,      // collinear and repeated vertices, points, segments
  RigidMotion,     // any of the above under a large rotation and translation (rounded)
  // Numerical extremes (not mixed into RigidMotion, whose inner families stay the ones above).
  OffsetFeature,   // offsets 1e3..1e12, features 1e-3..1e-9 of the offset: near, coplanar-ish, touching, lattice
  NearlyCoplanar,  // B = a triangle in A's plane rotated by 1e-15..1e-6 rad about an in-plane axis
  TJunction,       // a vertex of B on the inside of an edge of A (exact, or rounded onto it), B coplanar or not
  TinyHuge,        // a triangle of 1e-9..1e-3 crossing, touching or just off a triangle of 1e2..1e6
  // Exact contacts whose exact signs need the expansions, not the lattice fast path.
  WideCoplanar,    // coplanar, vertex-on-plane and edge-in-plane pairs, exact in any plane: wide lattices
                   // (differences of 20-30 bits) or planes along an axis with a free coordinate spread
                   // over 2^-20..2^30 (differences that are not doubles)
  kCount
};

std::string_view family_name(Family f);

// The i-th case of family f for seed `seed` (deterministic).
TriPair make_case(Family f, Rng& rng);

// Applies a random large rigid motion (rotation, translation up to `max_shift`) to both triangles;
// coordinates are rounded to doubles, as the tests check the rounded values.
TriPair rigid_motion(const TriPair& p, Rng& rng, double max_shift);

// The oracle: exact intersection of the closed point sets with CGAL's Epeck (exact constructions).
bool oracle_intersect(const Tri& a, const Tri& b);

// The sign of (exact distance between the closed triangles) - limit, exactly (Epeck): -1 below,
// 0 equal, +1 above. limit >= 0.
int oracle_compare_distance(const Tri& a, const Tri& b, double limit);

// True when triangles_intersect may hand (a, b) to CGAL (triangles_intersect_exact): one of them is
// degenerate (collinear or repeated vertices, decided with Epeck), or a coordinate is beyond 2^48 in
// magnitude, or nonzero and below 2^-300 (outside the exact stage's domain).
bool may_need_cgal(const Tri& a, const Tri& b);

// The float-only answer: the same closed-set decision (CGAL's Guigue–Devillers triangle test, the
// algorithm triangles_intersect filters) evaluated in plain double (Simple_cartesian<double>), with
// no error bound and no exact fallback. What a naive implementation answers; often wrong on the
// adversarial families. A CGAL precondition the rounded arithmetic breaks (only in builds with CGAL
// assertions) returns false and sets *failed; callers count it as a wrong answer.
bool float_only_intersect(const Tri& a, const Tri& b, bool* failed = nullptr);

}  // namespace cadclash::test
