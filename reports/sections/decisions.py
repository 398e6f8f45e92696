"""Towing decisions (docs/towing.md): the paper's iceberg behind tugs of a few bollard pulls
(scenarios/towing_tug.toml, a 2.5 MN line), each pull an ensemble of field seeds; the odds that
a tow succeeds with their Wilson intervals, the smallest pull that reaches PROBABILITY, and the
line's design loads from a GEV fit of the per-tow largest tension with bootstrap intervals.

A tow succeeds when its line holds and it makes MIN_SPEED good over the run, the start from rest
included. Seeds are independent tows (each draws its own field); with SEEDS tows a point, an
interval about odds of one half is about +-0.2 wide at the quick scale and +-0.15 at the full
one, which separates a tow that nearly always works from one that often fails."""
import math
import os
import tomllib

import numpy as np

import floedem
from floedem import towing
from report_runner import Run

SCENARIO = "towing_tug.toml"
BASE_SEED = 2016
PULLS = {True: [1.0e6, 2.0e6], False: [1.0e6, 1.5e6, 2.0e6]}   # N
SEEDS = {True: 10, False: 16}    # a GEV is fitted to 10 maxima at the least (floedem.towing)
DURATION = {True: 600.0, False: 1200.0}   # s: the quick report's half the scenario's
# The quick report's field is the towing section's quick one (600 m x 400 m): about 1 200 floes.
QUICK_FIELD = ["field.width=600.0", "field.height=400.0", "field.origin=[-150.0, -200.0]"]
# m/s made good from rest: half a knot over the scenario's 20 minutes; over the quick report's 10,
# whose start from rest weighs twice as much, 0.15 (the same tows measured both ways: 2 MN makes
# 0.19 and 0.33, 1 MN 0.10 and 0.19).
MIN_SPEED = {True: 0.15, False: 0.25}
PROBABILITY = 0.8
PERIODS = [10, 100]   # tows


def tag(pull, k):
    return f"decisions_P{pull / 1e6:g}MN_s{k}"


def plan(ctx):
    sc = os.path.join(ctx.scenarios, SCENARIO)
    sets = (QUICK_FIELD if ctx.quick else []) + [f"run.duration={DURATION[ctx.quick]!r}", "run.output_every=1000"]
    cost = 3.0 if ctx.quick else 10.0
    return [Run(tag(p, k), sc, "native", sets + [f"tow.bollard_pull={p!r}", f"run.seed={BASE_SEED + k}"], cost=cost,
                meta=dict(pull=p, seed=k))
            for p in PULLS[ctx.quick] for k in range(SEEDS[ctx.quick])]


