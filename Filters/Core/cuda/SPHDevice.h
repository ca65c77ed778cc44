// The SPH fluid's state on the CUDA device for a whole SPHFluid::Advance(): positions, velocities,
// accelerations, densities, pressures and ids live there between steps; the host only asks for the CFL maxima
// (a few scalars) per step and downloads the state when it is reported. Declared without CUDA types (pimpl);
// defined in SPHDevice.cu, or SPHDeviceStub.cxx in a build without CUDA (every call fails with the reason).
//
// Each step does what the CPU loops of SPHFluid.cxx do, with the same shared arithmetic (SPH/SPHPhysics.h,
// SPH/SPHDensity.h): the neighbour grid is rebuilt on the device with NeighborGrid's geometry (origin = minimum
// of the points, NeighborGrid::ChooseCells for cellSize = h, its compact Morton keys, a stable radix sort of
// (cell key, index), so the sorted order equals the SortedOrder() of the solver's grid, which keeps each cell's
// points in index order: NeighborGrid::SetCellsByPosition(false)), and every sum visits its
// neighbours in the order of the CPU's rows (cells in (z, y, x) order, points of a cell in sorted order), so the
// sums match bit for bit. Wall dummies come from a device copy of the static boundary grid.
#ifndef MeshFree_cuda_SPHDevice_h
#define MeshFree_cuda_SPHDevice_h

#include "SPH/SPHPhysics.h"

#include <cstdint>
#include <memory>
#include <string>

namespace meshfree
{
class NeighborGrid;
struct SPHState;

namespace cuda
{

class SPHDevice
{
public:
  SPHDevice();
  ~SPHDevice();
  SPHDevice(const SPHDevice&) = delete;
  SPHDevice& operator=(const SPHDevice&) = delete;

  /// Copies the constants and the static wall dummies (positions, and `grid`, their NeighborGrid built with
  /// cell size h) to the device. Every call below fails with the reason in `error` when this build has no CUDA,
  /// no device is usable or a CUDA call fails.
  bool Setup(const SPHConstants& constants, const double* boundaryPositions, std::int64_t boundaryCount,
    const NeighborGrid& boundaryGrid, std::string* error);

  /// Copies a state's particles to the device (its Density and Pressure are not needed: the next force
  /// evaluation recomputes them).
  bool Upload(const SPHState& state, std::string* error);
  /// Copies the particles back into `state` (Position, Velocity, Acceleration, Density, Pressure, Id; Time and
  /// Steps are the caller's).
  bool Download(SPHState& state, std::string* error);

  /// The CFL maxima of the current state (SPHExtremes; Rho starts from the rest density).
  bool Extremes(SPHExtremes& extremes, std::string* error);
  /// v += half a, x += dt v, then the wall clamp (SPHKickDrift, SPHWallClamp).
  bool KickDrift(double half, double dt, std::string* error);
  /// Permutes the particles into the grid's Z-order (SPHFluid's Reorder: positions, velocities, accelerations,
  /// ids).
  bool Reorder(std::string* error);
  /// Density, pressure, the dummies' extrapolated pressures and the accelerations of the current positions.
  bool ComputeAccelerations(std::string* error);
  /// v += half a.
  bool Kick(double half, std::string* error);

  /// Particles uploaded.
  std::int64_t Size() const;

private:
  struct Internals;
  std::unique_ptr<Internals> Impl;
};

} // namespace cuda
} // namespace meshfree

#endif
