// The forecast of the triangle level's task costs (task_costs.h): the order a short loop on a team
// starts its tasks in. Longest first by the last check's times, tasks it did not run before all, ties
// in index order; each check's times replace the last's.
#include "task_costs.h"

#include <gtest/gtest.h>

#include <vector>

namespace cadclash {
namespace {

using detail::TaskCosts;
using Order = std::vector<std::uint32_t>;

TEST(TaskCosts, WithNothingKnownTheTasksKeepTheirOrder) {
  const TaskCosts costs;
  const std::vector<TaskCosts::Key> keys = {TaskCosts::key(0, 1, 5, 6), TaskCosts::key(0, 1, 5, 7),
                                            TaskCosts::key(0, 2, 5, 6)};
  EXPECT_EQ(costs.longest_first(keys), (Order{0, 1, 2}));
  EXPECT_TRUE(costs.longest_first({}).empty());
}

TEST(TaskCosts, LongestFirstUnknownBeforeAllTiesInIndexOrder) {
  TaskCosts costs;
  const auto a = TaskCosts::key(0, 1, 5, 6), b = TaskCosts::key(0, 1, 5, 7), c = TaskCosts::key(0, 2, 5, 6),
             d = TaskCosts::key(1, 2, 3, 4);
  const std::vector<TaskCosts::Key> last = {a, b, c};
  const std::vector<float> took = {1.0F, 3.0F, 1.0F};
  costs.remember(last, took);
  EXPECT_EQ(costs.longest_first(last), (Order{1, 0, 2}));
  // A task of the last check that moved in the list keeps its cost; d was not run: it goes first.
  const std::vector<TaskCosts::Key> now = {c, a, d, b};
  EXPECT_EQ(costs.longest_first(now), (Order{2, 3, 0, 1}));
}

TEST(TaskCosts, InstancesAndSurfacesAreToldApart) {
  // The same surfaces in other instances, or swapped, are other tasks (their costs unknown).
  TaskCosts costs;
  const std::vector<TaskCosts::Key> last = {TaskCosts::key(0, 1, 5, 6)};
  costs.remember(last, std::vector<float>{1.0F});
  const std::vector<TaskCosts::Key> now = {TaskCosts::key(0, 1, 5, 6), TaskCosts::key(0, 1, 6, 5),
                                           TaskCosts::key(1, 0, 5, 6), TaskCosts::key(0, 2, 5, 6)};
  EXPECT_EQ(costs.longest_first(now), (Order{1, 2, 3, 0}));
}

TEST(TaskCosts, EachCheckReplacesTheLast) {
  TaskCosts costs;
  const auto a = TaskCosts::key(0, 1, 5, 6), b = TaskCosts::key(0, 1, 5, 7);
  costs.remember(std::vector<TaskCosts::Key>{a, b}, std::vector<float>{1.0F, 2.0F});
  costs.remember(std::vector<TaskCosts::Key>{a}, std::vector<float>{5.0F});
  // b is forgotten (unknown, so first); a has its newest cost.
  EXPECT_EQ(costs.longest_first(std::vector<TaskCosts::Key>{a, b}), (Order{1, 0}));
  costs.clear();
  EXPECT_EQ(costs.longest_first(std::vector<TaskCosts::Key>{a, b}), (Order{0, 1}));
}

}  // namespace
}  // namespace cadclash
