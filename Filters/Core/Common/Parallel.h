// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: the one way the core runs loops on several threads.
//
// Loops are cut into ranges that idle threads take from each other (oneTBB's work stealing, in a task arena
// of MaxThreads() slots). On a machine shared with other busy processes a thread that the OS deschedules
// leaves its untaken ranges to the threads that run, and a thread with nothing to take sleeps instead of
// spinning on a barrier: fork-join loops with static shares (OpenMP's model) instead wait for the slowest
// thread at every barrier, which on 2 cores beside one busy process made a step up to 18 times slower.
//
// Results never depend on the number of threads: ParallelFor bodies write disjoint outputs, and
// ParallelReduce combines partial results of fixed blocks (independent of the threads) in block order.
// A ParallelFor called from inside a parallel body runs serially on the calling thread (as OpenMP's nested
// regions do), so per-thread scratch indexed by ThreadIndex() is never shared by interleaved bodies.
#ifndef meshfree_Parallel_h
#define meshfree_Parallel_h

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

namespace meshfree
{
using Index = std::int64_t;

/// Threads the core uses: SetMaxThreads(n) when n > 0 was called; otherwise MESHFREE_NUM_THREADS, or else
/// OMP_NUM_THREADS (honoured so that existing scripts keep their meaning), or else the CPUs this process may
/// run on.
int MaxThreads();
/// Sets the number of threads (0: back to the default above). Not to be called from inside a parallel loop.
void SetMaxThreads(int threads);
/// Slot of the calling thread inside a parallel body, in [0, MaxThreads()); 0 outside parallel loops.
int ThreadIndex();
/// Describes what runs loops, e.g. "oneTBB, 2 threads".
const char* ParallelBackend();

/// Per-thread scratch: one T for each thread slot, made once before a parallel loop; inside the loop's body
/// Local() is the calling thread's own (no allocation per item, nothing shared between threads). Iterating
/// visits every slot (e.g. to merge per-thread results after the loop).
template <class T>
class PerThread
{
public:
  PerThread()
    : Slots(static_cast<std::size_t>(MaxThreads()))
  {
  }
  explicit PerThread(const T& prototype)
    : Slots(static_cast<std::size_t>(MaxThreads()), prototype)
  {
  }
  T& Local() { return this->Slots[static_cast<std::size_t>(ThreadIndex())]; }
  std::size_t size() const { return this->Slots.size(); }
  T& operator[](std::size_t slot) { return this->Slots[slot]; }
  typename std::vector<T>::iterator begin() { return this->Slots.begin(); }
  typename std::vector<T>::iterator end() { return this->Slots.end(); }

private:
  std::vector<T> Slots;
};

namespace detail
{
using RangeFunction = void (*)(void* body, Index begin, Index end);
/// Runs fn(body, b, e) over ranges [b, e) covering [0, n), each of at most grain items.
void ParallelRanges(Index n, Index grain, RangeFunction fn, void* body);
} // namespace detail

/// Calls body(begin, end) for ranges covering [0, n) exactly once, in parallel when n >= serialBelow and
/// more than one thread is allowed. Ranges hold at most `grain` items (at least about half as many): small
/// enough that a thread the OS deschedules holds back little work (the others finish the rest; the loop
/// waits only for the range in hand), large enough to pay for handing a range out (about a microsecond).
template <class Body>
void ParallelFor(Index n, Index grain, Body&& body, Index serialBelow = 0)
{
  if (n <= 0)
  {
    return;
  }
  if (n < serialBelow || n <= grain)
  {
    body(Index(0), n);
    return;
  }
  using B = std::remove_reference_t<Body>;
  detail::ParallelRanges(
    n, grain, [](void* b, Index begin, Index end) { (*static_cast<B*>(b))(begin, end); },
    const_cast<void*>(static_cast<const void*>(&body)));
}

/// Reduces [0, n) cut into fixed blocks of `block` items: partial(begin, end) -> T for each block in parallel,
/// then combine(accumulated, partial) in block order starting from identity. Deterministic whatever the
/// number of threads.
template <class T, class Partial, class Combine>
T ParallelReduce(Index n, Index block, T identity, Partial&& partial, Combine&& combine, Index serialBelow = 0)
{
  if (n <= 0)
  {
    return identity;
  }
  block = block > 0 ? block : 1;
  const Index blocks = (n + block - 1) / block;
  std::vector<T> parts(static_cast<std::size_t>(blocks), identity);
  ParallelFor(
    blocks, 1,
    [&](Index b0, Index b1) {
      for (Index b = b0; b < b1; ++b)
      {
        parts[static_cast<std::size_t>(b)] = partial(b * block, std::min(n, (b + 1) * block));
      }
    },
    n < serialBelow ? blocks + 1 : 0);
  T result = std::move(identity);
  for (T& p : parts)
  {
    result = combine(std::move(result), std::move(p));
  }
  return result;
}
} // namespace meshfree

#endif
