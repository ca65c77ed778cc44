# MESHFREE_ENABLE_CUDA: the CUDA back ends. Included at the top level of a project (the plugin's, or the standalone
# core's), before any target: enable_language(CUDA) done deeper leaves the plugin MODULE without the CUDA runtime
# symbols (dlopen fails with an undefined __cudaLaunchKernel).
# ON by default when nvcc is found (on PATH, under $CUDA_PATH / $CUDA_HOME, or in /usr/local/cuda/bin); an explicit
# ON without nvcc is an error. The runtime is linked statically: the plugin needs no CUDA library to load, and
# without a GPU the back ends fall back to the CPU at run time (meshfree::cuda::Available()).
include_guard(GLOBAL)

if (DEFINED ENV{CUDACXX})
  set(MESHFREE_NVCC "$ENV{CUDACXX}" CACHE FILEPATH "The CUDA compiler")
else ()
  find_program(MESHFREE_NVCC nvcc HINTS ENV CUDA_PATH ENV CUDA_HOME PATH_SUFFIXES bin PATHS /usr/local/cuda/bin
    DOC "The CUDA compiler")
endif ()
set(meshfree_cuda_default OFF)
if (MESHFREE_NVCC)
  set(meshfree_cuda_default ON)
endif ()
option(MESHFREE_ENABLE_CUDA "Build the CUDA back ends (needs nvcc; without a GPU they fall back to the CPU)"
  ${meshfree_cuda_default})

if (MESHFREE_ENABLE_CUDA)
  if (NOT MESHFREE_NVCC)
    message(FATAL_ERROR "MESHFREE_ENABLE_CUDA is ON but nvcc was found neither on PATH nor in /usr/local/cuda/bin "
      "(set CUDACXX or CUDA_PATH, or configure with -DMESHFREE_ENABLE_CUDA=OFF)")
  endif ()
  # check_language() and enable_language() read CUDACXX; the host compiler is the C++ compiler, so that the host
  # parts of .cu files and the .cxx files are compiled alike.
  set(ENV{CUDACXX} "${MESHFREE_NVCC}")
  if (NOT DEFINED CMAKE_CUDA_HOST_COMPILER)
    set(CMAKE_CUDA_HOST_COMPILER "${CMAKE_CXX_COMPILER}" CACHE FILEPATH "Host compiler of nvcc")
  endif ()
  include(CheckLanguage)
  check_language(CUDA)
  if (NOT CMAKE_CUDA_COMPILER)
    message(FATAL_ERROR "MESHFREE_ENABLE_CUDA is ON but ${MESHFREE_NVCC} does not compile CUDA "
      "(see CMakeFiles/CMakeError.log, or configure with -DMESHFREE_ENABLE_CUDA=OFF)")
  endif ()
  # sm_90 code (H100/H200) and compute_90 PTX for newer chips; must be set before enable_language (or CMake
  # caches nvcc's default, 75).
  if (NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
    set(CMAKE_CUDA_ARCHITECTURES 90-real 90-virtual CACHE STRING "CUDA architectures of the MeshFree kernels")
  endif ()
  set(CMAKE_CUDA_STANDARD 17)
  set(CMAKE_CUDA_STANDARD_REQUIRED ON)
  enable_language(CUDA)
  message(STATUS "MeshFree: CUDA back ends ON (${CMAKE_CUDA_COMPILER}, architectures ${CMAKE_CUDA_ARCHITECTURES})")
else ()
  message(STATUS "MeshFree: CUDA back ends OFF")
endif ()
