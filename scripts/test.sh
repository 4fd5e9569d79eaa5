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
  scripts/setup.sh --build-dir build-sanitize --sanitize diefill unit_tests
  # A unit test whose executable is missing leaves only an unlabelled placeholder behind, which
  # `ctest -L unit` would skip without a word.
  not_built=$(cd build-sanitize && ctest -N | grep -oE '[A-Za-z0-9_]+_NOT_BUILT' | sed 's/_NOT_BUILT$//' |
              grep -Fxf unit_tests.txt || true)
  if [[ -n "$not_built" ]]; then
    echo "test.sh: unit tests not built in build-sanitize: $not_built" >&2
    exit 1
  fi
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  (cd build-sanitize && ctest --output-on-failure -L unit -j"$jobs")
elif [[ $# -gt 0 ]]; then
  echo "usage: scripts/test.sh [--sanitize]" >&2
  exit 2
else
  scripts/setup.sh
  (cd build && ctest --output-on-failure -j"$jobs")
fi
