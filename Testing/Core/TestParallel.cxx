// The core's parallel-loop layer (Common/Parallel.h): every item exactly once, slots within bounds, nested
// loops serial on their slot, deterministic reductions; and the simulations built on it give the same bits
// whatever the number of threads (the SPH fluid, the elastic solid's forces and energy, the neighbour grid).
#include "Common/NeighborGrid.h"
#include "Common/Parallel.h"
#include "Elastic/ElasticSolid.h"
#include "SPH/SPHFluid.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <random>
#include <string>
#include <thread>
#include <vector>

using meshfree::Index;

namespace
{
// Restores the default number of threads when a test ends, whatever it asserted.
struct ThreadsGuard
{
  ~ThreadsGuard() { meshfree::SetMaxThreads(0); }
};

// Enough work per item that both threads take ranges.
double Busy(Index i)
{
  double s = static_cast<double>(i);
  for (int k = 0; k < 200; ++k)
  {
    s = std::sqrt(s + k);
  }
  return s;
}
}

TEST(Parallel, EveryItemOnceSlotsInRangeNestedLoopsSerial)
{
  ThreadsGuard guard;
  for (int threads : { 1, 2, 3, 8 })
  {
    meshfree::SetMaxThreads(threads);
    ASSERT_EQ(meshfree::MaxThreads(), threads);
    const Index n = 100003;
    std::vector<int> hits(n, 0);
    std::vector<double> values(n, 0.0);
    std::atomic<int> badSlot{ 0 }, nestedMoved{ 0 }, nestedItems{ 0 };
    meshfree::ParallelFor(n, 97, [&](Index begin, Index end) {
      const int slot = meshfree::ThreadIndex();
      if (slot < 0 || slot >= threads)
      {
        ++badSlot;
      }
      for (Index i = begin; i < end; ++i)
      {
        ++hits[i];
        values[i] = Busy(i);
      }
      // A loop inside a loop's body runs on the calling thread, keeping its slot.
      meshfree::ParallelFor(1000, 1, [&](Index b, Index e) {
        nestedItems += static_cast<int>(e - b);
        nestedMoved += meshfree::ThreadIndex() != slot ? 1 : 0;
      });
    });
    for (Index i = 0; i < n; ++i)
    {
      ASSERT_EQ(hits[i], 1) << "item " << i << " with " << threads << " threads";
      ASSERT_EQ(values[i], Busy(i));
    }
    EXPECT_EQ(badSlot.load(), 0);
    EXPECT_EQ(nestedMoved.load(), 0);
    EXPECT_EQ(nestedItems.load() % 1000, 0);
    EXPECT_GE(nestedItems.load(), 1000);
  }
  EXPECT_EQ(meshfree::ThreadIndex(), 0); // outside loops
}

TEST(Parallel, EmptyTinyAndSerialBelow)
{
  ThreadsGuard guard;
  meshfree::SetMaxThreads(2);
  int calls = 0;
  meshfree::ParallelFor(0, 16, [&](Index, Index) { ++calls; });
  meshfree::ParallelFor(-5, 16, [&](Index, Index) { ++calls; });
  EXPECT_EQ(calls, 0);
  Index seenBegin = -1, seenEnd = -1;
  meshfree::ParallelFor(10, 16, [&](Index b, Index e) { // at most one grain: one call on this thread
    ++calls;
    seenBegin = b;
    seenEnd = e;
  });
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(seenBegin, 0);
  EXPECT_EQ(seenEnd, 10);
  calls = 0; // below serialBelow: one call over everything
  meshfree::ParallelFor(
    5000, 8, [&](Index b, Index e) { calls += (b == 0 && e == 5000) ? 1 : 100; }, 10000);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(meshfree::ParallelReduce(
              0, 8, 7.0, [](Index, Index) { return 1.0; }, [](double a, double b) { return a + b; }),
    7.0);
}

