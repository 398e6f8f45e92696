"""Sweeps and ensembles: a sweep file's parameter points x seeds x engines, run by Snakemake (on
this machine, or on a cluster through a profile), each run leaving a small JSON summary of the
figures asked for beside its HDF5, reduced at the end to one CSV row per point and engine with
the mean, the spread across seeds and a 95 % confidence interval, and a plot per figure and
varied parameter. The format is docs/sweeps.md of the repository.

    floedem sweep SPEC.toml --out DIR [--jobs N] [--profile PROFILE] [--dry-run]

Runs are named by a hash of what makes them (the scenario's text, the overrides, the engine, the
floedem version): one whose summary exists is not run again, a failed one is retried, a killed
native run continues from its checkpoint (floedem run --resume)."""
import hashlib
import itertools
import json
import math
import os
import subprocess
import sys
import time
import tomllib

import numpy as np

from . import figures as figs
from . import tdist
from . import towing
from .launch import Job, csv_text, launch, write_atomic
from .run import FileError, Run

KEYS = {"scenario", "engines", "set", "vary", "seeds", "figures", "threads_per_run", "decision"}


class SweepError(ValueError):
    """A sweep file refused: one line naming the file, the key and what is allowed."""


def _value_text(v):
    """A TOML value as --set takes it."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value_text(x) for x in v) + "]"
    return str(v)


def load(path):
    """The sweep file read and checked (not yet against the scenario: see check())."""
    try:
        with open(path, "rb") as f:
            spec = tomllib.load(f)
    except OSError as e:
        raise SweepError(f"{path}: cannot read it ({e.strerror})") from None
    except tomllib.TOMLDecodeError as e:
        raise SweepError(f"{path}: not TOML: {e}") from None
    for k in spec:
        if k not in KEYS:
            raise SweepError(f"{path}: {k}: unknown key; allowed {', '.join(sorted(KEYS))}")
    if not isinstance(spec.get("scenario"), str):
        raise SweepError(f"{path}: scenario: required, the scenario file (relative to the sweep file)")
    scenario = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(path)), spec["scenario"]))
    if not os.path.isfile(scenario):
        raise SweepError(f"{path}: scenario: {spec['scenario']}: no such file")
    engines = spec.get("engines", ["native"])
    if not isinstance(engines, list) or not engines or not all(isinstance(e, str) for e in engines):
        raise SweepError(f"{path}: engines: {engines!r}; allowed a non-empty list of engine names")
    common = spec.get("set", [])
    if not isinstance(common, list) or not all(isinstance(s, str) and "=" in s for s in common):
        raise SweepError(f"{path}: set: allowed a list of \"KEY=VALUE\" strings, as --set takes them")
    vary = spec.get("vary", {})
    if not isinstance(vary, dict):
        raise SweepError(f"{path}: vary: allowed a table of KEY = [values] or KEY = {{from, to, count}}")
    points = {}
    for key, v in vary.items():
        if isinstance(v, dict):
            extra = set(v) - {"from", "to", "count"}
            if extra or not all(k in v for k in ("from", "to", "count")):
                raise SweepError(f"{path}: vary.{key}: allowed a list, or {{from = A, to = B, count = N}}")
            if not (isinstance(v["count"], int) and v["count"] >= 1):
                raise SweepError(f"{path}: vary.{key}.count: {v['count']!r}; allowed an integer >= 1")
            values = [float(x) for x in np.linspace(float(v["from"]), float(v["to"]), v["count"])]
        elif isinstance(v, list):
            values = v
        else:
            raise SweepError(f"{path}: vary.{key}: {v!r}; allowed a list of values or a range table")
        if not values:
            raise SweepError(f"{path}: vary.{key}: empty; allowed at least one value")
        points[key] = values
    seeds = spec.get("seeds", {"count": 1})
    if not isinstance(seeds, dict) or set(seeds) - {"count", "values", "keys"} or \
            ("count" in seeds) == ("values" in seeds):
        raise SweepError(f"{path}: seeds: allowed count = N or values = [...], and keys = [...]")
    if "count" in seeds:
        if not (isinstance(seeds["count"], int) and 1 <= seeds["count"] <= 100000):
            raise SweepError(f"{path}: seeds.count: {seeds['count']!r}; allowed 1 to 100000")
        seed_values = list(range(1, seeds["count"] + 1))
    else:
        seed_values = seeds["values"]
        if not isinstance(seed_values, list) or not seed_values or \
                not all(isinstance(s, int) and s >= 0 for s in seed_values):
            raise SweepError(f"{path}: seeds.values: allowed a non-empty list of integers >= 0")
    seed_keys = seeds.get("keys", ["run.seed"])
    if not isinstance(seed_keys, list) or not seed_keys or not all(isinstance(k, str) for k in seed_keys):
        raise SweepError(f"{path}: seeds.keys: allowed a non-empty list of keys (run.seed: the field's too, "
                         "unless its [field] gives a seed of its own)")
    decision = None
    if "decision" in spec:
        try:
            decision = towing.check_decision(spec["decision"], path, list(points))
        except ValueError as e:
            raise SweepError(str(e)) from None
    figures = spec.get("figures", {})
    if not isinstance(figures, dict) or (not figures and decision is None):
        raise SweepError(f"{path}: figures: required, at least one [figures.NAME] table (or a [decision] table)")
    for name, f in figures.items():
        if not isinstance(f, dict):
            raise SweepError(f"{path}: figures.{name}: allowed a table")
        try:
            figs.check(name, f, path)
        except ValueError as e:
            raise SweepError(str(e)) from None
    threads = spec.get("threads_per_run", 1)
    if not (isinstance(threads, int) and 1 <= threads <= 256):
        raise SweepError(f"{path}: threads_per_run: {threads!r}; allowed 1 to 256")
    return dict(path=os.path.abspath(path), scenario=scenario, engines=engines, set=common, vary=points,
                seeds=seed_values, seed_keys=seed_keys, figures=figures, threads_per_run=threads, decision=decision)


def _floedem_text(floedem, *args):
    r = subprocess.run([floedem, *args], capture_output=True, text=True)
    return r.returncode, (r.stdout + r.stderr).strip()


def plan(spec, floedem):
    """Every run of the sweep: a list of jobs (id, engine, point, seed, overrides)."""
    code, version = _floedem_text(floedem, "--version")
    with open(spec["scenario"]) as f:
        text = f.read()
    keys = list(spec["vary"])
    jobs = []
    for values in itertools.product(*(spec["vary"][k] for k in keys)):
        point = dict(zip(keys, values))
        for seed in spec["seeds"]:
            for engine in spec["engines"]:
                overrides = list(spec["set"]) + [f"{k}={_value_text(v)}" for k, v in point.items()] + \
                    [f"{k}={seed}" for k in spec["seed_keys"]]
                digest = hashlib.sha256(json.dumps([text, overrides, engine, version]).encode()).hexdigest()[:16]
                jobs.append(dict(id=f"{engine}-{digest}", engine=engine, point=point, seed=seed, overrides=overrides))
    return jobs, version


def check(spec, floedem):
    """Before any run: the engines are known, and `floedem check` accepts the first point on every
    engine and every other value of each key (on the first engine). SweepError naming the key."""
    code, listed = _floedem_text(floedem, "engines")
    known = [line.split("\t")[0] for line in listed.splitlines() if line.strip()]
    for e in spec["engines"]:
        if e not in known:
            raise SweepError(f"{spec['path']}: engines: {e!r}: not an engine of this build; allowed {', '.join(known)}")
    first = {k: v[0] for k, v in spec["vary"].items()}
    tried = []
    base = list(spec["set"]) + [f"{k}={spec['seeds'][0]}" for k in spec["seed_keys"]]
    tried.append((base + [f"{k}={_value_text(v)}" for k, v in first.items()], spec["engines"]))
    for key, values in spec["vary"].items():
        for v in values[1:]:
            point = dict(first, **{key: v})
            tried.append((base + [f"{k}={_value_text(x)}" for k, x in point.items()], spec["engines"][:1]))
    for overrides, engines in tried:
        args = ["check", spec["scenario"]] + [a for o in overrides for a in ("--set", o)] + \
            [a for e in engines for a in ("--engine", e)]
        code, out = _floedem_text(floedem, *args)
        if code != 0:
            line = out.splitlines()[-1] if out else f"exit {code}"
            raise SweepError(f"{spec['path']}: refused by the scenario: {line.replace('floedem: error: ', '')}")


def _write_json(path, data):
    write_atomic(path, json.dumps(data, indent=1, sort_keys=True) + "\n")


def prepare(spec_path, out, floedem):
    """Checks the sweep and writes OUT/sweep.json (what the workflow runs). Returns it."""
    spec = load(spec_path)
    jobs, version = plan(spec, floedem)
    check(spec, floedem)
    try:
        os.makedirs(os.path.join(out, "runs"), exist_ok=True)
        probe = os.path.join(out, ".writable")
        open(probe, "w").close()
        os.remove(probe)
    except OSError as e:
        raise OSError(e.errno, f"{out}: cannot write the sweep there ({e.strerror})") from None
    sweep = dict(spec=spec, jobs=jobs, floedem=os.path.abspath(floedem), floedem_version=version,
                 python=sys.executable, threads_per_run=spec["threads_per_run"])
    _write_json(os.path.join(out, "sweep.json"), sweep)
    return sweep


def sweep(spec_path, out, floedem, jobs=None, profile=None, dry_run=False):
    """Checks, plans, runs (floedem.launch: Snakemake) and reduces a sweep; returns 0, or
    Snakemake's exit status when runs failed (the reduction is then not written)."""
    s = prepare(spec_path, out, floedem)
    sweep_json = os.path.abspath(os.path.join(out, "sweep.json"))
    todo = [Job(j["id"], [sys.executable, "-m", "floedem", "sweep-run", sweep_json, j["id"]],
                threads=s["threads_per_run"]) for j in s["jobs"]]
    n = len(todo)
    done = sum(os.path.exists(os.path.join(out, "runs", j["id"] + ".summary.json")) for j in s["jobs"])
    points = n // max(1, len(s["spec"]["engines"]) * len(s["spec"]["seeds"]))
    print(f"sweep: {n} runs ({len(s['spec']['engines'])} engines x {len(s['spec']['seeds'])} seeds x {points} points), "
          f"{done} done already, into {out}", flush=True)
    start = time.monotonic()
    _, status = launch(todo, out, jobs, profile, dry_run, label="sweep")
    if dry_run:
        return status
    missing = [j.id for j in todo if not os.path.exists(os.path.join(out, "runs", j.id + ".summary.json"))]
    if missing:
        print(f"sweep: {len(missing)} runs failed (their errors above); run the sweep again to retry them",
              file=sys.stderr)
        return status or 4
    reduce(sweep_json)
    decisions = f", {os.path.join(out, 'decisions.md')}" if s["spec"].get("decision") is not None else ""
    print(f"sweep: {os.path.join(out, 'reduced.csv')}{decisions} and plots in {os.path.join(out, 'plots')} "
          f"({time.monotonic() - start:.1f} s)")
    return 0


