#!/usr/bin/env bash
# The main job: installs what is missing, builds, runs the default scenario on the
# native engine and prints its summary.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
build="${FLOEDEM_BUILD_DIR:-$root/build}"
mkdir -p "$root/results"
"$build/floedem" run "$root/scenarios/default.toml" --engine native --out "$root/results/default.native.h5"
