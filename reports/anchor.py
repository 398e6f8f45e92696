#!/usr/bin/env python3
"""Side-by-side speed against an anchor built apart from floedem (Box2D v3): native and the
anchor on the same field benchmark, one thread, alternating, in rounds; one CSV row a run.

The anchor is not part of floedem or of its report (it is not packaged by Debian): its runner
is given on the command line, a script that takes FLOEDEM SCENARIO [SUBSTEPS] and prints a CSV
whose last line's fields `label`, `median_ms`, `touch_mean` (the fraction of bodies in contact)
and `min_separation_m` (the deepest overlap, negative) it reads. Native runs `floedem bench
--window 100` on the same scenario twice a round: with its defaults, and with the equal
iterations the report's speed section gives every engine (10 plain sweeps, colour order).

usage: anchor.py --anchor RUNNER --floedem FLOEDEM --out CSV [--sizes 1k 16k] [--rounds 2]
"""
import argparse
import csv
import io
import os
import subprocess
import sys

from sections.speed import EQUAL_ITERATIONS, equal
from floedem.launch import csv_text, write_atomic  # noqa: E402  (on the path through sections)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIELDS = ["host", "cpu", "floedem_version", "scenario", "round", "engine", "settings", "median_ms",
          "contact_fraction", "max_penetration_m"]


def native(floedem, scenario, sets):
    cmd = [floedem, "bench", scenario, "-q", "--window", "100"]
    for s in sets:
        cmd += ["--set", s]
    # One thread, as the anchor runs (floedem's pool defaults to every CPU the process may use).
    out = subprocess.run(cmd, capture_output=True, text=True, check=True,
                         env=dict(os.environ, FLOEDEM_THREADS="1")).stdout
    return list(csv.DictReader(io.StringIO(out)))[-1]


def anchor(runner, floedem, scenario, substeps):
    out = subprocess.run(["bash", runner, floedem, scenario, str(substeps)], capture_output=True, text=True,
                         check=True).stdout
    lines = [line for line in out.splitlines() if line.strip()]
    header = next(line for line in lines if line.startswith("label,"))
    return list(csv.DictReader(io.StringIO(header + "\n" + lines[-1])))[-1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--anchor", required=True, help="the anchor's runner script")
    ap.add_argument("--floedem", required=True)
    ap.add_argument("--out", required=True, help="CSV to write (replaced whole, once every run is made)")
    ap.add_argument("--sizes", nargs="+", default=["1k", "16k"])
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--substeps", type=int, default=4)
    a = ap.parse_args()
    equal_sets = equal("native")
    rows = []
    for size in a.sizes:
        scenario = os.path.join(ROOT, "scenarios", "bench", f"field_wall_{size}.toml")
        for r in range(1, a.rounds + 1):
            # Native first in odd rounds, the anchor first in even ones: each pair adjacent in time.
            order = ["native", "anchor"] if r % 2 else ["anchor", "native"]
            for who in order:
                if who == "native":
                    for label, sets in (("defaults", []), (f"{EQUAL_ITERATIONS} plain sweeps, colour order", equal_sets)):
                        row = native(a.floedem, scenario, sets)
                        rows.append(dict(host=row["host"], cpu=row["cpu"], floedem_version=row["floedem_version"],
                                         scenario=os.path.basename(scenario), round=r, engine="native", settings=label,
                                         median_ms=row["median_ms"], contact_fraction=row["contact_fraction"],
                                         max_penetration_m=row["max_penetration_m"]))
                        print(rows[-1], file=sys.stderr)
                else:
                    row = anchor(a.anchor, a.floedem, scenario, a.substeps)
                    rows.append(dict(host="", cpu="", floedem_version="", scenario=os.path.basename(scenario), round=r,
                                     engine="box2d v3", settings=f"{a.substeps} substeps",
                                     median_ms=row["median_ms"], contact_fraction=row["touch_mean"],
                                     max_penetration_m=f"{max(0.0, -float(row['min_separation_m'])):g}"))
                    print(rows[-1], file=sys.stderr)
    # The anchor's rows take the machine of the native rows (the same machine, one after the other).
    machine = next(x for x in rows if x["engine"] == "native")
    for row in rows:
        row["host"], row["cpu"] = machine["host"], machine["cpu"]
    write_atomic(a.out, csv_text(FIELDS, rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
