"""floedem.geojson: a geographic scene's run as GeoJSON for QGIS (docs/geography.md)."""
import json
import subprocess

import numpy as np
import pytest
from pyproj import Transformer

import floedem
from conftest import FLOEDEM

SCENE = """
[run]
duration = 7200.0
dt = 30.0
output_every = 20
[geo]
origin = [35.0, 77.0]
[environment]
wind = [12.0, 4.0]
[[body]]
name = "berg"
kind = "iceberg"
position_lonlat = [35.1, 77.05]
polygon = [[-70, -35], [70, -35], [70, 35], [-70, 35]]
draft = 50.0
sail_height = 11.0
[[body]]
name = "floe"
polygon_lonlat = [[34.9, 76.95], [34.91, 76.95], [34.91, 76.955], [34.9, 76.955]]
thickness = 1.0
"""


@pytest.fixture(scope="module")
def geo_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("geo")
    (d / "g.toml").write_text(SCENE)
    subprocess.run([FLOEDEM, "run", str(d / "g.toml"), "-o", str(d / "g.h5"), "-q"], check=True)
    return d / "g.h5"


def test_tracks_and_last_polygons_in_longitude_and_latitude(geo_run):
    out = floedem.geojson.export(str(geo_run))
    assert out == str(geo_run)[:-3] + ".geojson"
    collection = json.load(open(out))
    assert collection["type"] == "FeatureCollection"
    kinds = [(f["properties"]["layer"], f["geometry"]["type"], f["properties"]["name"]) for f in collection["features"]]
    assert kinds == [("track", "LineString", "berg"), ("track", "LineString", "floe"),
                     ("body", "Polygon", "berg"), ("body", "Polygon", "floe")]
    with floedem.open(str(geo_run)) as run:
        lonlat = run.lonlat
        assert lonlat.shape == (len(run.time), 2, 2)
        berg_track = np.array(collection["features"][0]["geometry"]["coordinates"])
        assert np.allclose(berg_track, lonlat[:, 0], atol=1e-9)
        assert np.allclose(berg_track[0], [35.1, 77.05], atol=1e-9)
        assert berg_track[-1, 0] > berg_track[0, 0]  # the wind blows it east
        # Each polygon's vertices: the run's plane back through the projection, pyproj's own way.
        to_plane = Transformer.from_crs("EPSG:4326", run.geo["projection"], always_xy=True)
        ox, oy = to_plane.transform(35.0, 77.0)
        for k, polygon in enumerate(run.polygons(-1)):
            ring = np.array(collection["features"][2 + k]["geometry"]["coordinates"][0])
            assert len(ring) == len(polygon) + 1 and np.array_equal(ring[0], ring[-1])
            x, y = to_plane.transform(ring[:-1, 0], ring[:-1, 1])
            assert np.allclose(np.column_stack([x, y]) - [ox, oy], polygon, atol=1e-4)
            # Counter-clockwise on the map as on the plane (RFC 7946's outer ring).
            area = 0.5 * np.sum(ring[:-1, 0] * ring[1:, 1] - ring[1:, 0] * ring[:-1, 1])
            assert area > 0


def test_the_command_writes_it_and_refuses_a_run_in_plain_metres(geo_run, tmp_path):
    target = tmp_path / "tracks.geojson"
    r = subprocess.run([FLOEDEM, "export", str(geo_run), "--geojson", "-o", str(target)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert json.load(open(target))["features"]
    plain = tmp_path / "plain.toml"
    plain.write_text("[run]\nduration = 1.0\ndt = 0.5\n[[body]]\nname = \"a\"\n"
                     "polygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\nthickness = 1.0\n")
    subprocess.run([FLOEDEM, "run", str(plain), "-o", str(tmp_path / "plain.h5"), "-q"], check=True)
    r = subprocess.run([FLOEDEM, "export", str(tmp_path / "plain.h5"), "--geojson"], capture_output=True, text=True)
    assert r.returncode == 2
    assert "/geo: missing" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "plain.geojson").exists()
    r = subprocess.run([FLOEDEM, "export", str(tmp_path / "plain.h5"), "--geojson", "--xdmf"], capture_output=True,
                       text=True)
    assert r.returncode != 0


def test_a_grid_on_longitude_and_latitude_drives_a_geographic_scene(tmp_path):
    # A uniform eastward current on a lon/lat grid written by floedem.forcing: the berg at the
    # origin drifts east, and `floedem check` tells the lattice the grid was resampled onto.
    pytest.importorskip("netCDF4")
    lon, lat = np.arange(30.0, 40.01, 0.5), np.arange(75.0, 79.01, 0.25)
    t = np.array([-3600.0, 10800.0])
    u = np.full((2, lat.size, lon.size), 0.3)
    v = np.zeros_like(u)
    floedem.forcing.write_grid(str(tmp_path / "ocean.nc"), lon, lat, t, u, v, start="2009-05-15T00:00:00Z", lonlat=True)
    scene = SCENE.replace("[environment]\nwind = [12.0, 4.0]",
                          "[environment]\n[environment.current_file]\nfile = \"ocean.nc\"\nu = \"uo\"\nv = \"vo\"")
    scene = scene.replace("[run]\n", "[run]\nstart = \"2009-05-15T00:00:00Z\"\n")
    (tmp_path / "grid.toml").write_text(scene)
    r = subprocess.run([FLOEDEM, "check", str(tmp_path / "grid.toml")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "resampled every" in r.stdout and "longitude [30" in r.stdout
    subprocess.run([FLOEDEM, "run", str(tmp_path / "grid.toml"), "-o", str(tmp_path / "grid.h5"), "-q"], check=True)
    with floedem.open(str(tmp_path / "grid.h5")) as run:
        moved = run.lonlat[-1, 0] - run.lonlat[0, 0]
        assert moved[0] > 0.005 and abs(moved[1]) < moved[0] * np.cos(np.radians(77.0))
