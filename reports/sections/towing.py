"""Towing forces (docs/model.md section 6): the paper's case (scenarios/towing_paper.toml) on every
engine, its statistics, the domain check, the concentration and speed sweeps against the
momentum-flux estimate, the restitution sensitivity, and free drift in ice against open water.

The statistics are over the stationary part of a run: from the moment the iceberg has
travelled S_STAT metres (the ice pushed ahead of it has built up; the mean over later windows
stays within the block scatter) to the end, on the 1 s means that /tow records. Their standard
errors are from 30 s block means (the force is correlated over a few seconds, the blocks are
not)."""
import math
import os

import numpy as np

import floedem
from floedem.stats import block_standard_error, stationary_window, summary
from report_runner import Run

SCENARIO = "towing_paper.toml"
OPEN_WATER = "towing_open_water.toml"
RAMP = 60.0          # s, the scenario's ramp to the towing speed
SPEED = 0.7          # m/s
BLOCK = 30.0         # s, blocks for the standard error of a mean (the 1 s means decorrelate in a few s)
LIGHT = ["run.output_every=1000"]   # sweeps: a frame of every floe each 100 s is enough

# Cross-check: the mean ice force of each engine against native's. The runs follow different
# trajectories after the first collisions (broken ice is chaotic), so only statistics can agree:
# within 4 standard errors of the difference of the means, and never closer than 10 % is asked
# (the engines' contact geometry differs: Box2D's speculative margin and linear slop, Bullet's
# 1 cm margin push floes aside at slightly different distances). --quick averages over 250 s of
# a narrow field, where one engine's mean carries about 8 % standard error (measured) and the
# block estimate of it is itself rough (8 blocks): 25 %, about 3 standard errors of a difference.
TOL_ENGINE_REL = 0.10
TOL_ENGINE_REL_QUICK = 0.25
TOL_ENGINE_SE = 4.0
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


def travel(duration, v):
    """Distance along the path after `duration` with the ramp to v."""
    return 0.5 * v * RAMP + v * (duration - RAMP)


