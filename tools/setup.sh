#!/usr/bin/env bash
# Installs the Debian packages loam needs (only those missing), then configures and builds
# incrementally into build/. Used by both README commands and by .ci/run.
#   --mpi   also OpenMPI (openmpi-bin, libopenmpi-dev) and the MPI parts (-DLOAM_MPI=ON:
#           libloam_mpi and the mpirun tests; docs/parallel.md). The serial loam is the same.
set -euo pipefail
cd "$(dirname "$0")/.."

MPI=OFF
for arg in "$@"; do
  case "$arg" in
    --mpi) MPI=ON ;;
    *) echo "loam setup: unknown option '$arg' (known: --mpi)" >&2; exit 2 ;;
  esac
done

PACKAGES=(g++ make cmake pkg-config git
          libeigen3-dev libyaml-cpp-dev libhdf5-dev libspdlog-dev catch2
          libcli11-dev nlohmann-json3-dev
          python3 python3-numpy python3-matplotlib python3-h5py)
if [ "$MPI" = ON ]; then PACKAGES+=(openmpi-bin libopenmpi-dev); fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "loam setup: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

BUILD_DIR=${LOAM_BUILD_DIR:-build}
if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
  cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DLOAM_MPI=$MPI
elif [ "$MPI" = ON ]; then
  cmake -S . -B "$BUILD_DIR" -DLOAM_MPI=ON >/dev/null  # an existing build gains the MPI parts
fi
cmake --build "$BUILD_DIR" -j "$(nproc)"
