// The CUDA launcher of the SPH density pass (cuda/SPHDensity.h).
#include "cuda/SPHDensity.h"

#include "cuda/Device.h"
#include "cuda/DeviceBuffer.cuh"

#include <cuda_runtime.h>

#include <vector>

namespace meshfree
{
namespace cuda
{
namespace
{
constexpr int BlockSize = 128;

__global__ void DensityKernel(std::int64_t n, const double* x, const std::int64_t* fluidStart,
  const std::int32_t* fluidNeighbors, const double* boundaryX, const std::int64_t* boundaryStart,
  const std::int32_t* boundaryNeighbors, SPHDensityConstants constants, double* rho)
{
  const std::int64_t i = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n)
  {
    rho[i] = SPHParticleDensity(i, x, fluidStart, fluidNeighbors, boundaryX, boundaryStart, boundaryNeighbors,
      constants);
  }
}

/// Whether a device is there to run on; otherwise `error` gets the reason.
bool Usable(std::string* error)
{
  std::string reason;
  if (Available(&reason))
  {
    return true;
  }
  if (error)
  {
    *error = reason;
  }
  return false;
}
} // namespace

bool SPHDensityOnDevice(std::int64_t n, const double* x, const std::int64_t* fluidStart,
  const std::int32_t* fluidNeighbors, const double* boundaryX, const std::int64_t* boundaryStart,
  const std::int32_t* boundaryNeighbors, const SPHDensityConstants& constants, double* rho, std::string* error)
{
  if (!Usable(error))
  {
    return false;
  }
  if (n <= 0)
  {
    return true;
  }
  const std::int64_t blocks = (n + BlockSize - 1) / BlockSize;
  DensityKernel<<<static_cast<unsigned>(blocks), BlockSize>>>(
    n, x, fluidStart, fluidNeighbors, boundaryX, boundaryStart, boundaryNeighbors, constants, rho);
  return Check(cudaGetLastError(), "density kernel launch", error) &&
    Check(cudaDeviceSynchronize(), "density kernel", error);
}

bool SPHDensityFromHost(std::int64_t n, const double* x, const std::int64_t* fluidStart,
  const std::int32_t* fluidNeighbors, std::int64_t nb, const double* boundaryX, const std::int64_t* boundaryStart,
  const std::int32_t* boundaryNeighbors, const SPHDensityConstants& constants, double* rho, std::string* error)
{
  if (!Usable(error))
  {
    return false;
  }
  if (n <= 0)
  {
    return true;
  }
  DeviceBuffer<double> dx, dbx, drho;
  DeviceBuffer<std::int64_t> dfs, dbs;
  DeviceBuffer<std::int32_t> dfn, dbn;
  const bool uploaded = dx.Upload(x, 3 * n, error) && dfs.Upload(fluidStart, n + 1, error) &&
    dfn.Upload(fluidNeighbors, fluidStart[n], error) && dbx.Upload(boundaryX, 3 * nb, error) &&
    dbs.Upload(boundaryStart, n + 1, error) && dbn.Upload(boundaryNeighbors, boundaryStart[n], error) &&
    drho.Reserve(n, error);
  if (!uploaded ||
    !SPHDensityOnDevice(n, dx.Data, dfs.Data, dfn.Data, dbx.Data, dbs.Data, dbn.Data, constants, drho.Data, error))
  {
    return false;
  }
  return Check(cudaMemcpy(rho, drho.Data, sizeof(double) * n, cudaMemcpyDeviceToHost), "cudaMemcpy", error);
}

} // namespace cuda
} // namespace meshfree
