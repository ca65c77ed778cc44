// cuda/Device.h with the CUDA runtime (linked statically: the plugin loads where no CUDA library is installed).
#include "cuda/Device.h"

#include <cuda_runtime.h>

#include <sstream>

namespace meshfree
{
namespace cuda
{
namespace
{
struct Probe
{
  bool Usable = false;
  std::string Reason;
  std::string Name;
};

std::string Describe(cudaError_t status)
{
  std::ostringstream s;
  switch (status)
  {
    case cudaErrorInsufficientDriver:
      s << "no CUDA driver";
      break;
    case cudaErrorNoDevice:
      s << "no CUDA device";
      break;
    default:
      s << "the CUDA runtime failed: " << cudaGetErrorString(status);
      break;
  }
  s << " (" << cudaGetErrorName(status) << ")";
  return s.str();
}

Probe Run()
{
  Probe probe;
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess)
  {
    cudaGetLastError(); // clears the error where it is not sticky
    probe.Reason = Describe(status);
    return probe;
  }
  if (count < 1)
  {
    probe.Reason = "no CUDA device";
    return probe;
  }
  cudaDeviceProp properties;
  const cudaError_t query = cudaGetDeviceProperties(&properties, 0);
  if (query != cudaSuccess)
  {
    cudaGetLastError();
    probe.Reason = Describe(query);
    return probe;
  }
  // The kernels are built for sm_90 with compute_90 PTX (CMAKE_CUDA_ARCHITECTURES): older devices cannot run them.
  if (properties.major < 9)
  {
    std::ostringstream s;
    s << properties.name << " has compute capability " << properties.major << "." << properties.minor
      << "; MeshFree's kernels are built for 9.0 and newer";
    probe.Reason = s.str();
    return probe;
  }
  probe.Usable = true;
  probe.Name = properties.name;
  return probe;
}

const Probe& Cached()
{
  static const Probe probe = Run(); // once per process; C++11 makes the initialisation thread-safe
  return probe;
}
} // namespace

bool Available(std::string* reason)
{
  const Probe& probe = Cached();
  if (!probe.Usable && reason)
  {
    *reason = probe.Reason;
  }
  return probe.Usable;
}

std::string DeviceName()
{
  const Probe& probe = Cached();
  return probe.Usable ? probe.Name : std::string();
}

} // namespace cuda
} // namespace meshfree
