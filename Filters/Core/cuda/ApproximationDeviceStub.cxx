// cuda/ApproximationDevice.h for a build without CUDA (MESHFREE_ENABLE_CUDA OFF): every call fails with the reason.
#include "cuda/ApproximationDevice.h"
#include "cuda/Stub.h"

namespace meshfree
{
namespace cuda
{

struct MLSDevice::State
{
};

MLSDevice::MLSDevice() = default;
MLSDevice::~MLSDevice() = default;

bool MLSDevice::Upload(const MLSDeviceCloud&, const MLSDeviceOptions&, std::string* error)
{
  return NotBuiltError(error);
}

bool MLSDevice::Evaluate(
  const double*, std::int64_t, const MLSDeviceOutput&, std::string* error, bool (*)(void*, double), void*)
{
  return NotBuiltError(error);
}

bool MLSDevice::EvaluateImage(
  const ImageGeometry&, const MLSDeviceOutput&, std::string* error, bool (*)(void*, double), void*)
{
  return NotBuiltError(error);
}

double MLSDevice::LastKernelSeconds() const
{
  return 0.0;
}

} // namespace cuda
} // namespace meshfree
