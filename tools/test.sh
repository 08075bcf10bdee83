#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to a green suite: installs refray's
# packages, builds the `ci` preset (optimised, warnings as errors) and runs every test.
#   bash tools/test.sh            the whole suite (what CI runs), then each libFuzzer program for
#                                 REFRAY_FUZZ_SECONDS (default 60) from its corpus (tools/fuzz.sh)
#   bash tools/test.sh --asan     the same suite under AddressSanitizer + UBSan (no fuzzing)
set -euo pipefail
cd "$(dirname "$0")/.."

preset=ci
if [ "${1:-}" = "--asan" ]; then preset=asan-ubsan; fi

bash tools/setup.sh
cmake --preset "$preset"
cmake --build --preset "$preset" -j "$(nproc)"
ctest --preset "$preset" -j "$(nproc)"
if [ "$preset" = ci ]; then bash tools/fuzz.sh "${REFRAY_FUZZ_SECONDS:-60}"; fi
