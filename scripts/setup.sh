#!/usr/bin/env bash
# Installs the Debian packages a job needs (only those missing), configures build/, builds into it
# and installs the extension folder build/KineticFriction (plugin, classes, help).
# Usage: scripts/setup.sh [--all] [extra cmake args...]
#   (none)  for the main job and the gallery: the packages they run with, and the extension folder
#           only (the plugin targets; a new build/ is configured without the tests and supernova)
#   --all   for the test command and the bench: every package (the checks', the cross check's)
#           and every target, the tests included
set -euo pipefail
cd "$(dirname "$0")/.."

all=false
if [ "${1:-}" = --all ]; then
  all=true
  shift
fi

# What the main job and the gallery run: the compiler and the plugin's libraries, SuperCollider,
# jackd and Xvfb (the live view's screenshot), the Debian python with numpy, matplotlib and soundfile.
MAIN_PACKAGES=(
  g++ cmake make ninja-build pkg-config
  supercollider-dev supercollider-server supercollider-language
  libhidapi-dev libusb-1.0-0-dev jackd2
  python3 python3-numpy python3-matplotlib python3-soundfile xvfb
)
# Everything: the tests, the checks and the bench need these too.
PACKAGES=(
  "${MAIN_PACKAGES[@]}"
  clang-format supercollider-supernova catch2 libsndfile1-dev
  python3-pytest python3-pyflakes python3-pil python3-pandas  # pandas: the tests read the study's BIDS tables
  python3-scipy python3-questplus psignifit  # the threshold fit and the study report's t test; their references
  rt-tests
  g++-mingw-w64-x86-64-posix wine64 libc++-dev libc++abi-dev  # scripts/check.sh cross
  clang libclang-rt-dev  # build-asan/ (check.sh installs them itself too; scripts/test.sh kills no apt-get)
  qemu-system-x86 linux-image-amd64 busybox-static udev systemd  # tests/kernel: the QEMU guest (python/kfharness/guest.py)
  libaio-dev  # the board gadget (device/board/gadget): FunctionFS through kernel AIO
)
source scripts/packages.sh
if $all; then
  kf_install_missing "${PACKAGES[@]}"
else
  kf_install_missing "${MAIN_PACKAGES[@]}"
fi

source scripts/env.sh  # the generator
# build/KineticFriction whatever an earlier configure cached (README's -DKF_EXTENSION_DIR=user).
configure=(-DCMAKE_BUILD_TYPE=Release -DKF_EXTENSION_DIR="$PWD/build/KineticFriction")
if $all; then
  configure+=(-DKF_TESTS=ON -DKF_SUPERNOVA=ON -DCMAKE_UNITY_BUILD=ON)  # unity: scripts/check.sh configure_and_build
elif [ ! -e build/CMakeCache.txt ]; then
  configure+=(-DKF_TESTS=OFF -DKF_SUPERNOVA=OFF)  # kept as they are in a build/ set up --all
fi
echo "== configuring and building (build/)"
cmake -S . -B build "${configure[@]}" "$@" > build-configure.log 2>&1 || { cat build-configure.log; exit 1; }
rm -f build-configure.log
if $all; then
  cmake --build build -j "$(nproc)"
else
  cmake --build build -j "$(nproc)" --target kf_extension
fi
cmake --install build > /dev/null
echo "== extension folder: $(pwd)/build/KineticFriction"
