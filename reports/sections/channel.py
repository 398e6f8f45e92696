"""The channel the towed iceberg opens: snapshots of the native towing run (and an animation
when ffmpeg is present), drawn from its frames."""
import os
import shutil

import h5py
import numpy as np

from floedem_h5 import body_polygons


def plan(ctx):
    return []


def draw_frame(ax, f, frame, speed_scale):
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import LinearSegmentedColormap
    polys = body_polygons(f, frame)
    v = np.hypot(*f["bodies/velocity"][frame].T)
    ice = LinearSegmentedColormap.from_list("ice", ["#deebf7", "#6baed6", "#08306b", "#d7301f"])
    floes = PolyCollection(polys[1:], array=v[1:], cmap=ice, edgecolors="#4d4d4d", linewidths=0.15)
    floes.set_clim(0.0, speed_scale)
    ax.add_collection(floes)
    ax.add_collection(PolyCollection(polys[:1], facecolors="0.3", edgecolors="k", linewidths=0.6))
    return floes


def write(ctx):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    run = ctx.run("towing_native")
    md = ["## The channel", "",
          f"The native towing run (`{os.path.relpath(run.out, ctx.out)}`) at four times; floes coloured by speed. The "
          "iceberg pushes a collar of ice ahead and leaves a channel of open water that the floes slowly close.", "",
          "![channel](fig/channel.png)", ""]
    with h5py.File(run.out, "r") as f:
        t = f["time"][:]
        fa = f["field"].attrs
        x0, y0, w, h = fa["origin_x"], fa["origin_y"], fa["width"], fa["height"]
        picks = np.linspace(0, len(t) - 1, 4).astype(int)
        fig, axes = plt.subplots(len(picks), 1, figsize=(10, len(picks) * (8.5 * h / w + 0.45) + 0.5),
                                 constrained_layout=True)
        for ax, p in zip(axes, picks):
            floes = draw_frame(ax, f, p, 1.0)
            ax.set_xlim(x0, x0 + w)
            ax.set_ylim(y0, y0 + h)
            ax.set_aspect("equal")
            ax.set_title(f"t = {t[p]:.0f} s", fontsize=9)
        axes[-1].set_xlabel("x (m)")
        fig.colorbar(floes, ax=axes, label="floe speed (m/s)", shrink=0.5)
        fig.savefig(os.path.join(ctx.fig, "channel.png"), dpi=120)
        plt.close(fig)
        if shutil.which("ffmpeg"):
            from matplotlib.animation import FFMpegWriter
            fig, ax = plt.subplots(figsize=(10, 10 * h / w + 0.6))
            writer = FFMpegWriter(fps=12)
            with writer.saving(fig, os.path.join(ctx.fig, "channel.mp4"), dpi=90):
                for p in range(len(t)):
                    ax.clear()
                    draw_frame(ax, f, p, 1.0)
                    ax.set_xlim(x0, x0 + w)
                    ax.set_ylim(y0, y0 + h)
                    ax.set_aspect("equal")
                    ax.set_title(f"t = {t[p]:.0f} s")
                    writer.grab_frame()
            plt.close(fig)
            md += ["An animation of the whole run: [fig/channel.mp4](fig/channel.mp4).", ""]
        else:
            md += ["(No animation: ffmpeg is not installed.)", ""]
    return md, []
