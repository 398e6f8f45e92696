"""Figures kept from a run for a sweep: statistics of one of its series over a window, computed
once from the run's file so that reductions never reopen it."""
import math

import numpy as np

from .run import FileError
from . import stats as _stats

#: The statistics a figure may ask for.
STATS = ("mean", "std", "min", "p50", "p90", "p99", "peak", "count")
#: Series with rows over time; `collisions.*` has one row per collision event (its time column).
SERIES = ("tow.force_mean", "tow.ice_force_mean", "tow.force", "collisions.peak_force", "collisions.mean_force",
          "collisions.normal_impulse", "collisions.approach_speed", "collisions.count")
COMPONENTS = ("x", "y", "magnitude")


def check(name, spec, where):
    """A figure's table from the sweep file checked; ValueError naming the key and what is allowed."""
    known = {"series", "component", "stats", "after_travel", "from_time"}
    for k in spec:
        if k not in known:
            raise ValueError(f"{where}: figures.{name}.{k}: unknown key; allowed {', '.join(sorted(known))}")
    series = spec.get("series")
    if not isinstance(series, str) or not (series in SERIES or series.startswith("loads.") or
                                           series.startswith("summary.")):
        raise ValueError(f"{where}: figures.{name}.series: {series!r}; allowed one of {', '.join(SERIES)}, "
                         "loads.BODY (the contact load on a body of [output] loads) or summary.KEY (a summary_* attribute)")
    if spec.get("component", "x") not in COMPONENTS:
        raise ValueError(f"{where}: figures.{name}.component: {spec['component']!r}; allowed {', '.join(COMPONENTS)}")
    st = spec.get("stats", ["mean"])
    if not isinstance(st, list) or not st or any(s not in STATS for s in st):
        raise ValueError(f"{where}: figures.{name}.stats: {st!r}; allowed a non-empty list of {', '.join(STATS)}")
    for k in ("after_travel", "from_time"):
        if k in spec and not (isinstance(spec[k], (int, float)) and spec[k] >= 0 and math.isfinite(spec[k])):
            raise ValueError(f"{where}: figures.{name}.{k}: {spec[k]!r}; allowed a number >= 0")
    if "after_travel" in spec and "from_time" in spec:
        raise ValueError(f"{where}: figures.{name}: after_travel and from_time together; allowed one window")


def _window_start(run, spec):
    """The time from which rows count: after_travel (the towed body's path, /tow) or from_time."""
    if "after_travel" in spec:
        if run.tow is None:
            raise FileError(f"{run.path}: /tow: missing, and the figure's window is after_travel (a towing run's)")
        t = run.tow.time
        keep = _stats.stationary_window(run.tow.tug_position[:, 0] if len(t) else t, float(spec["after_travel"]))
        return float(t[keep][0])
    return float(spec.get("from_time", -math.inf))


def _values(run, spec):
    series, comp = spec["series"], spec.get("component", "x")
    start = _window_start(run, spec)
    if series.startswith("summary."):
        key = series[len("summary."):]
        if key not in run.summary:
            raise FileError(f"{run.path}: /@summary_{key}: missing; the summary has {', '.join(sorted(run.summary))}")
        return np.array([float(run.summary[key])])
    if series.startswith("collisions."):
        ev = run.collisions
        if ev is None:
            raise FileError(f"{run.path}: /contacts/collisions: missing")
        late = ev.time >= start
        if series == "collisions.count":
            return np.array([float(np.count_nonzero(late))])
        return getattr(ev, series.split(".", 1)[1])[late]
    if series.startswith("loads."):
        body = series.split(".", 1)[1]
        if run.loads is None:
            raise FileError(f"{run.path}: /loads: missing (the scenario's [output] loads names no body)")
        names = [str(run.bodies.name[i]) for i in run.loads.body]
        if body not in names:
            raise FileError(f"{run.path}: /loads/body: has {', '.join(names)}, not {body}")
        t, v = run.loads.time, run.loads.force[:, names.index(body), :]
    else:
        if run.tow is None:
            raise FileError(f"{run.path}: /tow: missing (not a towing run)")
        t, v = run.tow.time, getattr(run.tow, series.split(".", 1)[1])
    keep = (t >= start) & np.all(np.isfinite(v), axis=1)
    keep[0] = False   # row 0 holds no step yet (NaN or zero)
    v = v[keep]
    return v[:, 0] if comp == "x" else v[:, 1] if comp == "y" else np.hypot(v[:, 0], v[:, 1])


def compute(run, figures):
    """{"NAME.STAT": value} for every figure of the sweep file (NaN where a window is empty)."""
    out = {}
    for name, spec in figures.items():
        v = _values(run, spec)
        for s in spec.get("stats", ["mean"]):
            if s == "count":
                out[f"{name}.count"] = float(len(v)) if not spec["series"].endswith(".count") else float(v[0])
            elif len(v) == 0:
                out[f"{name}.{s}"] = math.nan
            else:
                out[f"{name}.{s}"] = float({"mean": np.mean, "std": np.std, "min": np.min, "peak": np.max,
                                            "p50": lambda x: np.percentile(x, 50), "p90": lambda x: np.percentile(x, 90),
                                            "p99": lambda x: np.percentile(x, 99)}[s](v))
    return out
