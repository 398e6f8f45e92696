"""Runs of `floedem run` for the report: what to run (Run), and running a list of them in
parallel with a progress line per finished run. A run that fails stops nothing else; its
error is kept and the caller decides (the report fails at the end, naming it)."""
import concurrent.futures
import os
import subprocess
import sys
import time
from dataclasses import dataclass, field


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
    """Runs every Run (longest first, `jobs` at a time) into runs_dir, then the timing runs one
    at a time. Prints one line per finished run. Returns the runs that failed."""
    os.makedirs(runs_dir, exist_ok=True)
    for r in runs:
        r.out = os.path.join(runs_dir, r.tag + (".csv" if r.timed else ".h5"))
        for stale in (r.out, r.out + ".partial"):
            if os.path.exists(stale):
                os.remove(stale)
    order = sorted([r for r in runs if not r.timed], key=lambda r: -r.cost)
    timed = [r for r in runs if r.timed]
    start = time.monotonic()
    done = 0
    failed = []

    cores = os.cpu_count() or 1

    def one(r):
        # Threads per run: runs made side by side share the cores; a timing is single-threaded
        # unless it says otherwise (the thread-scaling runs).
        env = dict(os.environ)
        env["FLOEDEM_THREADS"] = str(r.threads or (1 if r.timed else max(1, cores // max(1, jobs))))
        t0 = time.monotonic()
        p = subprocess.run(r.command(floedem), capture_output=True, text=True, env=env)
        r.seconds = time.monotonic() - t0
        if p.returncode != 0:
            r.error = f"exit {p.returncode}: {p.stderr.strip()}"
        return r

    def finished():
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            futures = [pool.submit(one, r) for r in order]
            for future in concurrent.futures.as_completed(futures):
                yield future.result()
        for r in timed:   # alone: a timing shares the machine with nothing of ours
            yield one(r)

    for r in finished():
        done += 1
        status = "ok" if not r.error else ("failed" if r.meta.get("may_fail") else "FAILED")
        print(f"[{label} {done:4d}/{len(runs)}] {r.seconds:7.1f} s  {status:6s} {r.tag} ({r.engine})"
              f"   elapsed {time.monotonic() - start:6.0f} s", flush=True)
        if r.error and not r.meta.get("may_fail"):
            print(f"    {' '.join(r.command(floedem))}\n    {r.error}", file=sys.stderr, flush=True)
        if r.error:
            failed.append(r)
    return failed
