"""A hindcast from forcing files and an ice chart the report writes itself: examples/hindcast
(docs/forcing.md, "A hindcast from end to end"), its files made by the example's own script, run
over field seeds (the chart's floes differ with the seed), and beside it the same iceberg under
the same forcing in open water."""
import json
import math
import os
import re
import runpy
import shutil

import numpy as np

import floedem
from floedem import tdist
from report_runner import Run

HERE = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
EXAMPLE = os.path.join(os.path.dirname(HERE), "examples", "hindcast")
SEEDS = {True: 2, False: 8}                  # field seeds: quick, full
DURATION = {True: 3600.0, False: 86400.0}    # s
BASE_SEED = 2009                             # hindcast.toml's run.seed
# A chart polygon's achieved concentration against its code's: the generator fills a cell to
# 1e-6 of its target, and cells cut where a polygon's outline is concave lose up to a few per
# cent of their floe (docs/ice_charts.md); the example's polygons are rectangles in degrees,
# whose edges along parallels are curves on the plane.
CONCENTRATION_TOLERANCE = 0.02


def inputs(ctx):
    return os.path.join(ctx.out, "hindcast")


def tag(k):
    return f"hindcast_s{k}"


def plan(ctx):
    d = inputs(ctx)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    runpy.run_path(os.path.join(EXAMPLE, "make_forcing.py"))["main"](d)
    scene = os.path.join(d, "hindcast.toml")
    shutil.copy(os.path.join(EXAMPLE, "hindcast.toml"), scene)
    # The same scene without its field: the forcing alone.
    text = open(os.path.join(EXAMPLE, "hindcast.toml")).read()
    open_water = re.sub(r"\n\[field\]\n.*\Z", "\n", text, flags=re.S)
    assert "[field]" not in open_water and "[[body]]" in open_water
    with open(os.path.join(d, "hindcast_open_water.toml"), "w") as f:
        f.write(open_water)
    sets = [f"run.duration={DURATION[ctx.quick]!r}"]
    runs = [Run(tag(k), scene, sets=sets + [f"run.seed={BASE_SEED + k}"], cost=60.0 if not ctx.quick else 6.0)
            for k in range(SEEDS[ctx.quick])]
    runs.append(Run("hindcast_open_water", os.path.join(d, "hindcast_open_water.toml"), sets=sets, cost=5.0))
    return runs


def end_offset(run):
    """The iceberg's displacement (east, north; km) and its track in lon, lat."""
    with floedem.open(run.out) as f:
        ll = f.lonlat[:, 0]
        xy = f.position[:, 0]
    return (xy[-1] - xy[0]) / 1000.0, ll


def interval(values):
    v = np.asarray(values, float)
    n = len(v)
    half = tdist.ppf(0.975, n - 1) * v.std(ddof=1) / math.sqrt(n) if n > 1 else float("nan")
    return float(v.mean()), half


