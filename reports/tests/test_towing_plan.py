"""The towing cross-check's runs: each engine's ensemble at its own step (towing.ENGINE_DT), the
/tow rows 1 s means on every engine, and the scenario's step for the rest."""
import os
import sys
from types import SimpleNamespace

import pytest

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from sections import towing  # noqa: E402

ENGINES = ["native", "box2d", "bullet", "ode"]


def settings(run):
    return dict(s.split("=", 1) for s in run.sets)


@pytest.mark.parametrize("quick", [True, False])
def test_each_engine_runs_its_ensemble_at_its_own_step(quick):
    ctx = SimpleNamespace(quick=quick, scenarios="scenarios", engines=ENGINES)
    runs = towing.plan(ctx)
    for e in ENGINES:
        ensemble = [r for r in runs if r.tag == f"towing_{e}" or r.tag.startswith(f"towing_{e}_s")]
        assert len(ensemble) == towing.SEEDS_ENGINES[quick]
        for r in ensemble:
            s = settings(r)
            if e in towing.ENGINE_DT:
                dt = towing.ENGINE_DT[e]
                assert float(s["run.dt"]) == dt
                # 10 steps of 0.1 s: the same 1 s means at any step
                assert int(s["output.tow_every"]) * dt == pytest.approx(1.0)
            else:
                assert "run.dt" not in s and "output.tow_every" not in s
        # The seeds differ and nothing else does.
        rest = [{k: v for k, v in settings(r).items() if k != "run.seed"} for r in ensemble]
        assert all(x == rest[0] for x in rest)
        assert len({settings(r).get("run.seed") for r in ensemble}) == len(ensemble)
    assert towing.ENGINE_DT == {"bullet": 0.05}  # docs/engines.md gives this step its measurements
    # The sweeps and the other native runs keep the scenario's step.
    assert all(float(settings(r).get("run.dt", towing.DT)) == towing.DT
               for r in runs if r.engine == "native" and r.tag.startswith("towing_"))
