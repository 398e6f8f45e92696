"""The verdict rules of the report's section "Against observations" (docs/validation.md)."""
import json
import os
import sys

import pytest

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from sections import observations as obs  # noqa: E402


def test_single_figures():
    assert obs.verdict(0.02, (0.016, 0.023)) == ("inside", "")
    assert obs.verdict(0.016, (0.016, 0.023))[0] == "inside"        # the ends belong to the range
    v, how = obs.verdict(0.0171, (0.010, 0.015))
    assert v == "outside" and how == "1.1x the upper end"
    v, how = obs.verdict(14.65, (20.0, 40.0))
    assert v == "outside" and how == "0.73x the lower end"


def test_angles_are_given_in_degrees():
    assert obs.verdict(9.9, (-6.0, 9.0), angle=True) == ("outside", "0.9 deg above")
    assert obs.verdict(-7.5, (-6.0, 9.0), angle=True) == ("outside", "1.5 deg below")
    assert obs.verdict(0.0, (-6.0, 9.0), angle=True)[0] == "inside"


def test_ranges_inside_overlapping_and_apart():
    assert obs.verdict((0.3, 0.4), (0.2, 0.6))[0] == "inside"
    assert obs.verdict((0.047, 0.35), (0.2, 0.6))[0] == "overlaps"
    v, how = obs.verdict((9.4e6, 1.65e8), (0.0, 2.4e6))
    assert v == "outside" and how == "3.9x the upper end"
    assert obs.passes("inside") and obs.passes("overlaps") and not obs.passes("outside")


def test_ensemble_verdicts_are_on_the_interval_of_the_mean():
    # Eight seeds well inside: the interval (mean +- t s / sqrt(n)) is inside, and every resample agrees.
    v, how, settled = obs.ensemble_verdict([0.019, 0.0195, 0.0188, 0.0192, 0.0191, 0.0189, 0.0193, 0.019],
                                           (0.016, 0.023))
    assert (v, how, settled) == ("inside", "", 1.0)
    # A mean inside whose interval reaches past the end: overlaps, not inside.
    m, half, sd = obs.interval([0.0155, 0.0175, 0.016, 0.017])
    assert m - half < 0.016 < m + half
    assert obs.ensemble_verdict([0.0155, 0.0175, 0.016, 0.017], (0.016, 0.023))[0] == "overlaps"
    # Apart: the factor from the interval's nearest end, not from the mean.
    values = [0.0171, 0.0175, 0.0168, 0.019, 0.0172, 0.018, 0.0169, 0.0177]
    m, half, _ = obs.interval(values)
    v, how, settled = obs.ensemble_verdict(values, (0.010, 0.015))
    assert v == "outside" and how == f"{(m - half) / 0.015:.2g}x the upper end" and settled == 1.0
    # An interval that straddles the end: another set of seeds may well fall either side.
    v, _, settled = obs.ensemble_verdict([15.1, 14.2, 16.0, 17.5, 15.0, 14.8, 15.3, 16.1], (10.0, 15.0), angle=True)
    assert v == "overlaps" and settled < obs.SETTLED
    # The resamples are a fixed stream: the same seeds, the same share.
    assert obs.ensemble_verdict([15.1, 14.2, 16.0, 17.5], (10.0, 15.0), True) == \
        obs.ensemble_verdict([15.1, 14.2, 16.0, 17.5], (10.0, 15.0), True)


def rows(**verdicts):
    return [dict(id=k, case="c", quantity="q", engine="native", observed="o", simulated="s", verdict=v, how="h")
            for k, v in verdicts.items()]


def test_only_a_recorded_pass_that_stops_passing_fails():
    recorded = {"a": "pass", "b": "miss", "c": "pass"}
    fails, newly = obs.regressions(rows(a="outside", b="outside", c="overlaps", d="inside"), recorded)
    assert len(fails) == 1 and "passed before" in fails[0]          # a: a regression
    assert newly == ["d"]                                            # d: passes, not recorded yet
    fails, newly = obs.regressions(rows(a="inside", b="inside"), recorded)
    assert fails == [] and newly == ["b"]                            # b: an improvement, named


@pytest.mark.parametrize("kind", ["quick", "full"])
def test_committed_verdicts_are_pass_or_miss(kind):
    path = os.path.join(os.path.dirname(HERE), obs.verdicts_name(kind == "quick"))
    with open(path) as f:
        recorded = json.load(f)
    assert recorded and set(recorded.values()) <= {"pass", "miss"}
