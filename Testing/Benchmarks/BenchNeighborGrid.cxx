// SPDX-License-Identifier: BSD-3-Clause
// Speed of meshfree::NeighborGrid against brute force and (with MESHFREE_HAVE_VTK) VTK's
// vtkStaticPointLocator, on uniform random points in the unit cube (10k, 100k, 1M):
// - Build: points per second, rebuilding into the same object (GridBuildCold: a new object each time,
//   allocation included); VTK's ForceBuildLocator() runs on vtkSMPTools' STDThread backend.
// - KNearest: 20-nearest-neighbour queries at every point of the cloud, OpenMP over queries with
//   per-thread buffers (one vtkIdList per thread for VTK); argument morton: 0 = queries in the cloud's
//   own order, 1 = in the grid's Morton order (cache friendly; both libraries get the same order).
//   GridKNearestPortable: the same without the AVX-512 kernel. GridKNearestAllPoints: the
//   FindKNearestForAllPoints() helper, which also writes the n x 20 result rows.
// - Radius: radius queries with about 20 neighbours each, same loop.
// Brute force runs at every point for 10k points and on a prefix of the points above; VTK's queries run
// on at most 250k of them. Rates are measured with a wall clock around each iteration; the best of all
// runs of a case is kept, and the ratios MeshFree / VTK and MeshFree / brute force are printed at the end.
// Run: BenchNeighborGrid --benchmark_repetitions=3
#include "Common/NeighborGrid.h"

#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#ifdef MESHFREE_HAVE_VTK
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSMPTools.h>
#include <vtkStaticPointLocator.h>
#endif

