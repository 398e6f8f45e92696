"""A geographic scene's run as GeoJSON (RFC 7946) for QGIS and other GIS: each body's track (its
centroid's longitude and latitude at every frame, a LineString) and its polygon at the last
frame (a Polygon), in WGS 84 longitude and latitude. docs/geography.md.

    floedem.geojson.export("drift.h5")            # drift.geojson beside the run
    floedem export drift.h5 --geojson              # the same from the command

The tracks are the run's own /bodies/lonlat; the polygons' vertices are taken from the scene's
plane back to longitude and latitude through the run's projection (/geo/projection, pyproj)."""
import json
import math
import os

import numpy as np

from .errors import FileError
from .run import Run


def default_path(run_path):
    return (run_path[:-3] if run_path.endswith(".h5") else run_path) + ".geojson"


def _to_lonlat(geo):
    """The map from the scene's plane (m, origin at (0, 0)) to longitude and latitude."""
    from pyproj import Transformer  # python3-pyproj: only a geographic export needs it
    projection = geo["projection"]
    forward = Transformer.from_crs("+proj=longlat +datum=WGS84 +no_defs +type=crs", projection, always_xy=True)
    inverse = Transformer.from_crs(projection, "+proj=longlat +datum=WGS84 +no_defs +type=crs", always_xy=True)
    ox, oy = forward.transform(geo["origin_lon"], geo["origin_lat"])

    def to_lonlat(xy):
        lon, lat = inverse.transform(xy[:, 0] + ox, xy[:, 1] + oy)
        return np.column_stack([lon, lat])
    return to_lonlat


def lonlat_polygons(run, frame=-1):
    """The bodies' polygons at a frame of an open geographic run, in longitude and latitude:
    [k, 2] arrays, as run.polygons(frame) gives them in the plane."""
    if run.geo is None:
        raise FileError(f"{run.path}: /geo: missing; only a geographic scene's run ([geo] in its scenario, "
                        "docs/geography.md) has longitudes and latitudes")
    to_lonlat = _to_lonlat(run.geo)
    return [to_lonlat(np.asarray(p)) for p in run.polygons(frame)]


def _finite(rows):
    """Coordinates as lists of [lon, lat] with 9 decimals (0.1 mm), rows that are not finite left out."""
    return [[round(float(a), 9), round(float(b), 9)] for a, b in rows if math.isfinite(a) and math.isfinite(b)]


def features(run):
    """The GeoJSON features of an open geographic run: tracks first, then the last frame's bodies."""
    if run.geo is None:
        raise FileError(f"{run.path}: /geo: missing; only a geographic scene's run ([geo] in its scenario, "
                        "docs/geography.md) has longitudes and latitudes to export")
    if len(run.time) == 0:
        raise FileError(f"{run.path}: /time: has no frames; nothing to export")
    lonlat = run.lonlat
    names = run.bodies.name
    out = []
    for i, name in enumerate(names):
        track = _finite(lonlat[:, i])
        geometry = {"type": "LineString", "coordinates": track} if len(track) >= 2 else \
            {"type": "Point", "coordinates": track[0]} if track else None
        if geometry is None:
            continue
        out.append({"type": "Feature", "geometry": geometry,
                    "properties": {"name": str(name), "layer": "track", "start_time": float(run.time[0]),
                                   "end_time": float(run.time[-1])}})
    speed = np.linalg.norm(run.velocity[-1], axis=1)
    thickness, fixed = run.bodies.thickness, run.bodies.fixed
    for i, polygon in enumerate(lonlat_polygons(run, -1)):
        ring = _finite(polygon)
        if len(ring) < 3:
            continue
        ring.append(ring[0])  # RFC 7946 3.1.6: a closed ring, counter-clockwise outside
        out.append({"type": "Feature", "geometry": {"type": "Polygon", "coordinates": [ring]},
                    "properties": {"name": str(names[i]), "layer": "body", "time": float(run.time[-1]),
                                   "thickness": float(thickness[i]), "speed": float(speed[i]),
                                   "fixed": bool(fixed[i])}})
    return out


def export(run_path, out=None):
    """Writes RUN.geojson (or `out`) and returns its path; FileError for a run that is not a
    geographic scene's, OSError when it cannot be written. Written under a .partial name and
    renamed when whole."""
    out = out or default_path(run_path)
    with Run(run_path) as run:
        collection = {"type": "FeatureCollection",
                      "name": os.path.basename(run_path[:-3] if run_path.endswith(".h5") else run_path),
                      "features": features(run)}
    tmp = out + ".partial"
    with open(tmp, "w") as f:
        json.dump(collection, f, separators=(",", ":"))
        f.write("\n")
    os.replace(tmp, out)
    return out
