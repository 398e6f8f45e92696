"""How floedem launches runs, for the report and for sweeps alike: a list of jobs (a command
each) run by Snakemake, on this machine (`cores` at a time) or on a cluster through a Snakemake
profile. Each job is one rule of a Snakefile written for the list (its threads, its priority:
the longest first, and what must finish before it); each leaves a record of its exit status and
wall time in WORKDIR/.floedem/done/ID.json, so that a job done is never run again, and a list
stopped half way and launched again runs only what is missing. A job whose command fails is
retried (twice) unless it may fail (its failure is then recorded, not retried). A job stopped
by a signal (a cluster's SIGTERM: `floedem run` checkpoints its step first) leaves no record,
and where it names how to continue its output, the next try continues it rather than starting
over."""
import csv
import io
import json
import os
import signal
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, field


@dataclass
class Job:
    id: str                       # unique; letters, digits, '-', '_' and '.'
    argv: list                    # the command
    threads: int = 1              # cores it takes, and its FLOEDEM_THREADS
    alone: bool = False           # nothing else runs beside it (a timing): it holds every core
    priority: float = 0.0         # higher first (the report: its cost guess, longest first)
    after: list = field(default_factory=list)   # ids of jobs that must finish before it
    may_fail: bool = False        # a failure is an outcome (recorded, not retried)
    stamp: str = ""               # what the job's result depends on beyond its command (a digest
                                  # of the program and its inputs): a record with another stamp
                                  # or command is not this job's, and the job runs again
    partial: str = ""             # the output a stopped or killed try leaves (RESULT.h5.partial)
    resume_argv: list = field(default_factory=list)  # the command that continues it (floedem run
                                  # --resume); used when `partial` is there and was left by a try
                                  # of this job's command and stamp (WORKDIR/.floedem/started/)


def _rule(job, index):
    deps = ", ".join(f'".floedem/done/{a}.json"' for a in job.after)
    threads = "workflow.cores" if job.alone else str(job.threads)
    lines = [f"rule job{index}:",
             f"    output: \".floedem/done/{job.id}.json\""]
    if deps:
        lines.append(f"    input: {deps}")
    lines += [f"    threads: {threads}",
              f"    priority: {int(job.priority)}",
              f"    shell: \"{{PY}} -m floedem launch-one {{LAUNCH}} {job.id} --threads {{threads}}\""]
    return "\n".join(lines)


def write_atomic(path, text):
    """Writes text to path through PATH.partial and a rename, so that a reader (a resumed sweep,
    Snakemake) never finds half a file under the final name."""
    with open(path + ".partial", "w") as f:
        f.write(text)
    os.replace(path + ".partial", path)


def csv_text(columns, rows):
    """Rows (dicts) as CSV text with a header, floats as repr (they read back to the bit)."""
    out = io.StringIO(newline="")
    w = csv.DictWriter(out, fieldnames=columns)
    w.writeheader()
    for row in rows:
        w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in row.items()})
    return out.getvalue()


def write(jobs, workdir, label):
    """WORKDIR/.floedem/launch.json and the Snakefile of the list."""
    meta = os.path.join(workdir, ".floedem")
    os.makedirs(os.path.join(meta, "done"), exist_ok=True)
    ids = [j.id for j in jobs]
    if len(set(ids)) != len(ids):
        raise ValueError("launch: two jobs have the same id")
    spec = dict(label=label, python=sys.executable, jobs=[asdict(j) for j in jobs])
    path = os.path.join(meta, "launch.json")
    write_atomic(path, json.dumps(spec))
    # Priorities: Snakemake orders ready jobs by them; rank the costs so that ties stay stable.
    text = ["# Written by floedem (python/floedem/launch.py) for this list of jobs; rewritten at each launch.",
            f"PY = {json.dumps(sys.executable)}", f"LAUNCH = {json.dumps(os.path.abspath(path))}", "",
            "rule all:", "    input: [" + ", ".join(f'".floedem/done/{i}.json"' for i in ids) + "]", "",
            "localrules: all", ""]
    text += [_rule(j, k) + "\n" for k, j in enumerate(jobs)]
    snakefile = os.path.join(meta, "Snakefile")
    write_atomic(snakefile, "\n".join(text))
    return path, snakefile


def forget_stale(jobs, workdir):
    """Removes the records of jobs whose command or stamp has changed since they ran, so that a
    list launched again reruns them rather than taking an old result for theirs. Returns the
    ids whose records were removed."""
    stale = []
    for j in jobs:
        for name in (j.id + ".json", j.id + ".failed.json"):
            p = os.path.join(workdir, ".floedem", "done", name)
            if not os.path.exists(p):
                continue
            try:
                with open(p) as f:
                    rec = json.load(f)
            except (OSError, ValueError):
                rec = {}
            if rec.get("argv", j.argv) != j.argv or rec.get("stamp", "") != j.stamp:
                os.remove(p)
                stale.append(j.id)
    return stale


