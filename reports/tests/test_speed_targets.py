"""The speed and thread targets of the report's sections "Speed" and "Threads": each verdict
from the rows a run would write, and the tables of where native's step goes."""
import os
import sys

import pytest

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from sections import speed, threads  # noqa: E402


@pytest.fixture(autouse=True)
def labels():
    # What `floedem stages` prints, for the stages these rows name.
    speed.STAGE_LABELS.clear()
    speed.STAGE_LABELS.update({"forcing": "forcing", "narrow_phase": "narrow phase", "contact_solve": "contact solve",
                               "redetect": "redetect"})


def row(bodies, median, stage_ms="", engine="native", penetration=0.001):
    return dict(bodies=str(bodies), median_ms=str(median), stage_ms=stage_ms, engine=engine,
                max_penetration_m=str(penetration))


def test_cost_per_floe_against_its_target():
    small = row(16000, 30.0)
    assert speed.per_floe_growth(small, row(100000, 30.0 * 100000 / 16000)) == pytest.approx(1.0)
    assert speed.per_floe_growth(small, row(100000, 250.0)) == pytest.approx(250.0 / 100000 / (30.0 / 16000))
    met = speed.targets({}, {}, {"speed_default_16k_native": small,
                                 "speed_default_100k_native": row(100000, 1.1 * 30.0 * 100000 / 16000 - 1e-6)})
    assert any("cost per floe" in line and "1.10 times" in line and line.endswith(": met.") for line in met)
    missed = speed.targets({}, {}, {"speed_default_16k_native": small, "speed_default_100k_native": row(100000, 250.0)})
    assert any("cost per floe" in line and "1.33 times" in line and "not met" in line for line in missed)
    # Without both fields (a quick report), no verdict is given.
    assert not any("cost per floe" in line for line in speed.targets({}, {}, {"speed_default_16k_native": small}))


def test_scaling_names_the_stage_that_grows_and_the_largest():
    small = row(16000, 30.0, "forcing=1 narrow_phase=4 contact_solve=24 redetect=0.2")
    large = row(100000, 250.0, "forcing=6.25 narrow_phase=25 contact_solve=200 redetect=2.5")
    text = " ".join(speed.stages_scaling(small, large, "native's defaults"))
    assert text.startswith("With native's defaults, from 16000 to 100000 floes (6.25 times as many)")
    assert "The largest stage, contact solve (86 % of the step), grows 1.33 times per floe." in text
    assert "redetect 2.0 times (0.20 -> 2.5 ms)" in text        # grown by 1.5 times or more: named
    assert "forcing" not in text.split("more than 1.5 times")[1]   # the same per floe: not named
    assert speed.stages_scaling(small, None, "x") == []
    assert "sweeps" not in text                                  # rows from before the work column
    small["work"], large["work"] = "sweeps=50 islands=103 redetections=0.17", "sweeps=50 islands=743 redetections=0.56"
    text = " ".join(speed.stages_scaling(small, large, "native's defaults"))
    assert ("A step's sweeps (its longest island's, mean): 50.0 at 16000 floes and 50.0 at 100000; the same "
            "number, so the contact solve's growth per floe is in the cost of a sweep, not in their number.") in text
    large["work"] = "sweeps=62.5"
    text = " ".join(speed.stages_scaling(small, large, "native's defaults"))
    assert "50.0 at 16000 floes and 62.5 at 100000. " in text and "cost of a sweep" not in text


def test_two_threads_against_their_target():
    rows = {"16k": [(1, row(16000, 32.0)), (2, row(16000, 20.0))],
            "100k": [(1, row(100000, 260.0)), (2, row(100000, 170.0))],
            "4k": [(1, row(4000, 7.0)), (2, row(4000, 7.0))]}
    lines = threads.two_thread_targets(rows)
    assert "- field 16k: two threads 1.60 times as fast as one (target at least 1.6): met." in lines
    assert "- field 100k: two threads 1.53 times as fast as one (target at least 1.6): not met." in lines
    assert not any("field 4k" in line for line in lines)       # not a target size
    assert threads.two_thread_targets({"16k": [(1, row(16000, 32.0))]}) == []   # one thread only: no verdict


def test_stage_tables_label_defaults_and_equal_iterations(tmp_path):
    class Ctx:
        fig = str(tmp_path)

    stage = "forcing=1 narrow_phase=4 contact_solve=24 redetect=0.2"
    defaults = {"speed_default_16k_native": row(16000, 30.0, stage)}
    rows = {"speed_field_16k_native": row(16000, 12.0, "forcing=1 narrow_phase=4 contact_solve=5 redetect=0.2"),
            "speed_towing_native": row(5000, 0.4, "forcing=0.05 contact_solve=0.2")}
    md = speed.stages_section(Ctx(), rows, defaults)
    text = "\n".join(md)
    first, second = text.index("With native's defaults"), text.index("At 10 plain sweeps")
    assert first < second
    assert "| **sum** | **29.200** |" in text[first:second]         # the defaults' table: its one field
    assert "| **sum** | **0.250** | **10.200** |" in text[second:]  # the towing case, then the field
    assert os.path.exists(os.path.join(str(tmp_path), "speed_stages.png"))
