#!/usr/bin/env bash
# The main job: installs what is missing, builds the floedem command, runs the default scenario
# (floes carried onto a caisson) on every engine, printing each run's summary, and writes the
# quick cross-engine report (`floedem report --quick`: about 2 minutes on 2 cores). Exit 5 when
# the report finds engines disagreeing beyond its stated tolerances (the report is written all
# the same, the disagreements listed first). Everything goes to results/. The full report
# (about 50 minutes) is `build/floedem report --out results/report-full`.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" floedem
build="${FLOEDEM_BUILD_DIR:-$root/build}"
results="$root/results"
mkdir -p "$results"
for engine in $("$build/floedem" engines | cut -f1); do
  "$build/floedem" run "$root/scenarios/default.toml" --engine "$engine" --out "$results/default.$engine.h5"
done
status=0
"$build/floedem" report --quick --out "$results/report" || status=$?
cat <<MSG

main: done (exit $status). Where to look:
  $results/report/REPORT.md        the quick cross-engine report, figures in $results/report/fig/
  $results/default.ENGINE.h5       the default scenario on each engine (layout: docs/output.md)
  reports/latest/REPORT.md         the committed full report
MSG
if [[ $status -eq 5 ]]; then
  echo "main: the report lists engines that disagree beyond its tolerances (exit 5)" >&2
fi
exit $status
