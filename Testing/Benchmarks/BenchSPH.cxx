// SPH fluid throughput: particle-steps per second of a 3D dam break (the thesis' headline scene size is 65,536
// particles) at 16k, 65k and 262k particles. Usage: BenchSPH [seconds of simulated time per size, default 0.01]
// Threads: all the CPUs, or MESHFREE_NUM_THREADS (OMP_NUM_THREADS is honoured too).
//
// BenchSPH --solver dfsph [--sizes 65536] [seconds]: the same 3D dam breaks with the DFSPH solver at its default
// tolerances and step rule (CFLNumber 0.25, TimeStep 1 ms), also reporting the solves' iterations per step; --sizes
// picks among 16,384, 65,536 and 262,144 particles. Both solvers report wall-clock seconds per simulated second.
// --warmup F: simulate F x seconds untimed first (default 0.2: buffers grown, flow started); --warmup 0 times the
// run from the initial state, as bench_splishsplash.py does for the comparison with SPlisHSPlasH.
//
// BenchSPH --backend cuda [--steps N] [--sizes 65536,1048576,4194304]: the CUDA device integrator
// (SPHFluid::SetBackend(CUDA)) beside the CPU on 3D dam breaks (double) of 65,536, 1,048,576 and 4,194,304
// particles (blocks 64x32x32, 128x128x64, 256x128x128 at dx = 1 cm; other sizes below 10^6: the 2b x b x b block
// nearest), a fixed step of 1e-4 s: N steps (default
// 50; the CPU takes max(2, N / 10) at 1 M particles and more) after 5 warm-up steps, each back end timed over one
// Advance() call (upload and download included), and whether the final states agree bit for bit (same steps
// only). Without a usable device it says why and exits 77.
// Then the time cache as the SPH Fluid source uses it (StateCache, an entry per output time): a 2D dam break
// (3,200 particles) simulated to 0.2 s with outputs every 0.02 s, then the cost of revisiting a cached time
// (restoring the state) against simulating forward to it again.
#include "Common/Parallel.h"
#include "Common/StateCache.h"
#include "SPH/SPHFluid.h"

#include "cuda/Device.h"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace
{
/// A 3D dam break of bx x by x bz particles at dx = 1 cm in a tank three times as long, fixed step dt.
meshfree::SPHParameters DamBreak3D(int bx, int by, int bz, double dt)
{
  meshfree::SPHParameters p;
  const double dx = 0.01;
  p.Dimension = 3;
  p.ParticleSpacing = dx;
  p.Viscosity = 1e-3;
  const double fluid[6] = { 0.0, bx * dx, 0.0, by * dx, 0.0, bz * dx };
  const double domain[6] = { 0.0, 3.0 * bx * dx, 0.0, by * dx, 0.0, 1.5 * bz * dx };
  for (int i = 0; i < 6; ++i)
  {
    p.FluidBounds[i] = fluid[i];
    p.DomainBounds[i] = domain[i];
  }
  p.TimeStep = dt;
  p.CFLNumber = 0.0;
  return p;
}

/// Particle-steps/s of about `steps` steps (the steps actually taken are counted) after 5 warm-up steps; the final
/// state in `state`.
double Rate(
  const meshfree::SPHParameters& p, meshfree::SPHBackend backend, long steps, meshfree::SPHState& state, bool& onDevice)
{
  meshfree::SPHFluid solver;
  solver.Setup(p);
  solver.SetBackend(backend);
  state = solver.InitialState();
  solver.Advance(state, 5 * p.TimeStep);
  const long before = state.Steps;
  const auto start = std::chrono::steady_clock::now();
  const meshfree::SPHFluid::Status status = solver.Advance(state, (5 + steps) * p.TimeStep);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  onDevice = solver.UsedBackend() == meshfree::SPHBackend::CUDA;
  if (status != meshfree::SPHFluid::Status::Ok)
  {
    std::printf("  (%s: %s)\n", onDevice ? "CUDA" : "CPU", solver.ErrorMessage().c_str());
  }
  return static_cast<double>(state.Steps - before) * static_cast<double>(state.Size()) / seconds;
}

int DeviceBenchmark(long steps, const std::vector<long>& sizes)
{
  std::string reason;
  if (!meshfree::cuda::Available(&reason))
  {
    std::printf("BenchSPH --backend cuda: no usable CUDA device (%s)\n", reason.c_str());
    return 77;
  }
  std::printf("device: %s; CPU: %s; 3D dam break, double, dt = 1e-4 s\n", meshfree::cuda::DeviceName().c_str(),
    meshfree::ParallelBackend());
  std::printf("%10s %8s %14s %8s %14s %9s %8s\n", "particles", "steps", "CUDA psteps/s", "steps", "CPU psteps/s",
    "speed-up", "bitwise");
  for (long size : sizes)
  {
    // Below 10^6: a 2b x b x b block with 2 b^3 nearest the size (65,536: 64 x 32 x 32).
    const int side = std::max(2, static_cast<int>(std::lround(std::cbrt(0.5 * static_cast<double>(size)))));
    int b[3] = { 2 * side, side, side };
    if (size >= 4000000)
    {
      b[0] = 256;
      b[1] = b[2] = 128;
    }
    else if (size >= 1000000)
    {
      b[0] = b[1] = 128;
      b[2] = 64;
    }
    const meshfree::SPHParameters p = DamBreak3D(b[0], b[1], b[2], 1e-4);
    meshfree::SPHState device, cpu;
    bool ran = false, cpuRan = false;
    const double deviceRate = Rate(p, meshfree::SPHBackend::CUDA, steps, device, ran);
    const long cpuSteps = size >= 1000000 ? std::max(2L, steps / 10) : steps;
    const double cpuRate = Rate(p, meshfree::SPHBackend::CPU, cpuSteps, cpu, cpuRan);
    const bool same = cpuSteps == steps && device.Position.size() == cpu.Position.size() &&
      std::memcmp(device.Position.data(), cpu.Position.data(), sizeof(double) * cpu.Position.size()) == 0 &&
      std::memcmp(device.Velocity.data(), cpu.Velocity.data(), sizeof(double) * cpu.Velocity.size()) == 0;
    std::printf("%10ld %8ld %14.4g %8ld %14.4g %9.1f %8s%s\n", static_cast<long>(device.Size()), steps, deviceRate,
      cpuSteps, cpuRate, deviceRate / cpuRate, cpuSteps == steps ? (same ? "yes" : "NO") : "-",
      ran ? "" : "  (the device declined: CPU both times)");
  }
  return 0;
}
} // namespace