# ---------------------------------------------------------------------------------------------
# One run (the workflow's rule), and the reduction


def _complete(path, job):
    """True when `path` is a complete output of this job (its engine and overrides; the version
    and the scenario's text are in the job's id, hence in the path)."""
    if not os.path.exists(path):
        return False
    try:
        with Run(path) as r:
            return r.status == "complete" and r.engine == job["engine"] and \
                [o for o in r.attrs.get("overrides", "").split("\n") if o] == job["overrides"]
    except FileError:
        return False


def run_one(sweep_json, job_id):
    """Runs one job (or continues it from its checkpoint, or finds it done) and writes its summary."""
    with open(sweep_json) as f:
        s = json.load(f)
    job = next(j for j in s["jobs"] if j["id"] == job_id)
    out = os.path.join(os.path.dirname(sweep_json), "runs", job_id + ".h5")
    env = dict(os.environ)   # FLOEDEM_THREADS: the job's share, set by floedem.launch
    start = time.monotonic()
    how = "reused"
    if not _complete(out, job):
        if os.path.exists(out + ".partial") and job["engine"] == "native":
            cmd = [s["floedem"], "run", "--quiet", "--resume", out + ".partial"]
            how = "resumed"
        else:
            cmd = [s["floedem"], "run", "--quiet", s["spec"]["scenario"], "--engine", job["engine"], "--out", out] + \
                [a for o in job["overrides"] for a in ("--set", o)]
            how = "run"
        r = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if r.returncode != 0:
            sys.stderr.write(f"sweep: run {job_id} failed (exit {r.returncode}): {(r.stderr or r.stdout).strip()}\n")
            return r.returncode
    wall = time.monotonic() - start
    with Run(out) as run:
        values = figs.compute(run, s["spec"]["figures"])
        summary = dict(id=job_id, engine=job["engine"], point=job["point"], seed=job["seed"],
                       overrides=job["overrides"], scenario=s["spec"]["scenario"],
                       floedem_version=run.attrs.get("floedem_version"), steps=run.summary.get("steps"),
                       wall_seconds=wall if how != "reused" else None, how=how, figures=values)
        if s["spec"].get("decision") is not None:
            summary["tow"] = towing.run_record(run)
    _write_json(out[:-3] + ".summary.json", summary)
    return 0


