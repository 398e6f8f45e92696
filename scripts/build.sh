#!/usr/bin/env bash
# Configures and builds floedem (Release) in ./build: every target, or those named
# (`scripts/build.sh floedem`: the command alone). Used by main.sh and test.sh.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${FLOEDEM_BUILD_DIR:-$root/build}"
jobs="$(nproc 2>/dev/null || echo 2)"
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE="${FLOEDEM_BUILD_TYPE:-Release}" >/dev/null
cmake --build "$build" -j "$jobs" "${targets[@]}"
