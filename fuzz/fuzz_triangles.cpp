// libFuzzer entry point: the exact triangle test and the distance built on it, checked against the
// CGAL oracle of tests/collide (exact constructions on the same doubles). Any disagreement aborts,
// so this fuzzer looks for wrong answers, not only for crashes.
//
// The bytes choose a mode and then the coordinates. Raw doubles alone would almost never be
// coplanar or touching, where the float filters are closest to their error bounds, so most modes
// build points on small integer lattices (in coordinate planes or in an arbitrary plane), scale and
// shift them exactly, and then optionally nudge single coordinates by a few ulps.
#include "test_triangle_cases.h"
#include "cadclash/geometry.h"

#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace {

using cadclash::Vec3;
using cadclash::test::Tri;

enum class Mode { Raw, Lattice, PlaneLattice, ScaledLattice, ExtremeLattice, Count };

Vec3 lattice_vec(FuzzedDataProvider& in, int r) {
  return {double(in.ConsumeIntegralInRange(-r, r)), double(in.ConsumeIntegralInRange(-r, r)),
          double(in.ConsumeIntegralInRange(-r, r))};
}

// Any finite double, with its binary exponent folded into [-64, 64]: the predicates require finite
// coordinates, and beyond about 1e150 squared lengths overflow, which no double-precision distance
// survives (cadclash coordinates are millimetres).
double raw_double(FuzzedDataProvider& in) {
  const double d = std::bit_cast<double>(in.ConsumeIntegral<std::uint64_t>());
  if (!std::isfinite(d) || d == 0) return 0.0;
  int exponent = 0;
  const double mantissa = std::frexp(d, &exponent);
  return std::ldexp(mantissa, exponent % 65);
}

std::array<Vec3, 6> decode(FuzzedDataProvider& in) {
  std::array<Vec3, 6> p;
  const auto mode = static_cast<Mode>(in.ConsumeIntegralInRange<int>(0, static_cast<int>(Mode::Count) - 1));
  switch (mode) {
    case Mode::Raw:
      for (Vec3& v : p) v = {raw_double(in), raw_double(in), raw_double(in)};
      return p;
    case Mode::Lattice:
    case Mode::ScaledLattice:
    case Mode::ExtremeLattice:
      for (Vec3& v : p) v = lattice_vec(in, 4);
      break;
    case Mode::PlaneLattice: {
      const Vec3 o = lattice_vec(in, 8), u = lattice_vec(in, 3), w = lattice_vec(in, 3);
      for (Vec3& v : p) v = o + in.ConsumeIntegralInRange(-4, 4) * u + in.ConsumeIntegralInRange(-4, 4) * w;
      break;
    }
    case Mode::Count: break;
  }
  if (mode == Mode::ExtremeLattice) {
    // Anywhere in the double range, down to subnormal lattice steps: squares and products of
    // coordinates leave the range there (the distance once lost 3 x 2^-1074 to an underflow).
    const double s = std::ldexp(1.0, in.ConsumeIntegralInRange(-1074, 1000));
    for (Vec3& v : p) v = v * s;
  } else if (mode == Mode::ScaledLattice || in.ConsumeBool()) {
    // Power-of-two scale and an integer shift: exact, so the lattice's coplanarity survives.
    const double s = std::ldexp(1.0, in.ConsumeIntegralInRange(-40, 40));
    const Vec3 t = lattice_vec(in, 1) * std::ldexp(1.0, in.ConsumeIntegralInRange(0, 40));
    for (Vec3& v : p) v = v * s + t;
  }
  // A few coordinates nudged by up to 3 ulps: just off (or onto) the plane or edge of the other.
  for (int n = in.ConsumeIntegralInRange(0, 3); n > 0; --n) {
    double& c = p[in.ConsumeIntegralInRange(0, 5)][in.ConsumeIntegralInRange(0, 2)];
    const int steps = in.ConsumeIntegralInRange(-3, 3);
    for (int k = 0; k < std::abs(steps); ++k) c = std::nextafter(c, steps > 0 ? HUGE_VAL : -HUGE_VAL);
  }
  return p;
}

[[noreturn]] void fail(const char* what, const std::array<Vec3, 6>& p, double distance = NAN) {
  std::fprintf(stderr, "fuzz_triangles: %s (triangle_distance %a)\n", what, distance);
  for (int i = 0; i < 6; ++i)
    std::fprintf(stderr, "  %c%d = (%a, %a, %a)\n", i < 3 ? 'a' : 'b', i % 3, p[i].x(), p[i].y(), p[i].z());
  std::fflush(stderr);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cadclash;
  FuzzedDataProvider in(data, size);
  const std::array<Vec3, 6> p = decode(in);
  const Vec3 &a0 = p[0], &a1 = p[1], &a2 = p[2], &b0 = p[3], &b1 = p[4], &b2 = p[5];

  TrianglePredicateStats stats;
  const bool expected = cadclash::test::oracle_intersect(Tri{a0, a1, a2}, Tri{b0, b1, b2});
  const bool got = triangles_intersect(a0, a1, a2, b0, b1, b2, stats);
  if (got != expected) fail(expected ? "triangles_intersect: false, oracle: true" : "triangles_intersect: true, oracle: false", p);
  if (triangles_intersect_exact(a0, a1, a2, b0, b1, b2) != expected) fail("triangles_intersect_exact disagrees with the oracle", p);
  // The answer is about two point sets: argument order and vertex order must not change it.
  if (triangles_intersect(b1, b2, b0, a2, a1, a0, stats) != expected) fail("swapped and reordered arguments change the answer", p);

  const double d = triangle_distance(a0, a1, a2, b0, b1, b2);
  if (std::isnan(d) || d < 0) fail("triangle_distance is negative or NaN", p);
  if ((d == 0) != expected) fail(expected ? "intersecting, but triangle_distance > 0" : "disjoint, but triangle_distance == 0", p);
  if (triangles_within(a0, a1, a2, b0, b1, b2, 0.0, stats) != expected) fail("triangles_within(d = 0) disagrees with the oracle", p);
  // "True iff triangle_distance <= d": the early outs must never contradict the distance. Checked a
  // little away from d, by 2^-40 of d plus 2^-44 of the pair's extent (the scale of the distance's
  // documented error) and at least one ulp of d: exactly at d, triangles_within can say false, e.g.
  // for a touching pair 1e13 across whose distance rounds to the smallest subnormal.
  double extent = 0;
  for (const Vec3& v : p) extent = std::max(extent, (v - a0).cwiseAbs().maxCoeff());
  const double margin = std::ldexp(d, -40) + std::ldexp(extent, -44);
  const double above = std::max(d + margin, std::nextafter(d, HUGE_VAL));
  const double below = std::min(d - margin, std::nextafter(d, 0.0));
  if (std::isfinite(d) && !triangles_within(a0, a1, a2, b0, b1, b2, above, stats))
    fail("triangles_within(d just above triangle_distance) is false", p, d);
  if (d > 0 && std::isfinite(d) && triangles_within(a0, a1, a2, b0, b1, b2, below, stats))
    fail("triangles_within(d just below triangle_distance) is true", p, d);
  return 0;
}