def interval(values):
    """(n, mean, std across seeds, half-width of the 95 % confidence interval of the mean):
    Student's t with n - 1 degrees of freedom (NaN half-width for a single run)."""
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], float)
    n = len(v)
    if n == 0:
        return 0, math.nan, math.nan, math.nan
    mean = float(v.mean())
    if n == 1:
        return 1, mean, math.nan, math.nan
    std = float(v.std(ddof=1))
    return n, mean, std, tdist.ppf(0.975, n - 1) * std / math.sqrt(n)


def reduce(sweep_json):
    """OUT/reduced.csv (a row per parameter point and engine) and OUT/plots/FIGURE.STAT.png."""
    with open(sweep_json) as f:
        s = json.load(f)
    out = os.path.dirname(sweep_json)
    summaries = []
    for j in s["jobs"]:
        with open(os.path.join(out, "runs", j["id"] + ".summary.json")) as f:
            summaries.append(json.load(f))
    keys = list(s["spec"]["vary"])
    names = list(summaries[0]["figures"]) if summaries else []
    groups = {}
    for x in summaries:
        groups.setdefault((x["engine"],) + tuple(json.dumps(x["point"][k]) for k in keys), []).append(x)
    rows = []
    for (engine, *point), runs in groups.items():
        row = dict(engine=engine, **{k: json.loads(p) for k, p in zip(keys, point)}, runs=len(runs))
        walls = [r["wall_seconds"] for r in runs if r["wall_seconds"] is not None]
        row["wall_seconds_mean"] = float(np.mean(walls)) if walls else math.nan
        for name in names:
            n, mean, std, half = interval([r["figures"][name] for r in runs])
            row.update({f"{name}_mean": mean, f"{name}_std": std, f"{name}_ci95": half, f"{name}_n": n})
        rows.append(row)
    columns = ["engine"] + keys + ["runs", "wall_seconds_mean"] + \
        [f"{name}_{q}" for name in names for q in ("mean", "std", "ci95", "n")]
    tmp = os.path.join(out, "reduced.csv.partial")
    with open(tmp, "w", newline="") as f:
        f.write(csv_text(columns, rows))
    _plots(out, rows, keys, names, s["spec"]["engines"])
    if s["spec"].get("decision") is not None:
        towing.write_decisions(out, summaries, keys, s["spec"]["decision"])
    os.replace(tmp, os.path.join(out, "reduced.csv"))
    return rows


