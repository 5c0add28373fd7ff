#!/usr/bin/env bash
# Installs exactly what jsatlas needs from Debian 12 packages. Idempotent.
set -euo pipefail
# libjs-three: `jsatlas view` inlines three.js into its pages (a runtime need,
# and its tests run in the README's test command; chromium, for the browser
# test only, is in scripts/install-view-deps.sh).
# libsuitesparse-dev: CHOLMOD's supernodal Cholesky for the UV solves, with
# OpenBLAS (its OpenMP build) under it: 6-7x Eigen's SimplicialLDLT on a
# 250k-vertex chart (io/geometry/sparse_spd.h). The build falls back to Eigen
# without them (-DJSATLAS_CHOLMOD=OFF).
# libblas-dev: cblas.h and the link library of the GEMMs' BLAS backend
# (engine/gemm.h, `fit --gemm`); at run time libblas.so.3 is OpenBLAS's OpenMP
# build, by Debian's alternatives. Without it the build has Eigen alone.
pkgs=(cmake g++ make pkg-config libeigen3-dev libnanoflann-dev libtinyobjloader-dev catch2
      libcli11-dev nlohmann-json3-dev libstb-dev libjs-three libsuitesparse-dev
      libopenblas0-openmp libblas-dev)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#pkgs[@]} packages present"
  exit 0
fi
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}"
