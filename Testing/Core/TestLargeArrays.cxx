// LargeArrays.h: mid-size blocks kept when freed and given again to a request they hold, within the pool's bound.
#include "Common/LargeArrays.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include <sys/resource.h>

using namespace meshfree;
using namespace meshfree::detail;

namespace
{
long MinorFaults()
{
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}
} // namespace

TEST(LargeArrays, FreedBlockStaysMapped)
{
  // A 4 MiB block written, freed and asked for again is the same memory, its pages still mapped: writing it again
  // faults (almost) no page, where fresh memory faults one per 4 KiB page (1024; without the pool glibc unmaps the
  // block, or reuses the heap's top after trimming it).
  const std::size_t bytes = std::size_t(4) << 20;
  char* first = static_cast<char*>(LargeAllocate(bytes));
  std::memset(first, 1, bytes);
  LargeFree(first, bytes);
  const long before = MinorFaults();
  char* again = static_cast<char*>(LargeAllocate(bytes));
  std::memset(again, 2, bytes);
  const long faults = MinorFaults() - before;
  EXPECT_EQ(again, first);
  EXPECT_LT(faults, 64) << "the block's pages were mapped afresh";
  LargeFree(again, bytes);
}

TEST(LargeArrays, FreedMidSizeBlockIsGivenAgain)
{
  const std::size_t bytes = PoolFrom + 4096;
  void* first = LargeAllocate(bytes);
  std::memset(first, 1, bytes);
  LargeFree(first, bytes);
  // The same size, and a smaller one the block still holds (at most half of it unused), take the kept block.
  void* again = LargeAllocate(bytes);
  EXPECT_EQ(again, first);
  LargeFree(again, bytes);
  void* smaller = LargeAllocate(bytes - 4096);
  EXPECT_EQ(smaller, first);
  // Freed with the size it was asked for: the block keeps its capacity and serves the first size again.
  LargeFree(smaller, bytes - 4096);
  void* whole = LargeAllocate(bytes);
  EXPECT_EQ(whole, first);
  std::memset(whole, 2, bytes); // all of it usable
  LargeFree(whole, bytes);
}

TEST(LargeArrays, BlocksTooLargeOrTooSmallAreNotReused)
{
  const std::size_t bytes = 4 * PoolFrom;
  void* block = LargeAllocate(bytes);
  LargeFree(block, bytes);
  // A request for less than half of it gets a block of its own (the kept one stays for its size).
  void* small = LargeAllocate(PoolFrom);
  EXPECT_NE(small, block);
  // A larger request does not fit in it.
  void* large = LargeAllocate(bytes + 1);
  EXPECT_NE(large, block);
  void* same = LargeAllocate(bytes);
  EXPECT_EQ(same, block);
  LargeFree(small, PoolFrom);
  LargeFree(large, bytes + 1);
  LargeFree(same, bytes);
}

TEST(LargeArrays, PoolHoldsAtMostItsBound)
{
  // Freeing more than PoolBytes lets the oldest blocks go: the first freed is not given again, the last is.
  const std::size_t bytes = std::size_t(4) << 20;
  const int count = static_cast<int>(PoolBytes / bytes) + 4;
  std::vector<void*> blocks;
  for (int b = 0; b < count; ++b)
  {
    blocks.push_back(LargeAllocate(bytes));
  }
  for (void* p : blocks)
  {
    LargeFree(p, bytes);
  }
  std::vector<void*> taken;
  for (int b = 0; b < count; ++b)
  {
    taken.push_back(LargeAllocate(bytes));
  }
  int reused = 0;
  for (void* p : taken)
  {
    for (void* q : blocks)
    {
      reused += p == q ? 1 : 0;
    }
  }
  EXPECT_LE(static_cast<std::size_t>(reused) * bytes, PoolBytes);
  EXPECT_GT(reused, 0);
  for (void* p : taken)
  {
    LargeFree(p, bytes);
  }
}

TEST(LargeArrays, BufferKeepsItsValuesAcrossReuse)
{
  // A Buffer grown past PoolFrom, freed and made again: assign() writes every element (no stale values).
  const std::size_t n = PoolFrom / sizeof(double) + 100;
  {
    Buffer<double> a(n, 3.0);
    EXPECT_EQ(a[n - 1], 3.0);
  }
  Buffer<double> b;
  AssignLarge(b, n, -1.0);
  for (std::size_t i = 0; i < n; ++i)
  {
    ASSERT_EQ(b[i], -1.0);
  }
}
