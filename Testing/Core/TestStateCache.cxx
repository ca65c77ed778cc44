#include "Common/StateCache.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
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

TEST(StateCache, OutputTimesEndWithEndTime)
{
  const std::vector<double> t = meshfree::OutputTimes(1.0, 0.3);
  ASSERT_EQ(t.size(), 5u);
  EXPECT_EQ(t.front(), 0.0);
  EXPECT_DOUBLE_EQ(t[3], 0.9);
  EXPECT_EQ(t.back(), 1.0); // not a multiple of the interval: EndTime itself is the last output time
  const std::vector<double> exact = meshfree::OutputTimes(0.9, 0.3);
  ASSERT_EQ(exact.size(), 4u); // 0.9 / 0.3 is 3 up to rounding: no extra step of ~1e-16 at the end
  EXPECT_NEAR(exact.back(), 0.9, 1e-15);
  for (double bad : { 0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity() })
  {
    EXPECT_EQ(meshfree::OutputTimes(bad, 0.1).size(), 1u);
    EXPECT_EQ(meshfree::OutputTimes(1.0, bad).size(), 1u);
  }
  EXPECT_EQ(meshfree::OutputTimes(1e9, 1e-3).size(), 1000001u); // capped at 10^6 steps
}

TEST(StateCache, RequestedTimesArePlacedAmongTheOutputTimes)
{
  const std::vector<double> t = meshfree::OutputTimes(1.0, 0.3); // 0, 0.3, 0.6, 0.9, 1.0
  long step = -1;
  EXPECT_EQ(meshfree::PlaceRequestedTime(t, 0.6, step), t[2]); // an output time: itself
  EXPECT_EQ(step, 2);
  EXPECT_EQ(meshfree::PlaceRequestedTime(t, t[2] * (1.0 + 1e-12), step), t[2]); // round-off: the output time
  EXPECT_EQ(step, 2);
  EXPECT_EQ(meshfree::PlaceRequestedTime(t, t[3] * (1.0 - 1e-12), step), t[3]);
  EXPECT_EQ(step, 3);
  EXPECT_EQ(meshfree::PlaceRequestedTime(t, 0.45, step), 0.45); // between: exactly the request, from step 1
  EXPECT_EQ(step, 1);
  EXPECT_EQ(meshfree::PlaceRequestedTime(t, 0.95, step), 0.95); // in the short last interval
  EXPECT_EQ(step, 3);
  EXPECT_EQ(meshfree::PlaceRequestedTime(t, 0.01, step), 0.01);
  EXPECT_EQ(step, 0);
  EXPECT_EQ(meshfree::PlaceRequestedTime(t, 7.0, step), 1.0); // past the end: the last output time
  EXPECT_EQ(step, 4);
  for (double outside : { -1.0, std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::infinity() })
  {
    EXPECT_EQ(meshfree::PlaceRequestedTime(t, outside, step), 0.0);
    EXPECT_EQ(step, 0);
  }
  EXPECT_EQ(meshfree::PlaceRequestedTime(t, std::numeric_limits<double>::infinity(), step), 1.0);
  EXPECT_EQ(step, 4);
  const std::vector<double> single = meshfree::OutputTimes(0.0, 0.1); // just {0}
  EXPECT_EQ(meshfree::PlaceRequestedTime(single, 0.5, step), 0.0);
  EXPECT_EQ(step, 0);
}
