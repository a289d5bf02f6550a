#!/usr/bin/env bash
# Installs the Debian packages the build, tests and main job need (only what is missing), then
# configures and builds into build/ and installs the extension folder build/KineticFriction.
# Usage: scripts/setup.sh [extra cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  g++ cmake make pkg-config clang-format
  supercollider-dev supercollider-server supercollider-supernova supercollider-language
  libhidapi-dev libusb-1.0-0-dev catch2 libsndfile1-dev jackd2
  python3 python3-numpy python3-matplotlib python3-soundfile python3-pytest python3-pyflakes python3-pil xvfb
  rt-tests
  g++-mingw-w64-x86-64-posix wine64 libc++-dev libc++abi-dev  # scripts/check.sh cross
  qemu-system-x86 linux-image-amd64 busybox-static udev systemd  # tests/kernel: the QEMU guest (python/kfharness/guest.py)
  libaio-dev  # the board gadget (device/board/gadget): FunctionFS through kernel AIO
)
source scripts/packages.sh
kf_install_missing "${PACKAGES[@]}"

echo "== configuring and building (build/)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@" > build-configure.log 2>&1 || { cat build-configure.log; exit 1; }
rm -f build-configure.log
cmake --build build -j "$(nproc)"
cmake --install build > /dev/null
echo "== extension folder: $(pwd)/build/KineticFriction"
