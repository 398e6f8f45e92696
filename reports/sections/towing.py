"""Towing forces (docs/model.md section 6): the paper's case (scenarios/towing_paper.toml) on every
engine, its statistics, the domain check, the concentration and speed sweeps against the
momentum-flux estimate, the restitution sensitivity, and free drift in ice against open water.

Broken ice is chaotic: two engines, or two field seeds, part ways after the first collisions, so
the cross-check, the sweeps and the restitution sensitivity are ensembles over field seeds
(run.seed, which the field's seed follows): SEEDS_ENGINES runs per engine, SEEDS_SWEEPS per
sweep point. A run's figure is the mean over its stationary part: from the moment the iceberg
has travelled S_STAT metres (the ice pushed ahead of it has built up) to the end, of the 1 s
means that /tow records. An ensemble's uncertainty is the spread of those means across seeds
(a standard error of std / sqrt(n), and Student's t for its 95 % interval); the 30 s block error
of one run is shown beside it, for comparison only. Where one run stands alone (the domain
check), its error comes from blocks ten of its own integrated autocorrelation times long."""
import math
import os

import numpy as np

import floedem
from floedem import tdist
from floedem.stats import (block_standard_error, integrated_autocorrelation_time, justified_block,
                           stationary_window, summary)
from report_runner import Run

SCENARIO = "towing_paper.toml"
OPEN_WATER = "towing_open_water.toml"
RAMP = 60.0          # s, the scenario's ramp to the towing speed
SPEED = 0.7          # m/s
BLOCK = 30.0         # s, blocks for the standard error of a mean (the 1 s means decorrelate in a few s)
LIGHT = ["run.output_every=1000"]   # sweeps: a frame of every floe each 100 s is enough

# Ensembles: field seeds per engine for the cross-check, and per point of the sweeps (the full
# report; --quick keeps CI's run short with 2 of each). Seed 0 is the scenario's own (run.seed =
# 2016); seed k > 0 sets run.seed = 2016 + k.
SEEDS_ENGINES = {False: 8, True: 2}
SEEDS_SWEEPS = {False: 4, True: 2}
BASE_SEED = 2016
# Cross-check: each engine's ensemble mean ice force against native's, by Welch's 95 % interval
# of the difference of the means (unequal spreads, Welch-Satterthwaite degrees of freedom). The
# engines fail when the whole interval lies more than TOL_ENGINE_REL of native's mean from zero:
# a difference that large is real, not seed noise, and larger than their contact geometry
# explains (Box2D's speculative margin and linear slop, Bullet's 1 cm margin push floes aside at
# slightly different distances: a few per cent, measured in the committed report). With 2 seeds
# (--quick) the interval is wide (t = 12.7 for one degree of freedom): the quick check catches
# gross disagreement only, which is its purpose in CI.
TOL_ENGINE_REL = 0.10
# Each engine's ensemble runs at a step where its own answer no longer moves with the step: the
# scenario's 0.1 s, except Bullet's 0.05 s. Bullet finds a contact only once the hulls overlap,
# and its mean ice force falls by 6 to 12 % from 0.1 to 0.05 s and then holds (0.025 s gives the
# same), where native's holds from 0.2 s down (docs/engines.md, "Agreement"). Compared at 0.1 s,
# the check would measure Bullet's step error, not the physics it shares with native.
ENGINE_DT = {"bullet": 0.05}
DT = 0.1             # s, the scenario's step
# The domain check (the full case only: --quick's field is narrow on purpose): a 1.6 times wider
# field, mean ice force within 5 % or 3 standard errors.
TOL_DOMAIN_REL = 0.05
TOL_DOMAIN_SE = 3.0


def config(quick):
    """The base case's --set list, the travel before the statistics start (m), its duration (s),
    and the sweep values."""
    if quick:
        return dict(sets=["field.width=600.0", "field.height=400.0", "field.origin=[-150.0, -200.0]",
                          "run.duration=450.0"],
                    wide=["field.width=600.0", "field.height=640.0", "field.origin=[-150.0, -320.0]",
                          "run.duration=450.0"],
                    duration=450.0, s_stat=120.0, concentrations=[0.3, 0.7], speeds=[0.4, 1.0],
                    restitutions=[0.0, 0.5, 0.9], drift=["field.width=600.0", "field.height=500.0",
                                                         "field.origin=[-300.0, -250.0]", "run.duration=300.0"],
                    drift_duration=300.0)
    return dict(sets=[], wide=["field.height=1120.0", "field.origin=[-150.0, -560.0]"],
                duration=1200.0, s_stat=190.0, concentrations=[0.3, 0.4, 0.6, 0.7], speeds=[0.3, 0.5, 1.0],
                restitutions=[0.0, 0.3, 0.5, 0.7, 0.9], drift=[], drift_duration=900.0)


