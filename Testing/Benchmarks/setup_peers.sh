#!/bin/sh
# Set-up for the real-scan benchmark (Testing/Benchmarks/bench_scans.py, issue 23): installs the peers from
# Debian 12 packages and builds the small CGAL driver. Run it once, as root (or through sudo), before the
# benchmark; ./run.sh test never calls it and no test needs it.
#
#   sh Testing/Benchmarks/setup_peers.sh [BUILD_DIR]
#
# Installs: pcl-tools (pcl_normal_estimation, pcl_poisson_reconstruction, pcl_xyz2pcd), libcgal-dev (CGAL 5.5,
# header-only) with libeigen3-dev, meshlab 2020.09 (meshlabserver) with xvfb (xvfb-run: meshlabserver needs a
# display), and the compiler and CMake. Then configures and builds peers/cgal_peer.cpp into
# BUILD_DIR/cgal_peer (default: <source>/build/scans-peers) with its own CMakeLists (not the project's CMake).
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
SOURCE=$(cd "$HERE/../.." && pwd)
BUILD=${1:-$SOURCE/build/scans-peers}

SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO=sudo; fi
PACKAGES="pcl-tools libcgal-dev libeigen3-dev libgmp-dev libmpfr-dev libtbb-dev meshlab xvfb xauth g++ cmake make"
missing=""
for p in $PACKAGES; do
    dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
done
if [ -n "$missing" ]; then
    echo "setup_peers: installing$missing"
    $SUDO apt-get update
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends $missing
fi

echo "setup_peers: building the CGAL driver in $BUILD"
cmake -S "$HERE/peers" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD" -j2
echo "setup_peers: versions"
dpkg-query -W -f '  ${Package} ${Version}\n' pcl-tools libcgal-dev meshlab
echo "setup_peers: done; the benchmark finds the driver at $BUILD/cgal_peer (or set SCANS_CGAL_PEER)"
