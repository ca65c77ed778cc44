// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: parallel loops on oneTBB (see Parallel.h for the design and why not fork-join).
#include "Common/Parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <atomic>
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
void ParallelRanges(Index n, Index grain, RangeFunction fn, void* body)
{
  const int threads = MaxThreads();
  if (threads <= 1 || NestingDepth > 0)
  {
    if (NestingDepth == 0)
    {
      Slot = 0;
    }
    ++NestingDepth;
    fn(body, 0, n);
    --NestingDepth;
    return;
  }
  grain = std::max<Index>(1, grain);
  CoreArena().Get(threads).execute([&] {
    tbb::parallel_for(
      tbb::blocked_range<Index>(0, n, static_cast<std::size_t>(grain)),
      [&](const tbb::blocked_range<Index>& r) {
        const int slot = tbb::this_task_arena::current_thread_index();
        Slot = (slot >= 0 && slot < threads) ? slot : 0;
        ++NestingDepth;
        fn(body, r.begin(), r.end());
        --NestingDepth;
      },
      tbb::simple_partitioner()); // ranges of at most `grain` items (see Parallel.h)
  });
}
} // namespace detail
} // namespace meshfree
