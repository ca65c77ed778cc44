// cuda/SPHDevice.h: the SPH integrator's passes as CUDA kernels around the shared arithmetic of
// SPH/SPHPhysics.h and SPH/SPHDensity.h. One thread per particle, launched in the grid's sorted order (the
// threads of a warp share cells); each thread gathers its own sums (no atomics), visiting its candidate cells in
// (z, y, x) order and the points of a cell in sorted order, as the CPU's neighbour rows list them.
#include "cuda/SPHDevice.h"

#include "Common/GridCell.h"
#include "Common/GridCellView.h"
#include "Common/NeighborGrid.h"
#include "SPH/SPHFluid.h"
#include "SPH/SPHGridPasses.h"
#include "cuda/Device.h"
#include "cuda/DeviceBuffer.cuh"

#include <cub/device/device_radix_sort.cuh>
#include <cuda_runtime.h>

#include <algorithm>
#include <vector>

namespace meshfree
{
namespace cuda
{
namespace
{
constexpr int BlockSize = 128;
constexpr int ReduceBlock = 256;
constexpr int ReduceBlocks = 256; // partial results of a reduction, merged on the host (order-independent maxima)

unsigned Blocks(std::int64_t n)
{
  return static_cast<unsigned>((n + BlockSize - 1) / BlockSize);
}

using Span = GridCellRange32;
using GridView = GridCells;

/// Bounds of the points and whether one was not finite (the grid's origin and extents).
struct Bounds
{
  double Lo[3];
  double Hi[3];
  int Invalid;

  __host__ __device__ void Reset()
  {
    for (int a = 0; a < 3; ++a)
    {
      this->Lo[a] = HUGE_VAL;
      this->Hi[a] = -HUGE_VAL;
    }
    this->Invalid = 0;
  }
  __host__ __device__ void Add(const double* p)
  {
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])))
    {
      this->Invalid = 1;
      return;
    }
    for (int a = 0; a < 3; ++a)
    {
      this->Lo[a] = p[a] < this->Lo[a] ? p[a] : this->Lo[a];
      this->Hi[a] = this->Hi[a] < p[a] ? p[a] : this->Hi[a];
    }
  }
  __host__ __device__ void Merge(const Bounds& b)
  {
    for (int a = 0; a < 3; ++a)
    {
      this->Lo[a] = b.Lo[a] < this->Lo[a] ? b.Lo[a] : this->Lo[a];
      this->Hi[a] = this->Hi[a] < b.Hi[a] ? b.Hi[a] : this->Hi[a];
    }
    this->Invalid = this->Invalid || b.Invalid;
  }
};

/// Shared-memory tree merge of one value per thread; thread 0 writes the block's result.
template <class T>
__device__ void BlockMerge(T value, T* out)
{
  __shared__ __align__(16) unsigned char storage[sizeof(T) * ReduceBlock];
  T* shared = reinterpret_cast<T*>(storage);
  shared[threadIdx.x] = value;
  __syncthreads();
  for (int stride = ReduceBlock / 2; stride > 0; stride /= 2)
  {
    if (static_cast<int>(threadIdx.x) < stride)
    {
      shared[threadIdx.x].Merge(shared[threadIdx.x + stride]);
    }
    __syncthreads();
  }
  if (threadIdx.x == 0)
  {
    *out = shared[0];
  }
}

__global__ void BoundsKernel(std::int64_t n, const double* x, Bounds* partials)
{
  Bounds b;
  b.Reset();
  for (std::int64_t i = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x; i < n;
       i += static_cast<std::int64_t>(gridDim.x) * blockDim.x)
  {
    b.Add(x + 3 * i);
  }
  BlockMerge(b, partials + blockIdx.x);
}

__global__ void ExtremesKernel(
  std::int64_t n, const double* v, const double* a, const double* rho, double restDensity, SPHExtremes* partials)
{
  SPHExtremes e;
  e.Rho = restDensity;
  for (std::int64_t i = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x; i < n;
       i += static_cast<std::int64_t>(gridDim.x) * blockDim.x)
  {
    e.Add(v + 3 * i, a + 3 * i, rho[i]);
  }
  BlockMerge(e, partials + blockIdx.x);
}

