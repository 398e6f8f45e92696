#!/usr/bin/env python3
"""Native's step where the ice jams against its step on the same scene before it does: each
scene timed twice by `floedem bench --stages`, one thread, over its first minutes (the pack
still loose) and over the end of the run (jammed); one CSV row a timing, per machine.

A field benchmark has no jam: its floes are all of one kind and the pack never closes about a
heavy body. The scenes here are where a drift or towing study spends its time: light floes
pressed against an iceberg (the heavy-light islands of docs/model.md, section 3), a pack
compacted by the wind against a coast, and a towed iceberg in close pack. docs/performance.md
shows the rows (reports/performance_doc.py).

usage: jam.py --floedem FLOEDEM --out CSV [--only LABEL ...]
"""
import argparse
import csv
import io
import os
import subprocess
import sys

import sections  # noqa: F401  (puts the floedem package of this checkout on the path)
from floedem.launch import csv_text, write_atomic

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# label, scenario, overrides, seconds of model time the start is timed over (the run cut to
# that length), the jam's window (the end of the whole run).
SCENES = [
    ("Barents drift (iceberg in 1 900 floes)", "scenarios/observations/wind_drift_barents.toml", [], 1200.0, 7200.0),
    ("Gulf compaction (wind against a coast)", "scenarios/observations/compaction_gulf.toml", [], 1200.0, 3600.0),
    ("towing at 70 % ice", "scenarios/towing_paper.toml", ["field.concentration=0.7"], 300.0, 300.0),
]
FIELDS = ["label", "phase", "window_s"]


def bench(floedem, scenario, sets, window, duration=None):
    cmd = [floedem, "bench", os.path.join(ROOT, scenario), "-q", "--stages", "--window", repr(window)]
    for s in sets + ([f"run.duration={duration!r}"] if duration else []):
        cmd += ["--set", s]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True,
                         env=dict(os.environ, FLOEDEM_THREADS="1")).stdout
    return list(csv.DictReader(io.StringIO(out)))[-1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--floedem", required=True)
    ap.add_argument("--out", required=True, help="CSV to write (replaced whole, once every run is made)")
    ap.add_argument("--only", nargs="*", help="labels' first words (Barents, Gulf, towing)")
    args = ap.parse_args()
    rows = []
    for label, scenario, sets, start, window in SCENES:
        if args.only and label.split()[0] not in args.only:
            continue
        for phase, row in (("start", bench(args.floedem, scenario, sets, start, duration=start)),
                           ("jam", bench(args.floedem, scenario, sets, window))):
            print(f"{label}, {phase}: mean {float(row['mean_ms']):.3g} ms a step", file=sys.stderr)
            rows.append({"label": label, "phase": phase, "window_s": window if phase == "jam" else start, **row})
    write_atomic(args.out, csv_text(FIELDS + [k for k in rows[0] if k not in FIELDS], rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
