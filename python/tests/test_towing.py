"""floedem.towing: the odds and the design loads on samples with known answers, and a tug's
outcome read back from its run."""
import math
import os

import numpy as np
import pytest

import floedem
from floedem import towing

from conftest import floedem as run_floedem


def test_wilson_interval_known_values():
    # Wilson (1927) at 95 %: 0 of 10 gives [0, 0.2775], 5 of 10 [0.2366, 0.7634].
    lo, hi = towing.wilson_interval(0, 10)
    assert lo == 0.0 and hi == pytest.approx(0.2775, abs=1e-4)
    lo, hi = towing.wilson_interval(5, 10)
    assert (lo, hi) == (pytest.approx(0.2366, abs=1e-4), pytest.approx(0.7634, abs=1e-4))
    with pytest.raises(ValueError):
        towing.wilson_interval(11, 10)


def test_wilson_interval_covers_a_binomial_proportion():
    # 4 000 ensembles of 40 tows, each succeeding with p = 0.15: the 95 % interval holds p in
    # about 95 % of them (binomial standard error of that share 0.0035; the Wilson interval's
    # coverage at n = 40 oscillates between about 0.93 and 0.97, Brown, Cai and DasGupta 2001).
    rng = np.random.default_rng(7)
    k = rng.binomial(40, 0.15, size=4000)
    held = [lo <= 0.15 <= hi for lo, hi in (towing.wilson_interval(int(x), 40) for x in k)]
    assert 0.925 <= np.mean(held) <= 0.975