def _plots(out, rows, keys, names, engines):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(os.path.join(out, "plots"), exist_ok=True)
    numeric = [k for k in keys if all(isinstance(r[k], (int, float)) and not isinstance(r[k], bool) for r in rows)]
    for name in names:
        for key in numeric or [None]:
            fig, ax = plt.subplots(figsize=(6, 4))
            others = [k for k in keys if k != key]
            for engine in engines:
                lines = {}
                for r in rows:
                    if r["engine"] == engine:
                        lines.setdefault(tuple(json.dumps(r[k]) for k in others), []).append(r)
                for other, rs in lines.items():
                    rs.sort(key=lambda r: r[key] if key else 0)
                    x = [r[key] for r in rs] if key else [0] * len(rs)
                    label = engine + ("" if not others else " (" + ", ".join(f"{k}={json.loads(v)}" for k, v in
                                                                            zip(others, other)) + ")")
                    ax.errorbar(x, [r[f"{name}_mean"] for r in rs],
                                yerr=[0.0 if math.isnan(r[f"{name}_ci95"]) else r[f"{name}_ci95"] for r in rs],
                                marker="o", capsize=3, label=label)
            ax.set_xlabel(key or "")
            ax.set_ylabel(f"{name} (mean, 95 % CI across seeds)")
            ax.grid(True, lw=0.3)
            ax.legend(fontsize=7)
            fig.tight_layout()
            fig.savefig(os.path.join(out, "plots", f"{name}{'.' + key if key else ''}.png"), dpi=100)
            plt.close(fig)
