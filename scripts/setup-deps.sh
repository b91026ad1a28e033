#!/usr/bin/env bash
# Installs what sphc needs to build and test, from Debian 12's packages. Run as root (or
# with sudo). Safe to run again: apt skips what is already installed.
set -euo pipefail

PACKAGES=(
  # toolchain
  cmake g++ make
  # LLVM/Clang 14: support library, diagnostics, FileCheck and lit; libTooling for bodies
  llvm-14-dev llvm-14-tools libclang-14-dev libclang-cpp14-dev clang-14
  # runtime: HDF5 output, fmt; Eigen for the solid-mechanics schemes to come
  libhdf5-dev hdf5-tools libfmt-dev libeigen3-dev
  # tests: GoogleTest; Python with numpy and h5py for the validation checks
  libgtest-dev googletest python3 python3-numpy python3-h5py
  # the validation checks' plots (PNG, matplotlib's Agg backend; a check without it still runs)
  python3-matplotlib
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers clinfo  # --backend=opencl (PoCL: CPU)
  # sphc --mpi: Open MPI, Zoltan (domain decomposition), parallel HDF5 (optional: the build
  # without them has no --mpi and runs every other test)
  libopenmpi-dev openmpi-bin libtrilinos-zoltan-dev libhdf5-openmpi-dev
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-deps: all packages present"
  exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; fi
echo "setup-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
# libhdf5-openmpi-dev makes pkg-config's hdf5.pc the MPI one; the serial solvers and the
# runtime link the serial library (CMake's FindHDF5 through h5cc), so keep pkg-config saying
# the same (--mpi solvers link the parallel library by its path, runtime/CMakeLists.txt).
if [ -e /usr/lib/x86_64-linux-gnu/pkgconfig/hdf5-serial.pc ]; then
  $SUDO update-alternatives --quiet --set hdf5.pc /usr/lib/x86_64-linux-gnu/pkgconfig/hdf5-serial.pc || true
fi