namespace
{
using meshfree::Index;
using meshfree::NeighborGrid;
constexpr int K = 20;

const std::vector<double>& Cloud(Index n)
{
  static std::map<Index, std::vector<double>> clouds;
  auto& cloud = clouds[n];
  if (cloud.empty())
  {
    std::mt19937_64 rng(12345 + n);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    cloud.resize(3 * n);
    for (double& v : cloud)
    {
      v = u(rng);
    }
  }
  return cloud;
}

const NeighborGrid& Grid(Index n)
{
  static std::map<Index, std::unique_ptr<NeighborGrid>> grids;
  auto& grid = grids[n];
  if (!grid)
  {
    grid = std::make_unique<NeighborGrid>();
    grid->Build(Cloud(n).data(), n);
  }
  return *grid;
}

// Query positions: the cloud's points in their own order or in the grid's Morton order.
const std::vector<double>& Queries(Index n, bool morton)
{
  static std::map<Index, std::vector<double>> sorted;
  if (!morton)
  {
    return Cloud(n);
  }
  auto& q = sorted[n];
  if (q.empty())
  {
    q.assign(Grid(n).SortedPoints(), Grid(n).SortedPoints() + 3 * n);
  }
  return q;
}

// Radius of a ball holding 20 points on average.
double Radius20(Index n)
{
  return std::cbrt(K * 3.0 / (4.0 * 3.14159265358979323846 * static_cast<double>(n)));
}

// Best rates per (case, library, n): [0] per second of wall clock, [1] per second of process CPU time
// (all threads; with OMP_NUM_THREADS=1 this is the single-core rate, robust on a busy machine).
std::map<std::tuple<std::string, std::string, Index>, std::array<double, 2>>& BestRates()
{
  static std::map<std::tuple<std::string, std::string, Index>, std::array<double, 2>> rates;
  return rates;
}

// Runs `body` once per benchmark iteration, timing it with a wall clock and the process CPU clock.
template <class Body>
void Measure(benchmark::State& state, const char* what, const char* who, Index n, Index items,
  const char* unit, Body&& body)
{
  double seconds = 0.0, cpuSeconds = 0.0;
  Index total = 0;
  for (auto _ : state)
  {
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpuStart = std::clock();
    body();
    cpuSeconds += static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC;
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    total += items;
  }
  const double rate = seconds > 0.0 ? static_cast<double>(total) / seconds : 0.0;
  const double cpuRate = cpuSeconds > 0.0 ? static_cast<double>(total) / cpuSeconds : 0.0;
  state.counters[unit] = rate;
  state.counters[std::string(unit) + "CPU"] = cpuRate;
  auto& best = BestRates()[{ what, who, n }];
  best[0] = std::max(best[0], rate);
  best[1] = std::max(best[1], cpuRate);
}

// ------------------------------------------------------------------------------------ MeshFree
void GridBuild(benchmark::State& state)
{
  const Index n = state.range(0);
  const auto& cloud = Cloud(n);
  NeighborGrid grid;
  grid.Build(cloud.data(), n); // rebuilds reuse the buffers (a simulation rebuilds every step)
  Measure(state, "Build", "MeshFree", n, n, "points/s", [&] { grid.Build(cloud.data(), n); });
  state.counters["cellSize"] = grid.CellSize();
}

// A first build into a new object: includes allocating (and page-faulting) its buffers.
void GridBuildCold(benchmark::State& state)
{
  const Index n = state.range(0);
  const auto& cloud = Cloud(n);
  Measure(state, "Build cold", "MeshFree", n, n, "points/s", [&] {
    NeighborGrid grid;
    grid.Build(cloud.data(), n);
    benchmark::DoNotOptimize(grid.NumberOfValidPoints());
  });
}

void GridKNearest(benchmark::State& state)
{
  const Index n = state.range(0);
  const bool morton = state.range(1) != 0;
  const NeighborGrid& grid = Grid(n);
  const double* q = Queries(n, morton).data();
  Measure(state, morton ? "20-NN Morton" : "20-NN", "MeshFree", n, n, "queries/s", [&] {
    Index checksum = 0;
#pragma omp parallel reduction(+ : checksum)
    {
      Index ids[K];
      double d2[K];
#pragma omp for schedule(dynamic, 256)
      for (Index i = 0; i < n; ++i)
      {
        checksum += grid.FindKNearest(q + 3 * i, K, ids, d2);
      }
    }
    benchmark::DoNotOptimize(checksum);
  });
}

// The same queries with the portable distance filter (no AVX-512), to show what the vector kernel buys.
void GridKNearestPortable(benchmark::State& state)
{
  NeighborGrid::SetVectorized(false);
  const Index n = state.range(0);
  const NeighborGrid& grid = Grid(n);
  const double* q = Queries(n, true).data();
  Measure(state, "20-NN Morton portable", "MeshFree", n, n, "queries/s", [&] {
    Index checksum = 0;
#pragma omp parallel reduction(+ : checksum)
    {
      Index ids[K];
      double d2[K];
#pragma omp for schedule(dynamic, 256)
      for (Index i = 0; i < n; ++i)
      {
        checksum += grid.FindKNearest(q + 3 * i, K, ids, d2);
      }
    }
    benchmark::DoNotOptimize(checksum);
  });
  NeighborGrid::SetVectorized(true);
}

// FindKNearestForAllPoints: Morton order, radius guesses from the previous query, and the n x 20 result
// rows written in the caller's numbering (random memory order for a random cloud).
void GridKNearestAllPoints(benchmark::State& state)
{
  const Index n = state.range(0);
  const NeighborGrid& grid = Grid(n);
  std::vector<Index> ids;
  std::vector<double> d2;
  grid.FindKNearestForAllPoints(K, ids, d2); // allocate the rows outside the timing
  Measure(state, "20-NN all-points helper", "MeshFree", n, n, "queries/s",
    [&] { grid.FindKNearestForAllPoints(K, ids, d2); });
}

void GridRadius(benchmark::State& state)
{
  const Index n = state.range(0);
  const bool morton = state.range(1) != 0;
  const NeighborGrid& grid = Grid(n);
  const double* q = Queries(n, morton).data();
  const double radius = Radius20(n);
  Index found = 0;
  Measure(state, morton ? "Radius Morton" : "Radius", "MeshFree", n, n, "queries/s", [&] {
    Index checksum = 0;
#pragma omp parallel reduction(+ : checksum)
    {
      std::vector<Index> ids;
      std::vector<double> d2;
      ids.reserve(256);
      d2.reserve(256);
#pragma omp for schedule(dynamic, 256)
      for (Index i = 0; i < n; ++i)
      {
        grid.FindWithinRadius(q + 3 * i, radius, ids, &d2);
        checksum += static_cast<Index>(ids.size());
      }
    }
    found = checksum;
  });
  state.counters["neighbours"] = static_cast<double>(found) / static_cast<double>(n);
}

// ------------------------------------------------------------------------------------ brute force
Index BruteSample(Index n)
{
  return std::min<Index>(n, 100000000 / n); // all points at 10k, a prefix of the points above
}

void BruteKNearest(benchmark::State& state)
{
  const Index n = state.range(0);
  const Index queries = BruteSample(n);
  const double* p = Cloud(n).data();
  Measure(state, "20-NN", "BruteForce", n, queries, "queries/s", [&] {
    double checksum = 0.0;
#pragma omp parallel reduction(+ : checksum)
    {
      double best[K];
#pragma omp for schedule(dynamic, 16)
      for (Index i = 0; i < queries; ++i)
      {
        const double* x = p + 3 * i;
        int count = 0;
        for (Index j = 0; j < n; ++j) // insertion into the sorted best K
        {
          const double dx = p[3 * j] - x[0], dy = p[3 * j + 1] - x[1], dz = p[3 * j + 2] - x[2];
          const double d2 = dx * dx + dy * dy + dz * dz;
          if (count == K && d2 >= best[K - 1])
          {
            continue;
          }
          int slot = count < K ? count++ : K - 1;
          for (; slot > 0 && best[slot - 1] > d2; --slot)
          {
            best[slot] = best[slot - 1];
          }
          best[slot] = d2;
        }
        checksum += best[K - 1];
      }
    }
    benchmark::DoNotOptimize(checksum);
  });
}

void BruteRadius(benchmark::State& state)
{
  const Index n = state.range(0);
  const Index queries = BruteSample(n);
  const double* p = Cloud(n).data();
  const double r2 = Radius20(n) * Radius20(n);
  Measure(state, "Radius", "BruteForce", n, queries, "queries/s", [&] {
    Index checksum = 0;
#pragma omp parallel reduction(+ : checksum)
    {
      std::vector<Index> ids;
      ids.reserve(256);
#pragma omp for schedule(dynamic, 16)
      for (Index i = 0; i < queries; ++i)
      {
        const double* x = p + 3 * i;
        ids.clear();
        for (Index j = 0; j < n; ++j)
        {
          const double dx = p[3 * j] - x[0], dy = p[3 * j + 1] - x[1], dz = p[3 * j + 2] - x[2];
          if (dx * dx + dy * dy + dz * dz <= r2)
          {
            ids.push_back(j);
          }
        }
        checksum += static_cast<Index>(ids.size());
      }
    }
    benchmark::DoNotOptimize(checksum);
  });
}

// ------------------------------------------------------------------------------------ VTK
#ifdef MESHFREE_HAVE_VTK
struct VtkCloud
{
  vtkNew<vtkPolyData> Data;
  vtkNew<vtkStaticPointLocator> Locator;
};

VtkCloud& Vtk(Index n)
{
  static std::map<Index, std::unique_ptr<VtkCloud>> clouds;
  auto& c = clouds[n];
  if (!c)
  {
    c = std::make_unique<VtkCloud>();
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(n);
    std::memcpy(points->GetVoidPointer(0), Cloud(n).data(), sizeof(double) * 3 * n);
    c->Data->SetPoints(points);
    c->Locator->SetDataSet(c->Data);
    c->Locator->BuildLocator();
  }
  return *c;
}

void VtkBuild(benchmark::State& state)
{
  const Index n = state.range(0);
  VtkCloud& vtk = Vtk(n);
  Measure(state, "Build", "VTK", n, n, "points/s", [&] { vtk.Locator->ForceBuildLocator(); });
}

// VTK's queries are slow: above 250k points they run on a prefix of the query order (a random sample in
// the caller's order, a compact block in Morton order), which keeps their memory behaviour.
Index VtkQueries(Index n)
{
  return std::min<Index>(n, 250000);
}

void VtkKNearest(benchmark::State& state)
{
  const Index n = state.range(0);
  const Index queries = VtkQueries(n);
  const bool morton = state.range(1) != 0;
  vtkStaticPointLocator* locator = Vtk(n).Locator;
  const double* q = Queries(n, morton).data();
  Measure(state, morton ? "20-NN Morton" : "20-NN", "VTK", n, queries, "queries/s", [&] {
    Index checksum = 0;
#pragma omp parallel reduction(+ : checksum)
    {
      vtkNew<vtkIdList> ids;
      ids->Allocate(K);
#pragma omp for schedule(dynamic, 256)
      for (Index i = 0; i < queries; ++i)
      {
        locator->FindClosestNPoints(K, q + 3 * i, ids);
        checksum += ids->GetNumberOfIds();
      }
    }
    benchmark::DoNotOptimize(checksum);
  });
  // Sanity: the same k-th distance as ours on a few queries.
  const NeighborGrid& grid = Grid(n);
  const double* p = Cloud(n).data();
  vtkNew<vtkIdList> ids;
  int mismatches = 0;
  for (Index i = 0; i < std::min<Index>(n, 200); ++i)
  {
    Index ours[K];
    double d2[K];
    grid.FindKNearest(q + 3 * i, K, ours, d2);
    locator->FindClosestNPoints(K, q + 3 * i, ids);
    const double* y = p + 3 * ids->GetId(K - 1);
    const double dx = y[0] - q[3 * i], dy = y[1] - q[3 * i + 1], dz = y[2] - q[3 * i + 2];
    mismatches += (dx * dx + dy * dy + dz * dz) != d2[K - 1];
  }
  state.counters["mismatches"] = mismatches;
}

void VtkRadius(benchmark::State& state)
{
  const Index n = state.range(0);
  const Index queries = VtkQueries(n);
  const bool morton = state.range(1) != 0;
  vtkStaticPointLocator* locator = Vtk(n).Locator;
  const double* q = Queries(n, morton).data();
  const double radius = Radius20(n);
  Index found = 0;
  Measure(state, morton ? "Radius Morton" : "Radius", "VTK", n, queries, "queries/s", [&] {
    Index checksum = 0;
#pragma omp parallel reduction(+ : checksum)
    {
      vtkNew<vtkIdList> ids;
      ids->Allocate(256);
#pragma omp for schedule(dynamic, 256)
      for (Index i = 0; i < queries; ++i)
      {
        locator->FindPointsWithinRadius(radius, q + 3 * i, ids);
        checksum += ids->GetNumberOfIds();
      }
    }
    found = checksum;
  });
  state.counters["neighbours"] = static_cast<double>(found) / static_cast<double>(queries);
}
#endif

void Sizes(benchmark::internal::Benchmark* b)
{
  b->ArgNames({ "n" })->Arg(10000)->Arg(100000)->Arg(1000000);
}
void SizesAndOrders(benchmark::internal::Benchmark* b)
{
  b->ArgNames({ "n", "morton" });
  for (const Index n : { 10000, 100000, 1000000 })
  {
    b->Args({ n, 0 })->Args({ n, 1 });
  }
}
} // namespace

