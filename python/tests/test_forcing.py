"""floedem.forcing: files written from numpy arrays that the command reads as a scene's forcing."""
import os
import subprocess

import numpy as np
import pytest

import floedem
from conftest import FLOEDEM

netCDF4 = pytest.importorskip("netCDF4")

SCENE = """
[run]
start = "2024-03-01T00:00:00Z"
duration = 1800.0
dt = 10.0
output_every = 30
[environment]
latitude = 70.0
[environment.current_file]
{table}
[[body]]
name = "floe"
polygon = [[-20, -20], [20, -20], [20, 20], [-20, 20]]
thickness = 1.5
"""


def run(tmp_path, name, table):
    scenario = tmp_path / f"{name}.toml"
    scenario.write_text(SCENE.format(table=table))
    out = tmp_path / f"{name}.h5"
    subprocess.run([FLOEDEM, "run", str(scenario), "-o", str(out), "-q"], check=True)
    with floedem.open(str(out)) as f:
        return f.position[-1].copy()


def test_a_grid_uniform_in_space_drives_the_run_its_record_does(tmp_path):
    # A current turning over the half hour, as a record and as a grid uniform in space: the
    # same velocities at every step, so the same drift to the bit (docs/forcing.md).
    t = np.arange(0.0, 1801.0, 300.0)
    u, v = 0.25 * np.cos(t / 900.0), 0.25 * np.sin(t / 900.0)
    floedem.forcing.write_series(str(tmp_path / "current.csv"), t, u, v)
    x, y = np.array([-5000.0, 5000.0]), np.array([-5000.0, 0.0, 5000.0])
    grid = lambda a: np.broadcast_to(a[:, None, None], (t.size, y.size, x.size))  # noqa: E731
    floedem.forcing.write_grid(str(tmp_path / "ocean.nc"), x, y, t, grid(u), grid(v), start="2024-03-01T00:00:00Z")
    by_record = run(tmp_path, "record", 'file = "current.csv"')
    by_grid = run(tmp_path, "grid", 'file = "ocean.nc"\nu = "uo"\nv = "vo"')
    assert np.linalg.norm(by_record[0]) > 100.0  # it drifted
    assert np.array_equal(by_record, by_grid)
    assert not os.path.exists(str(tmp_path / "ocean.nc.partial"))
    # Each run records the file it read: its size and digest, so an archived run says what it
    # was made from.
    for name, file in (("record", "current.csv"), ("grid", "ocean.nc")):
        with floedem.open(str(tmp_path / f"{name}.h5")) as f:
            rec = f.inputs["environment.current_file.file"]
        size = os.path.getsize(tmp_path / file)
        assert rec.startswith("fnv1a64 ") and f", {size} bytes, " in rec and rec.endswith(file), rec


def test_bad_arrays_are_refused_naming_the_argument(tmp_path):
    t = np.array([0.0, 60.0])
    with pytest.raises(ValueError, match="u: shape"):
        floedem.forcing.write_grid(str(tmp_path / "a.nc"), [0, 1], [0, 1], t, np.zeros((2, 2)), np.zeros((2, 2, 2)),
                                   start="2024-03-01T00:00:00Z")
    with pytest.raises(ValueError, match="time: must increase"):
        floedem.forcing.write_series(str(tmp_path / "a.csv"), [0.0, 0.0], [1, 1], [1, 1])
    with pytest.raises(ValueError, match="start"):
        floedem.forcing.write_grid(str(tmp_path / "a.nc"), [0, 1], [0, 1], t, np.zeros((2, 2, 2)), np.zeros((2, 2, 2)),
                                   start="2024-03-01")
    assert not os.listdir(tmp_path)
