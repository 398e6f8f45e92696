"""Writes the forcing files and the ice chart of hindcast.toml beside it, from formulas (no
download): the role a model extract, a weather record and an ice service's chart play in a real
hindcast (docs/forcing.md, "A hindcast from end to end").

    /usr/bin/python3 make_forcing.py [DIR]      # DIR: where to write them (default: here)

ocean.nc  a current on longitude and latitude (CF-NetCDF), hourly over the run and an hour each
          side: a mean eastward drift that grows northward, plus a clockwise semidiurnal (M2)
          tidal ellipse whose phase advances eastward, as a tide propagating along the shelf.
wind.csv  a wind record every 30 min: a westerly that freshens to a 15 m/s gale at 12 h and
          backs to the south-west as it eases.
chart.geojson  an ice chart in SIGRID-3 codes (docs/ice_charts.md): west of 45 E close ice
          (7-9/10) of medium first-year small floes; east of it open ice (4-6/10) of thin
          first-year small floes, with an open lead (less than 1/10) along its north.
"""
import math
import os
import sys

import numpy as np

try:
    import floedem
except ModuleNotFoundError:
    # Run from a checkout rather than an installed floedem: the package beside it.
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..", "python"))
    try:
        import floedem
    except ModuleNotFoundError:
        sys.exit("make_forcing.py: no Python package floedem: install floedem (cmake --install build) or set "
                 "PYTHONPATH to a checkout's python/ folder")

START = "2009-05-15T00:00:00Z"   # hindcast.toml's [run] start
M2 = 44714.16                    # s, the M2 period (docs/forcing.md)


# The chart's polygons (lon, lat), tiling 44.9 to 45.1 E, 79.49 to 79.51 N about the iceberg.
CHART = [
    {"lonlat": [(44.9, 79.49), (45.0, 79.49), (45.0, 79.51), (44.9, 79.51)], "CT": "79", "SA": "91", "FA": "03"},
    {"lonlat": [(45.0, 79.49), (45.1, 79.49), (45.1, 79.5025), (45.0, 79.5025)], "CT": "46", "SA": "87", "FA": "03"},
    {"lonlat": [(45.0, 79.5025), (45.1, 79.5025), (45.1, 79.51), (45.0, 79.51)], "CT": "01"},
]


def current(t, lon, lat):
    """Eastward and northward current (m/s) at time t (s from START) and lon, lat (deg)."""
    mean_u = 0.05 * (1.0 + 0.5 * (lat - 79.5))
    psi = 2.0 * math.pi * t / M2 - np.radians(20.0 * (lon - 45.0))   # 20 deg of phase a degree east
    major, minor, inclination = 0.15, -0.05, np.radians(60.0)        # clockwise ellipse
    a, b = major * np.cos(psi), minor * np.sin(psi)
    u = mean_u + a * math.cos(inclination) - b * math.sin(inclination)
    v = a * math.sin(inclination) + b * math.cos(inclination)
    return u, v


def main(out):
    os.makedirs(out, exist_ok=True)
    lon = np.round(np.arange(43.5, 46.5001, 0.1), 6)
    lat = np.round(np.arange(79.0, 80.0001, 0.05), 6)
    time = np.arange(-3600.0, 25 * 3600.0 + 1.0, 3600.0)
    glon, glat = np.meshgrid(lon, lat)
    u = np.empty((time.size, lat.size, lon.size))
    v = np.empty_like(u)
    for k, t in enumerate(time):
        u[k], v[k] = current(t, glon, glat)
    floedem.forcing.write_grid(os.path.join(out, "ocean.nc"), lon, lat, time, u, v, start=START, lonlat=True)
    wt = np.arange(-1800.0, 24 * 3600.0 + 1801.0, 1800.0)
    gale = np.exp(-((wt - 12 * 3600.0) / (5 * 3600.0)) ** 2)
    direction = np.radians(np.where(wt < 12 * 3600.0, 0.0, 45.0 * (wt - 12 * 3600.0) / (12 * 3600.0)))
    speed = 6.0 + 9.0 * gale
    floedem.forcing.write_series(os.path.join(out, "wind.csv"), wt, speed * np.cos(direction),
                                 speed * np.sin(direction))
    floedem.chart.write_chart(os.path.join(out, "chart.geojson"), CHART)
    return out


if __name__ == "__main__":
    print(main(sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))))
