"""Forcing files that floedem reads (docs/forcing.md), written from numpy arrays: a buoy record
or a model extract turned into a scene's wind or current.

    import numpy as np, floedem.forcing
    floedem.forcing.write_grid("ocean.nc", x, y, time, u, v, start="2024-03-01T00:00:00Z")
    floedem.forcing.write_series("current.csv", time, u, v)

and in the scenario `[environment.current_file] file = "ocean.nc"`, `u = "uo"`, `v = "vo"`
(the grid; with `[run] start` the instant its time axis counts from) or `file = "current.csv"`.
Each file is written through FILE.partial and a rename: a killed writer leaves no file that
looks complete. Arrays of the wrong shape, axes that do not increase or values that are not
finite raise ValueError naming the argument."""
import os

import numpy as np


def _axis(name, values):
    a = np.asarray(values, dtype=float)
    if a.ndim != 1 or a.size < 1:
        raise ValueError(f"{name}: a 1-D array of at least one value, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: not finite")
    if np.any(np.diff(a) <= 0):
        raise ValueError(f"{name}: must increase")
    return a


def write_series(path, time, u, v, u_name="u", v_name="v"):
    """A velocity record as CSV: time (s from the run's start), u and v (m/s)."""
    t = _axis("time", time)
    u, v = np.asarray(u, dtype=float), np.asarray(v, dtype=float)
    for name, a in (("u", u), ("v", v)):
        if a.shape != t.shape:
            raise ValueError(f"{name}: shape {a.shape}, expected that of time {t.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name}: not finite")
    with open(path + ".partial", "w") as f:
        f.write(f"time,{u_name},{v_name}\n")
        for row in zip(t, u, v):
            f.write(",".join(repr(float(c)) for c in row) + "\n")
    os.replace(path + ".partial", path)


def write_grid(path, x, y, time, u, v, start, depth=None, u_name="uo", v_name="vo", fill=None, lonlat=False):
    """A CF-NetCDF grid: x, y (m, the scene's frame; with lonlat=True longitude and latitude in
    degrees, axes lon and lat, for a geographic scene, u and v then eastward and northward),
    time (s from `start`, an instant in UTC as "YYYY-MM-DDTHH:MM:SSZ"), optional depth (m,
    positive down); u and v in m/s, shaped (time, y, x), or (time, depth, y, x) with a depth
    axis. NaN cells are written as the fill value (`fill`, default -999)."""
    import netCDF4

    x, y, t = _axis("x", x), _axis("y", y), _axis("time", time)
    z = None if depth is None else _axis("depth", depth)
    shape = (t.size,) + (() if z is None else (z.size,)) + (y.size, x.size)
    u, v = np.asarray(u, dtype=float), np.asarray(v, dtype=float)
    for name, a in (("u", u), ("v", v)):
        if a.shape != shape:
            raise ValueError(f"{name}: shape {a.shape}, expected {shape} (time, {'depth, ' if z is not None else ''}y, x)")
    if not (isinstance(start, str) and start.endswith("Z") and "T" in start):
        raise ValueError(f"start: {start!r}, expected an instant in UTC as \"YYYY-MM-DDTHH:MM:SSZ\"")
    fill = -999.0 if fill is None else float(fill)
    partial = path + ".partial"
    with netCDF4.Dataset(partial, "w", format="NETCDF4") as nc:
        nc.Conventions = "CF-1.8"
        nc.source = "floedem.forcing.write_grid"
        dims = [("time", t, "seconds since " + start[:-1].replace("T", " "))]
        if z is not None:
            dims.append(("depth", z, "m"))
        dims += [("lat", y, "degrees_north"), ("lon", x, "degrees_east")] if lonlat else [("y", y, "m"), ("x", x, "m")]
        for name, values, units in dims:
            nc.createDimension(name, values.size)
            var = nc.createVariable(name, "f8", (name,))
            var.units = units
            var[:] = values
        nc["time"].calendar = "standard"
        if z is not None:
            nc["depth"].positive = "down"
        for name, a in ((u_name, u), (v_name, v)):
            var = nc.createVariable(name, "f8", tuple(d[0] for d in dims), fill_value=fill)
            var.units = "m s-1"
            var[:] = np.where(np.isfinite(a), a, fill)
    os.replace(partial, path)
