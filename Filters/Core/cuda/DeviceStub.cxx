// cuda/Device.h for a build without CUDA (MESHFREE_ENABLE_CUDA OFF): never available.
#include "cuda/Device.h"
#include "cuda/Stub.h"

namespace meshfree
{
namespace cuda
{

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

} // namespace cuda
} // namespace meshfree
