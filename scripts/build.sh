#!/usr/bin/env bash
# Configures and builds jsatlas (Release, -O3, OpenMP, -march=native).
# Extra arguments go to CMake, e.g. scripts/build.sh -DJSATLAS_NATIVE=OFF for a
# portable binary. BUILD_DIR picks the build directory (default: build).
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${BUILD_DIR:-build}"
cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release "$@" > /dev/null
cmake --build "$dir" -j "$(nproc)"
echo "build: binaries in $dir/ (CLI: $dir/jsatlas)"
