"""Speed: wall time per step of the field benchmark (scenarios/bench/field_wall_*.toml:
floes 5-30 m at 50 % drifting onto a wall until nearly every floe touches another) and of the
paper's towing case, on every engine, by `floedem bench`: one run at a time after all other runs
of the report, one process per run, the median over the timed window (the packed state), with
allocations per step and peak memory. The 16k field's native and Box2D runs are timed again in
the other order (config's `again`), and its targets are judged on every round. Each run's CSV row is in runs/TAG.csv and all rows in
bench.csv. The speed targets are shown against what was measured; they are goals for the
solver, not agreement checks, so a target missed is reported here and is not a disagreement.

Penetration is shown beside the time: an engine that is faster by letting floes overlap more
has not won. The benchmark scenes carry no solver settings, so two sets of runs are made of
them: native's defaults (what a user gets: a large island's few plain sweeps and a smaller
one's NNCG, extra sweeps while a point closes by more than the allowed overlap, each island in
pair order or in colour order by its size; scenarios/README.md, `[engine.native]`), and every
engine at the same 10 iterations (native as plain Gauss-Seidel in colour order), the comparison
that is fair to the other engines. Each table says which it is. The same trade is swept on the
1k field (iterations and dt per engine: cost against mean overlap). Every run here is single
threaded; the thread count is the threads section's."""
import csv
import os
import subprocess

from report_runner import Run

SIZES = ["1k", "4k", "16k", "100k"]
TARGET_VS = {"box2d": 3.0, "bullet": 6.0}     # native at least this much faster at N = 16 000
TARGET_100K_MS = 80.0                          # ms per step for 10^5 floes, native
TARGET_TOWING = {"ode": 10.0, "bullet": 10.0}  # native at least 10x faster on the towing case
# A step of the 10^5 field at most this many times the 16k field's per floe, native's defaults:
# the fields differ only in the strip's length, so the work per floe is the same, and a solver
# whose work grows linearly with the floes keeps its cost per floe wherever memory keeps up.
TARGET_PER_FLOE = 1.1
ITERATIONS_KEY = {"native": "velocity_iterations", "box2d": "velocity_iterations", "bullet": "iterations",
                  "ode": "iterations"}


EQUAL_ITERATIONS = 10   # the equal-iterations comparison: every engine's velocity iterations


def equal(engine, count=EQUAL_ITERATIONS):
    """Overrides of the equal-iterations comparison: `count` iterations on `engine`, native's as
    plain sweeps in colour order (its fastest at a fixed count of sweeps)."""
    return iterations(engine, count) + (["engine.native.coloured_sweeps=true"] if engine == "native" else [])


def iterations(engine, count):
    """Overrides for `count` velocity iterations on `engine`: native's as plain Gauss-Seidel
    sweeps (no extra sweeps where a point would close by more than the allowed overlap, no
    conjugate-gradient steps), so that the count is what every engine makes."""
    sets = [f"engine.{engine}.{ITERATIONS_KEY[engine]}={count}"]
    return sets + ["engine.native.extra_iterations=0", "engine.native.accelerate=false"] if engine == "native" else sets


def config(quick):
    # again: the field size whose native and Box2D runs are timed a second time, in the other
    # order, right after the first round: a virtual machine's speed drifts (by up to 1.7x within
    # an hour: docs/performance.md), and the 16k ratio is a target, so it is taken from two pairs of
    # adjacent runs (native, box2d ... box2d, native), not from one.
    if quick:   # a smoke run of the machinery: the field is not packed yet at 40 s
        return dict(field=[("1k", 40.0, 20.0)], again="1k", towing=(60.0, 30.0), jam=(900.0, 600.0),
                    sweep=dict(duration=40.0, window=20.0, iterations=[3, 30], dts=[0.1]))
    # Packed by about 100 s (99 % of floes in contact); the larger fields are timed over a short
    # window after that, so that the section stays within half an hour on 2 cores.
    return dict(field=[("1k", 150.0, 50.0), ("4k", 150.0, 50.0), ("16k", 110.0, 10.0), ("100k", 105.0, 5.0)],
                again="16k", towing=(300.0, 240.0), jam=(21600.0, 21000.0),
                sweep=dict(duration=150.0, window=50.0, iterations=[2, 5, 20, 50], dts=[0.025, 0.1, 0.2]))


