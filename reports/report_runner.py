"""Runs of `floedem run` for the report: what to run (Run), and running a list of them through
floedem.launch (Snakemake), with a progress line per finished run. A run that fails stops
nothing else; its error is kept and the caller decides (the report fails at the end, naming it)."""
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


def run_all(runs, floedem, runs_dir, jobs, label="report"):
    """Runs every Run into runs_dir through floedem.launch (Snakemake, the project's one way of
    launching runs): `jobs` at a time, the longest first, then the timing runs one at a time,
    alone. Prints one line per finished run. Returns the runs that failed."""
    os.makedirs(runs_dir, exist_ok=True)
    for r in runs:
        r.out = os.path.join(runs_dir, r.tag + (".csv" if r.timed else ".h5"))
        for stale in (r.out, r.out + ".partial"):
            if os.path.exists(stale):
                os.remove(stale)
    cores = len(os.sched_getaffinity(0))
    # Threads per run: runs made side by side share the cores; a timing is single-threaded
    # unless it says otherwise (the thread-scaling runs), and shares the machine with nothing.
    share = max(1, cores // max(1, jobs))
    untimed = sorted([r for r in runs if not r.timed], key=lambda r: -r.cost)
    todo = [Job(r.tag, r.command(floedem), threads=r.threads or share, priority=len(untimed) - k + 1000,
                may_fail=True) for k, r in enumerate(untimed)]
    ids = [j.id for j in todo]
    todo += [Job(r.tag, r.command(floedem), threads=r.threads or 1, alone=True, after=ids, may_fail=True)
             for r in runs if r.timed]
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