def seeded(tag, k):
    """The tag of seed k of an ensemble (seed 0 keeps the plain tag other sections read)."""
    return tag if k == 0 else f"{tag}_s{k}"


def seed_sets(k):
    return [] if k == 0 else [f"run.seed={BASE_SEED + k}"]


def travel(duration, v):
    """Distance along the path after `duration` with the ramp to v."""
    return 0.5 * v * RAMP + v * (duration - RAMP)


def plan(ctx):
    c = config(ctx.quick)
    sc = os.path.join(ctx.scenarios, SCENARIO)
    n_floes = 5200 if not ctx.quick else 1200
    steps = c["duration"] / DT
    relative = {"native": 1.0, "box2d": 1.2, "bullet": 2.5, "ode": 2.5}
    runs = []
    for e in ctx.engines:
        dt = ENGINE_DT.get(e, DT)
        # The /tow rows stay 1 s means whatever the step (the scenario's tow_every is 10 steps).
        step = [] if dt == DT else [f"run.dt={dt!r}", f"output.tow_every={round(1.0 / dt)}"]
        for k in range(SEEDS_ENGINES[ctx.quick]):
            runs.append(Run(seeded(f"towing_{e}", k), sc, e, list(c["sets"]) + step + seed_sets(k),
                            cost=steps * DT / dt * n_floes * 2e-6 * relative.get(e, 3.0), meta=dict(part="engines")))
    native_cost = steps * n_floes * 2e-6
    runs.append(Run("towing_wide", sc, "native", c["wide"] + LIGHT, cost=1.6 * native_cost, meta=dict(part="wide")))
    seeds = range(SEEDS_SWEEPS[ctx.quick])
    for conc in c["concentrations"]:
        for k in seeds:
            runs.append(Run(seeded(f"towing_C{conc:g}", k), sc, "native",
                            c["sets"] + LIGHT + [f"field.concentration={conc!r}"] + seed_sets(k),
                            cost=native_cost * conc / 0.5, meta=dict(part="concentration", value=conc)))
    distance = travel(c["duration"], SPEED)
    for v in c["speeds"]:
        duration = RAMP + (distance - 0.5 * v * RAMP) / v
        for k in seeds:
            runs.append(Run(seeded(f"towing_v{v:g}", k), sc, "native",
                            c["sets"] + LIGHT + [f"tow.path=[[0.0, 0.0, 0.0], [{RAMP!r}, {v!r}, 0.0]]",
                                                 f"run.duration={duration!r}"] + seed_sets(k),
                            cost=native_cost * duration / c["duration"], meta=dict(part="speed", value=v)))
    for e in c["restitutions"]:
        for k in seeds:
            runs.append(Run(seeded(f"towing_e{e:g}", k), sc, "native",
                            c["sets"] + LIGHT + [f"contact.restitution={e!r}"] + seed_sets(k),
                            cost=native_cost, meta=dict(part="restitution", value=e)))
    runs.append(Run("towing_open_water", os.path.join(ctx.scenarios, OPEN_WATER), "native",
                    [f"tow.path=[[0.0, 0.0, 0.0], [{RAMP!r}, {SPEED!r}, 0.0]]", f"run.duration={c['duration']!r}",
                     "run.dt=0.1", "run.output_every=1000", "output.tow_every=10"],
                    cost=0.5, meta=dict(part="open_water")))
    runs.append(Run("drift_in_ice", os.path.join(ctx.scenarios, "drift_in_field.toml"), "native", list(c["drift"]),
                    cost=native_cost * 0.8, meta=dict(part="drift")))
    runs.append(Run("drift_open_water", os.path.join(ctx.scenarios, "free_drift.toml"), "native",
                    [f"run.duration={c['drift_duration']!r}", "run.dt=0.2", "run.output_every=50"],
                    cost=0.2, meta=dict(part="drift")))
    return runs


# ---------------------------------------------------------------------------------------------
# Reading


def tow_series(run):
    """/tow of a run (floedem.Run): time, towing force along x (N), its ice part along x (N), path
    position x (m)."""
    g = run.tow
    return g.time, g.force_mean[:, 0], g.ice_force_mean[:, 0], g.tug_position[:, 0]


def window(t, tug_x, s_stat):
    """Rows of the stationary part: after s_stat metres of travel (row 0 has no step yet)."""
    try:
        return stationary_window(tug_x, s_stat)
    except ValueError as e:
        raise RuntimeError(str(e)) from None


