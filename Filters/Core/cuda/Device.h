// The CUDA device, as the back ends see it. Declared without any CUDA type, so that every .cxx of the core and of
// the plugin can include it; defined in Device.cu (MESHFREE_ENABLE_CUDA) or DeviceStub.cxx (CPU-only build).
#ifndef MeshFree_cuda_Device_h
#define MeshFree_cuda_Device_h

#include <string>

namespace meshfree
{
namespace cuda
{

/// Whether this build has CUDA back ends and a usable device (compute capability >= 9.0, the code the kernels
/// are built for). The CUDA runtime is probed once per process (its "no driver" error is sticky), on first call,
/// thread-safely; later calls return the cached answer. When false and `reason` is given, it receives why, e.g.
/// "no CUDA driver (cudaErrorInsufficientDriver)" or "MeshFree was built without CUDA".
bool Available(std::string* reason = nullptr);

/// Name of the device used (device 0), e.g. "NVIDIA H200"; empty when Available() is false.
std::string DeviceName();

} // namespace cuda
} // namespace meshfree

#endif
