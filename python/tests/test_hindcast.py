"""examples/hindcast: the end-to-end hindcast of docs/forcing.md, from the forcing files its
script writes to the GeoJSON a GIS opens (shortened to 2 h here)."""
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
    scenario = str(tmp_path / "hindcast.toml")
    check = subprocess.run([FLOEDEM, "check", scenario], capture_output=True, text=True)
    assert check.returncode == 0, check.stderr
    assert "current grid" in check.stdout and "wind record" in check.stdout
    out = str(tmp_path / "hindcast.h5")
    subprocess.run([FLOEDEM, "run", scenario, "-o", out, "-q", "--set", "run.duration=7200.0"], check=True)
    with floedem.open(out) as run:
        bodies = len(run.bodies.name)
        assert "coriolis" in run.attrs["forcing_terms"] and "sea_surface_tilt" in run.attrs["forcing_terms"]
        start, end = run.lonlat[0, 0], run.lonlat[-1, 0]
        assert np.allclose(start, [45.0, 79.5], atol=1e-9)
        assert end[0] > start[0]            # the westerly and the mean current carry it east
    geojson = floedem.geojson.export(out)
    assert len(json.load(open(geojson))["features"]) == 2 * bodies
