// A bound on how deep the triangles of a surface pair can cross, from one plane for the whole pair:
// faces lying on each other (a nut on a bracket, a plate on a plate) need no look at their other
// candidates once one intersecting triangle pair is found. Internal to cadclash::collide.
#pragma once

#include "cadclash/geometry.h"
#include "cadclash/model.h"

#include <array>
#include <cstdint>
#include <vector>

namespace cadclash::detail {

// A core C and a function r: the axis of A's cylinder (r = distance to the axis), the centre of A's
// sphere (r = distance to it), else the plane Π of A's largest triangle in the range (r = signed
// height over Π). Every point of these triangles (A's survivors la[begin, end) and B's `tri_b`, one
// frame) lies in the shell r in [lo, hi] (r is convex or linear: its maximum over a triangle is at a
// vertex, its minimum the triangle's distance to the core, or for a plane at a vertex). A point z of
// triangle X inside the normal prism of triangle Y is z = f + h·n with f in Y: r(z) >= r(f) + h·(n·ρ̂(f)),
// ρ̂ the direction away from the core, so on the side where n points away from it |h| <= (hi - lo) /
// c_Y, c_Y = min over Y of n·ρ̂ (from Y's vertices: min_v n·ρ_v / max_v |ρ_v|; for a plane |n·u|).
// Hence straddle(X, Y) <= (hi - lo) / c_Y and crossing_depth(X, Y) <= (hi - lo) / max(c_X, c_Y),
// plus rounding below `slack`. For a line or point core the side toward the core is bounded too
// when X meets Y (crossing_bound.cpp, over_curved): a shaft through a hole crosses the plate's
// triangles no deeper than the chords' sag. A triangle is steep when its bound does not stay within
// `level`: only an intersecting pair of a steep triangle of A and a steep one of B can cross deeper
// than it (the run measures the crossing depth of intersecting pairs only).
struct CrossingBound {
  std::vector<char> steep_a;  // per A survivor in [begin, end), index i - begin
  std::vector<char> steep_b;  // per B survivor
  bool any = false;           // some A survivor and some B survivor are steep
};

// `slack` bounds the rounding of a height of these coordinates (PreparedPair::slack).
// `core_a` is A's analytic surface in A's frame (only a hint: the bound is the triangles' own).
// `curved`: also try lines and points as cores. Which cores are tried changes only how many pairs
// the run still visits, never its outcome: at a level of the order of the rounding (a plane pair's
// T) only a plane can hold both faces' triangles in so thin a shell, so the run asks for planes.
CrossingBound crossing_bound(const TriangleMesh& mesh_a, const AnalyticSurface& core_a,
                             const std::vector<std::uint32_t>& la, std::size_t begin, std::size_t end,
                             const std::vector<std::array<Vec3, 3>>& tri_b, double level, double slack,
                             bool curved = true);

}  // namespace cadclash::detail
