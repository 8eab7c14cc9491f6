#!/usr/bin/env bash
# Builds everything and runs the whole test suite: the release build with the Cortex-M
# images under qemu, then the AddressSanitizer + UBSan build of the host tests.
#   scripts/test.sh            # what CI runs
#   scripts/test.sh --quick    # release build only, skip the sanitizer build
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cmake --workflow --preset default
if [ "${1:-}" != "--quick" ]; then
  cmake --workflow --preset asan
fi
