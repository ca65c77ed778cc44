// cuda/SPHDensity.h for a build without CUDA (MESHFREE_ENABLE_CUDA OFF): the launchers fail with the reason.
#include "cuda/SPHDensity.h"
#include "cuda/Stub.h"

namespace meshfree
{
namespace cuda
{

bool SPHDensityOnDevice(std::int64_t, const double*, const std::int64_t*, const std::int32_t*, const double*,
  const std::int64_t*, const std::int32_t*, const SPHDensityConstants&, double*, std::string* error)
{
  return NotBuiltError(error);
}

bool SPHDensityFromHost(std::int64_t, const double*, const std::int64_t*, const std::int32_t*, std::int64_t,
  const double*, const std::int64_t*, const std::int32_t*, const SPHDensityConstants&, double*, std::string* error)
{
  return NotBuiltError(error);
}

} // namespace cuda
} // namespace meshfree
