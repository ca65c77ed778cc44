// SPDX-License-Identifier: BSD-3-Clause
// Large arrays on transparent huge pages (LargeArrays.h).
#include "Common/LargeArrays.h"

#include <cstdint>
#include <new>

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
