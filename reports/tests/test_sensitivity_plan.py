"""The sensitivity section's runs: each parameter at its low and high value with nothing else
changed, over the seeds, and the towing base asked for exactly as the towing section asks."""
import os
import sys
from types import SimpleNamespace

import pytest

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from sections import sensitivity, towing  # noqa: E402


@pytest.mark.parametrize("quick", [True, False])
def test_each_parameter_moves_alone_over_the_seeds(quick):
    root = os.path.dirname(os.path.dirname(HERE))
    ctx = SimpleNamespace(quick=quick, scenarios=os.path.join(root, "scenarios"), engines=["native"])
    runs = {r.tag: r for r in sensitivity.plan(ctx)}
    n = sensitivity.SEEDS[quick]
    base = set(runs[towing.seeded("sens_drift_base", 0)].sets)
    for label, key, default, lo, hi, _ in sensitivity.PARAMS:
        assert lo < default < hi or (lo <= default < hi)
        for side, value in (("lo", lo), ("hi", hi)):
            tag = sensitivity.key(label, side)
            for k in range(n):
                tow = runs[towing.seeded(f"sens_tow_{tag}", k)]
                assert f"{key}={value!r}" in tow.sets
                drift = runs[towing.seeded(f"sens_drift_{tag}", k)]
                moved = set(drift.sets) - set(runs[towing.seeded("sens_drift_base", k)].sets)
                assert moved == {f"{key}={value!r}"}
            assert f"{key}={value!r}" in runs[f"obs_sens_hans_{tag}_native"].sets
    assert not [s for s in base if s.startswith("contact.") or s.startswith("environment.")]
    # The base's towing runs are the towing section's, to the letter (the report refuses a tag
    # asked for twice in two ways).
    theirs = {r.tag: r for r in towing.plan(SimpleNamespace(quick=quick, scenarios=ctx.scenarios, engines=["native"]))}
    for k in range(n):
        tag = towing.seeded("towing_native", k)
        assert runs[tag].command("x") == theirs[tag].command("x")