/// Cell key (compact Morton code, NeighborGrid's) and index of every point.
__global__ void KeysKernel(std::int64_t n, const double* x, GridView g, const std::uint64_t* spreadX,
  const std::uint64_t* spreadY, const std::uint64_t* spreadZ, std::uint64_t* keys, std::int32_t* index)
{
  const std::int64_t i = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n)
  {
    const double* p = x + 3 * i;
    keys[i] = spreadX[GridAxisCell(p[0] - g.Origin[0], g.Inverse, g.Dims[0])] |
      spreadY[GridAxisCell(p[1] - g.Origin[1], g.Inverse, g.Dims[1])] |
      spreadZ[GridAxisCell(p[2] - g.Origin[2], g.Inverse, g.Dims[2])];
    index[i] = static_cast<std::int32_t>(i);
  }
}

/// Sorted coordinates, and the cell ranges: a run of equal keys is one cell.
__global__ void CellsKernel(std::int64_t n, const double* x, const std::int32_t* order, const std::uint64_t* keys,
  GridView g, double* sorted, Span* cells)
{
  const std::int64_t s = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (s >= n)
  {
    return;
  }
  const double* p = x + 3 * static_cast<std::int64_t>(order[s]);
  sorted[3 * s] = p[0];
  sorted[3 * s + 1] = p[1];
  sorted[3 * s + 2] = p[2];
  const std::int64_t cell = GridAxisCell(p[0] - g.Origin[0], g.Inverse, g.Dims[0]) +
    g.Dims[0] *
      (GridAxisCell(p[1] - g.Origin[1], g.Inverse, g.Dims[1]) +
        g.Dims[1] * GridAxisCell(p[2] - g.Origin[2], g.Inverse, g.Dims[2]));
  if (s == 0 || keys[s] != keys[s - 1])
  {
    cells[cell].Begin = static_cast<std::int32_t>(s);
  }
  if (s == n - 1 || keys[s] != keys[s + 1])
  {
    cells[cell].End = static_cast<std::int32_t>(s + 1);
  }
}

__global__ void DensityKernel(std::int64_t n, GridView fluid, GridView wall, SPHConstants c, double* rho,
  double* pressure, double* pressureTerm, double* inverseDensity)
{
  const std::int64_t s = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (s < n)
  {
    SPHGridDensity(s, fluid, wall, c, rho, pressure, pressureTerm, inverseDensity);
  }
}

__global__ void WallPressureKernel(std::int64_t nb, const double* boundaryX, GridView fluid, const double* pressure,
  const double* rho, SPHConstants c, double* wallTerm)
{
  const std::int64_t b = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (b < nb)
  {
    wallTerm[b] = SPHGridWallTerm(boundaryX + 3 * b, fluid, pressure, rho, c);
  }
}

__global__ void AccelerationKernel(std::int64_t n, GridView fluid, GridView wall, const double* v, const double* rho,
  const double* inverseDensity, const double* pressureTerm, const double* wallTerm, SPHConstants c, double* acc)
{
  const std::int64_t s = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (s < n)
  {
    SPHGridAcceleration(s, fluid, wall, v, rho, inverseDensity, pressureTerm, wallTerm, c, acc);
  }
}

__global__ void KickDriftKernel(
  std::int64_t n, double* x, double* v, const double* a, double half, double dt, SPHConstants c)
{
  const std::int64_t i = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n)
  {
    SPHKickDrift(x + 3 * i, v + 3 * i, a + 3 * i, half, dt);
    SPHWallClamp(x + 3 * i, v + 3 * i, c);
  }
}

__global__ void KickKernel(std::int64_t count, double* v, const double* a, double half)
{
  const std::int64_t k = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (k < count)
  {
    SPHKick(v + k, a + k, half);
  }
}

__global__ void PermuteKernel(std::int64_t n, const std::int32_t* order, const double* x, const double* v,
  const double* a, const std::int64_t* id, double* x2, double* v2, double* a2, std::int64_t* id2)
{
  const std::int64_t s = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (s < n)
  {
    const std::int64_t i = order[s];
    for (int k = 0; k < 3; ++k)
    {
      x2[3 * s + k] = x[3 * i + k];
      v2[3 * s + k] = v[3 * i + k];
      a2[3 * s + k] = a[3 * i + k];
    }
    id2[s] = id[i];
  }
}
} // namespace

struct SPHDevice::Internals
{
  SPHConstants C;
  std::int64_t N = 0;
  DeviceBuffer<double> X, V, A, Rho, P, Term, Inverse, X2, V2, A2;
  DeviceBuffer<std::int64_t> Id, Id2;

