"""floedem sweep: a small sweep through Snakemake on this machine, its cache, a kill and a rerun,
its reduction against one done by hand from the run files, its refusals, and the Slurm profile's
job commands (run by a stand-in sbatch)."""
import csv
import math
import os
import signal
import subprocess
import time

import numpy as np
import pytest

import floedem
from conftest import ROOT, floedem as run_floedem

ENGINES = ["native", "box2d"]
SPEC = """
scenario = "{scenario}"
engines = {engines}
set = ["run.duration=60", "field.width=300.0", "field.height=200.0", "field.origin=[-100.0, -100.0]",
       "run.output_every=1000"]
[vary]
"field.concentration" = [0.3, 0.6]
[seeds]
count = 2
[figures.ice_force]
series = "tow.ice_force_mean"
stats = ["mean", "p99"]
after_travel = 10.0
[figures.collisions]
series = "collisions.count"
stats = ["count"]
"""


def engines():
    listed = [line.split("\t")[0] for line in run_floedem("engines").stdout.splitlines()]
    return [e for e in ENGINES if e in listed]


def spec(tmp_path, text=None, **replace):
    body = (text or SPEC).format(scenario=os.path.join(ROOT, "scenarios", "towing_paper.toml"),
                                 engines=str(engines()).replace("'", '"'))
    for old, new in replace.items():
        body = body.replace(old, new)
    path = tmp_path / "sweep.toml"
    path.write_text(body)
    return path


def reduced(out):
    with open(out / "reduced.csv") as f:
        return list(csv.DictReader(f))


def by_hand(out):
    """The reduction from the run files alone: the mean ice force after 10 m of travel."""
    groups = {}
    for h5 in sorted((out / "runs").glob("*.h5")):
        with floedem.open(h5) as r:
            x = r.tow.tug_position[:, 0]
            keep = (x - x[0] >= 10.0)
            keep[0] = False
            keep[np.argmax(keep):] = True
            value = float(np.mean(r.tow.ice_force_mean[keep, 0]))
            conc = [o for o in r.attrs["overrides"].split("\n") if o.startswith("field.concentration")][0]
            groups.setdefault((r.engine, float(conc.split("=")[1])), []).append(value)
    return groups


def test_small_sweep_reduces_as_by_hand_and_runs_nothing_twice(tmp_path):
    out = tmp_path / "out"
    r = run_floedem("sweep", str(spec(tmp_path)), "--out", str(out))
    n_engines = len(engines())
    assert f"sweep: {4 * n_engines} runs" in r.stdout
    rows = reduced(out)
    assert len(rows) == 2 * n_engines
    hand = by_hand(out)
    for row in rows:
        values = hand[(row["engine"], float(row["field.concentration"]))]
        assert int(row["runs"]) == len(values) == 2
        assert float(row["ice_force.mean_mean"]) == pytest.approx(np.mean(values), rel=1e-12)
        assert float(row["ice_force.mean_std"]) == pytest.approx(np.std(values, ddof=1), rel=1e-12)
        # 95 % interval of a mean of two: t(0.975, 1 dof) = 12.7062 standard errors.
        assert float(row["ice_force.mean_ci95"]) == pytest.approx(12.7062 * np.std(values, ddof=1) / math.sqrt(2),
                                                                  rel=1e-4)
    assert (out / "plots" / "ice_force.mean.field.concentration.png").exists()
    summaries = sorted((out / "runs").glob("*.summary.json"))
    assert len(summaries) == 4 * n_engines
    stamps = [p.stat().st_mtime_ns for p in summaries]
    again = run_floedem("sweep", str(spec(tmp_path)), "--out", str(out))
    assert f"{4 * n_engines} done already" in again.stdout
    assert [p.stat().st_mtime_ns for p in summaries] == stamps


