#!/usr/bin/env bash
# The test command (README, CI): sets up and builds everything, runs every test of the Release
# build, then the fast unit tests again under AddressSanitizer and UndefinedBehaviorSanitizer.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

scripts/setup.sh
(cd build && ctest --output-on-failure -j"$(nproc 2>/dev/null || echo 2)")

scripts/setup.sh --build-dir build-sanitize --sanitize diefill test_core test_mesh test_cli
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
(cd build-sanitize && ctest --output-on-failure -L unit -j"$(nproc 2>/dev/null || echo 2)")
