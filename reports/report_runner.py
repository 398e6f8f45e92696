"""Runs of `floedem run` for the report: what to run (Run), and running a list of them through
floedem.launch (Snakemake), with a progress line per finished run. A run that fails stops
nothing else; its error is kept and the caller decides (the report fails at the end, naming it)."""
import hashlib
import os
import sys
from dataclasses import dataclass, field

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(__file__))), "python"))
from floedem.launch import Job, launch  # noqa: E402


@dataclass
class Run:
    tag: str                    # unique name; the output is RUNS_DIR/TAG.h5
    scenario: str               # path of the scenario file
    engine: str = "native"
    sets: list = field(default_factory=list)   # --set KEY=VALUE strings
    cost: float = 1.0           # a guess of its wall time, to start the longest first
    out: str = ""               # filled in by run_all
    seconds: float = 0.0        # wall time, filled in by run_all
    error: str = ""             # stderr of a failed run
    meta: dict = field(default_factory=dict)   # what the section needs to read it back
    bench_window: float = 0.0   # > 0: a timing run, `floedem bench --window W`, into TAG.csv,
                                # made after the others, alone (nothing else shares the cores)
    threads: int = 0            # FLOEDEM_THREADS; 0: 1 for a timing run, else the cores / jobs
    bench_stages: bool = False  # a timing run that also times each stage (`floedem bench --stages`)
    stamp: str = ""             # filled in by run_all: the digest of the program and inputs
    kept: bool = False          # filled in by run_all: made by an earlier launch (--resume)

    @property
    def timed(self):
        return self.bench_window > 0.0

    def command(self, floedem):
        if self.timed:
            cmd = [floedem, "bench", self.scenario, "-e", self.engine, "--window", repr(self.bench_window),
                   "--csv", self.out, "-q"] + (["--stages"] if self.bench_stages else [])
        else:
            cmd = [floedem, "run", self.scenario, "-e", self.engine, "-o", self.out, "-q"]
        for s in self.sets:
            cmd += ["--set", s]
        return cmd


def _digest_file(path, h):
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)


class Stamps:
    """A run's stamp: a digest of the program (the floedem binary's bytes) and of the files beside
    its scenario (the scenario and whatever it reads from its folder: forcing files, charts).
    Equal stamps and equal commands give equal results (floedem's runs are deterministic), so a
    resumed report may keep a run made earlier under the same stamp."""

    def __init__(self, floedem):
        h = hashlib.sha256()
        _digest_file(os.path.realpath(floedem), h)
        self.program = h.hexdigest()
        self.folders = {}

    def folder(self, d):
        if d not in self.folders:
            h = hashlib.sha256()
            for name in sorted(os.listdir(d)):
                p = os.path.join(d, name)
                if os.path.isfile(p):
                    h.update(name.encode() + b"\0")
                    _digest_file(p, h)
            self.folders[d] = h.hexdigest()
        return self.folders[d]

    def of(self, run):
        return hashlib.sha256((self.program + self.folder(os.path.dirname(os.path.abspath(run.scenario))))
                              .encode()).hexdigest()


def _finished(runs_dir, r, floedem):
    """Whether r's output in runs_dir is a finished run of r's command under r's stamp."""
    import json
    p = os.path.join(runs_dir, ".floedem", "done", r.tag + ".json")
    if not os.path.exists(p) or not os.path.exists(r.out) or os.path.exists(r.out + ".partial"):
        return False
    try:
        with open(p) as f:
            rec = json.load(f)
    except (OSError, ValueError):
        return False
    # A failed run is made again, unless failing is one of its outcomes (the stress suite's).
    ok = rec.get("returncode") == 0 or r.meta.get("may_fail")
    return ok and rec.get("argv") == r.command(floedem) and rec.get("stamp") == r.stamp


def continuable(r):
    """A run `floedem run --resume` continues from its checkpoint: native's (the reference
    engines' would be made again from the start, which the launcher does anyway)."""
    return not r.timed and r.engine == "native"


def continuation(r, floedem):
    """The Job fields that let floedem.launch continue r's stopped output; none where it cannot."""
    if not continuable(r):
        return {}
    return dict(partial=r.out + ".partial", resume_argv=[floedem, "run", "--resume", r.out + ".partial", "-q"])