AGAIN_ENGINES = ["box2d", "native"]   # the second round's order: the first round's reversed


def plan(ctx):
    c = config(ctx.quick)
    runs = []
    for size, duration, window in c["field"]:
        engines = ctx.engines if size != "100k" else ["native"]
        scenario = os.path.join(ctx.scenarios, "bench", f"field_wall_{size}.toml")
        runs.append(Run(f"speed_default_{size}_native", scenario, "native", [f"run.duration={duration!r}"],
                        bench_window=window, bench_stages=True, meta=dict(scene="default", size=size)))
        for e in engines:
            runs.append(Run(f"speed_field_{size}_{e}", scenario, e, [f"run.duration={duration!r}"] + equal(e),
                            bench_window=window, bench_stages=True, meta=dict(scene="field", size=size)))
        if size == c["again"]:   # timing runs go one at a time in plan order: these follow the first round
            for e in (e for e in AGAIN_ENGINES if e in ctx.engines):
                runs.append(Run(f"speed_again_{size}_{e}", scenario, e, [f"run.duration={duration!r}"] + equal(e),
                                bench_window=window, bench_stages=True, meta=dict(scene="again", size=size)))
    # Run time against error: the 1k field with the iterations and the step swept on every
    # engine (10 iterations at dt 0.05 s is the speed_field_1k run itself).
    sw = c["sweep"]
    base_dt = 0.05
    cases = [(it, base_dt) for it in sw["iterations"]] + [(10, dt) for dt in sw["dts"]]
    for e in ctx.engines:
        for it, dt in cases:
            runs.append(Run(f"speed_sweep_{e}_it{it}_dt{dt:g}", os.path.join(ctx.scenarios, "bench", "field_wall_1k.toml"),
                            e, [f"run.duration={sw['duration']!r}", f"run.dt={dt!r}"] + equal(e, it),
                            bench_window=sw["window"], meta=dict(scene="sweep", iterations=it, dt=dt)))
    duration, window = c["towing"]
    for e in ctx.engines:
        runs.append(Run(f"speed_towing_{e}", os.path.join(ctx.scenarios, "towing_paper.toml"), e,
                        [f"run.duration={duration!r}"], bench_window=window, bench_stages=True,
                        meta=dict(scene="towing")))
    # Sleeping (docs/model.md, section 3): native with islands at rest asleep (its default) and
    # without, on the jam (the whole 6 h after its first 10 min, when the pack has come to rest)
    # and on the towing case (as timed above).
    for scene, path, (duration, window) in (("jam", os.path.join("stress", "jam.toml"), c["jam"]),
                                            ("towing", "towing_paper.toml", c["towing"])):
        for on in (True, False):
            runs.append(Run(f"speed_sleep_{scene}_{'on' if on else 'off'}", os.path.join(ctx.scenarios, path), "native",
                            [f"run.duration={duration!r}", f"engine.native.sleep={'true' if on else 'false'}"],
                            bench_window=window, bench_stages=True, meta=dict(scene="sleep")))
    return runs


