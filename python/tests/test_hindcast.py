"""examples/hindcast: the end-to-end hindcast of docs/forcing.md, from the forcing files and
the ice chart its script writes to the GeoJSON a GIS opens (shortened to 2 h here)."""
import json
import os
import runpy
import shutil
import subprocess

import numpy as np
import pytest

import floedem
from conftest import FLOEDEM, ROOT

pytest.importorskip("netCDF4")
EXAMPLE = os.path.join(ROOT, "examples", "hindcast")


def test_the_hindcast_example_runs_from_its_own_files(tmp_path):
    shutil.copy(os.path.join(EXAMPLE, "hindcast.toml"), tmp_path)
    runpy.run_path(os.path.join(EXAMPLE, "make_forcing.py"))["main"](str(tmp_path))
    assert (tmp_path / "ocean.nc").exists() and (tmp_path / "wind.csv").exists()
    assert (tmp_path / "chart.geojson").exists()
    scenario = str(tmp_path / "hindcast.toml")
    check = subprocess.run([FLOEDEM, "check", scenario], capture_output=True, text=True)
    assert check.returncode == 0, check.stderr
    assert "current grid" in check.stdout and "wind record" in check.stdout and "chart chart.geojson" in check.stdout
    out = str(tmp_path / "hindcast.h5")
    subprocess.run([FLOEDEM, "run", scenario, "-o", out, "-q", "--set", "run.duration=7200.0"], check=True)
    with floedem.open(out) as run:
        bodies = len(run.bodies.name)
        assert "coriolis" in run.attrs["forcing_terms"] and "sea_surface_tilt" in run.attrs["forcing_terms"]
        start, end = run.lonlat[0, 0], run.lonlat[-1, 0]
        assert np.allclose(start, [45.0, 79.5], atol=1e-9)
        assert end[0] > start[0]            # the westerly and the mean current carry it east
        # Each chart polygon at its code's concentration: 7-9/10, 4-6/10, an open lead.
        chart = floedem.chart.polygons(run)
        assert [p["CT"] for p in chart] == [79, 46, 1]
        assert [round(p["concentration_achieved"], 3) for p in chart] == [0.8, 0.5, 0.0]
        assert sum(p["floes"] for p in chart) == bodies - 1
    geojson = floedem.geojson.export(out)
    assert len(json.load(open(geojson))["features"]) == 2 * bodies


def test_write_chart_closes_rings_and_writes_codes_as_text(tmp_path):
    path = floedem.chart.write_chart(tmp_path / "c.geojson", [
        {"lonlat": [(0.0, 70.0), (0.1, 70.0), (0.1, 70.1)], "CT": 92, "SA": "93", "FA": 4},
        {"lonlat": [(0.1, 70.0), (0.2, 70.0), (0.2, 70.1), (0.1, 70.0)], "CT": "00"}])
    features = json.load(open(path))["features"]
    ring = features[0]["geometry"]["coordinates"][0]
    assert ring[0] == ring[-1] and len(ring) == 4
    assert features[0]["properties"] == {"CT": "92", "SA": "93", "FA": "04"}
    assert features[1]["properties"] == {"CT": "00", "SA": "-9", "FA": "-9"}
    assert len(features[1]["geometry"]["coordinates"][0]) == 4   # already closed: not closed twice
    assert not (tmp_path / "c.geojson.partial").exists()
    with pytest.raises(ValueError, match="feature 0: a ring needs at least 3 points"):
        floedem.chart.write_chart(tmp_path / "d.geojson", [{"lonlat": [(0, 0), (1, 1)], "CT": "10"}])


def test_the_worked_towing_example_runs_and_its_plan_is_valid(tmp_path):
    # docs/towing.md, "A worked example": the hindcast's iceberg in tow through the chart's ice.
    for name in ("tow.toml", "tow_plan.toml"):
        shutil.copy(os.path.join(EXAMPLE, name), tmp_path)
    runpy.run_path(os.path.join(EXAMPLE, "make_forcing.py"))["main"](str(tmp_path))
    out = str(tmp_path / "tow.h5")
    subprocess.run([FLOEDEM, "run", str(tmp_path / "tow.toml"), "-o", out, "-q", "--set", "run.duration=300.0"],
                   check=True)
    with floedem.open(out) as run:
        outcome = run.tow.outcome
        assert not outcome["parted"]
        assert outcome["distance"] > 0.0       # the tug has the iceberg moving east
        assert run.tow.attrs["mode"] == "tug"
    plan = subprocess.run([FLOEDEM, "sweep", str(tmp_path / "tow_plan.toml"), "--out", str(tmp_path / "plan"), "-n"],
                          capture_output=True, text=True)
    assert plan.returncode == 0, plan.stderr
