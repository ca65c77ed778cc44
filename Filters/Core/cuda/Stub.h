// What the stubs of a build without CUDA (cuda/*Stub.cxx) answer.
#ifndef MeshFree_cuda_Stub_h
#define MeshFree_cuda_Stub_h

#include <string>

namespace meshfree
{
namespace cuda
{

constexpr const char* NotBuilt = "MeshFree was built without CUDA";

/// Puts NotBuilt into `error` (when given) and returns false: the answer of every launcher in a CPU-only build.
inline bool NotBuiltError(std::string* error)
{
  if (error)
  {
    *error = NotBuilt;
  }
  return false;
}

} // namespace cuda
} // namespace meshfree

#endif