BENCHMARK(GridBuild)->Apply(Sizes)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(GridBuildCold)->Apply(Sizes)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(GridKNearest)->Apply(SizesAndOrders)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(GridKNearestPortable)->Apply(Sizes)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(GridKNearestAllPoints)->Apply(Sizes)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(GridRadius)->Apply(SizesAndOrders)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BruteKNearest)->Apply(Sizes)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BruteRadius)->Apply(Sizes)->UseRealTime()->Unit(benchmark::kMillisecond);
#ifdef MESHFREE_HAVE_VTK
BENCHMARK(VtkBuild)->Apply(Sizes)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(VtkKNearest)->Apply(SizesAndOrders)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(VtkRadius)->Apply(SizesAndOrders)->UseRealTime()->Unit(benchmark::kMillisecond);
#endif

int main(int argc, char** argv)
{
#ifdef MESHFREE_HAVE_VTK
  vtkSMPTools::SetBackend("STDThread");
  vtkSMPTools::Initialize(omp_get_max_threads());
  std::printf("VTK SMP backend: %s, %d threads; OpenMP threads: %d\n", vtkSMPTools::GetBackend(),
    vtkSMPTools::GetEstimatedNumberOfThreads(), omp_get_max_threads());
#endif
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
  {
    return 1;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();

  // Ratios of the best rates: > 1 means MeshFree is faster.
  struct Row
  {
    const char* Ours; // and the VTK and brute-force cases it is compared with
    const char* Vtk;
    const char* Brute;
  };
  const Row rows[] = { { "Build", "Build", "" }, { "Build cold", "Build", "" }, { "20-NN", "20-NN", "20-NN" },
    { "20-NN Morton", "20-NN Morton", "20-NN" }, { "20-NN Morton portable", "20-NN Morton", "20-NN" },
    { "20-NN all-points helper", "20-NN Morton", "20-NN" }, { "Radius", "Radius", "Radius" },
    { "Radius Morton", "Radius Morton", "Radius" } };
  const auto& rates = BestRates();
  for (int clock = 0; clock < 2; ++clock)
  {
    std::printf("\nBest rates per second of %s\n%-24s %9s %12s %12s %12s %8s %9s\n",
      clock == 0 ? "wall clock" : "process CPU time (all threads)", "case", "n", "MeshFree", "VTK",
      "brute", "vs VTK", "vs brute");
    auto rate = [&](const char* what, const char* who, Index n) {
      const auto it = rates.find({ what, who, n });
      return it == rates.end() ? 0.0 : it->second[clock];
    };
    for (const Row& row : rows)
    {
      for (const Index n : { 10000, 100000, 1000000 })
      {
        const double ours = rate(row.Ours, "MeshFree", n), vtk = rate(row.Vtk, "VTK", n),
                     brute = rate(row.Brute, "BruteForce", n);
        if (ours > 0.0)
        {
          std::printf("%-24s %9lld %12.4g %12.4g %12.4g %8.2f %9.1f\n", row.Ours, static_cast<long long>(n),
            ours, vtk, brute, vtk > 0.0 ? ours / vtk : 0.0, brute > 0.0 ? ours / brute : 0.0);
        }
      }
    }
  }
  return 0;
}
