// The closest approach of each instance pair over one stretch of motion (check_motion with a
// clearance). Internal to collide.
#pragma once

#include "cadclash/trajectory.h"

#include <cstddef>
#include <functional>
#include <map>
#include <utility>

namespace cadclash::detail {

// `check_at(s, grow)`: the static check at fraction s with the clearance grown by `grow`;
// `travel(s0, s1)`: how far the pairs' points can move toward each other over [s0, s1]. For every
// instance pair within `clearance` somewhere and seen in contact by none of the checks: [lo, hi]
// holding its minimum distance and [s0, s1] every place it can be below hi. Halving stops at `resolution`; `checks` counts the static checks
// run; past `max_checks` the unsearched parts count as reaching 0 there and `complete` turns false.
std::map<std::pair<InstanceId, InstanceId>, ClosestApproach> closest_approach(
    const std::function<Report(double, double)>& check_at, const std::function<double(double, double)>& travel,
    double clearance, double resolution, std::size_t max_checks, std::size_t& checks, bool& complete);

}  // namespace cadclash::detail
