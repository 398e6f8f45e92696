"""A run as a film (matplotlib, written by ffmpeg): the bodies at every frame, floes coloured by
their speed or by the contact force they carry, fixed bodies and the towed one in grey, the
tug and its rope (rope towing) or the path behind the towed body (velocity towing), and the
time."""
import os
import sys
import time as clock
import tomllib

import numpy as np

from .run import FileError, Run


def contact_force(run):
    """[T, N] N: each body's mean contact force over the interval that ends at each frame, the
    sum over its contact rows of |impulse| / dt, over the steps of the interval. It holds the rows
    `[output] contacts` recorded: all, or collisions alone."""
    c = run.contacts
    if c is None or len(c) == 0:
        recorded = c.attrs.get("recorded", "none") if c is not None else "none"
        raise FileError(f"{run.path}: /contacts: holds no rows (the scenario's [output] contacts = "
                        f"\"{recorded}\"); colour by speed instead")
    dt = float(run.attrs["dt"])
    t = run.time
    frame = np.clip(np.searchsorted(t, c.time - 0.5 * dt), 0, len(t) - 1)  # the frame whose interval holds the step
    magnitude = np.hypot(c.normal_impulse, c.tangent_impulse) / dt
    force = np.zeros((len(t), len(run.bodies)))
    np.add.at(force, (frame, c.body_a.astype(int)), magnitude)
    np.add.at(force, (frame, c.body_b.astype(int)), magnitude)
    steps = np.maximum(np.round(np.diff(t, prepend=t[0]) / dt), 1.0)
    return force / steps[:, None]


def _rope(run):
    """The rope's attachment in the towed body's frame, m (scenario key [tow] attachment)."""
    try:
        tow = tomllib.loads(run.attrs.get("scenario", "")).get("tow", {})
        return np.array(tow.get("attachment", [0.0, 0.0]), float)
    except (tomllib.TOMLDecodeError, ValueError, TypeError):
        return np.zeros(2)


def animate(run_path, out, colour="speed", fps=12, dpi=100, progress=True):
    """Writes the film to `out` (its extension picks the format: .mp4, .gif, ...) and returns
    its path. FileError for a bad run or a colouring it cannot give; OSError when `out` cannot be
    written (nothing is left behind then: the film is written under OUT.partial and renamed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FFMpegWriter
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import LinearSegmentedColormap

    if colour not in ("speed", "force"):
        raise ValueError(f"colour {colour!r}: allowed 'speed' or 'force'")
    with Run(run_path) as run:
        n, frames = len(run.bodies), len(run.time)
        values = np.hypot(run.velocity[..., 0], run.velocity[..., 1]) if colour == "speed" else contact_force(run)
        label = "speed (m/s)" if colour == "speed" else "contact force, mean over the frame (N)"
        grey = run.bodies.fixed.astype(bool).copy()
        tow = run.tow
        towed = None
        if tow is not None:
            towed = run.bodies.name.tolist().index(tow.attrs["body"]) if tow.attrs.get("body") in \
                run.bodies.name.tolist() else None
            if towed is not None:
                grey[towed] = True
        floes = ~grey
        scale = float(np.percentile(values[:, floes], 99.5)) if floes.any() else 1.0
        scale = scale if scale > 0 else 1.0
        box = np.vstack([p for k in (0, frames - 1) for p in run.polygons(k)])
        lo, hi = box.min(axis=0), box.max(axis=0)
        pad = 0.02 * (hi - lo).max()
        lo, hi = lo - pad, hi + pad
        width = 10.0
        height = max(3.0, width * (hi[1] - lo[1]) / (hi[0] - lo[0]) + 0.8)
        fig, ax = plt.subplots(figsize=(width, height))
        ice = LinearSegmentedColormap.from_list("ice", ["#deebf7", "#6baed6", "#08306b", "#d7301f"])
        partial = out + ".partial"
        fmt = os.path.splitext(out)[1].lstrip(".") or "mp4"
        writer = FFMpegWriter(fps=fps, extra_args=["-f", fmt] + (["-pix_fmt", "yuv420p"] if fmt == "mp4" else []))
        with open(partial, "wb"):   # an unwritable place is told now, not after the drawing
            pass
        attachment = _rope(run) if tow is not None and tow.attrs.get("mode") in ("rope", "tug") else None
        start = last = clock.monotonic()
        try:
            with writer.saving(fig, partial, dpi):
                for k in range(frames):
                    ax.clear()
                    polys = run.polygons(k)
                    coll = PolyCollection([polys[i] for i in range(n) if floes[i]], array=values[k, floes], cmap=ice,
                                          edgecolors="#4d4d4d", linewidths=0.15)
                    coll.set_clim(0.0, scale)
                    ax.add_collection(coll)
                    ax.add_collection(PolyCollection([polys[i] for i in range(n) if grey[i]], facecolors="0.35",
                                                     edgecolors="k", linewidths=0.6))
                    if tow is not None and towed is not None:
                        rows = tow.time <= run.time[k] + 1e-9
                        tug = tow.tug_position[rows]
                        if attachment is not None and len(tug):
                            c, s = np.cos(run.angle[k, towed]), np.sin(run.angle[k, towed])
                            end = run.position[k, towed] + np.array([c * attachment[0] - s * attachment[1],
                                                                     s * attachment[0] + c * attachment[1]])
                            ax.plot([end[0], tug[-1, 0]], [end[1], tug[-1, 1]], color="#8c510a", lw=1.2)
                            ax.plot(tug[-1, 0], tug[-1, 1], "s", color="#8c510a", ms=7, label="tug")
                        elif len(tug):
                            ax.plot(tug[:, 0], tug[:, 1], "--", color="#8c510a", lw=0.8, label="towing path")
                    ax.set_xlim(lo[0], hi[0])
                    ax.set_ylim(lo[1], hi[1])
                    ax.set_aspect("equal")
                    ax.set_xlabel("x (m)")
                    ax.set_title(f"{os.path.basename(run_path)}   t = {run.time[k]:.1f} s   floes coloured by {label}",
                                 fontsize=9)
                    if k == 0:
                        fig.colorbar(coll, ax=ax, label=label, shrink=0.7)
                        fig.tight_layout()
                    writer.grab_frame()
                    now = clock.monotonic()
                    if progress and (now - last > 1.0 or k == frames - 1):
                        last = now
                        print(f"\ranimate: frame {k + 1}/{frames} ({now - start:.0f} s)", end="", file=sys.stderr,
                              flush=True)
            if progress:
                print(file=sys.stderr)
            os.replace(partial, out)
        except BaseException:
            if os.path.exists(partial):
                os.remove(partial)
            raise
        finally:
            plt.close(fig)
    return out
