// What every launcher of cuda/ needs of the CUDA runtime: errors as text, and a device array that frees itself.
// Included by .cu files only (it has CUDA types).
#ifndef MeshFree_cuda_DeviceBuffer_cuh
#define MeshFree_cuda_DeviceBuffer_cuh

#include <cuda_runtime.h>

#include <cstddef>
#include <string>

namespace meshfree
{
namespace cuda
{

/// True on success; otherwise `error` (when given) receives "what: cudaErrorName (description)".
inline bool Check(cudaError_t status, const char* what, std::string* error)
{
  if (status == cudaSuccess)
  {
    return true;
  }
  if (error)
  {
    *error = std::string(what) + ": " + cudaGetErrorName(status) + " (" + cudaGetErrorString(status) + ")";
  }
  return false;
}

/// A device array freed on destruction; Reserve() keeps the allocation when it is large enough already.
template <class T>
struct DeviceBuffer
{
  T* Data = nullptr;
  std::size_t Capacity = 0;
  DeviceBuffer() = default;
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  ~DeviceBuffer() { cudaFree(this->Data); }
  bool Reserve(std::size_t count, std::string* error)
  {
    count = count > 0 ? count : 1;
    if (this->Data && count <= this->Capacity)
    {
      return true;
    }
    cudaFree(this->Data);
    this->Data = nullptr;
    this->Capacity = 0;
    if (!Check(cudaMalloc(&this->Data, sizeof(T) * count), "cudaMalloc", error))
    {
      return false;
    }
    this->Capacity = count;
    return true;
  }
  bool Upload(const T* host, std::size_t count, std::string* error)
  {
    return this->Reserve(count, error) &&
      (count == 0 ||
        Check(cudaMemcpy(this->Data, host, sizeof(T) * count, cudaMemcpyHostToDevice), "cudaMemcpy", error));
  }
  bool Download(T* host, std::size_t count, std::string* error) const
  {
    return count == 0 ||
      Check(cudaMemcpy(host, this->Data, sizeof(T) * count, cudaMemcpyDeviceToHost), "cudaMemcpy", error);
  }
};

} // namespace cuda
} // namespace meshfree

#endif
