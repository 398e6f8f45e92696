"""Run time against error, on three problems with a known answer, every engine, the
time step and the solver's iterations swept:

- impact: two equal floes head-on (scenarios/impacts/floe_floe_headon.toml, e = 0.1): the
  velocities after the impact against Newton's law, v' = ((m_a - e m_b) v_a + (1 + e) m_b v_b) /
  (m_a + m_b); error = the largest velocity error over the approach speed;
- free drift: a floe in a steady current with Coriolis and linearised drag
  (scenarios/free_drift_analytic.toml, closed form in its header): error = the largest position
  error over 24 h (m);
- towing: the paper's case on the smaller field of the report's --quick towing section: error =
  the mean ice force over the stationary part against that of a converged native run (dt / 4,
  200 iterations), relative. Its statistical scatter (the reference's standard error, drawn as
  a band) is the floor: a difference below it is not resolved.

The cost is wall time per second of model time (median per step from `floedem bench`, alone
and single-threaded, over dt), so that runs with different steps compare; the error comes from
the same scenario run with `floedem run`. A reference point is beaten when some native point is
both cheaper and no less accurate; "native below every reference" holds when all are beaten.
Errors below a resolution count as equal (RESOLUTION: 1e-9 of the approach speed for the
impact, far below what any restitution is known to; 1 mm over the 17 km of drift; the
towing reference's standard error), and so do errors within 1e-9 of each other, so that
rounding in the 13th digit decides nothing."""
import math
import os
import re

import floedem
import numpy as np

from report_runner import Run
from sections import towing
from sections.speed import iterations, read_row

CORIOLIS_OMEGA = 7.2921e-5
RESOLUTION = {"impact": 1e-9, "drift": 1e-3}   # towing: the reference's standard error, relative
# What the defaults must stay within, per problem: an impact's velocities to 1e-9 of the
# approach speed (far below any measured restitution); a drift track to 1 m over 24 h (a
# drifting buoy's or iceberg's GPS fix is good to some metres); the towing force within the
# converged run's 95 % interval (1.96 standard errors): below that, a difference is noise.
NOISE = {"impact": 1e-9, "drift": 1.0}


def config(quick):
    if quick:
        return dict(impact=[(2, 1.0), (20, 1.0)], drift=[5.0, 240.0],
                    towing=dict(points=[(0.1, 20)], reference=(0.05, 100), duration=250.0, window=100.0))
    return dict(impact=[(1, 1.0), (2, 1.0), (5, 1.0), (10, 1.0), (50, 1.0), (10, 0.25), (10, 4.0)],
                drift=[5.0, 15.0, 60.0, 240.0, 960.0],
                towing=dict(points=[(0.05, 50), (0.1, 10), (0.1, 50), (0.2, 50)], reference=(0.025, 200),
                            duration=450.0, window=300.0))


IMPACT = os.path.join("impacts", "floe_floe_headon.toml")
IMPACT_DT = 0.0007955       # the scenario's step
DRIFT = "free_drift_analytic.toml"
DRIFT_DT = 60.0             # the scenario's step
TOWING_DT = 0.1             # towing_paper.toml's step


def pair(tag, scenario, engine, sets, window, meta, cost=0.2):
    """The run that gives the error and the timing run that gives the cost, of one point."""
    # An engine may refuse a point (Box2D caps a step at 2 m of travel): reported, not an error.
    meta = dict(meta, point=tag, engine=engine, may_fail=True)
    return [Run(tag, scenario, engine, sets, cost=cost, meta=dict(meta, part="error")),
            Run(tag + "_t", scenario, engine, sets, bench_window=window, meta=dict(meta, part="cost"))]


