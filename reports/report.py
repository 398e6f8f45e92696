#!/usr/bin/env python3
"""The cross-engine report: runs the scenario suite on every engine (a progress line per
run), then writes OUT/REPORT.md with its figures in OUT/fig and the runs in OUT/runs. Every
figure and table is made here from the runs made here. Exit status: 0 when the engines agree
within the documented tolerances, 5 when they do not (each disagreement printed, the report
written all the same), 4 when a run failed (no report written).

`floedem report [--quick] [--out DIR]` runs this (the main job runs the quick one).

usage: report.py [--floedem build/floedem] [--out results/report] [--quick] [--jobs N] [--only S,...] [--resume]
"""
import argparse
import datetime
import os
import platform
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.realpath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from report_runner import cost_lines, run_all  # noqa: E402  (it puts the floedem package on the path)
from floedem.launch import write_atomic  # noqa: E402
from sections import SECTIONS  # noqa: E402
from sections.speed import load_stage_labels  # noqa: E402


REFERENCE_ENGINES = ["box2d", "bullet", "ode"]   # floedem's own references (docs/engines.md)
# References that join only the sections measured with them: MuJoCo's contact is the scene's
# spring-dashpot, whose shortest pulse on a towing field asks for 66 substeps of dt = 0.1 s
# (about 3 h a towing run on one core; docs/engines.md), so it runs the impact suite alone.
PARTIAL_ENGINES = {"mujoco": ["impacts"]}


class Context:
    """What every section sees: the options, where things go, and the runs by tag."""

    def __init__(self, a, engines, partial):
        self.floedem = a.floedem
        self.quick = a.quick
        self.out = os.path.abspath(a.out)
        self.fig = os.path.join(self.out, "fig")
        self.runs_dir = os.path.join(self.out, "runs")
        self.scenarios = os.path.join(ROOT, "scenarios")
        self.engines = engines          # native first
        self.partial = partial          # engine -> the sections it joins (PARTIAL_ENGINES)
        self.all_runs = []
        self.jobs = a.jobs              # runs at a time
        self.launch_seconds = 0.0       # wall time of launching every run (report_runner.run_all)

    def run(self, tag):
        for r in self.all_runs:
            if r.tag == tag:
                return r
        raise KeyError(f"report: no run {tag}")


def floedem_text(floedem, *args):
    return subprocess.run([floedem, *args], capture_output=True, text=True, check=True).stdout