  // The fluid grid, rebuilt from the positions for every force evaluation and reorder.
  GridView Fluid{};
  DeviceBuffer<double> Sorted;
  DeviceBuffer<std::uint64_t> Keys, SortedKeys, Spread;
  DeviceBuffer<std::int32_t> Index, Order;
  DeviceBuffer<Span> Cells;
  DeviceBuffer<unsigned char> SortTemp;
  std::int64_t SpreadDims[3] = { 0, 0, 0 };
  int KeyBits = 0;
  DeviceBuffer<Bounds> BoundsPartials;
  DeviceBuffer<SPHExtremes> ExtremesPartials;

  // The wall dummies: static, their grid copied once.
  GridView Wall{};
  std::int64_t WallCount = 0;
  DeviceBuffer<double> WallX, WallSorted, WallTerm;
  DeviceBuffer<std::int32_t> WallOrder;
  DeviceBuffer<Span> WallCells;

  bool BuildGrid(std::string* error);
};

bool SPHDevice::Internals::BuildGrid(std::string* error)
{
  const std::int64_t n = this->N;
  // Bounds on the device, merged here (a few KB), then NeighborGrid's own choice of cells and keys.
  if (!this->BoundsPartials.Reserve(ReduceBlocks, error))
  {
    return false;
  }
  BoundsKernel<<<ReduceBlocks, ReduceBlock>>>(n, this->X.Data, this->BoundsPartials.Data);
  std::vector<Bounds> partials(ReduceBlocks);
  if (!Check(cudaGetLastError(), "bounds kernel", error) ||
    !this->BoundsPartials.Download(partials.data(), ReduceBlocks, error))
  {
    return false;
  }
  Bounds bounds;
  bounds.Reset();
  for (const Bounds& b : partials)
  {
    bounds.Merge(b);
  }
  if (bounds.Invalid)
  {
    if (error)
    {
      *error = "a particle position is not finite";
    }
    return false;
  }
  GridView& g = this->Fluid;
  for (int a = 0; a < 3; ++a)
  {
    g.Origin[a] = bounds.Lo[a];
    g.Extent[a] = bounds.Hi[a] - bounds.Lo[a];
  }
  NeighborGrid::ChooseCells(g.Extent, this->C.H, n, 8.0, g.Size, g.Inverse, g.Dims);
  if (g.Dims[0] != this->SpreadDims[0] || g.Dims[1] != this->SpreadDims[1] || g.Dims[2] != this->SpreadDims[2])
  {
    std::vector<std::uint64_t> spread[3];
    this->KeyBits = NeighborGrid::MortonTables(g.Dims, spread);
    std::vector<std::uint64_t> all;
    for (int a = 0; a < 3; ++a)
    {
      all.insert(all.end(), spread[a].begin(), spread[a].end());
    }
    if (!this->Spread.Upload(all.data(), all.size(), error))
    {
      return false;
    }
    std::copy(g.Dims, g.Dims + 3, this->SpreadDims);
  }
  const std::int64_t cellCount = g.Dims[0] * g.Dims[1] * g.Dims[2];
  if (!this->Keys.Reserve(n, error) || !this->SortedKeys.Reserve(n, error) || !this->Index.Reserve(n, error) ||
    !this->Order.Reserve(n, error) || !this->Sorted.Reserve(3 * n, error) || !this->Cells.Reserve(cellCount, error))
  {
    return false;
  }
  const std::uint64_t* spread = this->Spread.Data;
  KeysKernel<<<Blocks(n), BlockSize>>>(
    n, this->X.Data, g, spread, spread + g.Dims[0], spread + g.Dims[0] + g.Dims[1], this->Keys.Data, this->Index.Data);
  if (!Check(cudaGetLastError(), "cell key kernel", error))
  {
    return false;
  }
  // Stable LSD radix sort of (key, index): equal keys keep the index order, as the grid's own sort does.
  if (this->KeyBits == 0)
  {
    if (!Check(cudaMemcpy(this->SortedKeys.Data, this->Keys.Data, sizeof(std::uint64_t) * n, cudaMemcpyDeviceToDevice),
          "cudaMemcpy", error) ||
      !Check(cudaMemcpy(this->Order.Data, this->Index.Data, sizeof(std::int32_t) * n, cudaMemcpyDeviceToDevice),
        "cudaMemcpy", error))
    {
      return false;
    }
  }
  else
  {
    std::size_t bytes = 0;
    if (!Check(cub::DeviceRadixSort::SortPairs(nullptr, bytes, this->Keys.Data, this->SortedKeys.Data, this->Index.Data,
                 this->Order.Data, static_cast<int>(n), 0, this->KeyBits),
          "cub::DeviceRadixSort", error) ||
      !this->SortTemp.Reserve(bytes, error) ||
      !Check(cub::DeviceRadixSort::SortPairs(this->SortTemp.Data, bytes, this->Keys.Data, this->SortedKeys.Data,
               this->Index.Data, this->Order.Data, static_cast<int>(n), 0, this->KeyBits),
        "cub::DeviceRadixSort", error))
    {
      return false;
    }
  }
  if (!Check(cudaMemset(this->Cells.Data, 0, sizeof(Span) * cellCount), "cudaMemset", error))
  {
    return false;
  }
  CellsKernel<<<Blocks(n), BlockSize>>>(
    n, this->X.Data, this->Order.Data, this->SortedKeys.Data, g, this->Sorted.Data, this->Cells.Data);
  g.Sorted = this->Sorted.Data;
  g.Order = this->Order.Data;
  g.Cells = this->Cells.Data;
  g.Count = n;
  return Check(cudaGetLastError(), "cell kernel", error);
}

