"""Ice charts for `[field] chart` (docs/ice_charts.md): write one from polygons in longitude
and latitude, and read back what a run made of each polygon.

    floedem.chart.write_chart("chart.geojson", [
        {"lonlat": [(14.98, 75.99), (15.0, 75.99), (15.0, 76.01), (14.98, 76.01)],
         "CT": "46", "SA": "87", "FA": "03"},
        ...])
    floedem.chart.polygons(run)   # [{fid, CT, SA, FA, concentration, floes, ...}] from /field

The chart is GeoJSON (RFC 7946: longitude and latitude on WGS 84), its codes the SIGRID-3
attributes as text, as the ice services' shapefiles carry them.
"""
import json
import os

CODES = ("CT", "SA", "FA")


def write_chart(path, features):
    """Writes a GeoJSON chart: each feature a dict with "lonlat" (the outer ring, [(lon, lat),
    ...], open or closed), optionally "holes" (rings likewise), and its SIGRID-3 codes "CT", "SA",
    "FA" (text or int; "SA" and "FA" may be left out where "CT" is ice free). Written to
    PATH.partial, then renamed. Returns PATH."""
    out = []
    for k, f in enumerate(features):
        rings = [f["lonlat"]] + list(f.get("holes", []))
        coords = []
        for ring in rings:
            ring = [[float(lon), float(lat)] for lon, lat in ring]
            if len(ring) < 3:
                raise ValueError(f"feature {k}: a ring needs at least 3 points, got {len(ring)}")
            if ring[0] != ring[-1]:
                ring.append(ring[0])
            coords.append(ring)
        props = {}
        for c in CODES:
            v = f.get(c, "-9")
            props[c] = f"{int(v):02d}" if not isinstance(v, str) else v
        out.append({"type": "Feature", "id": k, "properties": props,
                    "geometry": {"type": "Polygon", "coordinates": coords}})
    tmp = str(path) + ".partial"
    with open(tmp, "w") as fh:
        json.dump({"type": "FeatureCollection", "features": out}, fh)
    os.replace(tmp, path)
    return path


def polygons(run):
    """What a run (floedem.open) or field file made of each chart polygon: one dict per polygon,
    the attributes of /field/chart_feature_FID (docs/output.md), in the chart's order; [] for a
    field not made from a chart."""
    f = run._file
    if "field" not in f:
        return []
    groups = [f["field"][k] for k in f["field"] if k.startswith("chart_feature_")]
    rows = [{k: (v.item() if hasattr(v, "item") else v) for k, v in g.attrs.items()} for g in groups]
    return sorted(rows, key=lambda r: r["fid"])
