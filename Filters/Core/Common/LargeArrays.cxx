// SPDX-License-Identifier: BSD-3-Clause
// Large arrays on transparent huge pages (LargeArrays.h).
#include "Common/LargeArrays.h"

#include <cstdint>
#include <mutex>
#include <new>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#define MESHFREE_HUGE_PAGES 1
#endif

namespace meshfree
{
namespace detail
{
namespace
{
constexpr std::size_t HugePage = std::size_t(2) << 20;

std::size_t RoundUp(std::size_t bytes, std::size_t to)
{
  return (bytes + to - 1) / to * to;
}

/// The pooled blocks' header: their capacity (bytes after the header), which may exceed what a reuse asks for.
constexpr std::size_t PoolHeader = 64;

/// Freed blocks of PoolFrom <= size < LargeBytes kept for reuse (LargeArrays.h), oldest first. Never destroyed: a
/// static array may be freed after the pool would have been.
struct BlockPool
{
  std::mutex Mutex;
  std::vector<std::pair<char*, std::size_t>> Free; // (block with its header, capacity)
  std::size_t Held = 0;
};

BlockPool& Pool()
{
  static BlockPool* pool = new BlockPool;
  return *pool;
}

std::size_t& Capacity(char* block)
{
  return *reinterpret_cast<std::size_t*>(block);
}
} // namespace

void* LargeAllocate(std::size_t bytes)
{
#ifdef MESHFREE_HUGE_PAGES
  if (bytes >= LargeBytes)
  {
    // One huge page more than needed, then the unaligned head and the tail beyond the rounded size unmapped.
    const std::size_t length = RoundUp(bytes, HugePage);
    void* mapped = mmap(nullptr, length + HugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapped == MAP_FAILED)
    {
      throw std::bad_alloc();
    }
    const std::uintptr_t begin = reinterpret_cast<std::uintptr_t>(mapped);
    const std::uintptr_t aligned = RoundUp(begin, HugePage);
    if (aligned > begin)
    {
      munmap(mapped, aligned - begin);
    }
    const std::uintptr_t end = begin + length + HugePage;
    if (end > aligned + length)
    {
      munmap(reinterpret_cast<void*>(aligned + length), end - (aligned + length));
    }
    void* block = reinterpret_cast<void*>(aligned);
    madvise(block, length, MADV_HUGEPAGE);
    return block;
  }
#endif
  if (bytes >= PoolFrom)
  {
    {
      // The smallest kept block that holds `bytes`, unless it is more than twice as large (it would leave a later
      // request for its size without one).
      BlockPool& pool = Pool();
      std::lock_guard<std::mutex> lock(pool.Mutex);
      size_t best = pool.Free.size();
      for (size_t b = 0; b < pool.Free.size(); ++b)
      {
        const std::size_t capacity = pool.Free[b].second;
        const bool fits = capacity >= bytes && capacity <= 2 * bytes;
        if (fits && (best == pool.Free.size() || capacity < pool.Free[best].second))
        {
          best = b;
        }
      }
      if (best < pool.Free.size())
      {
        char* block = pool.Free[best].first;
        pool.Held -= pool.Free[best].second;
        pool.Free.erase(pool.Free.begin() + static_cast<std::ptrdiff_t>(best));
        return block + PoolHeader;
      }
    }
    char* block = static_cast<char*>(::operator new(bytes + PoolHeader));
    Capacity(block) = bytes;
    return block + PoolHeader;
  }
  return ::operator new(bytes);
}

void LargeFree(void* p, std::size_t bytes) noexcept
{
  if (!p)
  {
    return;
  }
#ifdef MESHFREE_HUGE_PAGES
  if (bytes >= LargeBytes)
  {
    munmap(p, RoundUp(bytes, HugePage));
    return;
  }
#endif
  if (bytes >= PoolFrom)
  {
    char* block = static_cast<char*>(p) - PoolHeader;
    {
      BlockPool& pool = Pool();
      std::lock_guard<std::mutex> lock(pool.Mutex);
      try
      {
        pool.Free.emplace_back(block, Capacity(block));
        pool.Held += Capacity(block);
        block = nullptr;
      }
      catch (...) // no room to list it: freed below
      {
      }
      size_t oldest = 0;
      std::size_t held = pool.Held;
      while (held > PoolBytes && oldest < pool.Free.size())
      {
        held -= pool.Free[oldest++].second;
      }
      for (size_t b = 0; b < oldest; ++b)
      {
        ::operator delete(pool.Free[b].first);
      }
      pool.Free.erase(pool.Free.begin(), pool.Free.begin() + static_cast<std::ptrdiff_t>(oldest));
      pool.Held = held;
    }
    if (block)
    {
      ::operator delete(block);
    }
    return;
  }
  ::operator delete(p);
}

void AdviseHugePages(void* p, std::size_t bytes) noexcept
{
#ifdef MESHFREE_HUGE_PAGES
  const std::uintptr_t begin = RoundUp(reinterpret_cast<std::uintptr_t>(p), HugePage);
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(p) + bytes) / HugePage * HugePage;
  if (p && end > begin)
  {
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  }
#else
  (void)p;
  (void)bytes;
#endif
}
} // namespace detail
} // namespace meshfree