SPHDevice::SPHDevice()
  : Impl(new Internals)
{
}

SPHDevice::~SPHDevice() = default;

std::int64_t SPHDevice::Size() const
{
  return this->Impl->N;
}

bool SPHDevice::Setup(const SPHConstants& constants, const double* boundaryPositions, std::int64_t boundaryCount,
  const NeighborGrid& boundaryGrid, std::string* error)
{
  std::string reason;
  if (!Available(&reason))
  {
    if (error)
    {
      *error = reason;
    }
    return false;
  }
  Internals& d = *this->Impl;
  d.C = constants;
  d.WallCount = boundaryCount;
  d.Wall = GridView{};
  if (boundaryCount <= 0 || boundaryGrid.NumberOfValidPoints() != boundaryCount)
  {
    d.WallCount = 0;
    return true;
  }
  if (boundaryCount >= (std::int64_t(1) << 31))
  {
    if (error)
    {
      *error = "too many wall dummies for the device integrator (2^31 or more)";
    }
    return false;
  }
  std::vector<std::int32_t> order;
  std::vector<Span> cells;
  GridView& w = d.Wall;
  w = GridCellView(boundaryGrid, order, cells);
  if (!d.WallX.Upload(boundaryPositions, 3 * boundaryCount, error) ||
    !d.WallSorted.Upload(boundaryGrid.SortedPoints(), 3 * boundaryCount, error) ||
    !d.WallOrder.Upload(order.data(), order.size(), error) || !d.WallCells.Upload(cells.data(), cells.size(), error) ||
    !d.WallTerm.Reserve(boundaryCount, error))
  {
    return false;
  }
  w.Sorted = d.WallSorted.Data; // the view's host pointers replaced by the device copies
  w.Order = d.WallOrder.Data;
  w.Cells = d.WallCells.Data;
  return true;
}

bool SPHDevice::Upload(const SPHState& state, std::string* error)
{
  Internals& d = *this->Impl;
  const std::int64_t n = state.Size();
  if (n >= (std::int64_t(1) << 31))
  {
    if (error)
    {
      *error = "too many particles for the device integrator (2^31 or more)";
    }
    return false;
  }
  d.N = n;
  d.Fluid.Count = 0;
  return d.X.Upload(state.Position.data(), 3 * n, error) && d.V.Upload(state.Velocity.data(), 3 * n, error) &&
    d.A.Upload(state.Acceleration.data(), 3 * n, error) && d.Rho.Upload(state.Density.data(), n, error) &&
    d.P.Upload(state.Pressure.data(), n, error) && d.Id.Upload(state.Id.data(), n, error) && d.Term.Reserve(n, error) &&
    d.Inverse.Reserve(n, error) && d.X2.Reserve(3 * n, error) && d.V2.Reserve(3 * n, error) &&
    d.A2.Reserve(3 * n, error) && d.Id2.Reserve(n, error);
}

bool SPHDevice::Download(SPHState& state, std::string* error)
{
  Internals& d = *this->Impl;
  const std::int64_t n = d.N;
  state.Position.resize(3 * n);
  state.Velocity.resize(3 * n);
  state.Acceleration.resize(3 * n);
  state.Density.resize(n);
  state.Pressure.resize(n);
  state.Id.resize(n);
  return d.X.Download(state.Position.data(), 3 * n, error) && d.V.Download(state.Velocity.data(), 3 * n, error) &&
    d.A.Download(state.Acceleration.data(), 3 * n, error) && d.Rho.Download(state.Density.data(), n, error) &&
    d.P.Download(state.Pressure.data(), n, error) && d.Id.Download(state.Id.data(), n, error);
}

