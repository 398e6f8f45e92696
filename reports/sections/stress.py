"""Numerical stability under stress: scenarios/stress/ on every engine, and the
stability map. A run "holds" when it finishes (no NaN or infinity: floedem exits 4 on one),
its deepest penetration stays below 1 % of the thinnest floe's thickness, no body moves faster
than the case allows, no body ends up beyond a wall (tunnelling), the contacts make no energy
(the energy balance, native/run/energy_balance.hpp: the kinetic energy change less the work of
the loads and of a towed body is the contacts' work, which must not be positive, net over the
run or by more than 1e-6 of the energy in play in any one step), and, without forcing, the
kinetic energy never rises above its start (summary attributes of each run: max_penetration,
max_speed, contact_work, max_relative_energy_gain, max_kinetic_energy; the last frame for the
walls).

Why these bounds: 1 % of the thickness is the required bound (a floe 0.11 m thick may overlap
its neighbour by 1.1 mm); the speed bounds are what momentum allows (a floe struck by a body of
speed V leaves at most at (1 + e) V, so 2 V is a generous bound for the unforced cases; wind
and current drive floes at a few per cent of the wind, so 2 m/s bounds the jam). 1e-6 of a
step's energy: far above rounding (1e-13 for sums over 1e5 bodies), and a gain that, repeated,
would add 1 % over 10^4 steps; inelastic contacts and friction only ever take energy away."""
import math
import os

import floedem
import numpy as np

from report_runner import Run

MASSES = [1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10]   # kg, iceberg: ratios 1e2..1e8 to the 99 kg floes
FLOE_MASS = 0.11 * 900.0                         # kg, the mass_ratio floes
PENETRATION_FRACTION = 0.01
STEP_GAIN = 1e-6                                 # largest energy a step's contacts may make, of the energy in play
# Where the moving bodies must stay (x_min, x_max, y_min, y_max; m): in front of the wall whose
# face is x = 0 (mass_ratio, slivers), inside the walled bay (jam). A centroid beyond is a body
# pushed through a wall: tunnelling.
INF = math.inf
WALL_AT_X0 = (0.0, INF, -INF, INF)
BAY = (-INF, 200.0, -100.0, 100.0)
COLUMN = (-INF, 309.0, -5.3, 5.3)  # pressed_column.toml: short of the wall, between the banks


# The fast impact: mass_ratio.toml with a 1e6 kg iceberg at 5 m/s, 4 s at dt 0.01 s.
FAST = ["body[0].mass=1e6", "body[0].velocity=[-5.0, 0.0]", "run.duration=4.0", "run.dt=0.01"]
# Native's sweeps as they were before the conjugate-gradient steps and the extra sweeps.
PLAIN_SWEEPS = ["engine.native.accelerate=false", "engine.native.extra_iterations=0"]


def jam_overrides(dt, duration):
    """jam.toml at another dt and duration: no frames, the iceberg's load as 1 s means."""
    return [f"run.dt={dt!r}", f"run.duration={duration!r}", "run.output_every=1000000",
            f"output.load_every={max(1, round(1.0 / dt))}"]


def config(quick):
    if quick:
        return dict(masses=[1e4, 1e6, 1e8, 1e10], jam=[(0.2, 300.0), (0.5, 300.0)], jam_long=None)
    return dict(masses=MASSES, jam=[(0.1, 600.0), (0.2, 1200.0), (0.5, 1200.0)], jam_long=(0.5, 21600.0))


