#!/usr/bin/env bash
# The GPU check of the CUDA back ends, prepared to run once on a lent GPU machine (CMake and nvcc, no ParaView)
# in under 5 minutes: builds the standalone core (Filters/Core) with CUDA, runs the CUDA tests (parity with the
# CPU; skipped without a device), the fallback test with the device hidden, and the device benchmarks beside the
# CPU, and writes a short report.
#
#   Testing/Benchmarks/gpu_check.sh --pack DIR   on a Debian 12 developer machine: copies Eigen, oneTBB and
#                                                GoogleTest (headers, libraries, CMake files) into DIR, for a GPU
#                                                machine that lacks them
#   Testing/Benchmarks/gpu_check.sh [DIR]        from the repository root; DIR: the packed dependencies (optional)
#
# Output: $OUT/gpu_report.md and $OUT/gpu_check.log when OUT is set, else in the build folder. Exit status: 0 when
# every test passed or was skipped and every benchmark ran or was skipped for want of a device.
# Without a device (a developer machine) it still builds, and every GPU part reports "skipped".
set -uo pipefail

if [[ "${1:-}" == "--pack" ]]; then
  dest="${2:?usage: gpu_check.sh --pack DIR}"
  lib=/usr/lib/x86_64-linux-gnu
  mkdir -p "$dest/usr/include" "$dest/usr/share" "$dest/usr/lib/x86_64-linux-gnu/cmake"
  cp -a /usr/include/eigen3 /usr/include/tbb /usr/include/oneapi /usr/include/gtest "$dest/usr/include/"
  mkdir -p "$dest/usr/share/eigen3" && cp -a /usr/share/eigen3/cmake "$dest/usr/share/eigen3/"
  cp -a "$lib"/libtbb*.so* "$lib"/libgtest*.a "$lib"/libgmock*.a "$dest/usr/lib/x86_64-linux-gnu/"
  cp -a "$lib/cmake/TBB" "$lib/cmake/GTest" "$dest/usr/lib/x86_64-linux-gnu/cmake/"
  du -sh "$dest"
  exit 0
fi

root="$(cd "$(dirname "$0")/../.." && pwd)"
deps="${1:-}"
build="${MESHFREE_GPU_BUILD:-/tmp/meshfree-gpu-check}"
out="${OUT:-$build}"
mkdir -p "$build" "$out"
log="$out/gpu_check.log"
report="$out/gpu_report.md"
exec > >(tee "$log") 2>&1
start=$(date +%s)
jobs=$(nproc)

prefix=()
if [[ -n "$deps" ]]; then
  deps="$(cd "$deps" && pwd)"
  prefix=(-DCMAKE_PREFIX_PATH="$deps/usr")
  export LD_LIBRARY_PATH="$deps/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi
nvcc=$(command -v nvcc || echo /usr/local/cuda/bin/nvcc)
gpu=$(nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null || echo "none")
echo "== machine: $(nproc) cores; GPU: $gpu"
"$nvcc" --version | tail -2

rc=0
generator=()
command -v ninja > /dev/null && generator=(-G Ninja)
echo "== build (standalone core, CUDA on)"
if ! cmake -S "$root/Filters/Core" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
     -DMESHFREE_ENABLE_CUDA=ON "${prefix[@]}" > "$build/configure.log" 2>&1; then
  tail -30 "$build/configure.log"
  echo "configure failed"
  exit 1
fi
if ! cmake --build "$build" -j "$jobs" > "$build/build.log" 2>&1; then
  grep -E "error|Error" "$build/build.log" | head -30
  echo "build failed"
  exit 1
fi
echo "built in $(($(date +%s) - start)) s"

echo "== CUDA tests (parity with the CPU; skipped without a device) and the core tests that use the device when there is one"
(cd "$build" && ctest -j 4 -R "Cuda|ApproximationBackend|MLSDevicePoint|MLSFastPath|SPHDeviceEmulation" \
  --output-on-failure --timeout 240) | tee "$build/ctest_cuda.txt" || rc=1
echo "== the same fallback with the device hidden (CUDA_VISIBLE_DEVICES empty)"
(cd "$build" && CUDA_VISIBLE_DEVICES= ctest -R "CudaNoDevice|ApproximationBackend" --output-on-failure --timeout 120) \
  | tee "$build/ctest_hidden.txt" || rc=1

# Benchmarks (exit 77: no usable device). BenchSPH --backend cuda: 3D dam breaks (double) of 65,536, 1,048,576 and
# 4,194,304 particles, device and CPU rates side by side and a bitwise check at 65,536. BenchApproximation --backend
# cuda: MLS degree 2 (Wendland, 20 neighbours), 2D and 3D clouds of 10^6 points onto 10^7 image probes generated on
# the device, beside the CPU on 10^6 probes.
bench() {
  local name="$1"
  shift
  echo "== $name $*"
  "$build/$name" "$@" 2>&1 | tee -a "$build/bench.txt"
  local status=${PIPESTATUS[0]}
  if [[ $status -ne 0 && $status -ne 77 ]]; then
    echo "$name failed ($status)" | tee -a "$build/bench.txt"
    rc=1
  fi
}
: > "$build/bench.txt"
bench BenchSPH --backend cuda
bench BenchApproximation --backend cuda

{
  echo "# MeshFree GPU check"
  echo
  echo "- commit: $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)"
  echo "- GPU: $gpu; $(nproc) CPU cores; $("$nvcc" --version | tail -1)"
  echo "- wall time: $(($(date +%s) - start)) s"
  echo
  echo "## Tests"
  echo '```'
  grep -E "tests passed|Test +#|Skipped|Failed" "$build/ctest_cuda.txt" "$build/ctest_hidden.txt" | sed "s|$build/||"
  echo '```'
  echo
  echo "## Benchmarks"
  echo '```'
  cat "$build/bench.txt"
  echo '```'
  echo
  echo "exit status: $rc"
} > "$report"
cat "$report"
exit $rc
