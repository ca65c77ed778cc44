#!/usr/bin/env bash
# Builds SPlisHSPlasH's command-line simulator (Release, no Python bindings, no file dialogs, GLFW without a
# window system) for the time-to-solution comparison in bench_splishsplash.py -- benchmark set-up only, never a test.
#
# Nothing is downloaded here. SPlisHSPlasH (https://github.com/InteractiveComputerGraphics/SPlisHSPlasH) bundles
# Eigen, zlib, partio, GLFW, imgui, ... in extern/, but pulls four of its own libraries through CMake
# ExternalProject_Add(GIT_REPOSITORY https://github.com/... GIT_TAG <commit>): CompactNSearch, Discregrid,
# GenericParameters and PositionBasedDynamics. Give this script local git directories of all five (clones or
# mirrors, bare or not). It checks SPlisHSPlasH and each dependency's pinned commit out under the build folder and,
# in that checkout only, replaces each GIT_REPOSITORY/GIT_TAG pair by SOURCE_DIR <the dependency's checkout>. Files
# whose blobs a local copy lacks (mirrors may leave out large data files: images, example meshes) are not checked
# out and are listed. When a local copy lacks the exact commit SPlisHSPlasH pins, the script stops and says so;
# --fallback-tag NAME=COMMIT then names the commit to use instead (printed; the script never guesses).
#
# SPlisHSPlasH 2.16.0 (c5a063d, 2025-11-28) pins CompactNSearch a9ab7c71 (2.15, 6bf568b: f6c0f32), which a mirror
# of CompactNSearch taken in 2024 lacks, and with the older CompactNSearch 3f11ece it does not compile (its
# SimulatorBase calls NeighborhoodSearch::reset()). --commit 80b7284 (2025-08-12; 2.14.0 and two CI/README commits)
# is the newest SPlisHSPlasH whose four pinned dependencies such mirrors all hold; bench_splishsplash.py's scene
# is written for both scene formats (before and after 2.16's per-method blocks).
#
# Usage:
#   setup_splishsplash.sh --sph DIR --compactnsearch DIR --discregrid DIR --genericparameters DIR --pbd DIR \
#                         [--build DIR] [--commit COMMIT] [--fallback-tag NAME=COMMIT ...] [--jobs N] [--no-build]
#   --build defaults to ${XDG_CACHE_HOME:-$HOME/.cache}/meshfree-bench/splishsplash (outside the repository);
#   --commit defaults to the SPlisHSPlasH copy's HEAD; --no-build stops after CMake's configure step.
# Prints the path of the SPHSimulator executable on its last line.
set -euo pipefail

SPH= CNS= DG= GP= PBD= COMMIT=HEAD JOBS=2 BUILD_IT=1
BUILD="${XDG_CACHE_HOME:-$HOME/.cache}/meshfree-bench/splishsplash"
declare -A FALLBACK=()
while [ $# -gt 0 ]; do
  case "$1" in
    --sph) SPH=$2; shift 2;;
    --compactnsearch) CNS=$2; shift 2;;
    --discregrid) DG=$2; shift 2;;
    --genericparameters) GP=$2; shift 2;;
    --pbd) PBD=$2; shift 2;;
    --build) BUILD=$2; shift 2;;
    --commit) COMMIT=$2; shift 2;;
    --jobs) JOBS=$2; shift 2;;
    --no-build) BUILD_IT=0; shift;;
    --fallback-tag) FALLBACK[${2%%=*}]=${2#*=}; shift 2;;
    -h|--help) sed -n '2,27p' "$0"; exit 0;;
    *) echo "setup_splishsplash.sh: unknown argument '$1' (see --help)" >&2; exit 2;;
  esac
done
for v in SPH CNS DG GP PBD; do
  if [ -z "${!v}" ]; then echo "setup_splishsplash.sh: missing a git directory (see --help)" >&2; exit 2; fi
  if ! git -C "${!v}" rev-parse --git-dir >/dev/null 2>&1; then
    echo "setup_splishsplash.sh: '${!v}' is not a git directory" >&2; exit 2
  fi
done
abs() { (cd "$1" && pwd); }
SPH=$(abs "$SPH"); CNS=$(abs "$CNS"); DG=$(abs "$DG"); GP=$(abs "$GP"); PBD=$(abs "$PBD")
mkdir -p "$BUILD/deps"
BUILD=$(abs "$BUILD")

