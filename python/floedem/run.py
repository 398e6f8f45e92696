"""A floedem run's output (or field file) read into numpy arrays, with its layout checked."""
import os

import h5py
import numpy as np

from .errors import FileError  # noqa: F401  (raised here; floedem.FileError)

#: The output layout this package writes and reads: the root attribute `format_version` of
#: floedem's files (docs/output.md; the C++ library's kOutputFormatVersion). Version 2 stores
#: every string fixed-length; version 1 files (variable-length strings) are read as well.
FORMAT_VERSION = 2
OLDEST_FORMAT_VERSION = 1


# Each table: its datasets and their shapes after the row count ("N": bodies, "B": load bodies).
_BODIES = {"name": (), "mass": (), "inertia": (), "area": (), "thickness": (), "density": (), "fixed": ()}
_FRAMES = {"position": ("N", 2), "angle": ("N",), "velocity": ("N", 2), "angular_velocity": ("N",)}
_CONTACTS = {"time": (), "body_a": (), "body_b": (), "point": (2,), "normal": (2,), "normal_impulse": (),
             "tangent_impulse": (), "approach_velocity": (), "separation": (), "kind": ()}
_COLLISIONS = {"time": (), "body_a": (), "body_b": (), "normal_impulse": (), "effective_mass": (),
               "approach_speed": (), "restitution_achieved": (), "duration": (), "mean_force": (),
               "peak_force": ()}
# With [contact] force_model = "pressure_area" (the group's attribute force_model says so).
_COLLISIONS_CRUSHING = {"contact_width": (), "crushed": ()}
_TOW = {"time": (), "force": (2,), "force_mean": (2,), "ice_force_mean": (2,), "tug_position": (2,)}
# A rope's tow (modes rope and tug, /tow's attribute mode) adds its tension; a tug its velocity.
_TOW_ROPE = {"tension_max": ()}
_TOW_TUG = {"tug_velocity": (2,)}
_LOADS = {"time": (), "force": ("B", 2)}


class Table:
    """Datasets of one group, as attributes (numpy arrays, read on first use), all with the same
    number of rows; `attrs` holds the group's attributes. len() is the row count. NaN is a value
    the layout uses ("none yet": /tow's row 0), so values are not checked for finiteness."""

    def __init__(self, run, group, fields, sizes):
        self._run, self._group, self._fields, self._cache = run, group, fields, {}
        g = run._file[group]
        self.attrs = _attrs(g)
        rows = None
        for name, tail in fields.items():
            path = f"/{group}/{name}"
            if name not in g or not isinstance(g[name], h5py.Dataset):
                raise run._error(path, "missing; expected in every floedem file of this kind (docs/output.md)")
            shape = g[name].shape
            want = tuple(sizes.get(x, x) for x in tail)
            if len(shape) != 1 + len(want) or shape[1:] != want:
                raise run._error(path, f"has shape {list(shape)}; expected [rows{''.join(', ' + str(x) for x in want)}]")
            if rows is None:
                rows = shape[0]
            elif shape[0] != rows:
                raise run._error(path, f"has {shape[0]} rows; the other datasets of /{group} have {rows}")
        self._rows = rows or 0

    def __len__(self):
        return self._rows

    def __getattr__(self, name):
        fields = self.__dict__.get("_fields", {})
        if name not in fields:
            raise AttributeError(f"{self.__dict__.get('_group', 'table')} has no dataset {name!r}")
        if name not in self._cache:
            data = self._run._file[f"{self._group}/{name}"][()]
            if data.dtype.kind == "O" or data.dtype.kind == "S":
                data = np.array([x.decode() if isinstance(x, bytes) else str(x) for x in data], dtype=object)
            self._cache[name] = data
        return self._cache[name]

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(self._fields))

    def __repr__(self):
        return f"<floedem table {self._group}: {self._rows} rows: {', '.join(self._fields)}>"


def _attrs(obj):
    out = {}
    for k, v in obj.attrs.items():
        if isinstance(v, bytes):
            v = v.decode()
        elif isinstance(v, np.generic):
            v = v.item()
        out[k] = v
    return out


