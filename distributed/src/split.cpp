// Splitting a plan's instance pairs into runs of equal estimated cost.
#include "cadclash/distributed.h"

#include <cassert>

namespace cadclash {

std::vector<std::vector<std::uint32_t>> split_by_cost(const CheckPlan& plan, int parts) {
  assert(parts >= 1);
  std::vector<std::vector<std::uint32_t>> out(static_cast<std::size_t>(parts));
  // Every pair costs at least 1: pairs of zero estimated cost (no candidate surfaces) still take a
  // broad-phase and object-level look.
  long double total = 0.0L;
  for (const PlannedPair& p : plan.pairs) total += static_cast<long double>(p.cost + 1);
  long double before = 0.0L;
  for (std::uint32_t k = 0; k < plan.pairs.size(); ++k) {
    const auto cost = static_cast<long double>(plan.pairs[k].cost + 1);
    const long double middle = before + 0.5L * cost;
    auto r = static_cast<std::size_t>(middle * parts / total);
    if (r >= out.size()) r = out.size() - 1;
    out[r].push_back(k);
    before += cost;
  }
  return out;
}

}  // namespace cadclash
