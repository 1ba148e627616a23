// SceneData::first_need: per surface, the first instance pair of the running query that needs it,
// stamped with the query's serial so that a query starts from "no surface needed" without clearing
// an entry per surface of the model.
#include "scene_data.h"

#include <gtest/gtest.h>

namespace cadclash::detail {
namespace {

TEST(FirstNeed, EachQueryStartsWithNothingNeeded) {
  FirstNeed need;
  need.resize(4);
  need.start();
  for (SurfaceId s = 0; s < 4; ++s) EXPECT_EQ(need[s], kInvalidId);
  need.set(1, 7);
  need.set(3, 0);
  EXPECT_EQ(need[1], 7u);
  EXPECT_EQ(need[3], 0u);
  EXPECT_EQ(need[0], kInvalidId);
  need.start();
  for (SurfaceId s = 0; s < 4; ++s) EXPECT_EQ(need[s], kInvalidId) << s;
  need.set(3, 2);
  EXPECT_EQ(need[3], 2u);
  EXPECT_EQ(need[1], kInvalidId);
}

}  // namespace
}  // namespace cadclash::detail