class Run:
    """One floedem output file (a run's, or a field file: one frame). Use as a context manager,
    or call close(); arrays already read stay valid after closing.

    Attributes: path, attrs (root attributes), format_version, status, engine, time [T],
    bodies (Table: name, mass, inertia, area, thickness, density, fixed; polygon_vertices and
    polygon_offsets through local_polygons()), position [T, N, 2], angle [T, N], velocity
    [T, N, 2], angular_velocity [T, N], contacts, collisions, tow, loads (Tables, or None when
    the file has none), summary (the summary_* attributes without the prefix), engine_info
    (/engine's attributes), provenance ({group: attributes}, e.g. "field"); a geographic
    scene's run (docs/geography.md) also geo (/geo's attributes: origin_lon, origin_lat,
    projection; None for a scene in plain metres) and lonlat [T, N, 2] (deg); inputs ({scenario
    key: "fnv1a64 DIGEST, N bytes, PATH"} for the files the scenario read, {} if none)."""

    def __init__(self, path):
        self.path = os.fspath(path)
        if not os.path.isfile(self.path):
            raise FileError(f"{self.path}: no such file")
        try:
            self._file = h5py.File(self.path, "r")
        except OSError as e:
            if "unable to lock file" in str(e):
                # HDF5's own lock: a floedem run has the file open for writing.
                raise FileError(f"{self.path}: a run is writing it (the file is locked); open it once the run has "
                                "ended or been stopped, or open a copy") from None
            raise FileError(f"{self.path}: not an HDF5 file ({e}); floedem's runs and fields are") from None
        try:
            self._check()
        except Exception:
            self._file.close()
            raise

    def _error(self, what, problem):
        return FileError(f"{self.path}: {what}: {problem}")

    def _check(self):
        f = self._file
        self.attrs = _attrs(f)
        if "format_version" not in self.attrs:
            raise self._error("/@format_version", "missing: not written by floedem, or by one older than the "
                                                  f"format's first version; this package reads {FORMAT_VERSION}")
        self.format_version = self.attrs["format_version"]
        if not isinstance(self.format_version, int) or not \
                OLDEST_FORMAT_VERSION <= self.format_version <= FORMAT_VERSION:
            newer = isinstance(self.format_version, int) and self.format_version > FORMAT_VERSION
            raise self._error("/@format_version", f"is {self.format_version}, this package reads {FORMAT_VERSION}: "
                                                  f"{'a newer' if newer else 'an older'} floedem wrote it")
        self.status = self.attrs.get("status", "")
        self.engine = self.attrs.get("engine", "")
        if "bodies" not in f:
            raise self._error("/bodies", "missing; expected in every floedem file (docs/output.md)")
        self.bodies = Table(self, "bodies", _BODIES, {})
        n = len(self.bodies)
        offsets = f["bodies/polygon_offsets"][()] if "polygon_offsets" in f["bodies"] else None
        vertices = f["bodies"].get("polygon_vertices")
        if offsets is None or vertices is None:
            raise self._error("/bodies/polygon_offsets", "missing, or polygon_vertices missing")
        if offsets.shape != (n + 1,) or offsets[0] != 0 or np.any(np.diff(offsets) < 3) or \
                vertices.ndim != 2 or vertices.shape[1] != 2 or offsets[-1] != vertices.shape[0]:
            raise self._error("/bodies/polygon_offsets", f"expected {n + 1} offsets from 0 rising by at least 3 to "
                                                         f"the {vertices.shape[0] if vertices.ndim else 0} rows of "
                                                         "/bodies/polygon_vertices")
        self._offsets = offsets
        if "time" not in f or f["time"].ndim != 1:
            raise self._error("/time", "missing, or not one-dimensional")
        self.time = f["time"][()]
        frames = Table(self, "bodies", _FRAMES, {"N": n})
        if len(frames) != len(self.time):
            raise self._error("/bodies/position", f"has {len(frames)} frames; /time has {len(self.time)}")
        self._frames = frames
        self.contacts = Table(self, "contacts", _CONTACTS, {}) if "contacts/time" in f else None
        self.collisions = None
        if "contacts/collisions/time" in f:
            crushing = _attrs(f["contacts/collisions"]).get("force_model") == "pressure_area"
            self.collisions = Table(self, "contacts/collisions",
                                    dict(_COLLISIONS, **(_COLLISIONS_CRUSHING if crushing else {})), {})
        # The files the scenario read, by scenario key: "fnv1a64 DIGEST, N bytes, PATH" ({} if none).
        self.inputs = _attrs(f["inputs"]) if "inputs" in f else {}
        self.tow = None
        if "tow/time" in f:
            mode = _attrs(f["tow"]).get("mode")
            fields = dict(_TOW, **(_TOW_ROPE if mode in ("rope", "tug") else {}), **(_TOW_TUG if mode == "tug" else {}))
            self.tow = Table(self, "tow", fields, {})
            self.tow.outcome = self._tow_outcome()
        if "loads/time" in f:
            b = f["loads/body"][()] if "body" in f["loads"] else None
            if b is None or b.ndim != 1 or np.any(b < 0) or np.any(b >= n):
                raise self._error("/loads/body", f"expected indices of bodies, 0 to {n - 1}")
            self.loads = Table(self, "loads", _LOADS, {"B": len(b)})
            self.loads.body = b
        else:
            self.loads = None
        self.summary = {k[len("summary_"):]: v for k, v in self.attrs.items() if k.startswith("summary_")}
        self.engine_info = _attrs(f["engine"]) if "engine" in f else {}
        self.provenance = {name: _attrs(f[name]) for name in ("field",) if name in f}
        self.geo = _attrs(f["geo"]) if "geo" in f else None
        if self.geo is not None:
            missing = [k for k in ("origin_lon", "origin_lat", "projection") if k not in self.geo]
            if missing or "lonlat" not in f["bodies"]:
                raise self._error("/geo", f"a geographic run needs /geo's origin_lon, origin_lat, projection and "
                                          f"/bodies/lonlat; missing {', '.join(missing) or '/bodies/lonlat'}")
            if f["bodies/lonlat"].shape != (len(self.time), n, 2):
                raise self._error("/bodies/lonlat", f"has shape {f['bodies/lonlat'].shape}; expected "
                                                    f"{(len(self.time), n, 2)}")

    def _tow_outcome(self):
        """The tow's outcome over the run (docs/towing.md), from the summary's tow_* attributes:
        direction [2], distance and cross_track (m), speed_made_good and stall_speed (m/s),
        stalled_time and parted_at (s; NaN when the rope held), parted (bool), tension_max and
        tension_p99 (N). None for a run not finished, or written before floedem recorded it."""
        s = {k[len("summary_tow_"):]: v for k, v in self.attrs.items() if k.startswith("summary_tow_")}
        if "distance" not in s:
            return None
        out = {k: float(v) for k, v in s.items() if k not in ("direction_x", "direction_y", "parted")}
        out["direction"] = np.array([s.get("direction_x", np.nan), s.get("direction_y", np.nan)], float)
        out["parted"] = bool(s.get("parted", 0.0) == 1.0)
        return out

    # Frames -----------------------------------------------------------------------------------
    @property
    def position(self):
        """[T, N, 2] m: centroids."""
        return self._frames.position

    @property
    def angle(self):
        """[T, N] rad."""
        return self._frames.angle

    @property
    def velocity(self):
        """[T, N, 2] m/s."""
        return self._frames.velocity

    @property
    def angular_velocity(self):
        """[T, N] rad/s."""
        return self._frames.angular_velocity

    @property
    def lonlat(self):
        """[T, N, 2] deg: the centroids' longitude and latitude (a geographic scene's run), or None."""
        return self._file["bodies/lonlat"][()] if self.geo is not None else None

    @property
    def frames(self):
        return len(self.time)

    def frame_index(self, frame):
        """A frame number (negative: from the end) checked against the file's frames."""
        t = len(self.time)
        k = frame + t if frame < 0 else frame
        if not 0 <= k < t:
            raise FileError(f"{self.path}: frame {frame} is out of range; the file has {t} frames "
                            f"(allowed 0 to {t - 1}, or -1 to -{t} from the end)")
        return k

    def local_polygons(self):
        """Each body's polygon relative to its centroid at angle 0 ([k, 2] arrays, counter-clockwise)."""
        v = self._file["bodies/polygon_vertices"][()]
        o = self._offsets
        return [v[o[i]:o[i + 1]] for i in range(len(o) - 1)]

    def polygons(self, frame=-1):
        """World polygons of every body at a frame ([k, 2] arrays)."""
        k = self.frame_index(frame)
        pos = self._file["bodies/position"][k]
        ang = self._file["bodies/angle"][k]
        out = []
        for i, local in enumerate(self.local_polygons()):
            c, s = np.cos(ang[i]), np.sin(ang[i])
            out.append(local @ np.array([[c, s], [-s, c]]) + pos[i])
        return out

    def world_vertices(self, frame=-1):
        """Every body's vertices at a frame, stacked as polygon_vertices is ([V, 2])."""
        k = self.frame_index(frame)
        v = self._file["bodies/polygon_vertices"][()]
        body = np.repeat(np.arange(len(self._offsets) - 1), np.diff(self._offsets))
        ang = self._file["bodies/angle"][k][body]
        c, s = np.cos(ang), np.sin(ang)
        pos = self._file["bodies/position"][k][body]
        return np.column_stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]]) + pos

    def field_range(self):
        """(first, end): the bodies of a generated field (a run's output has the scenario's own
        bodies first); (0, 0) for a file without /field."""
        f = self.provenance.get("field")
        if not f:
            return 0, 0
        first = int(f.get("first_floe", 0))
        return first, first + int(f["floes"])

    def keep_out(self):
        """The keep-out zones of a generated field, [k, 2] arrays (none: an empty list)."""
        f = self._file
        if "field/keep_out_vertices" not in f:
            return []
        v, o = f["field/keep_out_vertices"][()], f["field/keep_out_offsets"][()]
        return [v[o[i]:o[i + 1]] for i in range(len(o) - 1)]

    @property
    def polygon_offsets(self):
        """[N + 1]: body k owns rows offsets[k] to offsets[k + 1] of the stacked vertices."""
        return self._offsets

    # Life -------------------------------------------------------------------------------------
    def close(self):
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __repr__(self):
        return (f"<floedem run {self.path}: {self.engine or 'field'}, {len(self.bodies)} bodies, "
                f"{len(self.time)} frames, {self.status}>")


def open(path):  # noqa: A001  (floedem.open, as h5py.File or builtins.open read a file)
    """Reads a floedem output file; FileError when it is missing, not floedem's, of another
    format_version or damaged."""
    return Run(path)


