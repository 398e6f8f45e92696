"""The channel the towed iceberg opens: snapshots of the native towing run, drawn from its frames,
and the film of the whole run (floedem animate)."""
import os
import shutil

import numpy as np

import floedem


def plan(ctx):
    return []


def draw_frame(ax, run, frame, speed_scale):
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import LinearSegmentedColormap
    polys = run.polygons(frame)
    v = np.hypot(*run.velocity[frame].T)
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
    with floedem.open(run.out) as f:
        t = f.time
        fa = f.provenance["field"]
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
    # The film of the whole run: floedem animate's, coloured by speed as the snapshots are.
    fails = []
    if shutil.which("ffmpeg"):
        from floedem.animate import animate
        animate(run.out, os.path.join(ctx.fig, "channel.mp4"), colour="speed", fps=12, dpi=90, progress=False)
        md += ["The whole run as a film (`floedem animate`): [fig/channel.mp4](fig/channel.mp4).", ""]
    else:
        fails.append("channel: no film: ffmpeg is missing (scripts/setup.sh installs it)")
    return md, fails