def plan(ctx):
    c = config(ctx.quick)
    d = os.path.join(ctx.scenarios, "stress")
    runs = []
    for e in ctx.engines:
        for m in c["masses"]:
            runs.append(Run(f"stress_mass_{e}_{m:.0e}", os.path.join(d, "mass_ratio.toml"), e, [f"body[0].mass={m!r}"],
                            cost=0.5, meta=dict(may_fail=True, case="mass ratio", ratio=m / FLOE_MASS, thickness=0.11,
                                                bound=2 * 0.2, unforced=True, inside=WALL_AT_X0)))
        runs.append(Run(f"stress_fast_{e}", os.path.join(d, "mass_ratio.toml"), e, FAST,
                        cost=0.5, meta=dict(may_fail=True, case="fast impact, 5 m/s", ratio=1e6 / FLOE_MASS,
                                            thickness=0.11, bound=2 * 5.0, unforced=True, inside=WALL_AT_X0)))
        runs.append(Run(f"stress_fast_floes_{e}", os.path.join(ctx.scenarios, "impacts", "floe_floe_headon.toml"), e,
                        ["body[0].velocity=[2.5, 0.0]", "body[1].velocity=[-2.5, 0.0]", "run.dt=0.01",
                         "run.duration=2.0"],
                        cost=0.1, meta=dict(may_fail=True, case="floes head-on, 5 m/s", thickness=1.0, bound=2 * 2.5,
                                            unforced=True)))
        runs.append(Run(f"stress_many_{e}", os.path.join(d, "many_contacts.toml"), e, [], cost=0.2,
                        meta=dict(may_fail=True, case="8 simultaneous contacts", thickness=1.0, bound=2 * 0.5,
                                  unforced=True)))
        runs.append(Run(f"stress_column_{e}", os.path.join(d, "pressed_column.toml"), e,
                        [] if not ctx.quick else ["run.duration=600.0"], cost=1.0,
                        meta=dict(may_fail=True, case="resting column, 30 floes", thickness=1.0, bound=2.0,
                                  unforced=False, inside=COLUMN)))
        runs.append(Run(f"stress_slivers_{e}", os.path.join(d, "slivers.toml"), e, [], cost=1.0,
                        meta=dict(may_fail=True, case="slivers 1:50", thickness=0.5, bound=2.0, unforced=False,
                                  inside=WALL_AT_X0)))
        for dt, duration in c["jam"]:
            runs.append(Run(f"stress_jam_{e}_dt{dt:g}", os.path.join(d, "jam.toml"), e, jam_overrides(dt, duration),
                            cost=duration / dt * 0.01 * {"native": 1.0, "box2d": 1.0}.get(e, 3.0),
                            meta=dict(may_fail=True, case=f"jam 95 %, dt {dt:g} s, {duration / 60:.0f} min",
                                      thickness=1.0, bound=2.0, unforced=False, dt=dt, inside=BAY)))
    # Native without its direct solve of heavy-light islands: Gauss-Seidel alone, which hands on
    # about a floe's worth of momentum per sweep, so its penetration goes as ratio / iterations.
    for m in c["masses"][1:]:
        runs.append(Run(f"stress_mass_native_gs_{m:.0e}", os.path.join(d, "mass_ratio.toml"), "native",
                        [f"body[0].mass={m!r}", "engine.native.direct_solve=false"], cost=0.5,
                        meta=dict(may_fail=True, case="mass ratio (native, Gauss-Seidel alone)",
                                  ratio=m / FLOE_MASS, thickness=0.11, bound=2 * 0.2, unforced=True,
                                  inside=WALL_AT_X0)))
    # Native without redetect (on by default): the struck floes that cross a gap within one step
    # are then missed by the step's contacts.
    runs.append(Run("stress_fast_native_no_redetect", os.path.join(d, "mass_ratio.toml"), "native",
                    FAST + ["engine.native.redetect=false"],
                    cost=0.5, meta=dict(may_fail=True, case="fast impact, 5 m/s (native, without redetect)",
                                        ratio=1e6 / FLOE_MASS, thickness=0.11, bound=2 * 5.0, unforced=True,
                                        inside=WALL_AT_X0)))
    # Native with plain sweeps (no conjugate-gradient steps, never more than 50): a pressed pack
    # then creeps, the sweeps passing the walls' reaction on one contact at a time.
    for dt, duration in c["jam"]:
        runs.append(Run(f"stress_jam_native_plain_dt{dt:g}", os.path.join(d, "jam.toml"), "native",
                        jam_overrides(dt, duration) + PLAIN_SWEEPS, cost=duration / dt * 0.012,
                        meta=dict(may_fail=True,
                                  case=f"jam 95 %, dt {dt:g} s, {duration / 60:.0f} min (native, plain sweeps)",
                                  thickness=1.0, bound=2.0, unforced=False, inside=BAY)))
    if c["jam_long"]:
        dt, duration = c["jam_long"]
        runs.append(Run("stress_jam_native_6h", os.path.join(d, "jam.toml"), "native",
                        [f"run.dt={dt!r}", f"run.duration={duration!r}"], cost=duration / dt * 0.01,
                        meta=dict(may_fail=True, case="jam 95 %, dt 0.5 s, 6 h", thickness=1.0, bound=2.0,
                                  unforced=False, dt=dt, inside=BAY)))
    runs.append(Run("stress_drift_24h", os.path.join(ctx.scenarios, "free_drift.toml"), "native",
                    ["run.duration=86400.0"], cost=0.5,
                    meta=dict(may_fail=True, case="free drift, 24 h", thickness=80.0, bound=2.0, unforced=False)))
    return runs


