# core.CudaNoFMA: the PTX of the core's CUDA sources (built with the core's own CUDA options) holds kernels and no
# double-precision fused multiply-add. nvcc contracts a * b + c into fma.rn.f64 unless --fmad=false; the CPU code
# has no contraction, so an FMA on the device would break the bitwise parity of the shared functions.
#   cmake -DPTX_FILES="a.ptx;b.ptx" -P CheckNoFMA.cmake
set(entries 0)
foreach (ptx IN LISTS PTX_FILES)
  if (NOT EXISTS "${ptx}")
    message(FATAL_ERROR "missing PTX file ${ptx}")
  endif ()
  file(STRINGS "${ptx}" kernels REGEX "\\.entry ")
  list(LENGTH kernels count)
  math(EXPR entries "${entries} + ${count}")
  file(STRINGS "${ptx}" fmas REGEX "fma\\.rn\\.f64")
  list(LENGTH fmas fmaCount)
  if (fmaCount GREATER 0)
    message(FATAL_ERROR "${ptx}: ${fmaCount} fma.rn.f64 instructions (is --fmad=false missing?)")
  endif ()
  message(STATUS "${ptx}: ${count} kernels, no fma.rn.f64")
endforeach ()
if (entries EQUAL 0)
  message(FATAL_ERROR "no kernel found in ${PTX_FILES}")
endif ()
