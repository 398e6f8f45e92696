#!/usr/bin/env bash
# The test command: installs what is missing, builds, and runs every test with ctest.
#   scripts/test.sh              Release build in ./build, then the cross-engine check
#                                (`floedem report --quick`, 3 to 4 minutes on 2 cores)
#   scripts/test.sh --sanitize   the same suite built with AddressSanitizer and
#                                UndefinedBehaviorSanitizer in ./build-sanitize; any report fails
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/setup.sh"
jobs="$(nproc 2>/dev/null || echo 2)"
if [[ "${1:-}" == "--sanitize" ]]; then
  build="${FLOEDEM_BUILD_DIR:-$root/build-sanitize}"
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFLOEDEM_SANITIZE=ON >/dev/null
  cmake --build "$build" -j "$jobs"
  export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:${ASAN_OPTIONS:-}"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
else
  bash "$root/scripts/build.sh"
  build="${FLOEDEM_BUILD_DIR:-$root/build}"
fi
cd "$build"
ctest --output-on-failure -j "$jobs"
if [[ "${1:-}" != "--sanitize" ]]; then
  # The engines against each other and native against the closed forms, on small cases:
  # fails (exit 5, each disagreement printed) beyond the tolerances the report states.
  "$build/floedem" report --quick --out "$build/report-quick"
fi