def read_row(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return rows[-1]


def write_rows(path, rows):
    """Bench rows (dicts of one header, the machine in each) into one CSV file."""
    rows = list(rows)
    with open(path, "w", newline="") as f:
        if rows:
            w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            w.writeheader()
            w.writerows(rows)


def write(ctx):
    timed = [r for r in ctx.all_runs if r.timed and r.tag.startswith("speed_")]
    every = {r.tag: read_row(r.out) for r in timed}
    rows = {t: r for t, r in every.items()
            if not t.startswith(("speed_sweep_", "speed_again_", "speed_default_", "speed_sleep_"))}
    sleeping = {t: r for t, r in every.items() if t.startswith("speed_sleep_")}
    defaults = {t: r for t, r in every.items() if t.startswith("speed_default_")}
    again = {t: r for t, r in every.items() if t.startswith("speed_again_")}
    # All rows in one CSV per report (the machine is in each row).
    write_rows(os.path.join(ctx.out, "bench.csv"), (every[tag] for tag in sorted(every)))
    any_row = next(iter(rows.values()))
    md = ["## Speed", "",
          f"`floedem bench`, one run at a time on {any_row['cpu']} ({any_row['host']}), single thread per engine; "
          "median wall time per step over the timed window (p10-p90 beside it). The field benchmark is "
          "`scenarios/bench/field_wall_*.toml`; the towing case is `scenarios/towing_paper.toml`. "
          "All rows: `bench.csv`.", ""]
    if ctx.quick:
        md += ["(--quick: the 1 000-floe field over 40 s, timed over its last 20 s, before the pack has formed; the "
               "full report times the packed field at 1 000 to 100 000 floes.)", ""]
    md += defaults_table(defaults, rows)
    md += [f"Every engine at {EQUAL_ITERATIONS} iterations on the field (native: plain sweeps in colour order; "
           "`x native` is each run's median over native's on the same scene), and the towing case with each "
           "engine's settings in its scenario:", "",
           "| scene | engine | bodies | ms per step (median) | p10-p90 | x native | floes in contact | "
           "max penetration (mm) | allocations per step | peak memory (MB) |", "|---|---|---|---|---|---|---|---|---|---|"]
    native_ms = {}
    for tag, row in sorted(rows.items(), key=lambda kv: (kv[0].split("_")[1], int(kv[1]["bodies"]))):
        if row["engine"] == "native":
            native_ms[(tag.rsplit("_", 1)[0])] = float(row["median_ms"])
    for tag, row in sorted(rows.items(), key=lambda kv: (kv[0].split("_")[1], int(kv[1]["bodies"]),
                                                          ctx.engines.index(kv[1]["engine"]))):
        base = native_ms.get(tag.rsplit("_", 1)[0])
        ratio = float(row["median_ms"]) / base if base else float("nan")
        md.append(f"| {tag.split('_')[1]}{' ' + tag.split('_')[2] if tag.startswith('speed_field') else ''} "
                  f"| {row['engine']} | {row['bodies']} | {float(row['median_ms']):.2f} | "
                  f"{float(row['p10_ms']):.2f}-{float(row['p90_ms']):.2f} | {ratio:.2f} | "
                  f"{100 * float(row['contact_fraction']):.1f} % | {1e3 * float(row['max_penetration_m']):.2f} | "
                  f"{float(row['allocations_per_step']):.3g} | {float(row['peak_rss_mb']):.0f} |")
    md.append("")
    md += repeated(rows, again)
    md += targets(rows, again, defaults)
    md += sleep_table(sleeping)
    figure(ctx, rows, defaults)
    md += ["![ms per step against floes](fig/speed_field.png)", ""]
    md += stages_section(ctx, rows, defaults)
    md += cost_against_error(ctx, every)
    return md, []


def defaults_table(defaults, rows):
    """Native with its defaults on the field, beside native and Box2D at equal iterations."""
    if not defaults:
        return []
    md = ["Native with its defaults (the scenes' own settings: none), what a user gets:", "",
          "| field | bodies | ms per step (median) | p10-p90 | max penetration (mm) | mean overlap (mm) | "
          f"native at {EQUAL_ITERATIONS} plain sweeps (ms, max penetration mm) | Box2D at {EQUAL_ITERATIONS} "
          "(ms, max penetration mm) |", "|---|---|---|---|---|---|---|---|"]
    for tag, row in sorted(defaults.items(), key=lambda kv: int(kv[1]["bodies"])):
        size = tag.split("_")[2]
        cells = []
        for e in ("native", "box2d"):
            other = rows.get(f"speed_field_{size}_{e}")
            cells.append(f"{float(other['median_ms']):.2f}, {1e3 * float(other['max_penetration_m']):.2f}"
                         if other else "-")
        md.append(f"| {size} | {row['bodies']} | {float(row['median_ms']):.2f} | "
                  f"{float(row['p10_ms']):.2f}-{float(row['p90_ms']):.2f} | "
                  f"{1e3 * float(row['max_penetration_m']):.2f} | {1e3 * float(row['mean_penetration_m']):.3f} | "
                  + " | ".join(cells) + " |")
    return md + [""]


def sleep_table(sleeping):
    """Native with islands at rest asleep (its default) against every body stepped every step."""
    if not sleeping:
        return []
    md = ["Sleeping islands (docs/model.md, section 3; `engine.native.sleep`): native's defaults against every "
          "body stepped every step, on the jam (a pack at rest after its first minutes) and the towing case (the "
          "floes far from the iceberg at rest). The mean is what a run's length goes by: a step of a pack that has "
          "fallen asleep costs its forcing and its held contacts only (from its third step asleep a body is left out "
          "of the broad phase, the loads and the integration).", "",
          "| scene | sleep | ms per step (median) | mean | p10-p90 | max penetration (mm) | mean overlap (mm) | "
          "mean: off / on |", "|---|---|---|---|---|---|---|---|"]
    for scene in ("jam", "towing"):
        on, off = sleeping.get(f"speed_sleep_{scene}_on"), sleeping.get(f"speed_sleep_{scene}_off")
        for label, row in (("on", on), ("off", off)):
            if row is None:
                continue
            gain = (f"{float(off['mean_ms']) / float(on['mean_ms']):.2f}"
                    if label == "on" and off is not None else "")
            md.append(f"| {scene} | {label} | {float(row['median_ms']):.3f} | {float(row['mean_ms']):.3f} | "
                      f"{float(row['p10_ms']):.3f}-{float(row['p90_ms']):.3f} | "
                      f"{1e3 * float(row['max_penetration_m']):.2f} | {1e3 * float(row['mean_penetration_m']):.3f} | "
                      f"{gain} |")
    return md + [""]


def name_values(text):
    """A bench row's "name=value ..." column as {name: value}, in order."""
    out = {}
    for item in (text or "").split():
        name, _, value = item.partition("=")
        out[name] = float(value)
    return out


def stages(row):
    """A bench row's stage_ms column: {stage: mean ms per timed step}, in order."""
    return name_values(row.get("stage_ms"))


def work(row):
    """A bench row's work column: {count: mean per timed step} (native: sweeps, position_sweeps,
    islands, redetections; empty for an engine that counts none, or a row from before the column)."""
    return name_values(row.get("work"))


# The stages of a native step as the report names them, in the order of a step: filled once from
# `floedem stages` (include/floedem/engine/step_stages.hpp, the one list) by load_stage_labels.
STAGE_LABELS = {}


def load_stage_labels(floedem):
    """Fills STAGE_LABELS ({name: label}, in order) from `floedem stages`."""
    out = subprocess.run([floedem, "stages"], capture_output=True, text=True, check=True).stdout
    STAGE_LABELS.clear()
    for line in out.splitlines():
        name, label, _ = line.split("\t", 2)
        STAGE_LABELS[name] = label


def stage_rows(runs, names, label):
    """A table of mean ms per step by stage (its share of the step beside it), a column a run."""
    md = ["| stage | " + " | ".join(label(t) for t, _ in runs) + " |", "|---|" + "---|" * len(runs)]
    for n in names:
        cells = []
        for _, r in runs:
            st = stages(r)
            total = sum(st.values())
            cells.append(f"{st.get(n, 0.0):.3f} ({100 * st.get(n, 0.0) / total:.0f} %)" if total > 0 else "-")
        md.append(f"| {STAGE_LABELS[n]} | " + " | ".join(cells) + " |")
    md.append("| **sum** | " + " | ".join(f"**{sum(stages(r).values()):.3f}**" for _, r in runs) + " |")
    return md + [""]


def stages_section(ctx, rows, defaults):
    """Where native's step goes: mean ms per step by stage (`floedem bench` times each stage of
    every timed step, the stage_ms column), on the field sizes and the towing case at equal
    iterations, and on the field with native's defaults: what a target left unmet would have to
    shrink."""
    runs = [(t, r) for t, r in sorted(rows.items(), key=lambda kv: int(kv[1]["bodies"]))
            if r["engine"] == "native" and stages(r)]
    mine = [(t, r) for t, r in sorted(defaults.items(), key=lambda kv: int(kv[1]["bodies"])) if stages(r)]
    if not runs and not mine:
        return []
    names = [n for n in STAGE_LABELS if any(stages(r).get(n, 0.0) > 0.0 for _, r in runs + mine)]

    def label(tag):
        parts = tag.split("_")
        return f"field {parts[2]}" if tag.startswith(("speed_field", "speed_default")) else parts[1]

    md = ["Where native's step goes: mean ms per step by stage over the same timed windows (`floedem bench "
          "--stages` times each stage of every timed step: the `stage_ms` column of `bench.csv`; its clocks add "
          "about 0.3 us to a step, within the noise of these). The stages add up to the mean step; the median "
          "above is a little below the mean.", ""]
    if mine:
        md += ["With native's defaults (what a user gets), on the field:", ""] + stage_rows(mine, names, label)
        done = [(label(t), work(r)) for t, r in mine if "sweeps" in work(r)]
        if done:
            # The stopping rules' work (docs/performance.md, "Why the defaults are what they are"):
            # what the defaults spent a step, so that an easy scene is seen to cost little.
            md += ["The work the defaults' stopping rules left a step (mean over the window): " + "; ".join(
                f"{name}: {w['sweeps']:.1f} velocity sweeps of its longest island, {w.get('position_sweeps', 0.0):.2f} "
                f"position sweeps, {w.get('islands', 0.0):.0f} islands" for name, w in done) + ".", ""]
    if runs:
        md += [f"At {EQUAL_ITERATIONS} plain sweeps on the field (the equal-iterations comparison), and on the "
               "towing case with its scenario's settings:", ""] + stage_rows(runs, names, label)
    # The 16k target as a budget: what the step would have to cost, against what its stages cost.
    n16, b16 = rows.get("speed_field_16k_native"), rows.get("speed_field_16k_box2d")
    if n16 and b16 and stages(n16):
        budget = float(b16["median_ms"]) / TARGET_VS["box2d"]
        st = stages(n16)
        top = sorted(st.items(), key=lambda kv: -kv[1])[:3]
        forcing = st.get("forcing", 0.0)
        md += [f"At 16 000 floes, {TARGET_VS['box2d']:g}x Box2D's {float(b16['median_ms']):.1f} ms is a budget of "
               f"{budget:.1f} ms a step against native's {float(n16['median_ms']):.1f}. The forcing, "
               f"{forcing:.1f} ms, is floedem's own and the same on every engine (the engines are handed its loads), "
               f"so native's own stages would have to fit in {budget - forcing:.1f} ms; they take "
               f"{sum(st.values()) - forcing:.1f} (mean). Its three largest stages: "
               + ", ".join(f"{STAGE_LABELS[k]} {v:.1f} ms" for k, v in top) + ".", ""]
    for chosen, what in ((defaults, "default"), (rows, "field")):
        md += stages_scaling(chosen.get(f"speed_{what}_16k_native"), chosen.get(f"speed_{what}_100k_native"),
                             "native's defaults" if what == "default" else f"{EQUAL_ITERATIONS} plain sweeps")
    md += stages_against_box2d(rows)

    def setting(tag):
        if tag.startswith("speed_default"):
            return f"{label(tag)}, defaults"
        return f"{label(tag)}, {EQUAL_ITERATIONS} sweeps" if tag.startswith("speed_field") else label(tag)

    stages_figure(ctx, mine + runs, names, setting)
    md += ["![ms per step by stage](fig/speed_stages.png)", ""]
    return md


def per_floe_growth(small, large):
    """How many times a step's median cost per floe at the large field is the small one's."""
    return (float(large["median_ms"]) / int(large["bodies"])) / (float(small["median_ms"]) / int(small["bodies"]))


def stages_scaling(small, large, setting):
    """The stages whose cost per floe grows from 16 000 to 100 000 floes (two runs with the same
    `setting`): what keeps the largest field from scaling linearly. Beside the stages that grow
    most, the largest stage's own growth: where most of the step's time is, a small growth
    counts."""
    if not (small and large and stages(small) and stages(large)):
        return []
    n_small, n_large = int(small["bodies"]), int(large["bodies"])
    a, b = stages(small), stages(large)
    growth = {k: (b[k] / n_large) / (a[k] / n_small) for k in a if a[k] > 0 and b.get(k, 0.0) > 0}
    linear = sum(a.values()) * n_large / n_small
    grown = sorted(((k, g) for k, g in growth.items() if g >= 1.5), key=lambda kv: -kv[1])
    biggest = max(b, key=b.get)
    text = (f"With {setting}, from {n_small} to {n_large} floes ({n_large / n_small:.2f} times as many), the step "
            f"grows from {sum(a.values()):.1f} to {sum(b.values()):.1f} ms (mean), against {linear:.0f} ms were "
            f"every stage to cost the same per floe; the whole step's cost per floe grows "
            f"{sum(b.values()) / linear:.2f} times. The largest stage, {STAGE_LABELS[biggest]} "
            f"({100 * b[biggest] / sum(b.values()):.0f} % of the step), grows {growth.get(biggest, 0.0):.2f} times "
            "per floe. ")
    sweeps = [work(r).get("sweeps") for r in (small, large)]
    if None not in sweeps:
        # Within a sweep of each other: the fields differ only in length (the same contacts per
        # floe), so the solve's growth per floe is then the cost of a sweep.
        same = abs(sweeps[1] - sweeps[0]) < 1.0
        text += (f"A step's sweeps (its longest island's, mean): {sweeps[0]:.1f} at {n_small} floes and "
                 f"{sweeps[1]:.1f} at {n_large}" + ("; the same number, so the contact solve's growth per floe is "
                                                   "in the cost of a sweep, not in their number. " if same else ". "))
    if grown:
        text += ("Stages whose cost per floe grows more than 1.5 times: " +
                 ", ".join(f"{STAGE_LABELS[k]} {g:.1f} times ({a[k]:.2f} -> {b[k]:.1f} ms)" for k, g in grown) +
                 f"; together {sum(b[k] for k, _ in grown):.1f} ms of the {sum(b.values()):.0f}.")
    # Why, where the code says so (native_engine.cpp, contact_solver.cpp): a local cause acting
    # on the whole field, whose odds grow with the number of floes.
    why = {"position_projection": "the position projection stops once the deepest overlap of all the step's "
                                  "contacts is within 1.5 times the allowed overlap, so one deep contact anywhere "
                                  "keeps the projection sweeping (each later sweep measures only the contacts "
                                  "whose floes moved, but the first measures every contact)",
           "redetect": "redetect finds the step's contacts again, and solves again the islands the widened "
                       "reach can touch, when any body the impulses sent beyond its reach meets a contact the "
                       "step did not hold; in a packed field the struck floe's island is nearly the whole field"}
    reasons = [why[k] for k, _ in grown if k in why]
    if reasons:
        text += " Of these, " + "; ".join(reasons) + ": the larger the field, the likelier such a cause somewhere."
    return [text, ""]


def stages_against_box2d(rows):
    """The field runs of native and Box2D side by side, by the stages both have: Box2D's own
    b2Profile (collide: its narrow phase; solveInit + solveVelocity + solvePosition: its contact
    solve; broadphase), the same forcing (floedem's, for every engine), and the rest."""
    common = ["forcing", "broad_phase", "narrow_phase", "contact_solve"]
    lines = []
    for size in SIZES:
        for e in ("native", "box2d"):
            r = rows.get(f"speed_field_{size}_{e}")
            st = stages(r) if r else {}
            if not st:
                continue
            total = sum(st.values())
            rest = total - sum(st.get(n, 0.0) for n in common)
            lines.append(f"| {size} | {e} | " + " | ".join(f"{st.get(n, 0.0):.2f}" for n in common)
                         + f" | {rest:.2f} | {total:.2f} |")
    if not any("| box2d |" in x for x in lines):
        return []
    return ["Native and Box2D by stage on the field (mean ms per step; Box2D's stages from its own b2Profile: "
            "`collide` is its narrow phase, `solveInit` + `solveVelocity` + `solvePosition` its contact solve; "
            "the rest is native's contact list, redetect, integration and position projection, Box2D's island "
            "search and integration, and each adapter's copying):", "",
            "| field | engine | forcing | broad phase | narrow phase | contact solve | rest | sum |",
            "|---|---|---|---|---|---|---|---|"] + lines + [""]


def stages_figure(ctx, runs, names, label):
    """Each native run's step as shares of its stages (the stages against threads are in the
    threads section)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 2.6 + 0.3 * len(runs)))
    colours = plt.get_cmap("tab20")(range(len(names)))
    for y, (tag, r) in enumerate(runs):
        st = stages(r)
        total = sum(st.values()) or 1.0
        left = 0.0
        for k, n in enumerate(names):
            share = 100 * st.get(n, 0.0) / total
            ax.barh(y, share, left=left, color=colours[k], label=STAGE_LABELS[n] if y == 0 else None)
            left += share
    ax.set_yticks(range(len(runs)))
    ax.set_yticklabels([f"{label(t)} ({sum(stages(r).values()):.2f} ms)" for t, r in runs])
    ax.set_xlabel("share of the step (%)")
    ax.set_xlim(0, 100)
    ax.set_title("native, one thread: where a step goes", fontsize=9)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.17), ncol=3)
    fig.tight_layout()
    fig.savefig(os.path.join(ctx.fig, "speed_stages.png"), dpi=110, bbox_inches="tight")
    plt.close(fig)


def repeated(rows, again):
    """The second round of the repeated field size against the first: how far a timing on this
    machine moves between runs of the same build, and the native-to-Box2D ratio of each pair of
    adjacent runs."""
    if not again:
        return []
    size = next(iter(again)).split("_")[2]   # speed_again_SIZE_ENGINE
    out = [f"Timed again (the {size} field, native and Box2D in the other order, right after the first round; "
           "the runs of a pair are adjacent in time, so their ratio sees the machine at one speed):", "",
           "| engine | first round (ms, median) | second round | second / first |", "|---|---|---|---|"]
    for e in AGAIN_ENGINES:
        first, second = rows.get(f"speed_field_{size}_{e}"), again.get(f"speed_again_{size}_{e}")
        if first and second:
            a, b = float(first["median_ms"]), float(second["median_ms"])
            out.append(f"| {e} | {a:.2f} | {b:.2f} | {b / a:.2f} |")
    ratios = round_ratios(rows, again, f"field_{size}", "box2d", size)
    if ratios:
        out += ["", "Box2D over native, per round: " + ", ".join(f"{r:.2f}x" for r in ratios) + "."]
    return out + [""]


def round_ratios(rows, again, scene, engine, size=None):
    """engine's median over native's on `scene`, in each round that timed both: the first, then
    with `size` the field's second round where the report timed one."""
    out = []
    rounds = [(rows, f"speed_{scene}")] + ([(again, f"speed_again_{size}")] if size else [])
    for table, prefix in rounds:
        mine, other = table.get(f"{prefix}_native"), table.get(f"{prefix}_{engine}")
        if mine and other:
            out.append(float(other["median_ms"]) / float(mine["median_ms"]))
    return out


def targets(rows, again, defaults):
    """The speed targets against what this report measured. The 16k field's: each engine's
    speed ratio in every round that timed it (the lowest decides) and the penetration beside it
    (the issue asks equal or smaller). The scaling's: a step's median cost per floe at 10^5 floes
    against 16 000, native's defaults."""
    def ms(tag):
        return float(rows[tag]["median_ms"]) if tag in rows else None

    out = ["The speed targets, as measured here:", ""]

    def versus(scene, targets, label, size=None):
        # With `size` (the field): every round, and the penetration beside the speed.
        for e, factor in targets.items():
            ratios = round_ratios(rows, again, scene, e, size)
            if not ratios:
                continue
            met = min(ratios) >= factor
            rounds = " and ".join(f"{r:.2f}x" for r in ratios)
            if size is None:
                out.append(f"- {label}: native {rounds} faster than {e} (target {factor:g}x): {'met' if met else 'not met'}.")
                continue
            depth = [1e3 * float(rows[f"speed_{scene}_{x}"]["max_penetration_m"]) for x in ("native", e)]
            met = met and depth[0] <= depth[1]
            out.append(f"- {label}: native {rounds} faster than {e} ({'two rounds' if len(ratios) > 1 else 'one round'}; "
                       f"target {factor:g}x), max penetration {depth[0]:.2f} mm against {depth[1]:.2f}: "
                       f"{'met' if met else 'not met'}.")

    versus("field_16k", TARGET_VS, "16 000 floes", size="16k")
    n100 = ms("speed_field_100k_native")
    if n100:
        out.append(f"- 100 000 floes: {n100:.1f} ms per step on native (target at most {TARGET_100K_MS:g}): "
                   f"{'met' if n100 <= TARGET_100K_MS else 'not met'}.")
    small, large = defaults.get("speed_default_16k_native"), defaults.get("speed_default_100k_native")
    if small and large:
        g = per_floe_growth(small, large)
        out.append(f"- cost per floe, 100 000 against 16 000 floes, native's defaults: {g:.2f} times (target at most "
                   f"{TARGET_PER_FLOE:g}): {'met' if g <= TARGET_PER_FLOE else 'not met'}.")
    versus("towing", TARGET_TOWING, "towing case")
    if not any("floes" in x for x in out):
        out.append("- (the field at 16 000 and 100 000 floes is timed by the full report only)")
    return out + [""]


def figure(ctx, rows, defaults):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4))
    series = [(f"{e}, {EQUAL_ITERATIONS} iterations", "o-",
               [r for t, r in rows.items() if t.startswith("speed_field") and r["engine"] == e]) for e in ctx.engines]
    series.append(("native, defaults", "s--", list(defaults.values())))
    for label, style, chosen in series:
        pts = sorted((int(r["bodies"]), float(r["median_ms"]), float(r["max_penetration_m"])) for r in chosen)
        if not pts:
            continue
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, label=label)
        bx.loglog([p[0] for p in pts], [1e3 * max(p[2], 1e-6) for p in pts], style, label=label)
    ax.axhline(TARGET_100K_MS, color="grey", lw=0.8, ls=":")
    ax.set_xlabel("bodies")
    ax.set_ylabel("ms per step (median)")
    ax.set_title("field onto a wall, dt 0.05 s")
    ax.legend(fontsize=7)
    bx.set_xlabel("bodies")
    bx.set_ylabel("max penetration over the window (mm)")
    bx.set_title("what the speed buys")
    fig.tight_layout()
    fig.savefig(os.path.join(ctx.fig, "speed_field.png"), dpi=110)
    plt.close(fig)


