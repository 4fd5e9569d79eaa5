#!/usr/bin/env bash
# Installs the Debian 12 packages diefill needs (non-interactive, idempotent) and builds it.
#   scripts/setup.sh [--build-dir DIR] [--sanitize] [TARGET...]
# With no TARGET every target is built. Re-running it does only what is missing.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

build_dir=build
# Warnings are errors: the toolchain is Debian 12's g++, which setup installs, so a warning is ours.
cmake_args=(-DCMAKE_BUILD_TYPE=Release -DDIEFILL_WERROR=ON)
targets=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build-dir) build_dir="$2"; shift 2 ;;
    # Release flags, to which our own targets add -O0 and the sanitizers (cmake/Warnings.cmake).
    --sanitize) cmake_args=(-DCMAKE_BUILD_TYPE=Release -DDIEFILL_WERROR=ON -DDIEFILL_SANITIZE=ON); shift ;;
    *) targets+=("$1"); shift ;;
  esac
done

packages=(
  cmake g++ make ccache pkg-config
  libcgal-dev libassimp-dev libembree-dev libeigen3-dev libopenvdb-dev libtbb-dev libgtest-dev
  libboost-iostreams-dev                    # OpenVDB needs it; its package does not pull it in
  libtomlplusplus-dev nlohmann-json3-dev libfmt-dev libcli11-dev zlib1g-dev
  python3-openvdb python3-numpy libopenvdb-tools   # independent readers of our outputs in the tests:
  python3-vtk9 python3-meshio                     # OpenVDB, VTK and meshio, not our code
  python3-matplotlib                        # the pictures of reports and studies
  libopenmpi-dev openmpi-bin                # the DEM split over MPI ranks (dem/mpi_exchange.hpp)
  libtrilinos-zoltan-dev                    # the partitioner benchmark's reference (bench/partition.cpp)
  calculix-ccx                              # the FEM hand-off's worked compaction example and its tests
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [[ ${#missing[@]} -gt 0 ]]; then
  echo "setup: installing ${missing[*]}" >&2
  sudo=()
  if [[ $(id -u) -ne 0 ]]; then
    if command -v sudo >/dev/null; then sudo=(sudo); else
      echo "setup: these Debian packages are missing and this user cannot install them: ${missing[*]}" >&2
      echo "setup: run scripts/setup.sh as root once, or install them with apt-get" >&2
      exit 1
    fi
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if [[ ! -f "$build_dir/CMakeCache.txt" ]]; then
  cmake -S . -B "$build_dir" "${cmake_args[@]}" >/dev/null
fi
jobs=$(nproc 2>/dev/null || echo 2)
if [[ ${#targets[@]} -gt 0 ]]; then
  cmake --build "$build_dir" -j"$jobs" --target "${targets[@]}"
else
  cmake --build "$build_dir" -j"$jobs"
fi
