// cuda/SPHDevice.h for a build without CUDA (MESHFREE_ENABLE_CUDA OFF): every call fails with the reason.
#include "cuda/SPHDevice.h"

#include "SPH/SPHFluid.h"
#include "cuda/Stub.h"

namespace meshfree
{
namespace cuda
{

struct SPHDevice::Internals
{
};

SPHDevice::SPHDevice() = default;
SPHDevice::~SPHDevice() = default;

std::int64_t SPHDevice::Size() const
{
  return 0;
}

bool SPHDevice::Setup(const SPHConstants&, const double*, std::int64_t, const NeighborGrid&, std::string* error)
{
  return NotBuiltError(error);
}

bool SPHDevice::Upload(const SPHState&, std::string* error)
{
  return NotBuiltError(error);
}

bool SPHDevice::Download(SPHState&, std::string* error)
{
  return NotBuiltError(error);
}

bool SPHDevice::Extremes(SPHExtremes&, std::string* error)
{
  return NotBuiltError(error);
}

bool SPHDevice::KickDrift(double, double, std::string* error)
{
  return NotBuiltError(error);
}

bool SPHDevice::Reorder(std::string* error)
{
  return NotBuiltError(error);
}

bool SPHDevice::ComputeAccelerations(std::string* error)
{
  return NotBuiltError(error);
}

bool SPHDevice::Kick(double, std::string* error)
{
  return NotBuiltError(error);
}

} // namespace cuda
} // namespace meshfree
