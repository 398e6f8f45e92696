"""A report resumed after a kill (`floedem report --resume`): a run is kept only where it finished
under the same program, the same command and the same files beside its scenario; anything else
is made again. And floedem.launch never takes a record of another command for a job's."""
import json
import os
import shutil
import sys

import pytest

HERE = os.path.dirname(os.path.realpath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))
from report_runner import Run, run_all  # noqa: E402
from floedem.launch import Job, forget_stale  # noqa: E402

FLOEDEM = os.environ.get("FLOEDEM", os.path.join(ROOT, "build", "floedem"))

SCENE = """
[run]
duration = 2.0
dt = 0.1
[[body]]
name = "a"
polygon = [[0, 0], [10, 0], [10, 10], [0, 10]]
thickness = 1.0
velocity = [0.5, 0.0]
"""


def make_runs(scene):
    return [Run("one", str(scene)), Run("two", str(scene), sets=["run.duration=3.0"])]


def stamps(runs):
    return {r.tag: os.stat(r.out).st_mtime_ns for r in runs}


@pytest.fixture
def setup(tmp_path, monkeypatch):
    if not os.path.exists(FLOEDEM):
        pytest.skip(f"no floedem command at {FLOEDEM}")
    # The launcher's jobs run `python -m floedem launch-one`: the package of this checkout.
    monkeypatch.setenv("PYTHONPATH", os.path.join(ROOT, "python"))
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (scenes / "s.toml").write_text(SCENE)
    return scenes / "s.toml", tmp_path / "runs"


def test_a_resumed_report_keeps_finished_runs_and_makes_the_rest(setup, capsys):
    scene, runs_dir = setup
    runs = make_runs(scene)
    assert run_all(runs, FLOEDEM, str(runs_dir), 1, "t") == []
    before = stamps(runs)
    # Killed before "two" finished: its record is gone, a partial file is left.
    os.remove(runs_dir / ".floedem" / "done" / "two.json")
    shutil.copy(runs[1].out, runs[1].out + ".partial")
    runs = make_runs(scene)
    assert run_all(runs, FLOEDEM, str(runs_dir), 1, "t", resume=True) == []
    assert "1 of 2 runs kept" in capsys.readouterr().out
    assert [r.kept for r in runs] == [True, False]   # what the report's head counts
    after = stamps(runs)
    assert after["one"] == before["one"]
    assert after["two"] != before["two"]
    assert not os.path.exists(runs[1].out + ".partial")


def test_a_changed_command_or_input_is_run_again(setup, capsys):
    scene, runs_dir = setup
    runs = make_runs(scene)
    run_all(runs, FLOEDEM, str(runs_dir), 1, "t")
    before = stamps(runs)
    runs = make_runs(scene)
    runs[1].sets = ["run.duration=4.0"]
    run_all(runs, FLOEDEM, str(runs_dir), 1, "t", resume=True)
    assert "1 of 2 runs kept" in capsys.readouterr().out
    mid = stamps(runs)
    assert mid["one"] == before["one"] and mid["two"] != before["two"]
    # A file beside the scenario (a forcing file, a chart) changes every run's stamp.
    (scene.parent / "wind.csv").write_text("time,u,v\n0,1,0\n")
    runs = make_runs(scene)
    runs[1].sets = ["run.duration=4.0"]
    run_all(runs, FLOEDEM, str(runs_dir), 1, "t", resume=True)
    assert "0 of 2 runs kept" in capsys.readouterr().out
    assert all(stamps(runs)[k] != mid[k] for k in mid)


def test_without_resume_nothing_is_kept(setup, capsys):
    scene, runs_dir = setup
    runs = make_runs(scene)
    run_all(runs, FLOEDEM, str(runs_dir), 1, "t")
    before = stamps(runs)
    runs = make_runs(scene)
    run_all(runs, FLOEDEM, str(runs_dir), 1, "t")
    assert all(stamps(runs)[k] != before[k] for k in before)


def test_launch_forgets_a_record_of_another_command_or_stamp(tmp_path):
    done = tmp_path / ".floedem" / "done"
    done.mkdir(parents=True)
    jobs = [Job("a", ["x", "1"], stamp="s"), Job("b", ["x", "2"], stamp="s"), Job("c", ["x", "3"], stamp="s")]
    (done / "a.json").write_text(json.dumps(dict(returncode=0, argv=["x", "1"], stamp="s")))
    (done / "b.json").write_text(json.dumps(dict(returncode=0, argv=["x", "2", "more"], stamp="s")))
    (done / "c.failed.json").write_text(json.dumps(dict(returncode=1, argv=["x", "3"], stamp="old")))
    assert sorted(forget_stale(jobs, str(tmp_path))) == ["b", "c"]
    assert sorted(os.listdir(done)) == ["a.json"]


def same_file(a, b):
    """Every dataset and attribute of two HDF5 files, the same to the bit."""
    import h5py
    import numpy as np
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        names = []
        fa.visit(names.append)
        other = []
        fb.visit(other.append)
        assert sorted(names) == sorted(other)
        for obj in [""] + names:
            x, y = (fa[obj] if obj else fa), (fb[obj] if obj else fb)
            assert sorted(x.attrs) == sorted(y.attrs), obj
            for k in x.attrs:
                assert np.array_equal(np.asarray(x.attrs[k]), np.asarray(y.attrs[k])), (obj, k)
            if isinstance(x, h5py.Dataset):
                assert x.shape == y.shape and x[()].tobytes() == y[()].tobytes(), obj


def test_a_run_stopped_by_sigterm_is_continued_from_its_checkpoint(setup, monkeypatch):
    # SIGTERM after step 7 of 30 (a cluster's notice): floedem checkpoints that step and exits
    # 143; the launcher records nothing, and its next try continues the run rather than
    # starting over. The file is the uninterrupted run's.
    scene, runs_dir = setup
    whole = [Run("two", str(scene), sets=["run.duration=3.0"])]
    assert run_all(whole, FLOEDEM, str(runs_dir / "whole"), 1, "t") == []
    monkeypatch.setenv("FLOEDEM_TEST_TERM_AT_STEP", "7")
    runs = [Run("two", str(scene), sets=["run.duration=3.0"])]
    assert run_all(runs, FLOEDEM, str(runs_dir / "cut"), 1, "t") == []
    with open(runs_dir / "cut" / ".floedem" / "done" / "two.json") as f:
        assert json.load(f)["continued"] is True
    same_file(whole[0].out, runs[0].out)
    # Stopped, then the report resumed: the partial of this command is continued, too.
    runs = [Run("two", str(scene), sets=["run.duration=3.0"])]
    assert run_all(runs, FLOEDEM, str(runs_dir / "again"), 1, "t") == []
    os.remove(runs[0].out)
    os.remove(runs_dir / "again" / ".floedem" / "done" / "two.json")
    shutil.copy(whole[0].out, runs[0].out + ".partial")   # as a run's file stands before its rename
    monkeypatch.delenv("FLOEDEM_TEST_TERM_AT_STEP")
    runs = [Run("two", str(scene), sets=["run.duration=3.0"])]
    assert run_all(runs, FLOEDEM, str(runs_dir / "again"), 1, "t", resume=True) == []
    with open(runs_dir / "again" / ".floedem" / "done" / "two.json") as f:
        assert json.load(f)["continued"] is True
    same_file(whole[0].out, runs[0].out)
