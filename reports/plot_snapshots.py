#!/usr/bin/env python3
"""Snapshots of a floedem run: the bodies' polygons at a few frames, from the HDF5 output.

usage: plot_snapshots.py RESULT.h5 OUT.png [--frames N]
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(__file__))), "python"))
import floedem  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("result")
    ap.add_argument("out")
    ap.add_argument("--frames", type=int, default=4)
    a = ap.parse_args()
    try:
        f = floedem.open(a.result)
    except floedem.FileError as e:
        raise SystemExit(f"plot_snapshots: {e}")
    with f:
        t = f.time
        fixed = f.bodies.fixed.astype(bool)
        picks = np.linspace(0, len(t) - 1, a.frames).astype(int)
        fig, axes = plt.subplots(1, len(picks), figsize=(4 * len(picks), 4), squeeze=False)
        all_pts = np.concatenate([f.world_vertices(p) for p in picks])
        lo, hi = all_pts.min(axis=0), all_pts.max(axis=0)
        for ax, p in zip(axes[0], picks):
            polys = f.polygons(p)
            colours = ["0.35" if fx else "#9ecae1" for fx in fixed]
            ax.add_collection(PolyCollection(polys, facecolors=colours, edgecolors="k", linewidths=0.4))
            ax.set_xlim(lo[0], hi[0])
            ax.set_ylim(lo[1], hi[1])
            ax.set_aspect("equal")
            ax.set_title(f"t = {t[p]:.1f} s")
            ax.set_xlabel("x (m)")
        axes[0][0].set_ylabel("y (m)")
        fig.suptitle(f"{f.attrs.get('scenario_path', a.result)} on {f.engine}")
        fig.tight_layout()
        fig.savefig(a.out, dpi=110)


if __name__ == "__main__":
    main()
