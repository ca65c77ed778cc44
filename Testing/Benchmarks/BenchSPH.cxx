// SPH fluid throughput: particle-steps per second of a 3D dam break (the thesis' headline scene size is 65,536
// particles) at 16k, 65k and 262k particles. Usage: BenchSPH [seconds of simulated time per size, default 0.01]
// Threads: all the CPUs, or MESHFREE_NUM_THREADS (OMP_NUM_THREADS is honoured too).
// Then the time cache as the SPH Fluid source uses it (StateCache, an entry per output time): a 2D dam break
// (3,200 particles) simulated to 0.2 s with outputs every 0.02 s, then the cost of revisiting a cached time
// (restoring the state) against simulating forward to it again.
#include "SPH/SPHFluid.h"
#include "Common/Parallel.h"
#include "Common/StateCache.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>


int main(int argc, char* argv[])
{
  const double span = argc > 1 ? std::atof(argv[1]) : 0.01;
  const int blocks[3][3] = { { 32, 16, 32 }, { 64, 32, 32 }, { 64, 64, 64 } };
  std::printf("%s\n%10s %8s %12s %14s %12s\n", meshfree::ParallelBackend(), "particles", "steps", "seconds",
    "psteps/s", "neighbours");
  for (const auto& b : blocks)
  {
    meshfree::SPHParameters p;
    const double dx = 0.01;
    p.Dimension = 3;
    p.ParticleSpacing = dx;
    p.Viscosity = 1e-3;
    const double fluid[6] = { 0.0, b[0] * dx, 0.0, b[1] * dx, 0.0, b[2] * dx };
    const double domain[6] = { 0.0, 3.0 * b[0] * dx, 0.0, b[1] * dx, 0.0, 1.5 * b[2] * dx };
    for (int i = 0; i < 6; ++i)
    {
      p.FluidBounds[i] = fluid[i];
      p.DomainBounds[i] = domain[i];
    }
    meshfree::SPHFluid solver;
    solver.Setup(p);
    meshfree::SPHState state = solver.InitialState();
    solver.Advance(state, 0.2 * span); // warm up: buffers grown, flow started
    const long first = state.Steps;
    const auto start = std::chrono::steady_clock::now();
    solver.Advance(state, 1.2 * span);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const long steps = state.Steps - first;
    double neighbours = 0.0;
    for (int c : solver.NeighborCounts(state))
    {
      neighbours += c;
    }
    std::printf("%10ld %8ld %12.3f %14.4g %12.1f\n", static_cast<long>(state.Size()), steps, seconds,
      static_cast<double>(steps) * state.Size() / seconds, neighbours / state.Size());
  }
  {
    meshfree::SPHParameters p;
    const double a = 0.1;
    p.Dimension = 2;
    p.ParticleSpacing = a / 40.0;
    p.Viscosity = 1e-3;
    const double fluid[6] = { 0.0, a, 0.0, 0.0, 0.0, 2.0 * a };
    const double domain[6] = { 0.0, 5.0 * a, 0.0, 0.0, 0.0, 2.5 * a };
    for (int i = 0; i < 6; ++i)
    {
      p.FluidBounds[i] = fluid[i];
      p.DomainBounds[i] = domain[i];
    }
    meshfree::SPHFluid solver;
    solver.Setup(p);
    meshfree::StateCache<meshfree::SPHState> cache(16);
    meshfree::SPHState state = solver.InitialState();
    cache.Insert(0, state);
    const double interval = 0.02;
    const auto start = std::chrono::steady_clock::now();
    for (long k = 1; k <= 10; ++k)
    {
      solver.Advance(state, k * interval);
      cache.Insert(k, state);
    }
    const double forward = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // Revisit every output time (backwards, as when scrubbing the slider), restoring from the cache.
    const auto revisit = std::chrono::steady_clock::now();
    double check = 0.0;
    for (long k = 10; k >= 0; --k)
    {
      long found = -1;
      const meshfree::SPHState* cached = cache.FindAtOrBefore(k, found);
      const meshfree::SPHState restored = *cached; // what the source copies into its output
      check += restored.Position[0] + static_cast<double>(found);
    }
    const double back = std::chrono::duration<double>(std::chrono::steady_clock::now() - revisit).count();
    std::printf("cache (2D dam break, %ld particles): simulate 0 -> 0.2 s: %.3f s (%ld steps); revisit all 11 "
                "cached times: %.6f s (%.2e of simulating forward) [%g]\n",
      static_cast<long>(state.Size()), forward, state.Steps, back, back / forward, check);
  }
  return 0;
}