def test_seeds_for_an_interval_of_ten_per_cent():
    n = towing.seeds_for_half_width(0.10)
    lo, hi = towing.wilson_interval(n // 2, n)
    assert (hi - lo) / 2 <= 0.10
    lo, hi = towing.wilson_interval((n - 2) // 2, n - 2)
    assert (hi - lo) / 2 > 0.10
    assert 85 <= n <= 100  # the Wald count 1.96^2 / 4 / 0.1^2 = 96, Wilson's a little fewer


def test_odds_criteria_and_smallest_pull():
    base = {"parted": False, "speed_made_good": 0.4, "distance": 600.0, "stalled_time": 0.0}
    assert towing.succeeded(base, min_speed=0.3, min_distance=500.0)
    assert not towing.succeeded(dict(base, parted=True))
    assert towing.succeeded(dict(base, parted=True), no_parting=False)
    assert not towing.succeeded(base, min_speed=0.5)
    assert not towing.succeeded(dict(base, stalled_time=100.0), max_stalled=60.0)
    o = towing.odds([True] * 18 + [False] * 2)
    assert o["p"] == 0.9 and o["n"] == 20 and o["lo"] < 0.9 < o["hi"]
    points = [(1e6, towing.odds([True] * 5 + [False] * 15)), (2e6, towing.odds([True] * 19 + [False])),
              (3e6, towing.odds([True] * 20))]
    assert towing.smallest_pull(points, 0.9, conservative=False) == 2e6
    assert towing.smallest_pull(points, 0.8) == 3e6       # 19 of 20: its lower end is 0.76
    assert towing.smallest_pull(points, 0.99) is None


def test_gev_fit_and_return_levels_on_a_gev_sample():
    from scipy.stats import genextreme
    xi, mu, sigma = 0.1, 1e6, 2e5
    x = genextreme.rvs(-xi, loc=mu, scale=sigma, size=4000, random_state=3)
    fit = towing.gev_fit(x)
    assert fit["shape"] == pytest.approx(xi, abs=0.04)
    assert fit["loc"] == pytest.approx(mu, rel=0.02)
    assert fit["scale"] == pytest.approx(sigma, rel=0.04)
    # The closed form against scipy's quantile, at the fit's own parameters.
    for T in (10, 100):
        assert towing.return_level(fit, T) == pytest.approx(
            genextreme.ppf(1 - 1 / T, -fit["shape"], fit["loc"], fit["scale"]), rel=1e-10)
    gumbel = {"shape": 0.0, "loc": 1.0, "scale": 2.0}
    assert towing.return_level(gumbel, 100) == pytest.approx(1.0 - 2.0 * math.log(-math.log(0.99)), rel=1e-12)


def test_maxima_that_differ_by_round_off_get_no_fit():
    # A line's largest tension set by the tug: 16 tows within parts in 10^5 of each other (as a
    # planning sweep measures them) is one load, not a tail; a spread of 1 % is one to fit.
    tug = 6.14e5 * (1.0 + 1e-5 * np.arange(16))
    with pytest.raises(ValueError, match="distinct at 0.0001 of their mean"):
        towing.gev_fit(tug)
    towing.gev_fit(6.14e5 * (1.0 + 1e-2 * np.sin(np.arange(16))))


def test_design_loads_bootstrap_interval_holds_the_true_level():
    # 48 tows (a planner's ensemble): the 10-tow load's 95 % interval holds the true one.
    from scipy.stats import genextreme
    xi, mu, sigma = 0.05, 1e6, 2e5
    x = genextreme.rvs(-xi, loc=mu, scale=sigma, size=48, random_state=11)
    rows, fit = towing.design_loads(x, periods=(10, 100), boot=200, seed=1)
    true10 = genextreme.ppf(0.9, -xi, mu, sigma)
    assert rows[0]["lo"] <= true10 <= rows[0]["hi"]
    assert rows[0]["lo"] < rows[0]["level"] < rows[0]["hi"]
    assert rows[1]["level"] > rows[0]["level"]
    assert rows[1]["hi"] - rows[1]["lo"] > rows[0]["hi"] - rows[0]["lo"]  # the longer period, the wider
    text = towing.table(rows, ["period", "level", "lo", "hi"])
    assert text.startswith("| period | level | lo | hi |") and text.count("\n") == 4
    # None (no pull reaches the odds) is an empty cell, not the word
    assert towing.table([dict(a=None, b=1.0)], ["a", "b"]).splitlines()[-1] == "|  | 1 |"


TUG = """
[run]
duration = 300.0
dt = 1.0
output_every = 10
[environment]
[[body]]
name = "berg"
kind = "iceberg"
polygon = [[-20.0,-20.0],[20.0,-20.0],[20.0,20.0],[-20.0,20.0]]
draft = 30.0
sail_height = 5.0
[tow]
mode = "tug"
body = "berg"
bollard_pull = 1e5
free_running_speed = 6.0
direction = [1.0, 0.0]
stiffness = 2e4
length = 200.0
damping = 1e4
breaking_load = 1.2e5
"""


def test_a_tugs_outcome_read_back(tmp_path):
    scene = tmp_path / "tug.toml"
    scene.write_text(TUG)
    run_floedem("run", "-q", str(scene), "-o", str(tmp_path / "tug.h5"))
    with floedem.open(tmp_path / "tug.h5") as r:
        assert r.tow.attrs["mode"] == "tug"
        o = r.tow.outcome
        assert o["parted"] and 0.0 < o["parted_at"] < 300.0
        assert o["tension_max"] <= 1.2e5 and o["tension_p99"] <= o["tension_max"] * 1.006
        assert np.all(r.tow.tension_max[1:] >= 0.0) and r.tow.tug_velocity.shape == (len(r.tow), 2)
        assert list(o["direction"]) == [1.0, 0.0]
        assert o["speed_made_good"] == pytest.approx(o["distance"] / 300.0)
        assert not towing.succeeded(o)


PLAN = """
scenario = "{scenario}"
[vary]
"tow.bollard_pull" = [3e4, 6e4]
[seeds]
count = 10
[decision]
min_speed = 0.3
probability = 0.8
periods = [10, 100]
"""


def test_a_planning_sweep_gives_the_odds_the_smallest_pull_and_design_loads(tmp_path):
    # Two pulls x 10 field seeds of a small berg towed through 60 % ice (tug_field.toml): the
    # smaller pull makes about 0.22 m/s, the larger 0.36. The reduction against the runs' own
    # outcomes: the odds and their interval, the partings and the GEV levels.
    import csv
    here = os.path.dirname(os.path.abspath(__file__))
    spec = tmp_path / "plan.toml"
    spec.write_text(PLAN.format(scenario=os.path.join(here, "tug_field.toml")))
    out = tmp_path / "plan"
    r = run_floedem("sweep", str(spec), "--out", str(out), "--jobs", "2")
    assert "decisions.md" in r.stdout
    with open(out / "decisions.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 2
    outcomes = {}
    for h5 in (out / "runs").glob("*.h5"):
        with floedem.open(h5) as run:
            pull = float([o for o in run.attrs["overrides"].split("\n") if o.startswith("tow.bollard_pull=")][0]
                         .split("=")[1])
            outcomes.setdefault(pull, []).append(towing.run_record(run))
    for row in rows:
        mine = outcomes[float(row["tow.bollard_pull"])]
        assert len(mine) == 10
        expect = towing.odds([towing.succeeded(o, min_speed=0.3) for o in mine])
        assert float(row["p"]) == expect["p"] and float(row["lo"]) == pytest.approx(expect["lo"])
        assert int(row["parted"]) == sum(o["parted"] for o in mine)
        fit = towing.gev_fit([o["tension_max"] for o in mine])
        assert float(row["tension_max_10_level"]) == pytest.approx(towing.return_level(fit, 10), rel=1e-9)
        assert float(row["tension_max_100_level"]) >= float(row["tension_max_10_level"])
    text = (out / "decisions.md").read_text()
    assert "| engine | tow.bollard_pull | n | successes | p | lo | hi | parted |" in text
    assert "The smallest `tow.bollard_pull`" in text
    assert [float(r["p"]) for r in sorted(rows, key=lambda r: float(r["tow.bollard_pull"]))] == [0.0, 1.0]
    assert (out / "plots" / "towability.png").stat().st_size > 0


@pytest.mark.parametrize("edit, needle", [
    ("probability = 0.8", "decision.probability"),
    ("periods = [10, 100]", "decision.periods"),
    ("min_speed = 0.3", "decision.min_speed"),
])
def test_bad_decision_tables_are_refused_before_any_run(tmp_path, edit, needle):
    here = os.path.dirname(os.path.abspath(__file__))
    bad = {"probability = 0.8": "probability = 1.5", "periods = [10, 100]": "periods = [1, 10]",
           "min_speed = 0.3": "min_speed = -1.0"}[edit]
    spec = tmp_path / "plan.toml"
    spec.write_text(PLAN.format(scenario=os.path.join(here, "tug_field.toml")).replace(edit, bad))
    r = run_floedem("sweep", str(spec), "--out", str(tmp_path / "o"), check=False)
    assert r.returncode == 2 and needle in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "o" / "runs").exists() or not any((tmp_path / "o" / "runs").iterdir())
