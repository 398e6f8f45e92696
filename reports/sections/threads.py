"""Threads: native's step on 1 thread up to every core of the machine the report runs
on, on the field benchmark packed on its wall (scenarios/bench/field_wall_*.toml), by `floedem
bench --stages` with FLOEDEM_THREADS set; and the check that the thread count changes nothing:
the same field run on 1 thread and on every core, in colour order (10 plain sweeps, the
speed section's equal iterations) and in pair order (native's defaults otherwise: NNCG, extra
sweeps), must write the same HDF5 file to the byte (no timestamps are stored;
tests/run/test_determinism.cpp checks 1 against 4 threads on every CI run, this checks every
core of the report's machine).

The scaling runs time native's defaults (what a user gets) on the 4k, 16k and 10^5 fields. The 16-core figures of the committed report come from `floedem report --only threads`
run on a 16-core machine (reports/threads-16/README.md says which and how)."""
import os

from report_runner import Run
from sections.speed import STAGE_LABELS, equal, read_row, stages, write_rows

# Colour order with 10 plain sweeps (the speed section's equal iterations), and pair order with
# native's defaults otherwise.
IDENTICAL_ORDERS = {"coloured": equal("native"), "pairs": ["engine.native.coloured_sweeps=false"]}


# Two threads at least this many times as fast as one on the 16k and 10^5 fields (native's
# defaults). Below it, what stays on one thread or waits on memory is named by the stages' table.
TARGET_TWO_THREADS = 1.6
TARGET_SIZES = ("16k", "100k")


def config(quick, cores):
    if quick:   # a smoke run of the machinery: the field is not packed yet at 40 s
        return dict(scaling=[("1k", 40.0, 20.0)], identical=("1k", 20.0))
    # Packed by about 100 s (99 % of floes in contact); the 16k and 10^5 fields are timed over a
    # short window after that (as in the speed section).
    scaling = [("4k", 150.0, 50.0), ("16k", 110.0, 10.0), ("100k", 105.0, 5.0)]
    return dict(scaling=scaling, identical=("4k", 120.0))


def thread_counts(cores):
    return sorted(t for t in {1, 2, 4, 8, 16, cores} if t <= cores)


def plan(ctx):
    cores = os.cpu_count() or 1
    c = config(ctx.quick, cores)
    runs = []
    for size, duration, window in c["scaling"]:
        for t in thread_counts(cores):
            runs.append(Run(f"threads_{size}_{t}", os.path.join(ctx.scenarios, "bench", f"field_wall_{size}.toml"),
                            "native", [f"run.duration={duration!r}"], bench_window=window, threads=t,
                            bench_stages=True, meta=dict(size=size, threads=t)))
    size, duration = c["identical"]
    if cores > 1:
        for order, sets in IDENTICAL_ORDERS.items():
            for t in (1, cores):
                runs.append(Run(f"threads_identical_{order}_{t}",
                                os.path.join(ctx.scenarios, "bench", f"field_wall_{size}.toml"), "native",
                                [f"run.duration={duration!r}", "run.output_every=100", "output.contacts=collisions"]
                                + sets, cost=3.0 * duration / t, threads=t, meta=dict(order=order, threads=t)))
    return runs


def read_bytes(path):
    with open(path, "rb") as f:
        return f.read()


def write(ctx):
    cores = os.cpu_count() or 1
    rows = {}   # size -> [(threads, row)]
    for r in ctx.all_runs:
        if r.timed and r.tag.startswith("threads_"):
            rows.setdefault(r.meta["size"], []).append((r.meta["threads"], read_row(r.out)))
    for v in rows.values():
        v.sort(key=lambda x: x[0])
    if not rows:
        return [], []
    write_rows(os.path.join(ctx.out, "threads.csv"), (row for size in rows for _, row in rows[size]))
    any_row = next(iter(rows.values()))[0][1]
    md = ["## Threads", "",
          f"Native on 1 to {cores} threads (FLOEDEM_THREADS) on {any_row['cpu']} ({any_row['host']}), `floedem bench "
          "--stages` with native's defaults, one run at a time (all rows: `threads.csv`): median ms per step over "
          "the timed window of the field packed on its wall. "
          "The per-body and per-pair loops (drag, forcing, placing, narrow phase, integration) and the contact "
          "solve's islands run on the pool, and the sweeps of an island large enough to be swept in colour order "
          "(`engine.native.coloured_from` manifolds, 1 024 by default: each packed field's one large island) run on every "
          "thread, colour by colour, and so do NNCG's steps between them, its packing into bundles and the "
          "impulses' return (`native/solver/coloured_sweeps.cpp`); an island swept in pair order with NNCG is one "
          "thread's. What stays on one thread bounds the speed-up: the position projection, the island grouping, "
          "the record of the step's contacts, and the large island's colouring and warm start (the stages' table "
          "below).", ""]
    sizes = sorted(rows, key=lambda s: int(rows[s][0][1]["bodies"]))
    md += ["| threads | " + " | ".join(f"field {s}: ms per step | speed-up" for s in sizes) + " |",
           "|---|" + "---|---|" * len(sizes)]
    counts = sorted({t for v in rows.values() for t, _ in v})
    for t in counts:
        cells = []
        for s in sizes:
            one = float(rows[s][0][1]["median_ms"])
            row = dict(rows[s]).get(t)
            cells += [f"{float(row['median_ms']):.2f}", f"{one / float(row['median_ms']):.2f}"] if row else ["-", "-"]
        md.append(f"| {t} | " + " | ".join(cells) + " |")
    md.append("")
    md += two_thread_targets(rows)
    # Stages against threads on the largest field timed: what scales and what stays on one thread.
    big = sizes[-1]
    names = [n for n in STAGE_LABELS if any(stages(r).get(n, 0.0) > 0.0 for _, r in rows[big])]
    md += [f"Field {big} by stage (mean ms per step):", "",
           "| stage | " + " | ".join(f"{t} thr." for t, _ in rows[big]) + f" | speed-up at {rows[big][-1][0]} |",
           "|---|" + "---|" * (len(rows[big]) + 1)]
    for n in names:
        ms = [stages(r).get(n, 0.0) for _, r in rows[big]]
        md.append(f"| {STAGE_LABELS[n]} | " + " | ".join(f"{m:.3f}" for m in ms)
                  + (f" | {ms[0] / ms[-1]:.2f} |" if ms[-1] > 0 else " | - |"))
    md.append("")
    figure(ctx, rows, sizes, big, names)
    md += ["![ms per step, speed-up and stages against threads](fig/threads.png)", ""]
    md_id, fails = identical(ctx, cores)
    return md + md_id, fails