def block_se(t, x):
    """Standard error of the mean of x from BLOCK-long block means."""
    return block_standard_error(t, x, BLOCK)


stats = summary


class Case:
    """A towing run read back: series, the stationary window and its statistics."""

    def __init__(self, run, s_stat, rel_to):
        self.run = run
        self.file = os.path.relpath(run.out, rel_to)
        self.wall = run.seconds   # the run's wall time as the report measured it (process start to end)
        with floedem.open(run.out) as f:
            self.t, self.force, self.ice, self.x = tow_series(f)
            self.keep = window(self.t, self.x, s_stat)
            self.t_stat = float(self.t[self.keep][0])
            self.force_stats = stats(self.force[self.keep])
            self.ice_stats = stats(self.ice[self.keep])
            self.ice_se = block_se(self.t[self.keep], self.ice[self.keep])
            # The same from blocks ten autocorrelation times long (the force's own correlation):
            # the error of one run's mean where there is one run (the domain check).
            self.tau = integrated_autocorrelation_time(self.ice[self.keep], self.t[2] - self.t[1])
            self.ice_se_tau = block_standard_error(self.t[self.keep], self.ice[self.keep],
                                                   justified_block(self.t[self.keep], self.ice[self.keep]))
            self.steps = int(f.summary["steps"])
            ev = f.collisions
            time = ev.time
            on_berg = (ev.body_a == 0) | (ev.body_b == 0)
            late = time >= self.t_stat
            self.collisions = int(np.count_nonzero(late))
            self.berg_collisions = int(np.count_nonzero(late & on_berg))
            peaks = ev.peak_force
            self.berg_peak_collision = float(peaks[late & on_berg].max()) if np.any(late & on_berg) else 0.0
            self.stat_seconds = float(self.t[-1] - self.t_stat)
            fa = f.provenance["field"]
            self.concentration = float(fa["concentration_achieved"])
            first = int(fa["first_floe"])
            self.thickness = float(np.mean(f.bodies.thickness[first:]))
            self.density = float(np.mean(f.bodies.density[first:]))
            self.floes = int(fa["floes"])
            verts = f.local_polygons()[0]
            self.width = float(verts[:, 1].max() - verts[:, 1].min())   # the iceberg (body 0) across the tow
            self.scenario_text = f.attrs["scenario"]


class Ensemble:
    """The runs of one point over field seeds (Cases): each run's stationary means, and across
    them the ensemble's mean, spread, standard error and 95 % interval. Attributes as a Case's
    where the tables read them (figures: the mean over seeds; ice_se: the ensemble's standard
    error)."""

    def __init__(self, cases):
        self.cases = cases
        self.n = len(cases)
        self.values = np.array([k.ice_stats["mean"] for k in cases])
        self.ice_stats = {s: float(np.mean([k.ice_stats[s] for k in cases])) for s in cases[0].ice_stats}
        self.force_stats = {s: float(np.mean([k.force_stats[s] for k in cases])) for s in cases[0].force_stats}
        self.spread = float(np.std(self.values, ddof=1)) if self.n > 1 else math.nan
        self.ice_se = self.spread / math.sqrt(self.n) if self.n > 1 else cases[0].ice_se
        self.ci = tdist.ppf(0.975, self.n - 1) * self.ice_se if self.n > 1 else math.nan
        self.block_se = float(np.mean([k.ice_se for k in cases]))   # one run's 30 s block error, mean over seeds
        for name in ("concentration", "collisions", "berg_collisions"):
            setattr(self, name, float(np.mean([getattr(k, name) for k in cases])))
        self.berg_peak_collision = float(np.max([k.berg_peak_collision for k in cases]))
        first = cases[0]
        self.thickness, self.density, self.width, self.floes = first.thickness, first.density, first.width, first.floes
        self.t_stat, self.stat_seconds, self.t = first.t_stat, first.stat_seconds, first.t
        self.wall = float(sum(k.wall for k in cases))
        self.file = first.file + (f" and {self.n - 1} more seeds" if self.n > 1 else "")


def ensemble(ctx, tag, seeds, s_stat, rel):
    return Ensemble([Case(ctx.run(seeded(tag, k)), s_stat, rel) for k in range(seeds)])


def welch(a, b):
    """Welch's 95 % interval of mean(a) - mean(b): (difference, half-width, degrees of freedom)."""
    va, vb = a.spread ** 2 / a.n, b.spread ** 2 / b.n
    d = float(np.mean(a.values) - np.mean(b.values))
    se = math.sqrt(va + vb)
    dof = (va + vb) ** 2 / (va ** 2 / (a.n - 1) + vb ** 2 / (b.n - 1)) if va + vb > 0 else float(a.n + b.n - 2)
    return d, tdist.ppf(0.975, dof) * se, dof


