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