int main(int argc, char* argv[])
{
  double span = 0.01;
  std::string backend = "cpu";
  long steps = 50;
  std::vector<long> sizes = { 65536, 1048576, 4194304 };
  double warmup = 0.2;
  bool sizesGiven = false, dfsph = false;
  for (int k = 1; k < argc; ++k)
  {
    const std::string a = argv[k];
    if (a == "--backend" && k + 1 < argc)
    {
      backend = argv[++k];
    }
    else if (a == "--steps" && k + 1 < argc)
    {
      steps = std::max(1L, std::atol(argv[++k]));
    }
    else if (a == "--solver" && k + 1 < argc)
    {
      const std::string solver = argv[++k];
      if (solver != "dfsph" && solver != "wcsph")
      {
        std::fprintf(stderr, "BenchSPH: --solver takes wcsph or dfsph, not %s\n", solver.c_str());
        return 2;
      }
      dfsph = solver == "dfsph";
    }
    else if (a == "--warmup" && k + 1 < argc)
    {
      warmup = std::max(0.0, std::atof(argv[++k]));
    }
    else if (a == "--sizes" && k + 1 < argc)
    {
      sizesGiven = true;
      sizes.clear();
      for (char* p = argv[++k]; *p;)
      {
        char* end = nullptr;
        sizes.push_back(std::strtol(p, &end, 10));
        p = (*end == ',') ? end + 1 : end;
        if (end == p && *p)
        {
          break;
        }
      }
    }
    else
    {
      span = std::atof(argv[k]);
    }
  }
  if (backend == "cuda")
  {
    return DeviceBenchmark(steps, sizes);
  }
  const int blocks[3][3] = { { 32, 16, 32 }, { 64, 32, 32 }, { 64, 64, 64 } };
  const char* dfsphColumns = "  density/divergence iterations per step";
  std::printf("%s%s\n%10s %8s %12s %12s %14s %12s %13s%s\n", meshfree::ParallelBackend(),
    dfsph ? ", DFSPH" : ", WCSPH", "particles", "steps", "sim s", "seconds", "psteps/s",
    "neighbours", "wall s/sim s", dfsph ? dfsphColumns : "");
  for (const auto& b : blocks)
  {
    const long count = static_cast<long>(b[0]) * b[1] * b[2];
    if (sizesGiven && std::find(sizes.begin(), sizes.end(), count) == sizes.end())
    {
      continue;
    }
    meshfree::SPHParameters p;
    if (dfsph)
    {
      p.Solver = meshfree::SPHSolver::DFSPH;
    }
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
    if (warmup > 0.0)
    {
      solver.Advance(state, warmup * span); // warm up: buffers grown, flow started
    }
    const long first = state.Steps;
    const double firstTime = state.Time;
    const auto start = std::chrono::steady_clock::now();
    solver.Advance(state, (warmup + 1.0) * span);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const long steps = state.Steps - first;
    double neighbours = 0.0;
    for (int c : solver.NeighborCounts(state))
    {
      neighbours += c;
    }
    std::printf("%10ld %8ld %12.4f %12.3f %14.4g %12.1f %13.1f", static_cast<long>(state.Size()), steps,
      state.Time - firstTime, seconds, static_cast<double>(steps) * state.Size() / seconds, neighbours / state.Size(),
      seconds / (state.Time - firstTime));
    if (dfsph)
    {
      std::printf("  %.2f / %.2f",
        static_cast<double>(state.Report.DensityIterations) / std::max(1L, state.Report.Steps),
        static_cast<double>(state.Report.DivergenceIterations) / std::max(1L, state.Report.Steps));
    }
    std::printf("\n");
  }
  if (dfsph)
  {
    return 0;
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