def plan(ctx):
    c = config(ctx.quick)
    sc = os.path.join(ctx.scenarios, SCENARIO)
    n_floes = 5200 if not ctx.quick else 1200
    steps = c["duration"] / 0.1
    relative = {"native": 1.0, "box2d": 1.2, "bullet": 2.5, "ode": 2.5}
    runs = []
    for e in ctx.engines:
        runs.append(Run(f"towing_{e}", sc, e, list(c["sets"]), cost=steps * n_floes * 2e-6 * relative.get(e, 3.0),
                        meta=dict(part="engines")))
    native_cost = steps * n_floes * 2e-6
    runs.append(Run("towing_wide", sc, "native", c["wide"] + LIGHT, cost=1.6 * native_cost, meta=dict(part="wide")))
    for conc in c["concentrations"]:
        runs.append(Run(f"towing_C{conc:g}", sc, "native", c["sets"] + LIGHT + [f"field.concentration={conc!r}"],
                        cost=native_cost * conc / 0.5, meta=dict(part="concentration", value=conc)))
    distance = travel(c["duration"], SPEED)
    for v in c["speeds"]:
        duration = RAMP + (distance - 0.5 * v * RAMP) / v
        runs.append(Run(f"towing_v{v:g}", sc, "native",
                        c["sets"] + LIGHT + [f"tow.path=[[0.0, 0.0, 0.0], [{RAMP!r}, {v!r}, 0.0]]",
                                             f"run.duration={duration!r}"],
                        cost=native_cost * duration / c["duration"], meta=dict(part="speed", value=v)))
    for e in c["restitutions"]:
        runs.append(Run(f"towing_e{e:g}", sc, "native", c["sets"] + LIGHT + [f"contact.restitution={e!r}"],
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
    engines = [Case(ctx.run(f"towing_{e}"), c["s_stat"], rel) for e in ctx.engines]
    base = engines[0]
    with floedem.open(ctx.run("towing_open_water").out) as f:
        ow = tow_series(f)
    ow_keep = window(ow[0], ow[3], c["s_stat"])
    drag = float(np.mean(ow[1][ow_keep]))
    md += [f"`scenarios/{SCENARIO}`{' (smaller for --quick: ' + ', '.join(c['sets']) + ')' if c['sets'] else ''}: "
           f"the iceberg ({base.width:.0f} m across the tow) towed at {SPEED} m/s after a {RAMP:.0f} s ramp through "
           f"{base.floes} floes of {base.thickness:.2f} m at concentration {base.concentration:.3f}; e = 0.1, mu = 0.3, "
           f"dt = 0.1 s. Statistics over the stationary part, after {c['s_stat']:.0f} m of travel "
           f"(t >= {base.t_stat:.0f} s, {base.stat_seconds:.0f} s), of the 1 s means of the force along the tow. "
           f"The ice part is minus the contact force on the iceberg: the towing force less the open-water drag "
           f"({kn(drag)} kN at {SPEED} m/s, `{os.path.relpath(ctx.run('towing_open_water').out, rel)}`).", "",
           "![towing force per engine](fig/towing_timeseries.png)", "",
           "| engine | towing force mean (kN) | ice part: mean +- s.e. | std | peak | p50 | p90 | p99 | towing force - open-water drag, mean | collisions with the iceberg | wall time (s) | file |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for case, e in zip(engines, ctx.engines):
        s, i = case.force_stats, case.ice_stats
        md.append(f"| {e} | {kn(s['mean'])} | {kn(i['mean'])} +- {kn(case.ice_se)} | {kn(i['std'])} | {kn(i['peak'])} | "
                  f"{kn(i['p50'])} | {kn(i['p90'])} | {kn(i['p99'])} | {kn(s['mean'] - drag)} | {case.berg_collisions} | "
                  f"{case.wall:.0f} | `{case.file}` |")
    md += ["", "Full towing force (kN) per engine over the same part: "
           + "; ".join(f"{e} std {kn(cs.force_stats['std'])}, peak {kn(cs.force_stats['peak'])}, p99 "
                       f"{kn(cs.force_stats['p99'])}" for cs, e in zip(engines, ctx.engines)) + ".", ""]
    tol_rel = TOL_ENGINE_REL_QUICK if ctx.quick else TOL_ENGINE_REL
    md += [f"Agreement (cross-check): each engine's mean ice force against native's, within "
           f"max({tol_rel:.0%}, {TOL_ENGINE_SE:g} standard errors of the difference). Broken ice is chaotic: the "
           "engines' floes part ways after the first collisions, so only the statistics can agree.", "",
           "| engine | mean ice force / native's | difference / its standard error |", "|---|---|---|"]
    for case, e in zip(engines[1:], ctx.engines[1:]):
        d = case.ice_stats["mean"] - base.ice_stats["mean"]
        se = math.hypot(case.ice_se, base.ice_se)
        md.append(f"| {e} | {case.ice_stats['mean'] / base.ice_stats['mean']:.3f} | {d / se:+.2f} |")
        allowed = max(tol_rel * abs(base.ice_stats["mean"]), TOL_ENGINE_SE * se)
        if abs(d) > allowed:
            fails.append(f"towing: mean ice force on {e} {kn(case.ice_stats['mean'])} kN against native's "
                         f"{kn(base.ice_stats['mean'])} kN: {abs(d) / 1e3:.1f} kN apart, allowed {allowed / 1e3:.1f} kN "
                         f"({case.file}, {base.file})")

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
    wide = Case(ctx.run("towing_wide"), c["s_stat"], rel)
    d = wide.ice_stats["mean"] - base.ice_stats["mean"]
    se = math.hypot(wide.ice_se, base.ice_se)
    md += ["### Is the domain large enough?", "",
           f"The same case on a field 1.6 times as wide ({', '.join(c['wide'])}): mean ice force "
           f"{kn(wide.ice_stats['mean'])} +- {kn(wide.ice_se)} kN against {kn(base.ice_stats['mean'])} +- "
           f"{kn(base.ice_se)} kN, a difference of {d / base.ice_stats['mean']:+.1%} ({d / se:+.2f} standard errors; "
           f"`{wide.file}`). Tolerance: {TOL_DOMAIN_REL:.0%} or {TOL_DOMAIN_SE:g} standard errors"
           + (" (not checked with --quick, whose field is narrow on purpose)." if ctx.quick else "."), ""]
    if not ctx.quick and abs(d) > max(TOL_DOMAIN_REL * abs(base.ice_stats["mean"]), TOL_DOMAIN_SE * se):
        fails.append(f"towing: the wider domain changes the mean ice force by {d / base.ice_stats['mean']:+.1%} "
                     f"({d / se:+.2f} s.e.; {wide.file})")

    # Sweeps against the momentum-flux estimate.
    conc_cases = sorted([base] + [Case(ctx.run(f"towing_C{x:g}"), c["s_stat"], rel) for x in c["concentrations"]],
                        key=lambda k: k.concentration)
    speed_cases = sorted([(SPEED, base)] + [(v, Case(ctx.run(f"towing_v{v:g}"), c["s_stat"], rel)) for v in c["speeds"]])
    md += ["### Concentration and speed against the momentum-flux estimate", "",
           "docs/model.md 6: the iceberg sweeps ice of mass rho_i h C W per metre; bringing it to the towing speed costs "
           "F_a = (1 + e) rho_i h C W v^2. It leaves out the ice pushed ahead and aside, which is dragged through the "
           "water and rubs on its neighbours, so the simulated force is expected above it; the ratio shows by how much.",
           "", "![sweeps](fig/towing_sweeps.png)", "",
           "| C (achieved) | v (m/s) | mean ice force (kN) | s.e. | F_a (kN) | ratio | p99 (kN) | file |",
           "|---|---|---|---|---|---|---|---|"]
    for k in conc_cases:
        fa = momentum_flux(k, 0.1, SPEED)
        md.append(f"| {k.concentration:.3f} | {SPEED} | {kn(k.ice_stats['mean'])} | {kn(k.ice_se)} | {kn(fa)} | "
                  f"{k.ice_stats['mean'] / fa:.2f} | {kn(k.ice_stats['p99'])} | `{k.file}` |")
    for v, k in speed_cases:
        if k is base:
            continue
        fa = momentum_flux(k, 0.1, v)
        md.append(f"| {k.concentration:.3f} | {v:g} | {kn(k.ice_stats['mean'])} | {kn(k.ice_se)} | {kn(fa)} | "
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
    axes[0].errorbar(cs, fc / 1e3, yerr=2 * np.array([k.ice_se for k in conc_cases]) / 1e3, fmt="o", capsize=3,
                     label="native, mean +- 2 s.e.")
    cg = np.linspace(0.0, max(cs) * 1.05, 50)
    axes[0].plot(cg, [momentum_flux(base, 0.1, SPEED) * x / base.concentration / 1e3 for x in cg], "k--",
                 label="(1 + e) rho_i h C W v^2")
    axes[0].set_xlabel("concentration C")
    axes[0].set_title(f"v = {SPEED} m/s")
    axes[1].errorbar(vs, fs / 1e3, yerr=2 * np.array([k.ice_se for _, k in speed_cases]) / 1e3, fmt="o", capsize=3,
                     label="native, mean +- 2 s.e.")
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
    rest = sorted([(0.1, base)] + [(e, Case(ctx.run(f"towing_e{e:g}"), c["s_stat"], rel)) for e in c["restitutions"]])
    md += ["## Restitution sensitivity", "",
           "The towing case on native with e from 0 to 0.9 (everything else as above). Collisions counted over the "
           "stationary part; the peak collision force is pi J / (2 tau), tau = C_tau sqrt(m_eff), of the collisions "
           "with the iceberg.", "", "![restitution sensitivity](fig/restitution_sensitivity.png)", "",
           "| e | mean ice force (kN) | s.e. | peak ice force, 1 s mean (kN) | p99 | collisions (all) | with the iceberg | peak collision force on the iceberg (MN) | file |",
           "|---|---|---|---|---|---|---|---|---|"]
    for e, k in rest:
        md.append(f"| {e:g} | {kn(k.ice_stats['mean'])} | {kn(k.ice_se)} | {kn(k.ice_stats['peak'])} | "
                  f"{kn(k.ice_stats['p99'])} | {k.collisions} | {k.berg_collisions} | {k.berg_peak_collision / 1e6:.2f} | "
                  f"`{k.file}` |")
    md.append("")
    es = np.array([e for e, _ in rest])
    fig, axes = plt.subplots(2, 2, figsize=(10, 7), sharex=True)
    axes[0][0].errorbar(es, [k.ice_stats["mean"] / 1e3 for _, k in rest],
                        yerr=[2 * k.ice_se / 1e3 for _, k in rest], fmt="o-", capsize=3)
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

    md += drift_section(ctx, c, plt)
    return md, fails


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