def momentum_flux(case, e, v):
    """docs/model.md 6: (1 + e) rho_i h C W v^2, the momentum the swept ice takes per second."""
    return (1.0 + e) * case.density * case.thickness * case.concentration * case.width * v * v


# ---------------------------------------------------------------------------------------------
# Writing


def kn(x):
    return f"{x / 1e3:.1f}"


def write(ctx):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    c = config(ctx.quick)
    rel = ctx.out
    fails = []
    md = ["## Towing forces: the paper's case", ""]
    ens = [ensemble(ctx, f"towing_{e}", SEEDS_ENGINES[ctx.quick], c["s_stat"], rel) for e in ctx.engines]
    engines = [x.cases[0] for x in ens]   # seed 0 of each engine: the time series and histogram
    base = ens[0]
    with floedem.open(ctx.run("towing_open_water").out) as f:
        ow = tow_series(f)
    ow_keep = window(ow[0], ow[3], c["s_stat"])
    drag = float(np.mean(ow[1][ow_keep]))
    md += [f"`scenarios/{SCENARIO}`{' (smaller for --quick: ' + ', '.join(c['sets']) + ')' if c['sets'] else ''}: "
           f"the iceberg ({base.width:.0f} m across the tow) towed at {SPEED} m/s after a {RAMP:.0f} s ramp through "
           f"{base.floes} floes of {base.thickness:.2f} m at concentration {base.concentration:.3f}; e = 0.1, mu = 0.3, "
           f"dt = {DT} s" + "".join(f" ({e}: {dt} s, where its force has stopped moving with the step: "
                                     "docs/engines.md)" for e, dt in ENGINE_DT.items() if e in ctx.engines) +
           f". Statistics over the stationary part, after {c['s_stat']:.0f} m of travel "
           f"(t >= {base.t_stat:.0f} s, {base.stat_seconds:.0f} s), of the 1 s means of the force along the tow. "
           f"The ice part is minus the contact force on the iceberg: the towing force less the open-water drag "
           f"({kn(drag)} kN at {SPEED} m/s, `{os.path.relpath(ctx.run('towing_open_water').out, rel)}`).", "",
           "![towing force per engine](fig/towing_timeseries.png)", "",
           f"Each engine's figures are over {SEEDS_ENGINES[ctx.quick]} field seeds (run.seed {BASE_SEED} to "
           f"{BASE_SEED + SEEDS_ENGINES[ctx.quick] - 1}): the mean over the seeds of each run's stationary statistics, "
           "with the 95 % interval of the ensemble mean from the spread of the runs' means across seeds (Student's t). "
           "The last columns hold that spread against one run's 30 s block standard error: a ratio above 1 means the "
           "block error understates how far another field would move the mean.", "",
           "| engine | seeds | towing force mean (kN) | ice part: ensemble mean +- 95 % CI | seed-to-seed std of the means | std | peak | p99 | towing force - open-water drag, mean | collisions with the iceberg | wall time, all seeds (s) | one run's block s.e. | spread / block s.e. | files |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for x, e in zip(ens, ctx.engines):
        s, i = x.force_stats, x.ice_stats
        md.append(f"| {e} | {x.n} | {kn(s['mean'])} | {kn(i['mean'])} +- {kn(x.ci)} | {kn(x.spread)} | {kn(i['std'])} | "
                  f"{kn(i['peak'])} | {kn(i['p99'])} | {kn(s['mean'] - drag)} | {x.berg_collisions:.0f} | {x.wall:.0f} | "
                  f"{kn(x.block_se)} | {x.spread / x.block_se:.2f} | `{x.file}` |")
    md += [""]
    md += [f"Agreement (cross-check): each engine's ensemble mean ice force against native's, by Welch's 95 % "
           f"interval of the difference of the means; an engine fails when the whole interval lies more than "
           f"{TOL_ENGINE_REL:.0%} of native's mean from zero (a real difference, not seed noise, and larger than the "
           "engines' contact geometry explains). Broken ice is chaotic: the engines' floes part ways after the first "
           "collisions, so only the statistics over fields can agree.", "",
           "| engine | ensemble mean / native's | difference (kN) | Welch 95 % interval (kN) | degrees of freedom |",
           "|---|---|---|---|---|"]
    for x, e in zip(ens[1:], ctx.engines[1:]):
        d, half, dof = welch(x, base)
        md.append(f"| {e} | {x.ice_stats['mean'] / base.ice_stats['mean']:.3f} | {d / 1e3:+.1f} | "
                  f"{(d - half) / 1e3:+.1f} to {(d + half) / 1e3:+.1f} | {dof:.1f} |")
        if abs(d) - half > TOL_ENGINE_REL * abs(base.ice_stats["mean"]):
            fails.append(f"towing: mean ice force on {e} {kn(x.ice_stats['mean'])} kN against native's "
                         f"{kn(base.ice_stats['mean'])} kN over {x.n} and {base.n} seeds: the 95 % interval of the "
                         f"difference, {(d - half) / 1e3:+.1f} to {(d + half) / 1e3:+.1f} kN, lies beyond "
                         f"{TOL_ENGINE_REL:.0%} ({x.file}, {base.file})")

    fig, axes = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    for case, e in zip(engines, ctx.engines):
        k = max(1, int(round(30.0 / (case.t[2] - case.t[1]))))
        run_mean = np.convolve(case.ice[1:], np.ones(k) / k, mode="valid")
        line, = axes[0].plot(case.t[1:], case.ice[1:] / 1e3, lw=0.3, alpha=0.35)
        axes[0].plot(case.t[k:][: len(run_mean)], run_mean / 1e3, lw=1.4, color=line.get_color(),
                     label=f"{e} (30 s mean)")
        axes[1].plot(case.t[1:], case.force[1:] / 1e3, lw=0.4, color=line.get_color(), label=e)
    for ax in axes:
        ax.axvspan(base.t_stat, base.t[-1], color="0.9", zorder=-1)
        ax.grid(True, lw=0.3)
    after_ramp = np.concatenate([cs.force[cs.t > RAMP + 1.0] for cs in engines])
    axes[1].set_ylim(0.0, 1.15 * after_ramp.max() / 1e3)
    axes[0].set_ylabel("ice part of the towing force (kN)")
    axes[1].set_ylabel("towing force (kN)\n(the ramp's inertia off the scale)")
    axes[1].set_xlabel("time (s); shaded: the stationary part")
    axes[0].legend(ncol=4, fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(ctx.fig, "towing_timeseries.png"), dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    top = max(np.percentile(cs.ice[cs.keep], 99.9) for cs in engines)
    bins = np.linspace(min(0.0, min(cs.ice[cs.keep].min() for cs in engines)), top, 60)
    for case, e in zip(engines, ctx.engines):
        ax.hist(case.ice[case.keep] / 1e3, bins=bins / 1e3, histtype="step", density=True, label=e)
    ax.set_xlabel("ice part of the towing force, 1 s means (kN)")
    ax.set_ylabel("probability density (1/kN)")
    ax.legend()
    ax.grid(True, lw=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(ctx.fig, "towing_histogram.png"), dpi=110)
    plt.close(fig)
    md += ["", "![histogram of the ice part](fig/towing_histogram.png)", ""]

    # Domain check.
    # One run each, on the same field seed: the wider field holds the narrower one's floes and more.
    wide = Case(ctx.run("towing_wide"), c["s_stat"], rel)
    b0 = base.cases[0]
    d = wide.ice_stats["mean"] - b0.ice_stats["mean"]
    # One run a side: each mean's error from blocks ten of its own autocorrelation times long.
    se = math.hypot(wide.ice_se_tau, b0.ice_se_tau)
    md += ["### Is the domain large enough?", "",
           f"The same case on a field 1.6 times as wide ({', '.join(c['wide'])}): mean ice force "
           f"{kn(wide.ice_stats['mean'])} +- {kn(wide.ice_se_tau)} kN against {kn(b0.ice_stats['mean'])} +- "
           f"{kn(b0.ice_se_tau)} kN (standard errors from blocks of ten integrated autocorrelation times, "
           f"tau_int = {wide.tau:.1f} s and {b0.tau:.1f} s), a difference of {d / b0.ice_stats['mean']:+.1%} ({d / se:+.2f} standard errors; "
           f"`{wide.file}`). Tolerance: {TOL_DOMAIN_REL:.0%} or {TOL_DOMAIN_SE:g} standard errors"
           + (" (not checked with --quick, whose field is narrow on purpose)." if ctx.quick else "."), ""]
    if not ctx.quick and abs(d) > max(TOL_DOMAIN_REL * abs(b0.ice_stats["mean"]), TOL_DOMAIN_SE * se):
        fails.append(f"towing: the wider domain changes the mean ice force by {d / b0.ice_stats['mean']:+.1%} "
                     f"({d / se:+.2f} s.e.; {wide.file})")

    # Sweeps against the momentum-flux estimate.
    seeds = SEEDS_SWEEPS[ctx.quick]
    conc_cases = sorted([base] + [ensemble(ctx, f"towing_C{x:g}", seeds, c["s_stat"], rel) for x in c["concentrations"]],
                        key=lambda k: k.concentration)
    speed_cases = sorted([(SPEED, base)] + [(v, ensemble(ctx, f"towing_v{v:g}", seeds, c["s_stat"], rel))
                                            for v in c["speeds"]], key=lambda p: p[0])
    md += ["### Concentration and speed against the momentum-flux estimate", "",
           "docs/model.md 6: the iceberg sweeps ice of mass rho_i h C W per metre; bringing it to the towing speed costs "
           "F_a = (1 + e) rho_i h C W v^2. It leaves out the ice pushed ahead and aside, which is dragged through the "
           "water and rubs on its neighbours, so the simulated force is expected above it; the ratio shows by how much. "
           f"Each point is an ensemble of {seeds} field seeds (the base point: native's {base.n} of the cross-check), "
           "its 95 % interval from the spread across seeds.",
           "", "![sweeps](fig/towing_sweeps.png)", "",
           "| C (achieved) | v (m/s) | seeds | mean ice force (kN) | 95 % CI | F_a (kN) | ratio | p99 (kN) | files |",
           "|---|---|---|---|---|---|---|---|---|"]
    for k in conc_cases:
        fa = momentum_flux(k, 0.1, SPEED)
        md.append(f"| {k.concentration:.3f} | {SPEED} | {k.n} | {kn(k.ice_stats['mean'])} | {kn(k.ci)} | {kn(fa)} | "
                  f"{k.ice_stats['mean'] / fa:.2f} | {kn(k.ice_stats['p99'])} | `{k.file}` |")
    for v, k in speed_cases:
        if k is base:
            continue
        fa = momentum_flux(k, 0.1, v)
        md.append(f"| {k.concentration:.3f} | {v:g} | {k.n} | {kn(k.ice_stats['mean'])} | {kn(k.ci)} | {kn(fa)} | "
                  f"{k.ice_stats['mean'] / fa:.2f} | {kn(k.ice_stats['p99'])} | `{k.file}` |")
    vs = np.array([v for v, _ in speed_cases])
    fs = np.array([k.ice_stats["mean"] for _, k in speed_cases])
    cs = np.array([k.concentration for k in conc_cases])
    fc = np.array([k.ice_stats["mean"] for k in conc_cases])
    p_v = float(np.polyfit(np.log(vs), np.log(np.maximum(fs, 1.0)), 1)[0])
    p_c = float(np.polyfit(np.log(cs), np.log(np.maximum(fc, 1.0)), 1)[0])
    md += ["", f"Power-law fits of the simulated mean: F ~ v^{p_v:.2f} (the estimate: v^2), F ~ C^{p_c:.2f} "
           "(the estimate: C^1).", ""]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    axes[0].errorbar(cs, fc / 1e3, yerr=np.array([k.ci for k in conc_cases]) / 1e3, fmt="o", capsize=3,
                     label="native, ensemble mean +- 95 % CI")
    cg = np.linspace(0.0, max(cs) * 1.05, 50)
    axes[0].plot(cg, [momentum_flux(base, 0.1, SPEED) * x / base.concentration / 1e3 for x in cg], "k--",
                 label="(1 + e) rho_i h C W v^2")
    axes[0].set_xlabel("concentration C")
    axes[0].set_title(f"v = {SPEED} m/s")
    axes[1].errorbar(vs, fs / 1e3, yerr=np.array([k.ci for _, k in speed_cases]) / 1e3, fmt="o", capsize=3,
                     label="native, ensemble mean +- 95 % CI")
    vg = np.linspace(0.0, max(vs) * 1.05, 50)
    axes[1].plot(vg, [momentum_flux(base, 0.1, v) / 1e3 for v in vg], "k--", label="(1 + e) rho_i h C W v^2")
    axes[1].set_xlabel("towing speed v (m/s)")
    axes[1].set_title(f"C = {base.concentration:.2f}")
    for ax in axes:
        ax.set_ylabel("mean ice force (kN)")
        ax.grid(True, lw=0.3)
        ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(ctx.fig, "towing_sweeps.png"), dpi=110)
    plt.close(fig)

    # Restitution sensitivity.
    rest = sorted([(0.1, base)] + [(e, ensemble(ctx, f"towing_e{e:g}", seeds, c["s_stat"], rel))
                                   for e in c["restitutions"]], key=lambda p: p[0])
    md += ["## Restitution sensitivity", "",
           "The towing case on native with e from 0 to 0.9 (everything else as above), each point an ensemble of "
           f"{seeds} field seeds (e = 0.1: native's {base.n} of the cross-check): means over the seeds, the mean ice "
           "force with its 95 % interval. Collisions counted over the stationary part; the peak collision force is "
           "pi J / (2 tau), tau = C_tau sqrt(m_eff), of the collisions with the iceberg, the largest over the seeds.",
           "", "![restitution sensitivity](fig/restitution_sensitivity.png)", "",
           "| e | seeds | mean ice force (kN) | 95 % CI | peak ice force, 1 s mean (kN) | p99 | collisions (all) | with the iceberg | peak collision force on the iceberg (MN) | files |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for e, k in rest:
        md.append(f"| {e:g} | {k.n} | {kn(k.ice_stats['mean'])} | {kn(k.ci)} | {kn(k.ice_stats['peak'])} | "
                  f"{kn(k.ice_stats['p99'])} | {k.collisions:.0f} | {k.berg_collisions:.0f} | "
                  f"{k.berg_peak_collision / 1e6:.2f} | `{k.file}` |")
    md.append("")
    es = np.array([e for e, _ in rest])
    fig, axes = plt.subplots(2, 2, figsize=(10, 7), sharex=True)
    axes[0][0].errorbar(es, [k.ice_stats["mean"] / 1e3 for _, k in rest],
                        yerr=[k.ci / 1e3 for _, k in rest], fmt="o-", capsize=3)
    axes[0][0].plot(es, [momentum_flux(base, e, SPEED) / 1e3 for e in es], "k--", label="(1 + e) rho_i h C W v^2")
    axes[0][0].set_ylabel("mean ice force (kN)")
    axes[0][0].legend()
    axes[0][1].plot(es, [k.ice_stats["peak"] / 1e3 for _, k in rest], "o-", label="peak")
    axes[0][1].plot(es, [k.ice_stats["p99"] / 1e3 for _, k in rest], "s-", label="p99")
    axes[0][1].set_ylabel("ice force, 1 s means (kN)")
    axes[0][1].legend()
    axes[1][0].plot(es, [k.collisions for _, k in rest], "o-", label="all")
    axes[1][0].plot(es, [k.berg_collisions for _, k in rest], "s-", label="with the iceberg")
    axes[1][0].set_ylabel("collisions (stationary part)")
    axes[1][0].legend()
    axes[1][1].plot(es, [k.berg_peak_collision / 1e6 for _, k in rest], "o-")
    axes[1][1].set_ylabel("peak collision force on the iceberg (MN)")
    for ax in axes.flat:
        ax.grid(True, lw=0.3)
    for ax in axes[1]:
        ax.set_xlabel("restitution e")
    fig.tight_layout()
    fig.savefig(os.path.join(ctx.fig, "restitution_sensitivity.png"), dpi=110)
    plt.close(fig)

    md += ensemble_cost(ctx, ens, conc_cases, speed_cases, rest)
    md += drift_section(ctx, c, plt)
    return md, fails


CLUSTER_CORES = 64


def ensemble_cost(ctx, ens, conc_cases, speed_cases, rest):
    """What the ensembles cost here, and what the full report's would take on a 64-core Slurm
    allocation: their runs' measured wall time over the cores, plus floedem.launch's overhead per
    job (Snakemake's scheduling and the job wrapper's start), measured on this report's launch."""
    groups = [(f"cross-check, {e}", x) for e, x in zip(ctx.engines, ens)]
    groups += [(f"concentration {k.concentration:.2f}", k) for k in conc_cases if k is not ens[0]]
    groups += [(f"speed {v:g} m/s", k) for v, k in speed_cases if k is not ens[0]]
    groups += [(f"restitution {e:g}", k) for e, k in rest if k is not ens[0]]
    runs = sum(k.n for _, k in groups)
    seconds = sum(k.wall for _, k in groups)
    all_seconds = sum(r.seconds for r in ctx.all_runs)
    cores = ctx.jobs
    overhead = max(0.0, (ctx.launch_seconds * cores - all_seconds) / max(1, len(ctx.all_runs)))
    md = ["### The ensembles' cost", "",
          f"{runs} runs in the towing ensembles, {seconds:.0f} s of run time ({seconds / cores:.0f} s on this machine's "
          f"{cores} cores at a time). This report's launch of all its {len(ctx.all_runs)} runs took "
          f"{ctx.launch_seconds:.0f} s for {all_seconds:.0f} s of run time on {cores} cores: {overhead:.2f} s of "
          "scheduling and waiting per run (Snakemake, the job wrapper, the cores idle at the end).", "",
          "| ensemble | runs | run time, all seeds (s) |", "|---|---|---|"]
    md += [f"| {name} | {k.n} | {k.wall:.0f} |" for name, k in groups]
    if ctx.quick:
        full_runs = sum(SEEDS_ENGINES[False] for _ in ens) + SEEDS_SWEEPS[False] * (len(config(False)["concentrations"]) +
                                                                                   len(config(False)["speeds"]) +
                                                                                   len(config(False)["restitutions"]))
        md += ["", f"The full report's ensembles are {full_runs} runs of the full case; this quick report does not "
               "time them (the full report states their cost and the 64-core estimate from its own runs)."]
    else:
        estimate = (seconds + runs * overhead) / CLUSTER_CORES
        longest = max(max(c.wall for c in k.cases) for _, k in groups)
        md += ["", f"On a {CLUSTER_CORES}-core Slurm allocation (one core a run, profiles/slurm): about "
               f"{max(estimate, longest) / 60:.0f} min (the run time and the overhead above over {CLUSTER_CORES} cores, "
               f"at least the longest run, {longest:.0f} s), against {seconds / cores / 60:.0f} min here."]
    return md + [""]


def drift_track(path):
    with floedem.open(path) as f:
        i = list(f.bodies.name).index("iceberg")
        return f.time, f.position[:, i, :], f.velocity[:, i, :]


def drift_section(ctx, c, plt):
    ice_run, ow_run = ctx.run("drift_in_ice"), ctx.run("drift_open_water")
    ti, pi_, vi = drift_track(ice_run.out)
    to, po, vo = drift_track(ow_run.out)
    # Compare over the common time span (both runs start at t = 0; frames may differ in spacing).
    end = min(ti[-1], to[-1])
    def at(t, p, when):
        return np.array([np.interp(when, t, p[:, 0]), np.interp(when, t, p[:, 1])])
    di = at(ti, pi_, end) - pi_[0]
    do = at(to, po, end) - po[0]
    md = ["## Free drift: the iceberg in broken ice against open water", "",
          f"`drift_in_field.toml` (the iceberg among a generated field, 40 % concentration) and `free_drift.toml` "
          f"(the same iceberg, wind, current and Coriolis, no ice) over the same {end:.0f} s "
          f"(`{os.path.relpath(ice_run.out, ctx.out)}`, `{os.path.relpath(ow_run.out, ctx.out)}`).", "",
          "![free drift](fig/free_drift.png)", "",
          "| case | displacement (m) | mean drift velocity (m/s) | final speed (m/s) |", "|---|---|---|---|",
          f"| in broken ice | ({di[0]:.1f}, {di[1]:.1f}) | ({di[0] / end:.4f}, {di[1] / end:.4f}) | "
          f"{np.hypot(*vi[-1]):.4f} |",
          f"| open water | ({do[0]:.1f}, {do[1]:.1f}) | ({do[0] / end:.4f}, {do[1] / end:.4f}) | "
          f"{np.hypot(*vo[np.searchsorted(to, end) if np.searchsorted(to, end) < len(to) else -1]):.4f} |", "",
          f"The ice changes the drift by {np.hypot(*(di - do)):.1f} m over {end:.0f} s "
          f"({np.hypot(*(di - do)) / max(np.hypot(*do), 1e-9):.1%} of the open-water displacement): the floes, driven by "
          "the wind faster than the deep-keeled iceberg, press on its up-wind side.", ""]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    axes[0].plot(pi_[:, 0] - pi_[0, 0], pi_[:, 1] - pi_[0, 1], label="in broken ice")
    axes[0].plot(po[:, 0] - po[0, 0], po[:, 1] - po[0, 1], label="open water")
    axes[0].set_xlabel("x displacement (m)")
    axes[0].set_ylabel("y displacement (m)")
    axes[0].set_aspect("equal", adjustable="datalim")
    axes[0].legend()
    axes[1].plot(ti, np.hypot(vi[:, 0], vi[:, 1]), label="in broken ice")
    mask = to <= end
    axes[1].plot(to[mask], np.hypot(vo[mask, 0], vo[mask, 1]), label="open water")
    axes[1].set_xlabel("time (s)")
    axes[1].set_ylabel("iceberg speed (m/s)")
    axes[1].legend()
    for ax in axes:
        ax.grid(True, lw=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(ctx.fig, "free_drift.png"), dpi=110)
    plt.close(fig)
    return md
