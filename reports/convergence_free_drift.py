#!/usr/bin/env python3
"""Convergence of the free-drift case: position error after 48 h against the time step.

Runs `floedem run scenarios/free_drift.toml --set run.dt=DT` for a ladder of time steps,
takes a run at a much finer step as the reference, and reports the error of the final
position and the observed order log2(e(2 dt) / e(dt)). Writes CSV and PNG.

usage: convergence_free_drift.py FLOEDEM OUTDIR
"""
import csv
import math
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(__file__))), "python"))
import floedem  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENARIO = os.path.join(ROOT, "scenarios", "free_drift.toml")
DURATION = 172800.0
STEPS = [960.0, 480.0, 240.0, 120.0, 60.0, 30.0, 15.0]
REFERENCE = 1.875


def final_state(command, outdir, dt):
    out = os.path.join(outdir, f"free_drift_dt{dt:g}.h5")
    steps = int(round(DURATION / dt))
    subprocess.run([command, "run", SCENARIO, "--quiet", "--out", out, "--set", f"run.dt={dt!r}",
                    "--set", f"run.output_every={steps}"], check=True)
    with floedem.open(out) as f:
        return f.time[-1], f.position[-1, 0], f.angle[-1, 0]


def main():
    command, outdir = sys.argv[1], sys.argv[2]
    os.makedirs(outdir, exist_ok=True)
    _, x_ref, a_ref = final_state(command, outdir, REFERENCE)
    rows = []
    for dt in STEPS:
        t, x, a = final_state(command, outdir, dt)
        assert abs(t - DURATION) < 1e-6 * DURATION
        rows.append({"dt_s": dt, "position_error_m": float(np.linalg.norm(x - x_ref)),
                     "angle_error_rad": float(abs(a - a_ref))})
    for k in range(1, len(rows)):
        e0, e1 = rows[k - 1]["position_error_m"], rows[k]["position_error_m"]
        rows[k]["observed_order"] = math.log2(e0 / e1) if e1 > 0 else float("nan")
    rows[0]["observed_order"] = float("nan")
    with open(os.path.join(outdir, "convergence_free_drift.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    dts = [r["dt_s"] for r in rows]
    errs = [r["position_error_m"] for r in rows]
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.loglog(dts, errs, "o-", label="final position error")
    ax.loglog(dts, [errs[-1] * (d / dts[-1]) ** 2 for d in dts], "k--", lw=0.8, label="second order")
    ax.set_xlabel("time step (s)")
    ax.set_ylabel(f"error after 48 h (m), reference dt = {REFERENCE} s")
    ax.set_title("free drift: convergence")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "convergence_free_drift.png"), dpi=110)
    for r in rows:
        print(f"dt {r['dt_s']:7.1f} s  error {r['position_error_m']:.4e} m  order {r['observed_order']:.2f}")


if __name__ == "__main__":
    main()
