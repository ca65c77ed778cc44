// MESHFREE_HD marks the functions that both the CPU loops and the CUDA kernels call (the single source of the
// arithmetic): __host__ __device__ when compiled by nvcc, nothing for the C++ compiler. Such functions are
// inline, in headers, on raw pointers and POD constants (no separable compilation, no Eigen decompositions:
// those are host-only and nvcc is told to reject host calls from device code).
#ifndef MeshFree_Common_HostDevice_h
#define MeshFree_Common_HostDevice_h

#ifdef __CUDACC__
#define MESHFREE_HD __host__ __device__
#else
#define MESHFREE_HD
#endif

// MESHFREE_UNROLL before a loop with compile-time bounds: fully unrolled, so that register arrays are indexed by
// constants only (a run-time index puts the array on the stack in device code). A bare "#pragma unroll" trips
// g++'s -Wunknown-pragmas, hence the two spellings.
#ifndef MESHFREE_UNROLL
#ifdef __CUDACC__
#define MESHFREE_UNROLL _Pragma("unroll")
#else
#define MESHFREE_UNROLL _Pragma("GCC unroll 32")
#endif
#endif

#endif