def launch(jobs, workdir, cores=None, profile=None, dry_run=False, label="launch", quiet=True):
    """Runs the jobs not yet done (a job whose command or stamp changed is not done); returns
    {id: record} for every job with a record (exit status, wall time, error) and Snakemake's
    exit status."""
    forget_stale(jobs, workdir)
    _, snakefile = write(jobs, workdir, label)
    cores = cores or len(os.sched_getaffinity(0))
    args = [sys.executable, "-m", "snakemake", "--snakefile", snakefile, "--directory", os.path.abspath(workdir),
            "--rerun-incomplete", "--keep-going",
            # A launch killed half way leaves Snakemake's lock behind: one launch at a time per
            # directory, and no lock to clear by hand before the launch that finishes it.
            "--nolock"]
    if quiet and not dry_run:   # the progress lines are launch-one's; a dry run lists the jobs
        args += ["--quiet", "all"]
    if profile:
        args += ["--profile", profile]
    else:
        args += ["--cores", str(cores), "--retries", "2"]
    if dry_run:
        args += ["--dry-run"]
    status = subprocess.run(args).returncode
    return records(jobs, workdir), status


def records(jobs, workdir):
    out = {}
    for j in jobs:
        for name in (j.id + ".json", j.id + ".failed.json"):
            p = os.path.join(workdir, ".floedem", "done", name)
            if os.path.exists(p):
                with open(p) as f:
                    out[j.id] = json.load(f)
                break
    return out


# Exit statuses of a command stopped by a signal: killed (negative), or `floedem run`'s own
# 128 + N after it wrote the checkpoint of its last step.
STOPPED = {128 + signal.SIGTERM, 128 + signal.SIGINT}


def _started_here(started, job):
    """Whether the job's last try was of this command and stamp (so its partial output is this
    job's to continue)."""
    try:
        with open(started) as f:
            rec = json.load(f)
    except (OSError, ValueError):
        return False
    return rec.get("argv") == job["argv"] and rec.get("stamp", "") == job.get("stamp", "")


def run_one(launch_json, job_id, threads):
    """The workflow's rule: runs one job's command (or continues its stopped output), records
    it, prints a progress line."""
    with open(launch_json) as f:
        spec = json.load(f)
    job = next(j for j in spec["jobs"] if j["id"] == job_id)
    meta = os.path.dirname(launch_json)
    done = os.path.join(meta, "done")
    env = dict(os.environ, FLOEDEM_THREADS=str(max(1, job["threads"] if job["alone"] else threads)))
    partial, resume = job.get("partial", ""), job.get("resume_argv", [])
    continued = False
    if partial and resume:   # only a job that can be continued keeps a record of its tries
        started = os.path.join(meta, "started", job_id + ".json")
        os.makedirs(os.path.dirname(started), exist_ok=True)
        continued = os.path.exists(partial) and _started_here(started, job)
        write_atomic(started, json.dumps(dict(argv=job["argv"], stamp=job.get("stamp", ""))))
    t0 = time.monotonic()
    p = subprocess.run(resume if continued else job["argv"], capture_output=True, text=True, env=env)
    seconds = time.monotonic() - t0
    if p.returncode < 0 or p.returncode in STOPPED:
        # Stopped, not finished: no record, so the job is tried again (and continued, where it can).
        print(f"[{spec['label']}] {seconds:7.1f} s  stopped {job_id}: {(p.stderr or p.stdout).strip()[-300:]}",
              file=sys.stderr, flush=True)
        return p.returncode if p.returncode > 0 else 1
    record = dict(returncode=p.returncode, seconds=seconds, error=(p.stderr or p.stdout).strip()[-2000:]
                  if p.returncode else "", argv=job["argv"], stamp=job.get("stamp", ""), continued=continued)
    ok = p.returncode == 0
    target = os.path.join(done, job_id + (".json" if ok or job["may_fail"] else ".failed.json"))
    write_atomic(target, json.dumps(record))
    # This launch's finished jobs: a folder reused with another plan keeps other jobs' records.
    ids = {j["id"] for j in spec["jobs"]}
    count = len([n for n in os.listdir(done) if n.endswith(".json") and n[:-len(".json")] in ids])
    status = "ok" if ok else ("failed" if job["may_fail"] else "FAILED")
    print(f"[{spec['label']} {count:4d}/{len(spec['jobs'])}] {seconds:7.1f} s  {status:6s} {job_id}", flush=True)
    if not ok and not job["may_fail"]:
        print(f"    {' '.join(job['argv'])}\n    {record['error']}", file=sys.stderr, flush=True)
        return p.returncode
    return 0
