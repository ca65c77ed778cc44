// SPH density on the CUDA device: one thread per particle runs meshfree::SPHParticleDensity (SPH/SPHDensity.h),
// the function of the CPU loop, on the same CSR neighbour rows. Declared without CUDA types; without CUDA (or
// without a device) the functions return false with the reason in `error`.
#ifndef MeshFree_cuda_SPHDensity_h
#define MeshFree_cuda_SPHDensity_h

#include "SPH/SPHDensity.h"

#include <cstdint>
#include <string>

namespace meshfree
{
namespace cuda
{

/// Device pointers: rho[i] for i < n, from positions x (3n), fluid rows (fluidStart: n + 1 entries), dummy
/// positions and rows (boundaryStart: n + 1 entries, all zero without walls). Synchronous.
bool SPHDensityOnDevice(std::int64_t n, const double* x, const std::int64_t* fluidStart,
  const std::int32_t* fluidNeighbors, const double* boundaryX, const std::int64_t* boundaryStart,
  const std::int32_t* boundaryNeighbors, const SPHDensityConstants& constants, double* rho, std::string* error);

/// The same from host arrays (nb dummies): copies them to the device, runs, copies rho (n values) back. For
/// tests and parity checks; a device integrator keeps its arrays on the device instead.
bool SPHDensityFromHost(std::int64_t n, const double* x, const std::int64_t* fluidStart,
  const std::int32_t* fluidNeighbors, std::int64_t nb, const double* boundaryX, const std::int64_t* boundaryStart,
  const std::int32_t* boundaryNeighbors, const SPHDensityConstants& constants, double* rho, std::string* error);

} // namespace cuda
} // namespace meshfree

#endif