# Checks commit `sha` of git directory `dir` out into `dest` (a --shared clone), every file whose blob is present.
checkout_present() {
  local dir=$1 sha=$2 dest=$3
  [ -d "$dest/.git" ] || git clone --quiet --shared --no-checkout "$dir" "$dest"
  git -C "$dest" ls-tree -r "$sha" | awk '$2=="blob"{print $3" "$4}' >"$dest.tree"
  cut -d' ' -f1 "$dest.tree" | git -C "$dest" cat-file --batch-check 2>/dev/null |
    awk '$2=="missing"{print $1}' >"$dest.missing" || true
  if [ -s "$dest.missing" ]; then
    echo "    blobs absent from $dir (not checked out):"
    grep -F -f "$dest.missing" "$dest.tree" | cut -d' ' -f2- | sed 's/^/      /'
  fi
  git -C "$dest" read-tree "$sha"
  grep -v -F -f "$dest.missing" "$dest.tree" | cut -d' ' -f2- | (cd "$dest" && git checkout-index --force --stdin)
  git -C "$dest" update-ref --no-deref HEAD "$sha"
}

SRC="$BUILD/src"
SHA=$(git -C "$SPH" rev-parse --verify "$COMMIT^{commit}")
echo "SPlisHSPlasH $SHA ($(git -C "$SPH" log -1 --format=%cs "$SHA"))"
checkout_present "$SPH" "$SHA" "$SRC"

# Each dependency: its pinned commit (the GIT_TAG line right after its GIT_REPOSITORY line) checked out locally and
# used as the ExternalProject's SOURCE_DIR.
repoint() {  # name local-dir cmake-file
  local name=$1 dir=$2 file="$SRC/$3"
  local url="https://github.com/InteractiveComputerGraphics/$name.git"
  if ! grep -q "GIT_REPOSITORY $url" "$file"; then
    echo "setup_splishsplash.sh: $3 no longer fetches $url; update this script" >&2; exit 1
  fi
  local tag use
  tag=$(grep -A1 "GIT_REPOSITORY $url" "$file" | sed -n 's/.*GIT_TAG *"\([0-9a-f]*\)".*/\1/p' | head -1)
  [ -n "$tag" ] || { echo "setup_splishsplash.sh: no GIT_TAG after $url in $3; update this script" >&2; exit 1; }
  if git -C "$dir" cat-file -e "$tag^{commit}" 2>/dev/null; then
    use=$tag
    echo "  $name: pinned $tag (present locally)"
  elif [ -n "${FALLBACK[$name]:-}" ]; then
    use=$(git -C "$dir" rev-parse --verify "${FALLBACK[$name]}^{commit}")
    echo "  $name: pinned $tag is NOT in $dir; using --fallback-tag $use instead"
  else
    echo "setup_splishsplash.sh: $name commit $tag (pinned in $3) is not in $dir: fetch a newer copy, or pass" \
      "--commit (an older SPlisHSPlasH) or --fallback-tag $name=COMMIT" >&2
    exit 1
  fi
  checkout_present "$dir" "$use" "$BUILD/deps/$name"
  sed -i -e "s|GIT_REPOSITORY $url|SOURCE_DIR \"$BUILD/deps/$name\"|" -e "/GIT_TAG \"$tag\"/d" "$file"
}
repoint CompactNSearch "$CNS" CMake/NeighborhoodSearch.cmake
repoint Discregrid "$DG" CMake/SetUpExternalProjects.cmake
repoint GenericParameters "$GP" CMake/SetUpExternalProjects.cmake
repoint PositionBasedDynamics "$PBD" CMake/SetUpExternalProjects.cmake

# Release; no Python bindings, no embedded Python; GLFW with its OSMesa/null platform so that no X11 development
# headers are needed (the simulator runs with --no-gui and never opens a window); nfd (file dialogs) finds no
# DBus/GTK and is left out by its own CMake. AVX, OpenMP and single precision stay at SPlisHSPlasH's defaults.
cmake -S "$SRC" -B "$BUILD/build" -DCMAKE_BUILD_TYPE=Release \
  -DUSE_PYTHON_BINDINGS=OFF -DUSE_EMBEDDED_PYTHON=OFF -DGLFW_USE_OSMESA=ON \
  -DGLFW_BUILD_EXAMPLES=OFF -DGLFW_BUILD_TESTS=OFF -DGLFW_BUILD_DOCS=OFF >"$BUILD/configure.log" 2>&1 ||
  { tail -30 "$BUILD/configure.log" >&2; exit 1; }
[ "$BUILD_IT" = 1 ] || { echo "configured in $BUILD/build (--no-build)"; exit 0; }
nice -n 10 cmake --build "$BUILD/build" --target SPHSimulator -j "$JOBS" >"$BUILD/build.log" 2>&1 ||
  { grep -E 'error|Error' "$BUILD/build.log" | head -30 >&2; tail -20 "$BUILD/build.log" >&2; exit 1; }
EXE="$SRC/bin/SPHSimulator"
[ -x "$EXE" ] || { echo "setup_splishsplash.sh: build finished but $EXE is missing" >&2; exit 1; }
echo "$EXE"
