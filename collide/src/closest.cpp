// How close each pair comes over a stretch of motion (trajectory.h, ClosestApproach): a branch and
// bound on the static checks' certified distance bounds and the travel bound.
#include "closest.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <utility>
#include <vector>

namespace cadclash::detail {
namespace {

using Key = std::pair<InstanceId, InstanceId>;

// Per instance pair in `r`: the smallest lower and upper bounds over its surface pairs (a contact:
// lower bound 0).
std::map<Key, std::pair<double, double>> bounds_of(const Report& r) {
  std::map<Key, std::pair<double, double>> out;
  for (const SurfacePairResult& p : r.pairs) {
    const bool contact = p.contact != ContactClass::Clearance;
    const double lo = contact ? 0.0 : std::max(0.0, p.distance_lo);
    const double hi = contact && !(p.distance_hi >= 0.0) ? 0.0 : std::max(0.0, p.distance_hi);
    auto [it, fresh] = out.try_emplace({p.instance_a, p.instance_b}, lo, hi);
    if (!fresh) it->second = {std::min(it->second.first, lo), std::min(it->second.second, hi)};
  }
  return out;
}

}  // namespace

std::map<Key, ClosestApproach> closest_approach(const std::function<Report(double, double)>& check_at,
                                                const std::function<double(double, double)>& travel,
                                                double clearance, double resolution, std::size_t max_checks,
                                                std::size_t& checks, bool& complete) {
  struct Best {
    double hi = std::numeric_limits<double>::infinity();
    double at = 0.0;
  };
  std::map<Key, Best> best;
  struct Leaf {
    double lo, s0, s1;
  };
  std::map<Key, std::vector<Leaf>> leaves;
  // Pairs seen in contact: their spans say where they touch; no closest approach is sought for them.
  std::set<Key> touching;
  auto improve = [&](const Report& r, double s) {
    for (const SurfacePairResult& p : r.pairs)
      if (p.contact == ContactClass::Touching || p.contact == ContactClass::Penetrating ||
          p.contact == ContactClass::Containment)
        touching.insert({p.instance_a, p.instance_b});
    for (const auto& [k, b] : bounds_of(r))
      if (b.second < best[k].hi) best[k] = {b.second, s};
  };
  // The end of the stretch: no part of it starts there.
  improve(check_at(1.0, 0.0), 1.0);
  ++checks;
  struct Stretch {
    double s0, s1;
  };
  std::vector<Stretch> stack{{0.0, 1.0}};
  while (!stack.empty()) {
    const Stretch st = stack.back();
    stack.pop_back();
    if (checks + 1 > max_checks) {
      complete = false;
      for (auto& [k, b] : best) leaves[k].push_back({0.0, st.s0, st.s1});  // nothing known here
      continue;
    }
    const double t = travel(st.s0, st.s1);
    const Report r = check_at(st.s0, t);
    ++checks;
    if (!r.complete) complete = false;
    improve(r, st.s0);
    bool open = false;
    for (const auto& [k, b] : bounds_of(r)) {
      const double lo = std::max(0.0, b.first - t);
      if (lo > clearance || touching.count(k)) continue;  // never within the clearance here, or touches
      if (lo >= best[k].hi) continue;            // cannot come closer than found already
      if (st.s1 - st.s0 <= resolution) leaves[k].push_back({lo, st.s0, st.s1});
      else open = true;
    }
    if (!r.complete) {  // pairs it did not examine: nothing is known of them here
      for (auto& [k, b] : best) leaves[k].push_back({0.0, st.s0, st.s1});
      continue;
    }
    if (!open) continue;
    const double mid = 0.5 * (st.s0 + st.s1);
    stack.push_back({mid, st.s1});
    stack.push_back({st.s0, mid});
  }
  std::map<Key, ClosestApproach> out;
  for (const auto& [k, b] : best) {
    if (touching.count(k)) continue;
    ClosestApproach c{b.hi, b.hi, b.at, b.at};
    for (const Leaf& l : leaves[k]) {
      if (l.lo >= b.hi) continue;  // found before the better bound came: cannot hold the minimum
      c.lo = std::min(c.lo, l.lo);
      c.s0 = std::min(c.s0, l.s0);
      c.s1 = std::max(c.s1, l.s1);
    }
    if (c.lo <= clearance) out.emplace(k, c);  // may come within the clearance
  }
  return out;
}

}  // namespace cadclash::detail
