// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief Large per-point arrays on transparent huge pages (Linux), so that their first touch faults once per
 *        2 MiB instead of once per 4 KiB.
 *
 * A page written for the first time costs a page fault. Under some hypervisors a fault is far dearer than the
 * write: measured on the project's 2-core virtual machine, 18 us per 4 KiB page (4.7 ms per MiB, about 50 times
 * the cost of writing the memory again), which made the fresh arrays of Meshless Normals (its field, the
 * orientation's graph, the grid) about a fifth of its time at 100k points and a serial share of seconds at 10M.
 * Memory advised MADV_HUGEPAGE, where the kernel's transparent huge pages are "always" or "madvise" (the
 * distributions' default), faults once per 2 MiB page: the same 64 MiB in 0.09 ms per MiB. Elsewhere (other
 * systems, huge pages disabled) the advice does nothing and the arrays are ordinary memory.
 *
 * LargeAllocate gives blocks of at least LargeBytes (8 MiB) their own 2 MiB-aligned mapping, advised for huge pages
 * (its last huge page may hold up to 2 MiB it does not use, at most a quarter of the block; from 256 KiB on, the
 * first threshold, a distributed surface's memory per rank grew by 30 MB at 1M points on 4 ranks, 39 %, issue 24);
 * smaller ones come from operator new. ReserveLarge gives a std::vector (a public
 * array, whose allocator is the standard one) untouched capacity and advises the whole huge pages inside it (an
 * array shorter than two of them may hold none).
 *
 * Mid-size blocks (PoolFrom = 64 KiB up to LargeBytes) are kept when freed, up to PoolBytes (32 MiB) of them, the
 * oldest let go first, and given again to a later request they hold (at most twice its size): their pages are
 * mapped already, so a filter's scratch arrays, freed at the end of one stage or run, cost no faults in the next
 * (the arrays of a 100k-point cloud are too small for huge pages: there Meshless Normals' core faulted about 6,400
 * pages a run, 0.1 CPU s of 0.7-0.9, mostly in serial stages; with the pool 2,100, its std::vector arrays, and
 * through the plugin, run again in pvpython, none instead of 5,400). glibc's malloc keeps up to 64 MiB of freed
 * memory at the top of its heap in the same way. detail::Buffer (a vector whose resize leaves trivial
 * elements uninitialised) allocates through LargeAllocate (the core's scratch arrays; public arrays stay std::vector).
 */
#ifndef meshfree_LargeArrays_h
#define meshfree_LargeArrays_h

#include <cstddef>
#include <new>
#include <utility>
#include <vector>

namespace meshfree
{
namespace detail
{
/// Blocks from this size on are mapped on their own, aligned and advised for huge pages.
constexpr std::size_t LargeBytes = std::size_t(8) << 20;
/// Blocks from this size up to LargeBytes are kept when freed, PoolBytes of them at most (the oldest go first), and
/// given again to a request they hold (at most twice its size).
constexpr std::size_t PoolFrom = std::size_t(64) << 10;
constexpr std::size_t PoolBytes = std::size_t(32) << 20;

/// At least `bytes` of memory (aligned for any type); throws std::bad_alloc when there is none.
void* LargeAllocate(std::size_t bytes);
/// Frees a block of LargeAllocate(bytes) (the same `bytes`).
void LargeFree(void* p, std::size_t bytes) noexcept;
/// Advises the whole 2 MiB pages inside [p, p + bytes) for huge pages (memory not yet touched, e.g. a vector's
/// fresh capacity; touched pages stay as they are). No effect where unsupported.
void AdviseHugePages(void* p, std::size_t bytes) noexcept;

/// Allocator whose resize() leaves trivial elements uninitialised (the build writes them in parallel), large
/// blocks on huge pages (LargeArrays.h: their first touch is a fraction of the cost).
template <class T>
struct UninitializedAllocator : std::allocator<T>
{
  using value_type = T;
  T* allocate(std::size_t n) { return static_cast<T*>(LargeAllocate(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { LargeFree(p, n * sizeof(T)); }
  template <class U>
  struct rebind
  {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept
  {
  }
  template <class U>
  void construct(U* p) noexcept
  {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args)
  {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T>
using Buffer = std::vector<T, UninitializedAllocator<T>>;

/// Makes v's capacity at least n elements; when that takes a new block of at least LargeBytes (v emptied first),
/// its whole huge pages are advised before anything is written to them.
template <class T, class A>
void ReserveLarge(std::vector<T, A>& v, std::size_t n)
{
  if (v.capacity() >= n)
  {
    return;
  }
  std::vector<T, A>().swap(v);
  v.reserve(n);
  if (n * sizeof(T) >= LargeBytes)
  {
    AdviseHugePages(v.data(), n * sizeof(T));
  }
}

/// v.assign(n, value) over capacity from ReserveLarge.
template <class T, class A>
void AssignLarge(std::vector<T, A>& v, std::size_t n, const T& value)
{
  ReserveLarge(v, n);
  v.assign(n, value);
}
} // namespace detail
} // namespace meshfree

#endif
