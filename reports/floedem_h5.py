"""Readers shared by the figure scripts: one for a run's output and a field file alike
(both have the /bodies layout; a field file has one frame and a /field group)."""
import numpy as np


def body_polygons(f, frame):
    """World polygons of every body at one frame (local vertices turned and moved)."""
    verts = f["bodies/polygon_vertices"][:]
    offsets = f["bodies/polygon_offsets"][:]
    pos = f["bodies/position"][frame]
    ang = f["bodies/angle"][frame]
    out = []
    for k in range(len(offsets) - 1):
        local = verts[offsets[k]:offsets[k + 1]]
        c, s = np.cos(ang[k]), np.sin(ang[k])
        rot = np.array([[c, -s], [s, c]])
        out.append(local @ rot.T + pos[k])
    return out


def polygons(f, group, name):
    """Polygons stored as NAME_vertices [V, 2] and NAME_offsets [P + 1] in a group."""
    verts = f[f"{group}/{name}_vertices"][:]
    offsets = f[f"{group}/{name}_offsets"][:]
    return [verts[offsets[k]:offsets[k + 1]] for k in range(len(offsets) - 1)]


def equal_area_diameters(f):
    """d = sqrt(4 A / pi) of every body (from /bodies/area)."""
    return np.sqrt(4.0 * f["bodies/area"][:] / np.pi)


def truncated_power_law_survival(d, alpha, d_min, d_max):
    """S(d) = (d^-alpha - d_max^-alpha) / (d_min^-alpha - d_max^-alpha) (docs/model.md section 5)."""
    d = np.clip(d, d_min, d_max)
    return (d ** -alpha - d_max ** -alpha) / (d_min ** -alpha - d_max ** -alpha)
