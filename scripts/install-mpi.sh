#!/usr/bin/env bash
# Installs OpenMPI from Debian 12 for the optional data-parallel fit
# (docs/mpi.md): with it CMake builds `mpirun -np P jsatlas fit` (JSATLAS_MPI=AUTO)
# and CTest runs the mpi_* tests. jsatlas builds and works without it.
# Idempotent.
set -euo pipefail
pkgs=(libopenmpi-dev openmpi-bin)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-mpi: OpenMPI present"
  exit 0
fi
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
echo "install-mpi: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}"