def cost_against_error(ctx, every):
    """Wall time per step against the constraint error (mean overlap of the overlapping contact
    points over the timed window) on the 1k field, the iterations and dt swept per engine."""
    points = {}
    for r in ctx.all_runs:
        if r.meta.get("scene") == "sweep" or r.tag == f"speed_field_1k_{r.engine}":
            row = every.get(r.tag)
            if row is None:
                continue
            it, dt = (r.meta["iterations"], r.meta["dt"]) if r.meta.get("scene") == "sweep" else (10, 0.05)
            points.setdefault(r.engine, []).append((float(row["median_ms"]) * 0.05 / dt,  # per 0.05 s of model time
                                                    1e3 * float(row["mean_penetration_m"]), it, dt))
    if not points:
        return []
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for e in ctx.engines:
        pts = sorted(points.get(e, []), key=lambda p: p[1])
        if not pts:
            continue
        ax.loglog([max(p[1], 1e-4) for p in pts], [p[0] for p in pts], "o", label=e)
        for p in pts:
            ax.annotate(f"{p[2]}it/{p[3]:g}s", (max(p[1], 1e-4), p[0]), fontsize=6, alpha=0.7)
    mine = every.get("speed_default_1k_native")
    if mine:
        ax.loglog([max(1e3 * float(mine["mean_penetration_m"]), 1e-4)], [float(mine["median_ms"])], "*", ms=13,
                  color="black", label="native defaults")
    ax.set_xlabel("mean overlap of overlapping contact points (mm)")
    ax.set_ylabel("ms of wall time per 0.05 s of model time")
    ax.set_title("1k field onto a wall: cost against constraint error")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(ctx.fig, "speed_error.png"), dpi=110)
    plt.close(fig)
    # A reference point is beaten when some native point is both cheaper and no less accurate.
    native = points.get("native", [])
    md = ["Run time against error: the 1 000-floe field with the iterations and the step swept on every engine "
          "(labels: iterations / dt). The error is the mean overlap of the overlapping contact points over the "
          "timed window, the constraint violation a contact solver is there to remove; the cost is wall time per "
          "0.05 s of model time (so that steps of different length compare). The other error measures "
          "(impact against Newton's law, free drift against its closed form, the towing force against a converged "
          "run) are in the next section, \"Run time against error\".", "",
          "| engine | points | beaten by a native point (cheaper and no worse) | least error (mm) | its cost (ms) |",
          "|---|---|---|---|---|"]
    for e in ctx.engines:
        pts = points.get(e, [])
        if not pts:
            continue
        beaten = sum(1 for p in pts if any(q[0] <= p[0] and q[1] <= p[1] for q in native)) if e != "native" else "-"
        best = min(pts, key=lambda p: p[1])
        md.append(f"| {e} | {len(pts)} | {beaten} | {best[1]:.3g} | {best[0]:.3g} |")
    if mine:
        md += ["", f"Native with its defaults (the star): {float(mine['median_ms']):.3g} ms, mean overlap "
               f"{1e3 * float(mine['mean_penetration_m']):.3g} mm, deepest {1e3 * float(mine['max_penetration_m']):.3g} mm "
               "(the floes 1 m thick: the defaults keep the deepest below 1 % of the thinnest floe)."]
    md += ["", "![cost against error](fig/speed_error.png)", ""]
    return md