class Outcome:
    def __init__(self, run):
        self.run = run
        m = run.meta
        self.case = m["case"]
        self.engine = run.engine
        self.failed = bool(run.error)
        self.reasons = []
        if self.failed:
            code = run.error.split(":")[0]
            self.reasons.append(code + (" (non-finite state)" if code == "exit 4" else ""))
            self.penetration = math.nan
            return
        with floedem.open(run.out) as f:
            a = f.summary
            self.penetration = float(a["max_penetration"])
            self.speed = float(a["max_speed"])
            self.energy_ratio = float(a["max_kinetic_energy"] / a["kinetic_energy_start"]) \
                if m["unforced"] and a["kinetic_energy_start"] > 0 else math.nan
            self.contact_work = float(a["contact_work"])
            self.step_gain = float(a["max_relative_energy_gain"])
            self.wall = run.seconds
            self.escaped = 0
            if "inside" in m:
                x0, x1, y0, y1 = m["inside"]
                moving = ~f.bodies.fixed.astype(bool)
                p = f.position[-1]
                out = (p[:, 0] < x0) | (p[:, 0] > x1) | (p[:, 1] < y0) | (p[:, 1] > y1)
                self.escaped = int(np.count_nonzero(out & moving))
            self.load = None
            if f.loads is not None:
                # The ice load on the first listed body (the grounded iceberg, the column's wall)
                # over the run's second half: its mean and its scatter (jitter) about the mean, 1 s
                # means.
                t = f.loads.time
                fx = f.loads.force[:, 0, 0]
                late = t >= 0.5 * t[-1]
                self.load = (float(np.mean(fx[late])), float(np.std(fx[late])))
        limit = PENETRATION_FRACTION * m["thickness"]
        if self.penetration > limit:
            self.reasons.append(f"penetration {self.penetration * 1e3:.3g} mm > {limit * 1e3:.3g} mm")
        if self.speed > m["bound"]:
            self.reasons.append(f"speed {self.speed:.3g} m/s > {m['bound']:.3g}")
        if self.escaped:
            self.reasons.append(f"{self.escaped} bodies through a wall")
        if m["unforced"] and self.energy_ratio > 1.0 + 1e-6:
            self.reasons.append(f"energy gain x{self.energy_ratio:.6g}")
        if self.contact_work > 0.0:
            self.reasons.append(f"contacts made {self.contact_work:.3g} J net")
        if not self.step_gain <= STEP_GAIN:
            self.reasons.append(f"a step's contacts made {self.step_gain:.2g} of its energy")

    @property
    def holds(self):
        return not self.reasons