def plan(ctx):
    c = config(ctx.quick)
    runs = []
    for e in ctx.engines:
        for it, scale in c["impact"]:
            dt = IMPACT_DT * scale
            runs += pair(f"ce_impact_{e}_it{it}_dt{dt:.3g}", os.path.join(ctx.scenarios, IMPACT), e,
                         [f"run.dt={dt!r}"] + iterations(e, it), 0.1,
                         dict(case="impact", iterations=it, dt=dt))
        for dt in c["drift"]:
            runs += pair(f"ce_drift_{e}_dt{dt:g}", os.path.join(ctx.scenarios, DRIFT), e,
                         [f"run.dt={dt!r}", f"run.output_every={max(1, round(600.0 / dt))}"], 43200.0,
                         dict(case="drift", iterations=0, dt=dt))
    t = c["towing"]
    base = [s for s in towing.config(True)["sets"] if not s.startswith("run.duration")] + \
        [f"run.duration={t['duration']!r}", "output.tow_every=10"]
    scenario = os.path.join(ctx.scenarios, towing.SCENARIO)
    for e in ctx.engines:
        for dt, it in t["points"]:
            runs += pair(f"ce_towing_{e}_it{it}_dt{dt:g}", scenario, e,
                         base + [f"run.dt={dt!r}"] + iterations(e, it), t["window"],
                         dict(case="towing", iterations=it, dt=dt), cost=t["duration"] / dt * 1e-3)
    # Native with its defaults at each problem's own step (the towing case's, the scenario's):
    # what a user gets, drawn on each curve (docs/performance.md, "Why the defaults are what they are").
    runs += pair("ce_impact_native_default", os.path.join(ctx.scenarios, IMPACT), "native", [], 0.1,
                 dict(case="impact", iterations="defaults", dt=IMPACT_DT, default=True))
    runs += pair("ce_drift_native_default", os.path.join(ctx.scenarios, DRIFT), "native",
                 [f"run.dt={DRIFT_DT!r}", f"run.output_every={round(600.0 / DRIFT_DT)}"], 43200.0,
                 dict(case="drift", iterations="defaults", dt=DRIFT_DT, default=True))
    runs += pair("ce_towing_native_default", scenario, "native", base + [f"run.dt={TOWING_DT!r}"], t["window"],
                 dict(case="towing", iterations="defaults", dt=TOWING_DT, default=True),
                 cost=t["duration"] / TOWING_DT * 1e-3)
    dt, it = t["reference"]
    runs.append(Run("ce_towing_reference", scenario, "native",
                    base + [f"run.dt={dt!r}", f"engine.native.velocity_iterations={it}"],
                    cost=t["duration"] / dt * 3e-3, meta=dict(case="towing", part="reference")))
    return runs


# ---------------------------------------------------------------------------------------------
# Errors, from the runs' files


def impact_error(path):
    with floedem.open(path) as f:
        m = f.bodies.mass
        v0, v1 = f.velocity[0], f.velocity[-1]
        e = float(re.search(r"^restitution\s*=\s*([0-9.eE+-]+)", f.attrs["scenario"], re.M).group(1))
    approach = abs(v0[0, 0] - v0[1, 0])
    ma, mb = m[0], m[1]
    exact = np.zeros_like(v0)
    exact[0, 0] = ((ma - e * mb) * v0[0, 0] + (1 + e) * mb * v0[1, 0]) / (ma + mb)
    exact[1, 0] = ((mb - e * ma) * v0[1, 0] + (1 + e) * ma * v0[0, 0]) / (ma + mb)
    exact[:, 1] = v0[:, 1]
    return float(np.abs(v1 - exact).max() / approach)


def drift_error(path):
    with floedem.open(path) as f:
        t = f.time
        p = f.position[:, 0, :]
        mass = f.bodies.mass[0]
        area = f.bodies.area[0]
    # The scenario's constants (free_drift_analytic.toml): K = rho_w C_dw A U_ref.
    a = 1025.0 * 0.005 * area * 0.1 / mass
    fc = 2.0 * CORIOLIS_OMEGA * math.sin(math.radians(75.0))
    s = a + 1j * fc
    ws = a * (0.2 + 0.05j) / s
    z = ws * t - ws * (1.0 - np.exp(-s * t)) / s
    return float(np.abs((p[:, 0] + 1j * p[:, 1]) - z).max())


