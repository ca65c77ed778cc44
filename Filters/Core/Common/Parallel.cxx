// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: parallel loops on oneTBB (see Parallel.h for the design and why not fork-join).
#include "Common/Parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>

namespace meshfree
{
namespace
{
std::atomic<int> RequestedThreads{ 0 };
thread_local int NestingDepth = 0; // > 0 inside a parallel body
thread_local int Slot = 0;         // the body's arena slot

int ThreadsFromEnvironment(const char* name)
{
  const char* value = std::getenv(name);
  if (!value || !*value)
  {
    return 0;
  }
  char* end = nullptr;
  const long n = std::strtol(value, &end, 10); // OMP_NUM_THREADS may be a list ("4,2"): its first entry
  return (end != value && n > 0 && n <= 4096) ? static_cast<int>(n) : 0;
}

int DefaultThreads()
{
  static const int threads = [] {
    int n = ThreadsFromEnvironment("MESHFREE_NUM_THREADS");
    n = n > 0 ? n : ThreadsFromEnvironment("OMP_NUM_THREADS");
    return n > 0 ? n : std::max(1, tbb::info::default_concurrency());
  }();
  return threads;
}

// One arena for the core's loops, rebuilt when the number of threads changes. Its slots bound ThreadIndex().
struct Arena
{
  std::mutex Mutex;
  std::unique_ptr<tbb::task_arena> Instance;
  int Threads = 0;
  std::string Description;

  tbb::task_arena& Get(int threads)
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    if (!this->Instance || this->Threads != threads)
    {
      this->Instance = std::make_unique<tbb::task_arena>(threads);
      this->Threads = threads;
      this->Description = "oneTBB, " + std::to_string(threads) + (threads == 1 ? " thread" : " threads");
    }
    return *this->Instance;
  }
};

Arena& CoreArena()
{
  static Arena arena;
  return arena;
}
} // namespace

int MaxThreads()
{
  const int requested = RequestedThreads.load(std::memory_order_relaxed);
  return requested > 0 ? requested : DefaultThreads();
}

void SetMaxThreads(int threads)
{
  RequestedThreads.store(threads > 0 ? threads : 0, std::memory_order_relaxed);
}

int ThreadIndex()
{
  return NestingDepth > 0 ? Slot : 0;
}

const char* ParallelBackend()
{
  Arena& arena = CoreArena();
  arena.Get(MaxThreads());
  return arena.Description.c_str();
}

namespace detail
{
namespace
{
// Whether the threads pay off now, per calling thread. A loop ends only when every range handed out is done, so
// beside busy processes it can wait for a range that a descheduled thread holds; for short loops (a few
// milliseconds) that wait can cost more than the other threads bring. Each parallel loop compares its wall time
// with what the calling thread alone would have taken (its own ranges' time per item, times all the items); when
// the recent runs of the same loop (below) ran slower than that, its next 63 runs are on the calling thread alone,
// and then the threads are tried again. Results do not depend on this: they never depend on the number of threads.
struct LoopHistory
{
  RangeFunction Site = nullptr; // the loop: its body's type (one function per ParallelFor instantiation)
  int SizeClass = -1;           // and its size: the number of ranges handed out, by its power of two
  double Ratio = 0.0;           // moving average of wall time / one-thread estimate; 0: no history
  int SerialLeft = 0;
};
// One history per loop and size: a verdict on one loop says nothing about another. (Measured: with one history per
// size class only, the cheap loops of the normals' crease pass and sample fits, which the workers' wake-up makes
// slower in parallel, switched the threads off for the jets' loop of the same size; Meshless Normals at 100k and 1M
// points then ran on one thread beside busy processes. Before, one history for all loops left the whole estimation
// of a 1M-point cloud on one thread on an idle machine.) Direct-mapped: a loop whose slot another took starts afresh.
constexpr int kHistorySlots = 256;
constexpr int kSizeClasses = 64;
thread_local LoopHistory Histories[kHistorySlots];
// A loop that one thread would take longer than this never falls back: the threads lose at most the wait for the
// range a descheduled thread holds (a time slice of the OS scheduler, a few milliseconds), a small part of it, and
// a wrong verdict would cost 63 runs of a long loop on one thread.
constexpr double kLongLoopSeconds = 0.05;
thread_local bool IsCaller = false;
using Clock = std::chrono::steady_clock;

void RunSerial(Index n, RangeFunction fn, void* body)
{
  if (NestingDepth == 0)
  {
    Slot = 0;
  }
  ++NestingDepth;
  fn(body, 0, n);
  --NestingDepth;
}
} // namespace

void ParallelRanges(Index n, Index grain, RangeFunction fn, void* body)
{
  const int threads = MaxThreads();
  if (threads <= 1 || NestingDepth > 0)
  {
    RunSerial(n, fn, body);
    return;
  }
  grain = std::max<Index>(1, grain);
  int sizeClass = 0;
  for (Index ranges = (n + grain - 1) / grain; ranges > 1 && sizeClass < kSizeClasses - 1; ranges /= 2)
  {
    ++sizeClass;
  }
  const std::uintptr_t key = reinterpret_cast<std::uintptr_t>(fn) ^ static_cast<std::uintptr_t>(sizeClass) << 4;
  LoopHistory& History = Histories[(key ^ key >> 9 ^ key >> 17) % kHistorySlots];
  if (History.Site != fn || History.SizeClass != sizeClass)
  {
    History = LoopHistory{ fn, sizeClass, 0.0, 0 };
  }
  if (History.SerialLeft > 0)
  {
    --History.SerialLeft;
    RunSerial(n, fn, body);
    return;
  }
  double ownSeconds = 0.0;
  Index ownItems = 0;
  IsCaller = true;
  const Clock::time_point start = Clock::now();
  CoreArena().Get(threads).execute([&] {
    tbb::parallel_for(
      tbb::blocked_range<Index>(0, n, static_cast<std::size_t>(grain)),
      [&](const tbb::blocked_range<Index>& r) {
        const int slot = tbb::this_task_arena::current_thread_index();
        Slot = (slot >= 0 && slot < threads) ? slot : 0;
        ++NestingDepth;
        if (IsCaller)
        {
          const Clock::time_point begin = Clock::now();
          fn(body, r.begin(), r.end());
          ownSeconds += std::chrono::duration<double>(Clock::now() - begin).count();
          ownItems += r.end() - r.begin();
        }
        else
        {
          fn(body, r.begin(), r.end());
        }
        --NestingDepth;
      },
      tbb::simple_partitioner()); // ranges of at most `grain` items (see Parallel.h)
  });
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  IsCaller = false;
  if (ownItems > 0 && ownSeconds > 0.0)
  {
    const double alone = ownSeconds * static_cast<double>(n) / static_cast<double>(ownItems);
    const double ratio = wall / alone;
    History.Ratio = History.Ratio > 0.0 ? 0.75 * History.Ratio + 0.25 * ratio : ratio;
    if (History.Ratio > 1.0 && alone < kLongLoopSeconds)
    {
      History.Ratio = 0.0;
      History.SerialLeft = 63;
    }
  }
}
} // namespace detail
} // namespace meshfree
