"""A run as XDMF for ParaView: RUN.xdmf, and beside it RUN.xdmf.h5 with what the run's own file
does not hold in the form a reader needs (each frame's world-frame vertices, the polygons as
XDMF cells, velocities as 3-vectors, the collision points). The run's file is read only: the
XDMF refers to it, by its path relative to the XDMF, for the datasets it holds as they are.

In ParaView: File > Open RUN.xdmf with any of its three XDMF readers (the Xdmf3 ones give the
first block alone; docs/python.md). Block "bodies" holds the polygons over
time, with cell data velocity, angular_velocity, mass, thickness, density and fixed; block
"collisions" holds every collision event as a point (between the bodies, at the impulse-weighted
contact point when the run recorded its contacts, else midway between the two centroids at the
event's frame), with point data time, normal_impulse, peak_force, approach_speed, body_a and
body_b: a Threshold on time shows those of a moment.
"""
import os
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from .run import FileError, Run

# XDMF's mixed-topology code of a polygon (XdmfTopologyType: Polygon = 0x3), followed by its
# number of vertices and their indices.
_POLYGON = 3


def default_paths(run_path):
    stem = run_path[:-3] if run_path.endswith(".h5") else run_path
    return stem + ".xdmf", stem + ".xdmf.h5"


def _item(parent, dims, path, number="Float", precision=8):
    e = ET.SubElement(parent, "DataItem", Dimensions=" ".join(str(d) for d in dims), NumberType=number,
                      Precision=str(precision), Format="HDF")
    e.text = path
    return e


def _collision_points(run):
    """One point per collision event, and the events' columns."""
    ev = run.collisions
    if ev is None or len(ev) == 0:
        return np.zeros((0, 2)), {}
    a, b, t = ev.body_a.astype(int), ev.body_b.astype(int), ev.time
    frames = np.clip(np.searchsorted(run.time, t), 0, len(run.time) - 1)
    pos = run.position
    points = 0.5 * (pos[frames, a] + pos[frames, b])
    c = run.contacts
    if c is not None and len(c) > 0:
        key = {}
        weights = c.normal_impulse
        for i in range(len(c)):
            if c.kind[i] == 0:  # collision
                k = (int(c.body_a[i]), int(c.body_b[i]), float(c.time[i]))
                s = key.setdefault(k, [np.zeros(2), 0.0])
                s[0] += weights[i] * c.point[i]
                s[1] += weights[i]
        for e in range(len(ev)):
            s = key.get((a[e], b[e], float(t[e])))
            if s and s[1] > 0.0:
                points[e] = s[0] / s[1]
    columns = dict(time=t, normal_impulse=ev.normal_impulse, peak_force=ev.peak_force,
                   approach_speed=ev.approach_speed, body_a=a.astype(np.int64), body_b=b.astype(np.int64))
    return points, columns


