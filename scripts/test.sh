#!/usr/bin/env bash
# The test command (README): sets up and builds everything (Release), then runs every test.
#   scripts/test.sh              every test of the Release build
#   scripts/test.sh --sanitize   the fast unit tests again, built with AddressSanitizer and
#                                UndefinedBehaviorSanitizer in build-sanitize/ (CI runs both)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
jobs=$(nproc 2>/dev/null || echo 2)

if [[ "${1:-}" == "--sanitize" ]]; then
  # The sanitizer tree takes the CGAL wrappers from the Release tree through ccache
  # (cmake/Warnings.cmake): build the Release tree first.
  scripts/setup.sh
  scripts/setup.sh --build-dir build-sanitize --sanitize diefill test_core test_mesh test_cli
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  (cd build-sanitize && ctest --output-on-failure -L unit -j"$jobs")
elif [[ $# -gt 0 ]]; then
  echo "usage: scripts/test.sh [--sanitize]" >&2
  exit 2
else
  scripts/setup.sh
  (cd build && ctest --output-on-failure -j"$jobs")
fi