def draw(rows, maxima, fits, min_speed, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    pulls = [r["pull"] / 1e6 for r in rows]
    p = np.array([r["p"] for r in rows])
    a.errorbar(pulls, p, yerr=[p - [r["lo"] for r in rows], [r["hi"] for r in rows] - p], marker="o", capsize=3)
    a.axhline(PROBABILITY, color="k", lw=0.6, ls="--")
    a.set_ylim(-0.02, 1.02)
    a.set_xlabel("bollard pull (MN)")
    a.set_ylabel("probability of success (Wilson 95 %)")
    a.set_title(f"line holds and {min_speed:g} m/s made good", fontsize=9)
    a.grid(True, lw=0.3)
    for pull, fit in fits.items():
        x = np.sort(np.asarray(maxima[pull], float)) / 1e6
        scaled = dict(fit, loc=fit["loc"] / 1e6, scale=fit["scale"] / 1e6)
        towing.quantile_plot(x, scaled, b)
        b.lines[-2].set_label(f"{pull / 1e6:g} MN")
    b.set_xlabel("GEV quantile (MN)")
    b.set_ylabel("largest collision force on the iceberg per tow (MN)")
    b.set_title("the fits' quantile plots", fontsize=9)
    b.legend(fontsize=8)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write(ctx):
    quick = ctx.quick
    records, fails = {}, []
    for p in PULLS[quick]:
        for k in range(SEEDS[quick]):
            run = ctx.run(tag(p, k))
            with floedem.open(run.out) as f:
                o = towing.run_record(f)
                breaking = float(tomllib.loads(f.attrs["scenario"])["tow"]["breaking_load"])
            records.setdefault(p, []).append(o)
            # The line's law, run by run: a line that held never carried more than its breaking
            # load; one that parted did so within the run; the percentile never above the largest.
            if not o["parted"] and o["tension_max"] > breaking:
                fails.append(f"decisions: {tag(p, k)}: the line held at {o['tension_max']:.4g} N, above its "
                             f"breaking load {breaking:.4g} N")
            if o["parted"] and not 0.0 <= o["parted_at"] <= DURATION[quick]:
                fails.append(f"decisions: {tag(p, k)}: parted at t = {o['parted_at']} s, outside the run")
            if o["tension_p99"] > o["tension_max"]:
                fails.append(f"decisions: {tag(p, k)}: p99 tension above the largest")
    summaries = [dict(id=tag(p, k), engine="native", point={"pull": p}, tow=o)
                 for p, os_ in records.items() for k, o in enumerate(os_)]
    decision = dict(no_parting=True, min_speed=MIN_SPEED[quick], probability=PROBABILITY, periods=PERIODS, pull="pull")
    rows, smallest = towing.decide(summaries, ["pull"], decision)
    rows.sort(key=lambda r: r["pull"])
    fits = {}
    for p, os_ in records.items():
        try:
            fits[p] = towing.gev_fit([o["collision_max"] for o in os_])
        except ValueError:
            pass
    draw(rows, {p: [o["collision_max"] for o in os_] for p, os_ in records.items()}, fits, MIN_SPEED[quick],
         os.path.join(ctx.fig, "decisions.png"))

    def mn(v):
        return "-" if not math.isfinite(v) else f"{v / 1e6:.3f}"

    table = ["| bollard pull (MN) | tows | succeeded | odds [95 %] | parted | speed made good (m/s) | line's largest "
             "tension (MN), the tows' range | collision on the iceberg once in 10 tows (MN) [95 %] | once in 100 tows "
             "(MN) [95 %] |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        mine = records[r["pull"]]
        speeds = [o["speed_made_good"] for o in mine]
        tensions = [o["tension_max"] for o in mine]
        table.append(f"| {r['pull'] / 1e6:g} | {r['n']} | {r['successes']} | {r['p']:.2f} [{r['lo']:.2f}, {r['hi']:.2f}] | "
                     f"{r['parted']} | {np.mean(speeds):.3f} ({min(speeds):.3f} to {max(speeds):.3f}) | "
                     f"{min(tensions) / 1e6:.4f} to {max(tensions) / 1e6:.4f} | "
                     f"{mn(r['collision_max_10_level'])} [{mn(r['collision_max_10_lo'])}, {mn(r['collision_max_10_hi'])}] | "
                     f"{mn(r['collision_max_100_level'])} [{mn(r['collision_max_100_lo'])}, "
                     f"{mn(r['collision_max_100_hi'])}] |")
    s = smallest[0] if smallest else {}

    def pull_text(v):
        return "none of the pulls tried" if v is None else f"{v / 1e6:g} MN"
    n = SEEDS[quick]
    md = ["## Towing decisions", "",
          f"`scenarios/towing_tug.toml` (docs/towing.md): the paper's iceberg behind a tug that pulls with what it has, "
          f"free running at 7.5 m/s, on a 400 m line that parts at 2.5 MN, through 50 % broken ice"
          f"{' (the quick field, 600 m x 400 m)' if quick else ''}, {DURATION[quick]:g} s a tow; "
          f"{n} field seeds (run.seed {BASE_SEED} to {BASE_SEED + n - 1}) for each bollard pull. A tow succeeds when "
          f"its line holds and it makes {MIN_SPEED[quick]:g} m/s good, the start from rest included. Odds with their Wilson "
          "95 % interval; design loads from a GEV fitted by maximum likelihood to each tow's largest collision "
          "force on the iceberg, with percentile bootstrap intervals (200 resamples).", "",
          "![decisions](fig/decisions.png)", ""] + table + ["",
          f"The smallest pull whose odds reach {PROBABILITY:g}: {pull_text(s.get('pull_estimate'))} by the estimate, "
          f"{pull_text(s.get('pull_interval'))} by the interval's lower end. An interval of +-10 % about odds of one "
          f"half needs {towing.seeds_for_half_width(0.1)} tows a point, about odds of 0.9 "
          f"{towing.seeds_for_half_width(0.1, p=0.9)}; these {n} give a first sort of the pulls. The 100-tow load is "
          f"an extrapolation from {n} maxima: its interval says how far. The line's largest tension is the tug's: "
          "it comes as the tug takes up the iceberg's mass from rest, before the ice counts, and the ice moves it "
          "by less than the table's digits for an iceberg of this mass, so it gets no fit (docs/towing.md). Checked "
          "run by run: no line that held carried more than its breaking load, every parting fell within its run, "
          "and no 99th percentile lay above the largest tension.", ""]
    return md, fails