def draw(ctx, first, tracks, water_track, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Polygon as Patch

    chart = json.load(open(os.path.join(inputs(ctx), "chart.geojson")))
    colour = {True: "#c6dbef", False: "#f7f7f7"}
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 5.2), constrained_layout=True)
    with floedem.open(first.out) as f:
        polys = floedem.geojson.lonlat_polygons(f, 0)
        thickness = f.bodies.thickness
    lon = np.concatenate([p[:, 0] for p in polys])
    lat = np.concatenate([p[:, 1] for p in polys])
    view = (lon.min() - 0.01, lon.max() + 0.01, lat.min() - 0.002, lat.max() + 0.002)
    for feat in chart["features"]:
        ring = np.asarray(feat["geometry"]["coordinates"][0])
        p = feat["properties"]
        a.add_patch(Patch(ring, closed=True, facecolor=colour[p["CT"] not in ("00", "01", "02")], edgecolor="k", lw=0.8))
        # The codes at the middle of the polygon's part in view.
        x0, x1 = max(ring[:, 0].min(), view[0]), min(ring[:, 0].max(), view[1])
        y0, y1 = max(ring[:, 1].min(), view[2]), min(ring[:, 1].max(), view[3])
        a.text(0.5 * (x0 + x1), y1 - 0.08 * (y1 - y0), f"CT {p['CT']} SA {p['SA']} FA {p['FA']}", ha="center",
               va="top", fontsize=7, color="0.2")
    floes = PolyCollection(polys[1:], array=thickness[1:], cmap="Blues", edgecolors="0.3", linewidths=0.15)
    a.add_collection(floes)
    a.add_collection(PolyCollection(polys[:1], facecolors="0.25", edgecolors="k"))
    a.set_xlim(view[0], view[1])
    a.set_ylim(view[2], view[3])
    a.ticklabel_format(useOffset=False)
    a.set_aspect(1.0 / math.cos(math.radians(float(lat.mean()))))
    a.set_xlabel("longitude (deg E)")
    a.set_ylabel("latitude (deg N)")
    a.set_title(f"the chart and the floes it gave (run.seed {BASE_SEED}), t = 0", fontsize=9)
    fig.colorbar(floes, ax=a, label="floe thickness (m)", shrink=0.7)
    for k, ll in enumerate(tracks):
        b.plot(ll[:, 0], ll[:, 1], color="C0", lw=0.8, alpha=0.7, label="in the chart's ice, each seed" if k == 0 else None)
    b.plot(water_track[:, 0], water_track[:, 1], color="C3", lw=1.2, label="open water")
    b.plot(*tracks[0][0], "ko", ms=4)
    b.set_aspect(1.0 / math.cos(math.radians(float(tracks[0][0, 1]))))
    b.ticklabel_format(useOffset=False)
    b.tick_params(axis="x", labelrotation=30)
    b.set_xlabel("longitude (deg E)")
    b.set_ylabel("latitude (deg N)")
    b.set_title("the iceberg's track", fontsize=9)
    b.legend(fontsize=8)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write(ctx):
    n = SEEDS[ctx.quick]
    runs = [ctx.run(tag(k)) for k in range(n)]
    water = ctx.run("hindcast_open_water")
    offsets, tracks = zip(*(end_offset(r) for r in runs))
    offsets = np.array(offsets)
    water_offset, water_track = end_offset(water)
    hours = DURATION[ctx.quick] / 3600.0
    east, east_half = interval(offsets[:, 0])
    north, north_half = interval(offsets[:, 1])
    ice_effect = offsets - water_offset
    effect = np.hypot(ice_effect[:, 0], ice_effect[:, 1])
    eff, eff_half = interval(effect)
    draw(ctx, runs[0], tracks, water_track, os.path.join(ctx.fig, "hindcast.png"))

    fails = []
    rows = []
    with floedem.open(runs[0].out) as f:
        polygons = floedem.chart.polygons(f)
        floes = int(f.provenance["field"]["floes"])
    for p in polygons:
        c, got = p["concentration"], p["concentration_achieved"]
        target = min(c, 0.99)
        ok = abs(got - target) <= CONCENTRATION_TOLERANCE
        if not ok:
            fails.append(f"hindcast: chart feature {int(p['fid'])} filled at {got:.3f}, its CT {int(p['CT']):02d} "
                         f"asks {target:.3f} (tolerance {CONCENTRATION_TOLERANCE})")
        ice = c > 0.0
        rows.append(f"| {int(p['fid'])} | {int(p['CT']):02d} / {int(p['SA']):02d} / {int(p['FA']):02d} | "
                    + (f"{c:.2f}" if ice else "0") + " | "
                    + (f"{p['d_min']:g} to {p['d_max_used']:g}" if ice else "-") + " | "
                    + (f"{p['thickness_min']:g} to {p['thickness_max']:g}" if ice else "-")
                    + f" | {p['area'] / 1e6:.3f} | {int(p['floes'])} | {got:.3f} |")
    if not np.all(np.isfinite(offsets)):
        fails.append("hindcast: a run's track is not finite")
    files = ", ".join(f"`{os.path.relpath(r.out, ctx.out)}`" for r in runs[:2]) + (f" and {n - 2} more" if n > 2 else "")
    md = ["## A hindcast from forcing files and an ice chart", "",
          f"`examples/hindcast/` as a user runs it (docs/forcing.md, \"A hindcast from end to end\"): its script "
          f"`make_forcing.py` wrote, into `{os.path.relpath(inputs(ctx), ctx.out)}/`, a current on longitude and "
          "latitude (`ocean.nc`, CF-NetCDF: a mean eastward drift plus a clockwise M2 ellipse), a wind record "
          "(`wind.csv`: a westerly gale at 12 h) and an ice chart in SIGRID-3 codes (`chart.geojson`); "
          f"`hindcast.toml` placed the average Barents Sea iceberg at 45 E, 79.5 N in the ice the chart gives about "
          f"it and ran {hours:g} h over {n} field seeds (run.seed {BASE_SEED} to {BASE_SEED + n - 1}: each draws "
          f"its own floes from the same chart), and once without the field (`{os.path.relpath(water.out, ctx.out)}`). "
          f"Files: {files}.", "",
          "![hindcast](fig/hindcast.png)", "",
          f"The chart's polygons as the generator filled them (seed {BASE_SEED}: {floes} floes). A polygon passes "
          f"when its floes cover its code's concentration of its free area within {CONCENTRATION_TOLERANCE} "
          "(10/10 is filled at 0.99, the generator's largest; docs/ice_charts.md):", "",
          "| feature | CT / SA / FA | concentration | floe sizes (m) | thickness (m) | area in the field (km^2) | floes | "
          "achieved |",
          "|---|---|---|---|---|---|---|---|"] + rows + ["",
          f"After {hours:g} h the iceberg is {east:.2f} +- {east_half:.2f} km east and {north:.2f} +- {north_half:.2f} "
          f"km north of its start (mean over the seeds with the 95 % interval of that mean, Student's t); in open "
          f"water {water_offset[0]:.2f} km and {water_offset[1]:.2f} km. The ice moves its end point by "
          f"{eff * 1000:.0f} +- {eff_half * 1000:.0f} m ({100 * eff / np.hypot(*water_offset):.1f} % of the open-water "
          "displacement).", ""]
    return md, fails
