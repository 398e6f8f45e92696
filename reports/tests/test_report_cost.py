"""The report's own cost section: each run counted once, in the section that planned it first;
sections ordered by run time; timing runs apart; shares that add up."""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from report_runner import Run, cost_lines  # noqa: E402


def run(tag, seconds, timed=False):
    r = Run(tag, "s.toml", bench_window=1.0 if timed else 0.0)
    r.seconds = seconds
    return r


def rows(md):
    out = {}
    for line in md:
        cells = [c.strip() for c in line.strip("|").split("|")]
        if line.startswith("| ") and cells[0] not in ("section",):
            out[cells[0]] = cells
    return out


def test_sections_are_ranked_by_run_time_and_timings_kept_apart():
    runs = [run("a1", 10.0), run("a2", 30.0), run("b1", 100.0), run("b_t", 20.0, timed=True), run("c1", 0.5)]
    owner = {"a1": "towing", "a2": "towing", "b1": "speed", "b_t": "speed", "c1": "impacts"}
    md = cost_lines(runs, owner, launch_seconds=95.0, jobs=2)
    assert md[0] == "## What this report cost"
    assert "5 runs, 160 s of run time" in md[2] and "20 s of it timing runs" in md[2] and "95 s with 2 runs" in md[2]
    table = [line for line in md if line.startswith("| ") and not line.startswith("| section")]
    assert [line.split("|")[1].strip() for line in table] == ["speed", "towing", "impacts"]
    r = rows(md)
    assert r["speed"][1:5] == ["2", "120", "74.8%", "20"] and r["speed"][5] == "100 (`b1`)"
    assert r["towing"][1:5] == ["2", "40", "24.9%", "0.0"] and r["towing"][5] == "30 (`a2`)"
    assert r["impacts"][3] == "0.3%"
    assert abs(sum(float(x[3].rstrip("%")) for x in r.values()) - 100.0) < 0.2


def test_runs_kept_from_an_earlier_launch_are_said():
    runs = [run("a", 10.0), run("b", 5.0)]
    runs[0].kept = True
    md = cost_lines(runs, {"a": "towing", "b": "towing"}, 5.0, 2)
    assert "2 runs (1 of them made by an earlier launch, at the time it took), 15 s of run time" in md[2]
    assert "earlier launch" not in cost_lines([run("b", 5.0)], {"b": "towing"}, 5.0, 2)[2]


def test_no_run_time_gives_zero_shares_not_a_division_by_zero():
    md = cost_lines([run("x", 0.0)], {"x": "impacts"}, 0.0, 1)
    assert rows(md)["impacts"][3] == "0.0%"