def write(ctx):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    outs = [Outcome(r) for r in ctx.all_runs if r.tag.startswith("stress_")]
    cases = []
    for o in outs:
        if o.case not in cases:
            cases.append(o.case)
    md = ["## Stability under stress", "",
          "`scenarios/stress/` on every engine. A run holds when it finishes without a non-finite state, its "
          f"deepest penetration stays below {PENETRATION_FRACTION:.0%} of the thinnest floe's thickness, no body moves "
          "faster than momentum allows (2 V for a body struck at V; 2 m/s under wind and current), none is pushed "
          "through a wall (its centroid beyond the wall's face at the end), the contacts make no energy (the kinetic "
          "energy change less the work of the loads and of a towed body is the contacts' work: not positive over the "
          f"run, nor above {STEP_GAIN:g} of the energy in play in any step), and without "
          "forcing the kinetic energy never exceeds its start (figures from each run's `summary_*` attributes). "
          "Cells: yes (with the deepest penetration), or no and why.", "",
          "![stability map](fig/stability_map.png)", "",
          "| case | " + " | ".join(ctx.engines) + " |", "|---|" + "---|" * len(ctx.engines)]
    for case in cases:
        sel = [o for o in outs if o.case == case]
        keys = sorted({o.run.meta.get("ratio") for o in sel if o.run.meta.get("ratio") is not None}) or [None]
        for key in keys:
            label = case.replace("mass ratio", f"mass ratio {key:.0e}", 1) if key is not None else case
            cells = []
            for e in ctx.engines:
                o = next((x for x in sel if x.engine == e and x.run.meta.get("ratio") == key), None)
                if o is None:
                    cells.append("")
                elif o.failed:
                    cells.append("**no**: " + "; ".join(o.reasons))
                else:
                    cells.append(f"yes ({o.penetration * 1e3:.3g} mm)" if o.holds else "**no**: " + "; ".join(o.reasons))
            md.append(f"| {label} | " + " | ".join(cells) + " |")
    # Native as shipped; the "Gauss-Seidel alone" and "without redetect" rows are comparisons (a
    # setting changed from its default).
    native = [o for o in outs if o.engine == "native" and "(native," not in o.case]
    broken = [o for o in native if not o.holds]
    md += ["", f"Native holds in {len(native) - len(broken)} of {len(native)} runs." +
           ("" if not broken else " Where it does not: " + "; ".join(
               f"{o.case.replace('mass ratio', 'mass ratio ' + format(o.run.meta['ratio'], '.0e'), 1) if 'ratio' in o.run.meta else o.case} "
               f"({', '.join(o.reasons)})" for o in broken) +
            "."), "",
           "A heavy body pressing light floes against a wall is the known limit of projected Gauss-Seidel: each "
           "sweep passes on only about a floe's worth of momentum, so its penetration goes as the mass ratio over "
           "the sweeps, and far beyond their reach the iceberg pushes through (the rows \"Gauss-Seidel alone\", "
           "`engine.native.direct_solve = false`). Native solves the normal impulses of such islands directly "
           "(mass ratio of 300 and more, left approaching by the sweeps: `native/solver/island_solve.cpp`), "
           "which holds the ladder. Floes struck across a gap within one step (the 5 m/s impact) are missed by "
           "the step's contacts, found at its start: redetect (`engine.native.redetect`, on by default) tests the "
           "bodies the impulses sent beyond their reach against their neighbours and, where a contact the step did "
           "not hold would close within it, finds the step's contacts again and solves it again (the row "
           "\"without redetect\" turns it off). A jammed pack is Gauss-Seidel's other limit: the walls' reaction "
           "travels one contact per sweep, so a pack N floes deep needs of order N^2 sweeps, and 50 leave it "
           "closing by centimetres a step at dt 0.5 s (rows \"plain sweeps\"). In an island below 1 024 manifolds "
           "(a pressed chain) native follows each sweep with a nonsmooth conjugate-gradient step (Silcowitz, Niebe "
           "and Erleben 2010), which carries the reaction along it in of order N; a larger island (the jam's pack) "
           "gets 3 plain sweeps. Either sweeps on (up to 450 more) while a point would still close by more than the "
           "allowed overlap (1 mm) within the step, and the position projection takes back what is left.", ""]
    jam = [o for o in outs if not o.failed and getattr(o, "load", None) is not None]
    if jam:
        md += ["Ice load on the grounded iceberg in the jam and on the wall of the resting column (`/loads`, 1 s means "
               "over the run's second half): a design load, and its scatter, the contact-force jitter of a resting "
               "pack (the column, at rest, should carry its drag with none). The engines' means differ where "
               "their packs creep differently (penetration above).", "",
               "| case | engine | mean load along the wind (kN) | std of the 1 s means (kN) | std / mean |",
               "|---|---|---|---|---|"]
        for o in jam:
            mean, std = o.load
            md.append(f"| {o.case} | {o.engine} | {mean / 1e3:.1f} | {std / 1e3:.3g} | "
                      f"{std / abs(mean) if mean else float('nan'):.2g} |")
        md.append("")
    runs_named = sorted({os.path.relpath(o.run.out, ctx.out) for o in outs})
    md += ["Files: " + ", ".join(f"`{x}`" for x in runs_named[:6]) + f" ... ({len(runs_named)} in `runs/stress_*`).", ""]

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for e in ctx.engines:
        sel = sorted([o for o in outs if o.engine == e and o.case == "mass ratio" and not o.failed],
                     key=lambda o: o.run.meta["ratio"])
        if sel:
            line, = axes[0].loglog([o.run.meta["ratio"] for o in sel], [max(o.penetration, 1e-9) / 0.11 for o in sel], "o-",
                                   label=e)
            more = sorted([o for o in outs if o.engine == e and o.case.startswith("mass ratio (native,")
                           and not o.failed], key=lambda o: o.run.meta["ratio"])
            if more:
                axes[0].loglog([o.run.meta["ratio"] for o in more], [max(o.penetration, 1e-9) / 0.11 for o in more], "o--",
                               color=line.get_color(), mfc="none", label=f"{e}, Gauss-Seidel alone")
        jam = sorted([o for o in outs if o.engine == e and "dt" in o.run.meta and not o.failed and "6 h" not in o.case],
                     key=lambda o: o.run.meta["dt"])
        if jam:
            axes[1].semilogy([o.run.meta["dt"] for o in jam], [max(o.penetration, 1e-9) / 1.0 for o in jam], "o-",
                             label=e)
    for ax in axes:
        ax.axhline(PENETRATION_FRACTION, color="k", ls="--", lw=0.8, label="1 % of the thickness")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
    axes[0].set_xlabel("mass ratio iceberg / floe")
    axes[0].set_ylabel("deepest penetration / floe thickness")
    axes[0].set_title("heavy iceberg into light floes against a wall")
    axes[1].set_xlabel("time step dt (s)")
    axes[1].set_ylabel("deepest penetration / floe thickness")
    axes[1].set_title("jammed ice (95 %) under wind and current")
    fig.tight_layout()
    fig.savefig(os.path.join(ctx.fig, "stability_map.png"), dpi=110)
    plt.close(fig)
    return md, []
