"""Which parameter matters: each contact and drag coefficient moved over its range with the others
at their defaults, one at a time, for the towing ice force, the drifting iceberg's wind factor
and deflection, and the peak force of a floe's direct hit on Hans Island; one ranked chart per
quantity (docs/validation.md, "Which parameter the verdicts hang on")."""
import math
import os

import numpy as np

import floedem
from floedem import tdist
from report_runner import Run
from sections import observations, towing

# (label, --set key, default, low, high, where the range comes from). Ranges the documentation
# gives are used as they are; where none is documented the default is halved and doubled, so
# that the bars compare the same relative change.
PARAMS = [
    ("restitution e", "contact.restitution", 0.1, 0.0, 0.9, "the report's restitution sweep"),
    ("friction mu", "contact.friction", 0.3, 0.15, 0.6, "halved and doubled"),
    ("duration coefficient C_tau", "contact.duration_coefficient", 1.5e-4, 1.3e-4, 5e-4,
     "the field figures of docs/model.md 4"),
    ("water form drag C_w", "environment.drag.water_form", 0.9, 0.5, 1.5, "iceberg-drift models (Bigg et al. 1997)"),
    ("water skin drag C_dw", "environment.drag.water_skin", 5e-4, 2.5e-4, 1e-3, "halved and doubled"),
    ("air form drag C_a", "environment.drag.air_form", 1.3, 0.65, 2.6, "halved and doubled"),
    ("air skin drag C_da", "environment.drag.air_skin", 2.5e-4, 1.25e-4, 5e-4, "halved and doubled"),
]
SEEDS = {False: 4, True: 1}      # field seeds per point: full, quick (quick: no interval)
# The drift at the observation section's quick scale (a 3 km square, dt 2 s) in both reports,
# 3 h and the last hour (full) or 45 min and the last 15 min (quick: the iceberg not yet steady).
DRIFT = {False: (10800.0, 3600.0), True: (2700.0, 900.0)}
HANS_SIDE = 1.5                  # km, the Hans Island scene's floe


def key(name, side):
    return f"{name.split()[-1].replace('_', '')}_{side}"


def drift_sets(quick):
    duration, _ = DRIFT[quick]
    sets = [s for s in observations.config(True)["drift"] if not s.startswith("run.duration")]
    return sets + [f"run.duration={duration!r}"]


def plan(ctx):
    c = towing.config(ctx.quick)
    tow_scene = os.path.join(ctx.scenarios, towing.SCENARIO)
    drift_scene = observations.scenario(ctx, "wind_drift_barents")
    runs = []
    n = SEEDS[ctx.quick]
    points = [("base", None, None)] + [(key(p[0], s), p[1], v) for p in PARAMS for s, v in (("lo", p[3]), ("hi", p[4]))]
    s = observations.disc_square(HANS_SIDE * 1000.0)
    m_hans = observations.ICE_DENSITY * 6.0 * s * s
    # The default's towing points are the towing section's own native ensemble, asked for here
    # as that section asks (runs are shared by tag), so that this section also runs alone.
    for k in range(n):
        runs.append(Run(towing.seeded("towing_native", k), tow_scene, "native", list(c["sets"]) + towing.seed_sets(k),
                        cost=30.0 if not ctx.quick else 3.0, meta=dict(part="engines")))
    for tag, setting, value in points:
        extra = [] if setting is None else [f"{setting}={value!r}"]
        for k in range(n):
            if tag != "base":   # the towing section's own native ensemble is the base
                runs.append(Run(towing.seeded(f"sens_tow_{tag}", k), tow_scene, "native",
                                list(c["sets"]) + towing.LIGHT + extra + towing.seed_sets(k), cost=30.0 if not ctx.quick else 3.0,
                                meta=dict(part="sensitivity")))
            runs.append(Run(towing.seeded(f"sens_drift_{tag}", k), drift_scene, "native",
                            drift_sets(ctx.quick) + extra + observations.seed_set(drift_scene, k), cost=10.0,
                            meta=dict(part="sensitivity")))
        runs.append(observations.collision_run(ctx, f"sens_hans_{tag}", "collision_hans_island", "native", m_hans, 0.5,
                                               [f"body[0].polygon={observations.square(s, -600.5 - 1.0 - s)}"] + extra,
                                               dict(case="hans", diameter=HANS_SIDE, gap=1.0,
                                                    c_tau=value if setting == "contact.duration_coefficient"
                                                    else observations.C_TAU)))
    return runs


