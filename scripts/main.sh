#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the default scenario on every
# engine (native, box2d, bullet, ode), printing each run's summary. Outputs go to results/.
# (The cross-engine report, `floedem report`, will end this job once it exists.)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
build="${FLOEDEM_BUILD_DIR:-$root/build}"
mkdir -p "$root/results"
for engine in $("$build/floedem" engines | cut -f1); do
  "$build/floedem" run "$root/scenarios/default.toml" --engine "$engine" --out "$root/results/default.$engine.h5"
done
