#!/usr/bin/env bash
# Installs every Debian package pathstream needs to build, test and benchmark.
# Idempotent: packages already present are skipped, so it is cheap to run again.
set -euo pipefail

packages=(
  # host toolchain and test framework
  build-essential cmake ninja-build pkg-config catch2
  # fuzz targets: clang with its libFuzzer runtime (scripts/test.sh preset fuzz)
  clang libclang-rt-14-dev
  # host libraries (CLI, data, math baseline for the bench)
  libcli11-dev nlohmann-json3-dev libeigen3-dev libpugixml-dev
  # Cortex-M proof: cross toolchain, C++ headers, emulator with TCG plugin support
  gcc-arm-none-eabi binutils-arm-none-eabi libstdc++-arm-none-eabi-newlib
  libnewlib-arm-none-eabi qemu-system-arm
  # plots: SVG to PNG
  librsvg2-bin
  # event stream tests: JSON Schema validation (tests/cli/events_test.sh)
  python3-jsonschema
  # Modbus TCP/RTU (libmodbus) and an independent Modbus master for interoperability tests
  libmodbus-dev mbpoll
  # CAN and GPIO: SocketCAN tools and libgpiod 1.6 with its command-line tools
  can-utils libgpiod-dev gpiod
  # real-kernel test VM (SocketCAN vcan, gpio-sim): emulator, initramfs tools
  qemu-system-x86 busybox-static cpio
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
else
  echo "setup: installing ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then sudo=sudo; else sudo=; fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -q
  $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The real-kernel test VM (Debian's kernel, its modules and out-of-tree gpio-sim) has its own
# step: it unpacks kernel packages into a cache instead of installing them.
if [ -x "$(dirname "$0")/setup_vm.sh" ]; then
  "$(dirname "$0")/setup_vm.sh"
fi