def export(run_path, out=None):
    """Writes the XDMF of a run (default: beside it, RUN.xdmf and RUN.xdmf.h5) and returns the
    XDMF's path. FileError for a file that is not a floedem run; OSError when the output cannot
    be written. Both files are written under .partial names and renamed when whole."""
    xdmf_path, side_path = default_paths(run_path) if out is None else (out, out + ".h5")
    with Run(run_path) as run:
        if len(run.time) == 0:
            raise FileError(f"{run_path}: /time: has no frames; nothing to export")
        here = os.path.dirname(os.path.abspath(xdmf_path))
        run_ref = os.path.relpath(os.path.abspath(run_path), here)
        side_ref = os.path.basename(side_path)
        n, t = len(run.bodies), len(run.time)
        offsets = run.polygon_offsets
        v = int(offsets[-1])
        counts = np.diff(offsets)
        topology = np.empty(2 * n + v, np.int64)
        at = 0
        for i in range(n):
            k = int(counts[i])
            topology[at] = _POLYGON
            topology[at + 1] = k
            topology[at + 2: at + 2 + k] = np.arange(offsets[i], offsets[i + 1])
            at += 2 + k
        points, columns = _collision_points(run)
        tmp_side = side_path + ".partial"
        with h5py.File(tmp_side, "w") as s:
            # Fixed-length, as floedem's own files store strings (format 2: no global heap).
            s.attrs["source"] = np.bytes_(os.path.basename(run_path).encode())
            s.attrs["format_version"] = run.format_version
            s["topology"] = topology
            # Each frame's vertices and per-body values datasets of their own: the Xdmf3 readers skip
            # an attribute given as a HyperSlab of one [T, N] array, and the older reader complains
            # that it cannot cache one.
            for k in range(t):
                s[f"vertices/{k}"] = run.world_vertices(k)
                velocity = np.zeros((n, 3))
                velocity[:, :2] = run.velocity[k]
                s[f"velocity/{k}"] = velocity
                s[f"angular_velocity/{k}"] = run.angular_velocity[k]
            s["collisions/points"] = np.column_stack([points, np.zeros(len(points))]) if len(points) else \
                np.zeros((0, 3))
            for name, col in columns.items():
                s[f"collisions/{name}"] = col

        root = ET.Element("Xdmf", Version="3.0")
        domain = ET.SubElement(root, "Domain")
        bodies = ET.SubElement(domain, "Grid", Name="bodies", GridType="Collection", CollectionType="Temporal")
        fixed_attrs = [("mass", "Float", 8), ("thickness", "Float", 8), ("density", "Float", 8), ("fixed", "UInt", 1)]
        for k in range(t):
            g = ET.SubElement(bodies, "Grid", Name=f"bodies_{k}", GridType="Uniform")
            ET.SubElement(g, "Time", Value=repr(float(run.time[k])))
            top = ET.SubElement(g, "Topology", TopologyType="Mixed", NumberOfElements=str(n))
            _item(top, (len(topology),), f"{side_ref}:/topology", "Int", 8)
            geo = ET.SubElement(g, "Geometry", GeometryType="XY")
            _item(geo, (v, 2), f"{side_ref}:/vertices/{k}")
            a = ET.SubElement(g, "Attribute", Name="velocity", AttributeType="Vector", Center="Cell")
            _item(a, (n, 3), f"{side_ref}:/velocity/{k}")
            a = ET.SubElement(g, "Attribute", Name="angular_velocity", AttributeType="Scalar", Center="Cell")
            _item(a, (n,), f"{side_ref}:/angular_velocity/{k}")
            for name, number, precision in fixed_attrs:
                a = ET.SubElement(g, "Attribute", Name=name, AttributeType="Scalar", Center="Cell")
                _item(a, (n,), f"{run_ref}:/bodies/{name}", number, precision)
        e = len(points)
        if e > 0:
            g = ET.SubElement(domain, "Grid", Name="collisions", GridType="Uniform")
            top = ET.SubElement(g, "Topology", TopologyType="Polyvertex", NumberOfElements=str(e), NodesPerElement="1")
            idx = ET.SubElement(top, "DataItem", Dimensions=str(e), NumberType="Int", Precision="8", Format="XML")
            idx.text = " ".join(str(i) for i in range(e))
            geo = ET.SubElement(g, "Geometry", GeometryType="XYZ")
            _item(geo, (e, 3), f"{side_ref}:/collisions/points")
            for name, col in columns.items():
                a = ET.SubElement(g, "Attribute", Name=name, AttributeType="Scalar", Center="Node")
                _item(a, (e,), f"{side_ref}:/collisions/{name}", "Int" if col.dtype.kind == "i" else "Float", 8)
        ET.indent(root)
        tmp_xdmf = xdmf_path + ".partial"
        with open(tmp_xdmf, "w") as f:
            f.write('<?xml version="1.0" ?>\n<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>\n')
            f.write(ET.tostring(root, encoding="unicode"))
            f.write("\n")
        os.replace(tmp_side, side_path)
        os.replace(tmp_xdmf, xdmf_path)
    return xdmf_path