def effect(lo, hi):
    """(high mean - low mean, half-width of its 95 % interval by Welch; nan for single runs)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    d = float(hi.mean() - lo.mean())
    if len(lo) < 2 or len(hi) < 2:
        return d, math.nan
    va, vb = hi.var(ddof=1) / len(hi), lo.var(ddof=1) / len(lo)
    if va + vb == 0.0:
        return d, 0.0
    dof = (va + vb) ** 2 / (va ** 2 / (len(hi) - 1) + vb ** 2 / (len(lo) - 1))
    return d, tdist.ppf(0.975, dof) * math.sqrt(va + vb)


def write(ctx):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    c = towing.config(ctx.quick)
    n = SEEDS[ctx.quick]
    _, window = DRIFT[ctx.quick]

    def tow(tag):
        if tag == "base":
            return [towing.Case(ctx.run(towing.seeded("towing_native", k)), c["s_stat"], ctx.out).ice_stats["mean"]
                    for k in range(n)]
        return [towing.Case(ctx.run(towing.seeded(f"sens_tow_{tag}", k)), c["s_stat"], ctx.out).ice_stats["mean"]
                for k in range(n)]

    def drift(tag):
        d = [observations.read_drift(ctx.run(towing.seeded(f"sens_drift_{tag}", k)), window) for k in range(n)]
        return [x["berg"][0] for x in d], [x["berg"][1] for x in d]

    def hans(tag):
        return [observations.read_collision(ctx.run(f"obs_sens_hans_{tag}_native"))["peak_force"]]

    quantities = [("towing ice force (kN)", 1e-3), ("iceberg wind factor", 1.0), ("iceberg deflection (deg)", 1.0),
                  ("peak force, Hans Island (MN)", 1e-6)]
    base = [tow("base"), *drift("base"), hans("base")]
    results = {}   # label -> [(effect, half) per quantity], low and high
    for p in PARAMS:
        lo_tag, hi_tag = key(p[0], "lo"), key(p[0], "hi")
        lo = [tow(lo_tag), *drift(lo_tag), hans(lo_tag)]
        hi = [tow(hi_tag), *drift(hi_tag), hans(hi_tag)]
        results[p[0]] = [effect(a, b) for a, b in zip(lo, hi)]

    fig, axes = plt.subplots(2, 2, figsize=(12, 7.5), constrained_layout=True)
    for q, (ax, (label, scale)) in enumerate(zip(axes.flat, quantities)):
        order = sorted(PARAMS, key=lambda p: abs(results[p[0]][q][0]))   # the largest at the top
        eff = [results[p[0]][q][0] * scale for p in order]
        err = [results[p[0]][q][1] * scale for p in order]
        # A quantity of one run each (the collision: no field, so deterministic) has no interval.
        has_err = not ctx.quick and not all(math.isnan(e) for e in err)
        ax.barh(range(len(order)), eff, xerr=np.nan_to_num(err) if has_err else None,
                color=["C3" if e > 0 else "C0" for e in eff], capsize=3)
        ax.set_yticks(range(len(order)))
        ax.set_yticklabels([f"{p[0]} {p[3]:g} -> {p[4]:g}" for p in order], fontsize=8)
        ax.axvline(0.0, color="k", lw=0.6)
        ax.set_title(f"{label}: at the default {np.mean(base[q]) * scale:.3g}", fontsize=9)
        ax.set_xlabel("high value's mean minus low value's", fontsize=8)
    fig.savefig(os.path.join(ctx.fig, "sensitivity.png"), dpi=110)
    plt.close(fig)

    interval = "" if ctx.quick else " +- the half-width of its 95 % interval (Welch)"
    md = ["## Which parameter matters", "",
          "Each contact and drag coefficient moved from a low to a high value with every other at its default, one "
          "at a time; each point " + (f"over {n} field seeds (the scenes' run.seed and the next). " if n > 1 else
                                      "on the scenes' own field seed. ") +
          "The towing ice force is the towing case's (the section above, its stationary part; the default's points "
          "are its native ensemble); the iceberg's wind factor and deflection are the Barents drift's at the "
          f"observation section's quick scale (a 3 km square, dt 2 s, {DRIFT[ctx.quick][0] / 3600:g} h, the last "
          f"{window / 3600:g} h); the peak force is the direct hit of a 1.5 km floe on Hans Island (no field: one "
          f"run). A bar is the high value's mean less the low value's{interval}; the largest effect is at the top. "
          "Ranges: where the documentation gives one it is used, otherwise the default is halved and doubled, so "
          "the bars compare like changes.", "",
          "![which parameter matters](fig/sensitivity.png)", "",
          "| parameter | low -> high | range from | " + " | ".join(q[0] for q in quantities) + " |",
          "|---|---|---|" + "---|" * len(quantities)]
    for p in PARAMS:
        cells = []
        for (d, h), (_, scale) in zip(results[p[0]], quantities):
            cells.append(f"{d * scale:+.3g}" + ("" if math.isnan(h) else f" +- {h * scale:.2g}"))
        md.append(f"| {p[0]} | {p[3]:g} -> {p[4]:g} | {p[5]} | " + " | ".join(cells) + " |")
    md.append("")
    # Reading the ranks: which parameters an interval excludes zero for, per quantity; for the
    # deterministic collision (one run a point, no interval), those that move it by more than
    # 1 % of its value at the defaults.
    def matters(q, d, h):
        if math.isnan(h):
            return abs(d) > 0.01 * abs(np.mean(base[q]))
        return abs(d) > h > 0.0 or (h == 0.0 and d != 0.0)

    if not ctx.quick:
        for q, (label, _) in enumerate(quantities):
            matter = [p[0] for p in sorted(PARAMS, key=lambda p: -abs(results[p[0]][q][0]))
                      if matters(q, *results[p[0]][q])]
            rule = "more than 1 % of its value" if math.isnan(results[PARAMS[0][0]][q][1]) else "beyond its interval"
            md.append(f"- {label}: " + (", ".join(matter) if matter else "none") + f" ({rule}).")
        md.append("")
    fails = []
    # C_tau sets the reported duration and peak of a collision only: it must move no body.
    ct = results["duration coefficient C_tau"]
    for q in range(3):
        if ct[q][0] != 0.0:
            fails.append(f"sensitivity: C_tau moved the {quantities[q][0]} by {ct[q][0]:g}; it must change no motion")
    return md, fails