def two_thread_targets(rows):
    """The thread target against what was measured: one thread's median over two threads'."""
    out = []
    for size in TARGET_SIZES:
        got = dict(rows.get(size, []))
        if 1 in got and 2 in got:
            x = float(got[1]["median_ms"]) / float(got[2]["median_ms"])
            out.append(f"- field {size}: two threads {x:.2f} times as fast as one (target at least "
                       f"{TARGET_TWO_THREADS:g}): {'met' if x >= TARGET_TWO_THREADS else 'not met'}.")
    return (["The thread target, as measured here:", ""] + out + [""]) if out else []


def identical(ctx, cores):
    """The runs on 1 thread and on every core: the same file to the byte, or a cross-check failure."""
    runs = [r for r in ctx.all_runs if r.tag.startswith("threads_identical_")]
    if not runs:
        return [], []
    fails, lines = [], []
    for order in IDENTICAL_ORDERS:
        pair = {r.meta["threads"]: r for r in runs if r.meta["order"] == order}
        one, many = read_bytes(pair[1].out), read_bytes(pair[cores].out)
        same = one == many
        lines.append(f"| {order} | {os.path.basename(pair[1].out)}, {os.path.basename(pair[cores].out)} | "
                     f"{len(one)} B, {len(many)} B | {'yes' if same else '**no**'} |")
        if not same:
            fails.append(f"threads: the {order}-order field run on 1 and on {cores} threads wrote different files "
                         f"({pair[1].out}, {pair[cores].out})")
    first = runs[0]
    md = [f"Does the thread count change the output? `{os.path.basename(first.scenario)}` run with "
          f"{' '.join('--set ' + s for s in first.sets[:3])} on 1 and on {cores} threads, in colour order (10 "
          "plain sweeps) and in pair order (native's defaults otherwise: NNCG); the HDF5 files (every body's state each 100 "
          "steps, every collision's impulses) compared byte for byte. Tolerance: none; the solver's order is fixed, "
          "so any difference is a bug.", "",
          "| order | files (runs/) | sizes | the same to the byte |", "|---|---|---|---|"] + lines + [""]
    return md, fails


def figure(ctx, rows, sizes, big, names):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, bx, cx) = plt.subplots(1, 3, figsize=(13, 3.8))
    for s in sizes:
        t = [x for x, _ in rows[s]]
        ms = [float(r["median_ms"]) for _, r in rows[s]]
        ax.plot(t, ms, "o-", label=f"field {s}")
        bx.plot(t, [ms[0] / m for m in ms], "o-", label=f"field {s}")
    counts = [t for t, _ in rows[big]]
    bx.plot(counts, counts, "k:", lw=0.8, label="ideal")
    ax.set_yscale("log")
    ax.set_ylabel("ms per step (median)")
    bx.set_ylabel("speed-up against 1 thread")
    colours = plt.get_cmap("tab20")(range(len(names)))
    first = sum(stages(rows[big][0][1]).values())
    for k, n in enumerate(names):
        ms = [stages(r).get(n, 0.0) for _, r in rows[big]]
        if max(ms) > 0.01 * first:   # the stages of at least 1 % of the step
            cx.plot(counts, ms, "o-", color=colours[k], label=STAGE_LABELS[n])
    cx.set_ylabel("ms per step (mean)")
    cx.set_ylim(bottom=0)
    cx.set_title(f"field {big}: stages", fontsize=9)
    for a in (ax, bx, cx):
        a.set_xscale("log", base=2)
        a.set_xticks(counts)
        a.set_xticklabels([str(t) for t in counts])
        a.set_xlabel("threads (FLOEDEM_THREADS)")
        a.legend(fontsize=7)
    row = rows[big][0][1]
    fig.suptitle(f"native, the field packed on its wall, {row['cpu']} ({row['host']})", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(ctx.fig, "threads.png"), dpi=110)
    plt.close(fig)
