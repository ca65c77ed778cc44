#include "StateCache.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

using meshfree::StateCache;

TEST(StateCache, FindsLargestStepAtOrBefore)
{
  StateCache<int> cache(8);
  long found = -1;
  EXPECT_EQ(cache.FindAtOrBefore(5, found), nullptr);
  cache.Insert(0, 100);
  cache.Insert(4, 104);
  cache.Insert(9, 109);
  ASSERT_NE(cache.FindAtOrBefore(5, found), nullptr);
  EXPECT_EQ(found, 4);
  EXPECT_EQ(*cache.FindAtOrBefore(9, found), 109);
  EXPECT_EQ(*cache.FindAtOrBefore(3, found), 100);
  EXPECT_EQ(found, 0);
}

TEST(StateCache, BoundedAndKeepsFirstAndLast)
{
  StateCache<std::vector<double>> cache(4);
  for (long s = 0; s <= 20; ++s)
  {
    cache.Insert(s, std::vector<double>(3, static_cast<double>(s)));
    EXPECT_LE(cache.Size(), 4u);
  }
  long found = -1;
  EXPECT_TRUE(cache.Contains(0));
  EXPECT_TRUE(cache.Contains(20));
  // The kept checkpoints stay spread out: the largest gap to re-simulate is well below the whole range.
  long previous = 0, largestGap = 0;
  for (long s = 1; s <= 20; ++s)
  {
    if (cache.Contains(s))
    {
      largestGap = std::max(largestGap, s - previous);
      previous = s;
    }
  }
  EXPECT_LT(largestGap, 20);
  ASSERT_NE(cache.FindAtOrBefore(19, found), nullptr);
  EXPECT_LT(found, 20);
  cache.Clear();
  EXPECT_EQ(cache.Size(), 0u);
  EXPECT_EQ(cache.FindAtOrBefore(19, found), nullptr);
}