def git_commit():
    # A copy of the tree whose .git is absent or not its own (a machine lent for one run) is
    # given its commit here.
    if os.environ.get("FLOEDEM_SOURCE_COMMIT"):
        return os.environ["FLOEDEM_SOURCE_COMMIT"] + " (as given by FLOEDEM_SOURCE_COMMIT)"
    try:
        c = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
        d = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True)
        return c.stdout.strip() + (" (with uncommitted changes)" if d.stdout.strip() else "") if c.returncode == 0 \
            else "unknown (not a git checkout)"
    except OSError:
        return "unknown (no git)"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--floedem", default=os.path.join(ROOT, "build", "floedem"))
    ap.add_argument("--out", default=os.path.join(ROOT, "results", "report"))
    ap.add_argument("--quick", action="store_true",
                    help="the same sections on smaller and shorter cases (the CI cross-check, a few minutes)")
    ap.add_argument("--jobs", type=int, default=len(os.sched_getaffinity(0)),
                    help="runs at a time (default: the CPUs this process may use)")
    ap.add_argument("--resume", action="store_true",
                    help="keep the runs an interrupted report into the same --out finished, where the program, "
                         "the command and the scenario's folder are the same as now; make the rest")
    names = [s.__name__.split(".")[-1] for s in SECTIONS]
    ap.add_argument("--only", default="",
                    help=f"a partial report of these sections alone, comma-separated ({', '.join(names)})")
    a = ap.parse_args()
    only = [x for x in a.only.split(",") if x]
    unknown = [x for x in only if x not in names]
    if unknown:
        print(f"report: --only: no section {', '.join(unknown)} (sections: {', '.join(names)})", file=sys.stderr)
        return 2
    sections = [s for s, n in zip(SECTIONS, names) if not only or n in only]
    start = time.monotonic()
    commit = git_commit()   # now: the tree the runs are made from
    version = floedem_text(a.floedem, "--version").strip()
    listed = [line.split("\t")[0] for line in floedem_text(a.floedem, "engines").splitlines() if line.strip()]
    engines = ["native"] + [e for e in listed if e != "native" and e not in PARTIAL_ENGINES]
    partial = {e: PARTIAL_ENGINES[e] for e in listed if e in PARTIAL_ENGINES}
    # A build configured without a reference engine (FLOEDEM_WITH_ODE=OFF, ...) reports on the
    # engines it has; what it skips is said here and at the head of the report.
    missing = [e for e in REFERENCE_ENGINES if e not in engines]
    if missing:
        print(f"report: this build has no {', '.join(missing)} engine: their runs and checks are skipped", flush=True)
    ctx = Context(a, engines, partial)
    load_stage_labels(a.floedem)
    # Nothing in the report may come from an earlier run, except, with --resume, runs of the same
    # program, command and inputs (report_runner.run_all checks each): the runs are deterministic.
    for d in (ctx.fig,) if a.resume else (ctx.fig, ctx.runs_dir):
        shutil.rmtree(d, ignore_errors=True)
    for d in (ctx.fig, ctx.runs_dir):
        os.makedirs(d, exist_ok=True)
    report = os.path.join(ctx.out, "REPORT.md")
    if os.path.exists(report):
        os.remove(report)

    seen, owner = {}, {}   # tag -> its run, and the section that asked for it first
    for section, name in ((s, n) for s, n in zip(SECTIONS, names) if s in sections):
        for r in section.plan(ctx):
            if r.tag in seen:
                if seen[r.tag].command("x") != r.command("x"):
                    raise SystemExit(f"report: two sections ask for run {r.tag} differently")
                continue
            seen[r.tag] = r
            owner[r.tag] = name
            ctx.all_runs.append(r)
    print(f"report: {len(ctx.all_runs)} runs on {', '.join(engines)}, {a.jobs} at a time, into {ctx.runs_dir}",
          flush=True)
    launch_start = time.monotonic()
    failed = run_all(ctx.all_runs, a.floedem, ctx.runs_dir, a.jobs, "report", resume=a.resume)
    ctx.launch_seconds = time.monotonic() - launch_start
    # The stress suite's runs may fail (a non-finite state is one of its outcomes): not an error.
    failed = [r for r in failed if not r.meta.get("may_fail")]
    if failed:
        for r in failed:
            print(f"report: run {r.tag} failed: {r.error}", file=sys.stderr)
        print(f"report: {len(failed)} runs failed; no REPORT.md written", file=sys.stderr)
        return 4
    run_seconds = time.monotonic() - start

    body, fails = [], []
    for section in sections:
        md, f = section.write(ctx)
        body += md
        fails += f
    body += cost_lines(ctx.all_runs, owner, ctx.launch_seconds, a.jobs)
    total = time.monotonic() - start
    kept = sum(1 for r in ctx.all_runs if r.kept)
    # A resumed report's run time is this launch's: the runs kept were made by an earlier one.
    resumed = (f" ({kept} of the runs made by an earlier launch of the same command into the same directory)"
               if kept else "")
    flags = ((" --quick" if a.quick else "") + (" --resume" if a.resume else "") +
             (f" --only {','.join(only)}" if only else ""))
    head = [f"# floedem cross-engine report{' (--quick)' if a.quick else ''}"
            f"{' (sections: ' + ', '.join(only) + ')' if only else ''}", "",
            f"Written {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC by `floedem report"
            f"{flags}` ({version}, source commit {commit}) on {platform.node()} "
            f"({os.cpu_count()} cores, {a.jobs} runs at a time): {len(ctx.all_runs)} runs in {run_seconds:.0f} s, "
            f"{total:.0f} s in all{resumed}. Every table and figure below comes from the HDF5 files of those runs, in "
            "`runs/` (each table names its files); none is typed or kept from an earlier report.", ""]
    if missing:
        head += [f"This build has no {', '.join(missing)} engine (configured off, or its library not found): the "
                 "runs and checks on it are skipped, and the report compares the engines it has.", ""]
    head += ["## Cross-check", ""]
    if fails:
        head += [f"**{len(fails)} disagreement{'s' if len(fails) > 1 else ''} beyond the documented tolerances:**", ""] + [f"- {x}" for x in fails]
    else:
        head += ["Every engine agrees with native, and native with the closed forms, within the tolerances stated "
                 "in each section."]
    head.append("")
    write_atomic(report, "\n".join(head + body) + "\n")
    for x in fails:
        print(f"report: DISAGREEMENT: {x}", file=sys.stderr)
    print(f"report: {report} ({len(fails)} disagreements, {total:.0f} s)", flush=True)
    return 5 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
