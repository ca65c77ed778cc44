// cuda/Device.h for a build without CUDA (MESHFREE_ENABLE_CUDA OFF): never available.
#include "cuda/Device.h"

#include "cuda/SPHDensity.h"

namespace meshfree
{
namespace cuda
{
namespace
{
const char* const NotBuilt = "MeshFree was built without CUDA";
}

bool Available(std::string* reason)
{
  if (reason)
  {
    *reason = NotBuilt;
  }
  return false;
}

std::string DeviceName()
{
  return std::string();
}

bool SPHDensityOnDevice(std::int64_t, const double*, const std::int64_t*, const std::int32_t*, const double*,
  const std::int64_t*, const std::int32_t*, const SPHDensityConstants&, double*, std::string* error)
{
  if (error)
  {
    *error = NotBuilt;
  }
  return false;
}

bool SPHDensityFromHost(std::int64_t, const double*, const std::int64_t*, const std::int32_t*, std::int64_t,
  const double*, const std::int64_t*, const std::int32_t*, const SPHDensityConstants&, double*, std::string* error)
{
  if (error)
  {
    *error = NotBuilt;
  }
  return false;
}

} // namespace cuda
} // namespace meshfree