def test_a_sweep_killed_half_way_finishes_when_run_again(tmp_path):
    out = tmp_path / "out"
    path = spec(tmp_path, **{'"run.duration=60"': '"run.duration=240"'})
    p = subprocess.Popen([os.environ.get("FLOEDEM", os.path.join(ROOT, "build", "floedem")), "sweep", str(path),
                          "--out", str(out), "--jobs", "1"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                         start_new_session=True)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not list((out / "runs").glob("*.summary.json")):
        time.sleep(0.05)
    os.killpg(p.pid, signal.SIGKILL)
    p.wait()
    done = len(list((out / "runs").glob("*.summary.json")))
    total = 4 * len(engines())
    assert 1 <= done < total, "the kill was meant to land half way"
    r = run_floedem("sweep", str(path), "--out", str(out))
    assert f"{done} done already" in r.stdout
    assert len(list((out / "runs").glob("*.summary.json"))) == total
    assert len(reduced(out)) == 2 * len(engines())


@pytest.mark.parametrize("edit, needle", [
    ({"[vary]": "colour = 3\n[vary]"}, "colour: unknown key"),
    ({'"field.concentration" = [0.3, 0.6]': '"field.concentration" = []'}, "vary.field.concentration: empty"),
    ({'"field.concentration" = [0.3, 0.6]': '"field.concentration" = [0.3, 1.5]'}, "field.concentration"),
    ({'"field.concentration" = [0.3, 0.6]': '"field.colour" = [1, 2]'}, "field.colour"),
    ({"engines = ": 'engines = ["native", "nosuch"] #'}, "engines: 'nosuch'"),
    ({'series = "tow.ice_force_mean"': 'series = "tow.nothing"'}, "figures.ice_force.series"),
])
def test_bad_sweeps_are_refused_before_any_run(tmp_path, edit, needle):
    out = tmp_path / "out"
    r = run_floedem("sweep", str(spec(tmp_path, **edit)), "--out", str(out), check=False)
    assert r.returncode == 2, r.stdout + r.stderr
    assert needle in r.stderr and r.stderr.count("\n") == 1, r.stderr
    assert not list(out.glob("runs/*")) if out.exists() else True


def test_unwritable_output_is_exit_3(tmp_path):
    r = run_floedem("sweep", str(spec(tmp_path)), "--out", "/proc/floedem-sweep", check=False)
    assert r.returncode == 3 and "/proc/floedem-sweep" in r.stderr


def test_slurm_profile_jobs_run_through_sbatch(tmp_path):
    # A stand-in sbatch that records its options and runs the job script: the profile's
    # commands, as Snakemake renders them, carry out the sweep.
    fake = tmp_path / "bin"
    fake.mkdir()
    log = tmp_path / "sbatch.log"
    (fake / "sbatch").write_text("#!/usr/bin/env bash\n"
                                 f'echo "$@" >> {log}\n'
                                 'script="${@: -1}"\n'
                                 'nohup bash "$script" > /dev/null 2>&1 &\n'
                                 "echo $RANDOM\n")
    (fake / "sbatch").chmod(0o755)
    out = tmp_path / "out"
    env = dict(os.environ, PATH=f"{fake}:{os.environ['PATH']}")
    r = subprocess.run([os.environ.get("FLOEDEM", os.path.join(ROOT, "build", "floedem")), "sweep",
                        str(spec(tmp_path)), "--out", str(out), "--profile", os.path.join(ROOT, "profiles", "slurm")],
                       env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    submitted = log.read_text().splitlines()
    assert len(submitted) == 4 * len(engines())   # the runs; the reduction is local
    assert all("--cpus-per-task=1" in s and "--job-name=floedem-job" in s for s in submitted)
    assert len(reduced(out)) == 2 * len(engines())
    # A dry run plans the same jobs and submits nothing.
    d = subprocess.run([os.environ.get("FLOEDEM", os.path.join(ROOT, "build", "floedem")), "sweep",
                        str(spec(tmp_path)), "--out", str(tmp_path / "dry"), "--profile",
                        os.path.join(ROOT, "profiles", "slurm"), "--dry-run"],
                       env=env, capture_output=True, text=True)
    assert d.returncode == 0 and "job0 " in d.stdout + d.stderr
    assert len(log.read_text().splitlines()) == len(submitted)


def test_a_killed_native_run_continues_from_its_checkpoint(tmp_path):
    # Two floes, 6 000 steps with a frame each: a checkpoint follows the first 4 096 frames. The
    # test hook kills every run at step 5 000 (SIGKILL, as a lost node would), so the first sweep
    # fails after its retries; the second, without the hook, continues from the checkpoint.
    scene = tmp_path / "two.toml"
    scene.write_text('[run]\nduration = 60.0\ndt = 0.01\n[[body]]\nname = "a"\n'
                     'polygon = [[0, 0], [10, 0], [10, 10], [0, 10]]\nthickness = 1.0\nvelocity = [0.2, 0.0]\n'
                     '[[body]]\nname = "b"\npolygon = [[20, 0], [30, 0], [20, 12]]\nthickness = 1.0\n')
    path = tmp_path / "sweep.toml"
    path.write_text(f'scenario = "{scene}"\n[vary]\n"contact.restitution" = [0.1]\n'
                    '[figures.ke]\nseries = "summary.kinetic_energy_end"\n')
    out = tmp_path / "out"
    command = os.environ.get("FLOEDEM", os.path.join(ROOT, "build", "floedem"))
    killed = subprocess.run([command, "sweep", str(path), "--out", str(out)], capture_output=True, text=True,
                            env=dict(os.environ, FLOEDEM_TEST_KILL_AT_STEP="5000"))
    assert killed.returncode != 0
    partial = list((out / "runs").glob("*.h5.partial"))
    assert len(partial) == 1
    with floedem.open(partial[0]) as p:
        assert p.status == "running"
    r = run_floedem("sweep", str(path), "--out", str(out))
    summaries = list((out / "runs").glob("*.summary.json"))
    assert len(summaries) == 1 and '"how": "resumed"' in summaries[0].read_text(), r.stdout
    # The continued run is the uninterrupted one: the same final energy.
    whole = tmp_path / "whole.h5"
    run_floedem("run", "-q", str(scene), "-o", str(whole), "--set", "contact.restitution=0.1", "--set", "run.seed=1")
    with floedem.open(whole) as a, floedem.open(out / "runs" / (summaries[0].name[:-len(".summary.json")] + ".h5")) as b:
        np.testing.assert_array_equal(a.position[-1], b.position[-1])
