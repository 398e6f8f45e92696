#!/usr/bin/env bash
# Configures and builds floedem (Release) in ./build. Used by main.sh and test.sh.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${FLOEDEM_BUILD_DIR:-$root/build}"
jobs="$(nproc 2>/dev/null || echo 2)"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE="${FLOEDEM_BUILD_TYPE:-Release}" >/dev/null
cmake --build "$build" -j "$jobs"