bool SPHDevice::Extremes(SPHExtremes& extremes, std::string* error)
{
  Internals& d = *this->Impl;
  extremes = SPHExtremes();
  extremes.Rho = d.C.RestDensity;
  if (d.N == 0)
  {
    return true;
  }
  if (!d.ExtremesPartials.Reserve(ReduceBlocks, error))
  {
    return false;
  }
  ExtremesKernel<<<ReduceBlocks, ReduceBlock>>>(
    d.N, d.V.Data, d.A.Data, d.Rho.Data, d.C.RestDensity, d.ExtremesPartials.Data);
  std::vector<SPHExtremes> partials(ReduceBlocks);
  if (!Check(cudaGetLastError(), "CFL kernel", error) ||
    !d.ExtremesPartials.Download(partials.data(), ReduceBlocks, error))
  {
    return false;
  }
  for (const SPHExtremes& e : partials)
  {
    extremes.Merge(e);
  }
  return true;
}

bool SPHDevice::KickDrift(double half, double dt, std::string* error)
{
  Internals& d = *this->Impl;
  if (d.N == 0)
  {
    return true;
  }
  KickDriftKernel<<<Blocks(d.N), BlockSize>>>(d.N, d.X.Data, d.V.Data, d.A.Data, half, dt, d.C);
  return Check(cudaGetLastError(), "kick-drift kernel", error);
}

bool SPHDevice::Kick(double half, std::string* error)
{
  Internals& d = *this->Impl;
  if (d.N == 0)
  {
    return true;
  }
  KickKernel<<<Blocks(3 * d.N), BlockSize>>>(3 * d.N, d.V.Data, d.A.Data, half);
  return Check(cudaGetLastError(), "kick kernel", error);
}

bool SPHDevice::Reorder(std::string* error)
{
  Internals& d = *this->Impl;
  if (d.N == 0)
  {
    return true;
  }
  if (!d.BuildGrid(error))
  {
    return false;
  }
  PermuteKernel<<<Blocks(d.N), BlockSize>>>(
    d.N, d.Order.Data, d.X.Data, d.V.Data, d.A.Data, d.Id.Data, d.X2.Data, d.V2.Data, d.A2.Data, d.Id2.Data);
  if (!Check(cudaGetLastError(), "permutation kernel", error))
  {
    return false;
  }
  std::swap(d.X.Data, d.X2.Data);
  std::swap(d.X.Capacity, d.X2.Capacity);
  std::swap(d.V.Data, d.V2.Data);
  std::swap(d.V.Capacity, d.V2.Capacity);
  std::swap(d.A.Data, d.A2.Data);
  std::swap(d.A.Capacity, d.A2.Capacity);
  std::swap(d.Id.Data, d.Id2.Data);
  std::swap(d.Id.Capacity, d.Id2.Capacity);
  d.Fluid.Count = 0; // the grid was built on the old order
  return true;
}

bool SPHDevice::ComputeAccelerations(std::string* error)
{
  Internals& d = *this->Impl;
  const std::int64_t n = d.N;
  if (n == 0)
  {
    return true;
  }
  if (!d.BuildGrid(error))
  {
    return false;
  }
  DensityKernel<<<Blocks(n), BlockSize>>>(n, d.Fluid, d.Wall, d.C, d.Rho.Data, d.P.Data, d.Term.Data, d.Inverse.Data);
  if (!Check(cudaGetLastError(), "density kernel", error))
  {
    return false;
  }
  if (d.WallCount > 0)
  {
    WallPressureKernel<<<Blocks(d.WallCount), BlockSize>>>(
      d.WallCount, d.WallX.Data, d.Fluid, d.P.Data, d.Rho.Data, d.C, d.WallTerm.Data);
    if (!Check(cudaGetLastError(), "wall pressure kernel", error))
    {
      return false;
    }
  }
  AccelerationKernel<<<Blocks(n), BlockSize>>>(
    n, d.Fluid, d.Wall, d.V.Data, d.Rho.Data, d.Inverse.Data, d.Term.Data, d.WallTerm.Data, d.C, d.A.Data);
  return Check(cudaGetLastError(), "acceleration kernel", error) &&
    Check(cudaDeviceSynchronize(), "SPH force kernels", error);
}

} // namespace cuda
} // namespace meshfree