def run_all(runs, floedem, runs_dir, jobs, label="report", resume=False):
    """Runs every Run into runs_dir through floedem.launch (Snakemake, the project's one way of
    launching runs): `jobs` at a time, the longest first, then the timing runs one at a time,
    alone. Prints one line per finished run. Returns the runs that failed.

    resume: keep a run already in runs_dir whose record says it finished with the same command
    and the same stamp (Stamps); continue a native run stopped or killed under them from its
    checkpoint (floedem.launch: its RESULT.h5.partial); every other output is removed and made
    again."""
    os.makedirs(runs_dir, exist_ok=True)
    stamps = Stamps(floedem)
    kept = 0
    for r in runs:
        r.out = os.path.join(runs_dir, r.tag + (".csv" if r.timed else ".h5"))
        r.stamp = stamps.of(r)
        r.kept = resume and _finished(runs_dir, r, floedem)
        if r.kept:
            kept += 1
            continue
        # A native run's .partial stays: the launcher continues it if a try of this command and
        # stamp left it, and the run overwrites it otherwise.
        keep = r.out + ".partial" if continuable(r) else None
        for stale in (r.out, r.out + ".partial", os.path.join(runs_dir, ".floedem", "done", r.tag + ".json"),
                      os.path.join(runs_dir, ".floedem", "done", r.tag + ".failed.json")):
            if stale != keep and os.path.exists(stale):
                os.remove(stale)
    if resume:
        print(f"{label}: resuming: {kept} of {len(runs)} runs kept from before (same program, command and inputs)",
              flush=True)
    cores = len(os.sched_getaffinity(0))
    # Threads per run: runs made side by side share the cores; a timing is single-threaded
    # unless it says otherwise (the thread-scaling runs), and shares the machine with nothing.
    share = max(1, cores // max(1, jobs))
    untimed = sorted([r for r in runs if not r.timed], key=lambda r: -r.cost)
    todo = [Job(r.tag, r.command(floedem), threads=r.threads or share, priority=len(untimed) - k + 1000,
                may_fail=True, stamp=r.stamp, **continuation(r, floedem)) for k, r in enumerate(untimed)]
    ids = [j.id for j in todo]
    todo += [Job(r.tag, r.command(floedem), threads=r.threads or 1, alone=True, after=ids, may_fail=True,
                 stamp=r.stamp) for r in runs if r.timed]
    records, _ = launch(todo, runs_dir, cores=min(cores, max(1, jobs) * share), label=label)
    failed = []
    for r in runs:
        rec = records.get(r.tag)
        if rec is None:
            r.error = "not run (its job did not finish)"
        else:
            r.seconds = rec["seconds"]
            r.error = f"exit {rec['returncode']}: {rec['error']}" if rec["returncode"] else ""
        if r.error:
            failed.append(r)
    return failed


def cost_lines(runs, owner, launch_seconds, jobs):
    """The report's own cost, measured: per section (owner: run tag -> the section that planned it
    first), its runs, their run time (wall seconds of each process: on one thread each, its CPU
    time), the share of the report's run time, and its longest run; the timing runs, made alone
    on an otherwise idle machine, apart. A resumed report counts the runs it kept at the time
    their launch measured. Markdown lines, for the report's last section."""
    rows = {}
    for r in runs:
        row = rows.setdefault(owner[r.tag], dict(n=0, seconds=0.0, timed=0.0, longest=(0.0, "")))
        row["n"] += 1
        row["seconds"] += r.seconds
        if r.timed:
            row["timed"] += r.seconds
        if r.seconds > row["longest"][0]:
            row["longest"] = (r.seconds, r.tag)
    total = sum(x["seconds"] for x in rows.values())
    timed = sum(x["timed"] for x in rows.values())
    kept = sum(1 for r in runs if r.kept)
    earlier = f" ({kept} of them made by an earlier launch, at the time it took)" if kept else ""
    md = ["## What this report cost", "",
          f"{len(runs)} runs{earlier}, {total:.0f} s of run time (each run's wall time, on one thread unless the "
          f"section says otherwise), {timed:.0f} s of it timing runs made alone; the launch took {launch_seconds:.0f} s "
          f"with {jobs} runs at a time. By section, the most costly first:", "",
          "| section | runs | run time (s) | share | of it timing runs, alone (s) | longest run (s) |",
          "|---|---|---|---|---|---|"]
    def sec(t):
        return f"{t:.0f}" if t >= 10.0 else f"{t:.1f}"

    for name, x in sorted(rows.items(), key=lambda kv: -kv[1]["seconds"]):
        share = x["seconds"] / total if total > 0 else 0.0
        md.append(f"| {name} | {x['n']} | {sec(x['seconds'])} | {share:.1%} | {sec(x['timed'])} | "
                  f"{sec(x['longest'][0])} (`{x['longest'][1]}`) |")
    md.append("")
    return md