def towing_mean(path, s_stat):
    with floedem.open(path) as f:
        t, _, ice, x = towing.tow_series(f)
    keep = towing.window(t, x, s_stat)
    return float(np.mean(ice[keep])), towing.block_se(t[keep], ice[keep])


def write(ctx):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s_stat = towing.config(True)["s_stat"]
    ref = next((r for r in ctx.all_runs if r.tag == "ce_towing_reference"), None)
    ref_mean, ref_se = towing_mean(ref.out, s_stat) if ref else (math.nan, math.nan)
    points = {}   # case -> engine -> [(error, cost ms per model s, label)]
    defaults = {}  # case -> (error, cost, label, dt): native with its defaults
    refused = []
    for r in ctx.all_runs:
        if not r.tag.startswith("ce_") or r.meta.get("part") != "error":
            continue
        case = r.meta["case"]
        timing = ctx.run(r.tag + "_t")
        if r.error or timing.error:
            refused.append(f"{r.tag} ({(r.error or timing.error).splitlines()[0][:160]})")
            continue
        row = read_row(timing.out)
        cost = float(row["median_ms"]) / r.meta["dt"]
        if case == "impact":
            err = impact_error(r.out)
        elif case == "drift":
            err = drift_error(r.out)
        else:
            err = abs(towing_mean(r.out, s_stat)[0] - ref_mean) / abs(ref_mean)
        if r.meta.get("default"):
            defaults[case] = (err, cost, f"defaults/{r.meta['dt']:.3g}s", r.meta["dt"])
            continue
        label = f"{r.meta['iterations']}it/{r.meta['dt']:.3g}s" if r.meta["iterations"] else f"{r.meta['dt']:g}s"
        points.setdefault(case, {}).setdefault(r.engine, []).append((err, cost, label, r.meta["dt"]))

    titles = {"impact": ("impact: velocity error / approach speed", "head-on floes, e = 0.1"),
              "drift": ("free drift: largest position error over 24 h (m)", "Coriolis + linear drag"),
              "towing": ("towing: |mean ice force - converged| / converged", "paper's case, 600 m x 400 m field")}
    cases = [c for c in ("impact", "drift", "towing") if c in points]
    fig, axes = plt.subplots(1, len(cases), figsize=(5.2 * len(cases), 4.3), squeeze=False)
    floor = 1e-16
    for ax, case in zip(axes[0], cases):
        for e in ctx.engines:
            pts = points[case].get(e, [])
            if not pts:
                continue
            ax.loglog([max(p[0], floor) for p in pts], [p[1] for p in pts], "o", label=e, alpha=0.8)
            for p in pts:
                ax.annotate(p[2], (max(p[0], floor), p[1]), fontsize=6, alpha=0.6)
        if case in defaults:
            d = defaults[case]
            ax.loglog([max(d[0], floor)], [d[1]], "*", ms=13, color="black", label="native defaults")
        if case == "towing" and ref_se == ref_se:
            ax.axvspan(floor, ref_se / abs(ref_mean), color="grey", alpha=0.15, lw=0)
        ax.set_xlabel(titles[case][0])
        ax.set_ylabel("ms of wall time per s of model time")
        ax.set_title(titles[case][1])
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(ctx.fig, "cost_error.png"), dpi=110)
    plt.close(fig)

    md = ["## Run time against error", "",
          "Three problems with a known answer, every engine, the time step and the iterations swept (labels: "
          "iterations / dt). Cost: wall time per second of model time (`floedem bench`, alone, single thread); "
          "error: impact, the velocities after a head-on impact of two floes (e = 0.1) against Newton's law, over "
          "the approach speed; free drift, the largest position error over 24 h against the closed form of "
          "`scenarios/free_drift_analytic.toml`; towing, the mean ice force over the stationary part against a "
          f"converged native run (dt {config(ctx.quick)['towing']['reference'][0]:g} s, "
          f"{config(ctx.quick)['towing']['reference'][1]} iterations: {ref_mean / 1e3:.1f} kN, standard error "
          f"{'%.1f kN' % (ref_se / 1e3) if ref_se == ref_se else 'not estimated (too short a run)'}; "
          "the grey band is that standard error, below which a difference is noise, not error). Errors below "
          f"{RESOLUTION['impact']:g} of the approach speed (impact), {RESOLUTION['drift'] * 1e3:g} mm (drift) or the "
          "towing reference's standard error count as equal, as do errors within 1e-9 of each other. Every engine gets the same forcing, so free drift "
          "compares the engines' per-step cost at the same error (Box2D's single-precision positions drift off "
          "by metres over 17 km, and it refuses steps of more than 2 m).", "",
          "![cost against error](fig/cost_error.png)", "",
          "| problem | engine | points | beaten by a native point (cheaper, no less accurate) | least error | its cost "
          "(ms per model s) |", "|---|---|---|---|---|---|"]
    verdicts = []
    resolution = dict(RESOLUTION, towing=ref_se / abs(ref_mean) if ref_se == ref_se else 0.0)
    for case in cases:
        floor_error = resolution[case]
        native = [(max(q[0], floor_error), q[1]) for q in points[case].get("native", [])]
        for e in ctx.engines:
            pts = points[case].get(e, [])
            if not pts:
                continue
            best = min(pts, key=lambda p: (p[0], p[1]))
            if e == "native":
                beaten = "-"
            else:
                n = sum(1 for p in pts if any(q[1] <= p[1] and q[0] <= max(p[0] * (1 + 1e-9), floor_error) for q in native))
                beaten = f"{n} of {len(pts)}"
                verdicts.append((case, e, n == len(pts)))
            md.append(f"| {case} | {e} | {len(pts)} | {beaten} | {best[0]:.3g} | {best[1]:.3g} |")
    md.append("")
    if defaults:
        # The defaults against each problem's noise (NOISE above).
        noise = dict(NOISE, towing=1.96 * ref_se / abs(ref_mean) if ref_se == ref_se else math.nan)
        md += ["Native with its defaults, at each problem's own step (the star on each panel), against each "
               "problem's noise (impact 1e-9 of the approach speed; drift 1 m over 24 h, below a GPS fix; towing "
               "the converged run's 95 % interval, 1.96 standard errors): " + "; ".join(
            f"{case}, error {d[0]:.3g} (" + (f"{'within' if d[0] <= noise[case] else 'beyond'} its noise {noise[case]:.3g}"
                                            if noise[case] == noise[case] else "no interval: too short a run") +
            f") at {d[1]:.3g} ms per model s" for case, d in
            ((c, defaults[c]) for c in ("impact", "drift", "towing") if c in defaults)) + ".", ""]
    if verdicts:
        below = [f"{c} vs {e}" for c, e, ok in verdicts if ok]
        not_below = [f"{c} vs {e}" for c, e, ok in verdicts if not ok]
        md += [f"Native's curve below the reference's (every reference point beaten): "
               f"{', '.join(below) if below else 'none'}; not: {', '.join(not_below) if not_below else 'none'}.", ""]
    order = drift_order(points.get("drift", {}).get("native", []))
    if order:
        md += ["Native's free drift converges at order " + ", ".join(
               f"{o:.2f} (dt {a:g} to {b:g} s)" for a, b, o in order) + ": log(e(dt_1) / e(dt_2)) / log(dt_1 / dt_2) "
               "between neighbouring steps, 2 for a second-order scheme (the leapfrog with the forcing taken at "
               "mid-step, `docs/model.md` 2).", ""]
    if refused:
        md += ["Points an engine refused: " + "; ".join(refused) + ".", ""]
    return md, []


def drift_order(pts):
    """Observed order between neighbouring steps of the drift points (err, cost, label, dt):
    [(dt_coarse, dt_fine, order)], errors at the resolution left out (rounding, not the scheme)."""
    pts = sorted((p for p in pts if p[0] > RESOLUTION["drift"]), key=lambda p: -p[3])
    return [(a[3], b[3], math.log(a[0] / b[0]) / math.log(a[3] / b[3])) for a, b in zip(pts, pts[1:])]