// A loop that runs on the calling thread alone (the fallback when its threads do not pay) is one call over all its
// items; a loop handed out to the threads is called per range.
TEST(Parallel, AFallbackIsOneLoopsOwn)
{
  ThreadsGuard guard;
  meshfree::SetMaxThreads(2);
  const Index n = 64; // grain 1: 64 ranges
  // A short loop that the threads make slower (another thread's ranges sleep; the caller's take microseconds): it
  // falls back to the calling thread after a few runs.
  bool fellBack = false;
  for (int run = 0; run < 50 && !fellBack; ++run)
  {
    meshfree::ParallelFor(n, 1, [&](Index b, Index e) {
      if (b == 0 && e == n)
      {
        fellBack = true;
      }
      else if (meshfree::ThreadIndex() != 0)
      {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    });
  }
  ASSERT_TRUE(fellBack);
  // Another loop of the same size keeps its threads: it is handed out in ranges.
  std::atomic<int> calls{ 0 };
  std::vector<double> values(n, 0.0);
  meshfree::ParallelFor(n, 1, [&](Index b, Index e) {
    ++calls;
    for (Index i = b; i < e; ++i)
    {
      values[i] = Busy(i);
    }
  });
  EXPECT_EQ(calls.load(), n);
  // A long loop (one thread would take over 50 ms) never falls back, even when a range that another thread holds
  // makes it slower than one thread.
  for (int run = 0; run < 3; ++run)
  {
    std::atomic<int> pieces{ 0 };
    std::atomic<bool> slept{ false };
    meshfree::ParallelFor(n, 1, [&](Index b, Index e) {
      ++pieces;
      if (meshfree::ThreadIndex() != 0 && !slept.exchange(true))
      {
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        return;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(1500 * (e - b))); // ~96 ms on one thread
    });
    EXPECT_EQ(pieces.load(), n) << "run " << run;
  }
}

TEST(Parallel, ReductionIsTheSameWhateverTheThreads)
{
  ThreadsGuard guard;
  // Terms of very different magnitudes: any change of the summation order changes the last bits.
  std::mt19937 random(3);
  std::uniform_real_distribution<double> exponent(-12.0, 12.0);
  std::vector<double> terms(200001);
  for (double& t : terms)
  {
    t = std::pow(10.0, exponent(random)) * (random() % 2 ? 1.0 : -1.0);
  }
  auto sum = [&] {
    return meshfree::ParallelReduce(
      static_cast<Index>(terms.size()), 1000, 0.0,
      [&](Index b, Index e) {
        double s = 0.0;
        for (Index i = b; i < e; ++i)
        {
          s += terms[i];
        }
        return s;
      },
      [](double a, double b) { return a + b; });
  };
  meshfree::SetMaxThreads(1);
  const double one = sum();
  // The serial sum of the block sums in block order: what the reduction promises.
  double expected = 0.0;
  for (std::size_t b = 0; b < terms.size(); b += 1000)
  {
    double s = 0.0;
    for (std::size_t i = b; i < std::min(terms.size(), b + 1000); ++i)
    {
      s += terms[i];
    }
    expected += s;
  }
  EXPECT_EQ(one, expected);
  for (int threads : { 2, 3, 5 })
  {
    meshfree::SetMaxThreads(threads);
    EXPECT_EQ(sum(), one) << threads << " threads";
  }
}

TEST(Parallel, SPHFluidBitsDoNotDependOnTheThreads)
{
  ThreadsGuard guard;
  // A 2D dam break above the fluid's parallel threshold (5,000 particles), with walls, tension and viscosity.
  meshfree::SPHParameters p;
  p.Dimension = 2;
  p.ParticleSpacing = 0.002;
  p.Viscosity = 0.05;
  p.SurfaceTension = 0.07;
  const double fluid[6] = { 0.0, 0.1, 0.0, 0.0, 0.0, 0.2 };
  const double domain[6] = { 0.0, 0.4, 0.0, 0.0, 0.0, 0.3 };
  std::copy(fluid, fluid + 6, p.FluidBounds);
  std::copy(domain, domain + 6, p.DomainBounds);
  auto run = [&](int threads) {
    meshfree::SetMaxThreads(threads);
    meshfree::SPHFluid solver;
    solver.Setup(p);
    meshfree::SPHState s = solver.InitialState();
    EXPECT_GE(s.Size(), 5000);
    EXPECT_EQ(solver.Advance(s, 0.004), meshfree::SPHFluid::Status::Ok);
    EXPECT_GT(s.Steps, 10);
    return s;
  };
  const meshfree::SPHState one = run(1);
  for (int threads : { 2, 3 })
  {
    const meshfree::SPHState other = run(threads);
    EXPECT_EQ(other.Steps, one.Steps);
    EXPECT_EQ(other.Position, one.Position) << threads << " threads";
    EXPECT_EQ(other.Velocity, one.Velocity) << threads << " threads";
    EXPECT_EQ(other.Density, one.Density) << threads << " threads";
    EXPECT_EQ(other.Id, one.Id) << threads << " threads";
  }
}

TEST(Parallel, ElasticSolidBitsDoNotDependOnTheThreads)
{
  ThreadsGuard guard;
  // 6,000 phyxels (above the solid's parallel threshold), deformed and spinning; forces, energy, 20 steps.
  std::vector<double> rest;
  for (int k = 0; k < 10; ++k)
  {
    for (int j = 0; j < 20; ++j)
    {
      for (int i = 0; i < 30; ++i)
      {
        rest.insert(rest.end(), { 0.01 * i, 0.01 * j, 0.01 * k });
      }
    }
  }
  meshfree::ElasticSettings settings;
  settings.YoungModulus = 1e5;
  settings.PoissonRatio = 0.3;
  settings.Density = 1000;
  auto run = [&](int threads, double& energy, std::vector<double>& force) {
    meshfree::SetMaxThreads(threads);
    meshfree::ElasticSolid solid;
    std::string message;
    EXPECT_TRUE(solid.Initialize(rest, 0.0, settings, message)) << message;
    auto& state = solid.State();
    for (std::size_t c = 0; c < state.Position.size(); ++c)
    {
      state.Position[c] = rest[c] * (1.0 + 0.03 * (c % 3)) + 1e-4 * std::sin(0.7 * static_cast<double>(c));
    }
    energy = solid.InternalEnergy(state.Position.data());
    solid.ComputeInternalForces(state.Position.data(), force);
    const double dt = solid.StableTimeStep();
    for (int step = 0; step < 20; ++step)
    {
      solid.StepSymplectic(dt);
    }
    return state.Position;
  };
  double energyOne = 0.0, energyOther = 0.0;
  std::vector<double> forceOne, forceOther;
  const std::vector<double> one = run(1, energyOne, forceOne);
  EXPECT_GT(energyOne, 0.0);
  for (int threads : { 2, 3 })
  {
    const std::vector<double> other = run(threads, energyOther, forceOther);
    EXPECT_EQ(energyOther, energyOne) << threads << " threads";
    EXPECT_EQ(forceOther, forceOne) << threads << " threads";
    EXPECT_EQ(other, one) << threads << " threads";
  }
}

TEST(Parallel, NeighborGridRowsDoNotDependOnTheThreads)
{
  ThreadsGuard guard;
  // 200,000 points: several build chunks per thread; radius rows and k-nearest rows compared exactly.
  std::mt19937 random(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> xyz(3 * 200000);
  for (double& c : xyz)
  {
    c = u(random);
  }
  auto run = [&](int threads, std::vector<Index>& offsets, std::vector<std::int32_t>& rows, std::vector<Index>& knn,
               std::vector<double>& knnDist2) {
    meshfree::SetMaxThreads(threads);
    meshfree::NeighborGrid grid;
    ASSERT_TRUE(grid.Build(xyz.data(), static_cast<Index>(xyz.size() / 3), 0.01));
    ASSERT_TRUE(grid.FindWithinRadiusForAllPoints(0.02, offsets, rows, true)); // ~6.7 neighbours each
    grid.FindKNearestForAllPoints(12, knn, knnDist2);
  };
  std::vector<Index> offsetsOne, offsetsOther, knnOne, knnOther;
  std::vector<std::int32_t> rowsOne, rowsOther;
  std::vector<double> distOne, distOther;
  run(1, offsetsOne, rowsOne, knnOne, distOne);
  ASSERT_GT(rowsOne.size(), 1000000u);
  for (int threads : { 2, 5 })
  {
    run(threads, offsetsOther, rowsOther, knnOther, distOther);
    EXPECT_EQ(offsetsOther, offsetsOne);
    EXPECT_EQ(rowsOther, rowsOne);
    EXPECT_EQ(knnOther, knnOne);
    EXPECT_EQ(distOther, distOne);
  }
}
