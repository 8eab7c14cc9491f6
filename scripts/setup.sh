#!/usr/bin/env bash
# Installs every Debian package pathstream needs to build, test and benchmark.
# Idempotent: packages already present are skipped, so it is cheap to run again.
set -euo pipefail

packages=(
  # host toolchain and test framework
  build-essential cmake ninja-build pkg-config catch2
  # fuzz targets: clang with its libFuzzer runtime (the asan preset builds them with clang)
  clang libclang-rt-14-dev
  # the format check in the tests (scripts/check_format.sh) and the tidy preset (.clang-tidy)
  clang-format clang-tidy
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
  # pathstream serve: the HTTP server library; its page's tests drive Debian's Chromium
  libboost-dev chromium
  # many machines: the MQTT client library and the broker the tests start on loopback
  libmosquitto-dev mosquitto mosquitto-clients
  # the TLS broker test makes its own certificate authority
  openssl
)
# Node.js and npm for the browser tests, from Debian unless a node is installed already.
command -v node > /dev/null && command -v npm > /dev/null || packages+=(nodejs npm)

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

# The browser tests' one npm package (playwright-core: it drives the system's Chromium and
# never downloads a browser) at the version package-lock.json pins; installed again only when
# the lock file is newer than the last install.
browser_dir="$(cd "$(dirname "$0")/.." && pwd)/tests/browser"
if [ ! -f "$browser_dir/node_modules/.package-lock.json" ] ||
   [ "$browser_dir/package-lock.json" -nt "$browser_dir/node_modules/.package-lock.json" ]; then
  echo "setup: npm ci in tests/browser (playwright-core)"
  PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --prefix "$browser_dir" --no-audit --no-fund --loglevel=error
fi

# The real-kernel test VM (Debian's kernel, its modules and out-of-tree gpio-sim) has its own
# step: it unpacks kernel packages into a cache instead of installing them.
if [ -x "$(dirname "$0")/setup_vm.sh" ]; then
  "$(dirname "$0")/setup_vm.sh"
fi
