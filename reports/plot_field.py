#!/usr/bin/env python3
"""A broken-ice field drawn from its field file: OUT.png (floes filled, domain outline,
keep-out zones hatched) and OUT-sizes.png (log-log survival of the floe sizes with the target
power law and the maximum-likelihood fit written by the generator).

usage: plot_field.py FIELD.h5 --out OUT.png
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.patches import Polygon, Rectangle  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(__file__))), "python"))
import floedem  # noqa: E402
from floedem.stats import equal_area_diameters, truncated_power_law_survival  # noqa: E402


def draw_field(f, out, title=None):
    """f: a floedem.Run with /field (a field file, or a run with a generated field)."""
    g = f.provenance["field"]
    x0, y0, w, h = g["origin_x"], g["origin_y"], g["width"], g["height"]
    a, b = f.field_range()
    bodies = f.polygons(0)
    floes = bodies[a:b]
    size = 9.0
    fig, ax = plt.subplots(figsize=(size, size * h / w + 0.8))
    ax.add_collection(PolyCollection(floes, facecolors="#c6dbef", edgecolors="#08306b",
                                     linewidths=0.3 if len(floes) < 5000 else 0.08))
    others = bodies[:a] + bodies[b:]
    if others:
        ax.add_collection(PolyCollection(others, facecolors="0.35", edgecolors="k", linewidths=0.5))
    for zone in f.keep_out():
        ax.add_patch(Polygon(zone, closed=True, fill=False, hatch="//", edgecolor="0.4", linewidth=0.8))
    ax.add_patch(Rectangle((x0, y0), w, h, fill=False, edgecolor="k", linewidth=1.0))
    ax.set_xlim(x0 - 0.02 * w, x0 + 1.02 * w)
    ax.set_ylim(y0 - 0.02 * h, y0 + 1.02 * h)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title or f"{len(floes)} floes, concentration {g['concentration_achieved']:.4f} "
                          f"(target {g['concentration']:.3f}), seed {g['seed']}")
    fig.tight_layout()
    fig.savefig(out, dpi=110 if len(floes) < 20000 else 250)
    plt.close(fig)


def draw_sizes(f, out):
    g = f.provenance["field"]
    a, b = f.field_range()
    d = np.sort(equal_area_diameters(f.bodies.area)[a:b])
    n = len(d)
    survival = 1.0 - (np.arange(n) + 0.5) / n  # fraction larger than d (midpoint plotting positions)
    grid = np.geomspace(g["d_min"], g["d_max"], 200)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.loglog(d, survival, ".", markersize=2, color="#08519c", label=f"floes (N = {n})")
    ax.loglog(grid, truncated_power_law_survival(grid, g["alpha"], g["d_min"], g["d_max"]), "k-", linewidth=1,
              label=f"target, alpha = {g['alpha']:.3f}")
    ax.loglog(grid, truncated_power_law_survival(grid, g["alpha_fitted"], g["d_min"], g["d_max"]), "r--",
              linewidth=1, label=f"ML fit, alpha = {g['alpha_fitted']:.4f} +- {g['alpha_fitted_stderr']:.4f}")
    ax.set_xlabel("equal-area diameter d (m)")
    ax.set_ylabel("fraction of floes larger than d")
    ax.set_ylim(0.5 / n, 1.5)
    ax.legend(loc="lower left")
    ax.grid(True, which="both", linewidth=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=130)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("field")
    ap.add_argument("--out", required=True, help="PNG of the field; the sizes go to OUT-sizes.png")
    a = ap.parse_args()
    try:
        f = floedem.open(a.field)
    except floedem.FileError as e:
        raise SystemExit(f"plot_field: {e}")
    with f:
        if "field" not in f.provenance:
            raise SystemExit(f"{a.field}: no /field group: not a field file (floedem field writes one)")
        draw_field(f, a.out)
        stem, ext = os.path.splitext(a.out)
        draw_sizes(f, f"{stem}-sizes{ext or '.png'}")


if __name__ == "__main__":
    main()
