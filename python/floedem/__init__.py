"""floedem's results in Python: `floedem.open(path)` reads a run's output or a field file.

    run = floedem.open("towing_paper.native.h5")
    run.time                     # [T] s
    run.bodies.name, run.bodies.mass, run.bodies.fixed
    run.position[-1]             # [N, 2] m, centroids at the last frame
    run.polygons(-1)             # world polygons at the last frame
    run.collisions.peak_force    # [E] N
    run.tow.ice_force_mean       # [W, 2] N
    run.tow.outcome              # the tow's outcome: speed made good, parting, tensions
    floedem.towing.odds(...), floedem.towing.design_loads(...)   # odds and design loads
    floedem.stats.stationary_window(...), floedem.stats.block_standard_error(...)
    floedem.forcing.write_grid(...), floedem.forcing.write_series(...)   # forcing files
    floedem.geojson.export("drift.h5")   # a geographic scene's run for QGIS
    floedem.chart.write_chart(...), floedem.chart.polygons(run)   # ice charts

Files of another layout (format_version) or damaged ones raise floedem.FileError naming the
file, the dataset and what was expected. The layout is docs/output.md of the repository.
"""
import importlib

from .errors import FileError  # noqa: F401

# numpy and h5py load on the first use of what needs them (PEP 562), not at `import floedem`:
# the workflow runs `python3 -m floedem launch-one` once per job, hundreds of times a report.
_LAZY = {"open": "run", "Run": "run", "FORMAT_VERSION": "run", "stats": None, "forcing": None, "geojson": None, "chart": None,
         "towing": None}


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module 'floedem' has no attribute {name!r}")
    module = importlib.import_module(f".{_LAZY[name] or name}", __name__)
    value = module if _LAZY[name] is None else getattr(module, name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))


__version__ = "0.1.0"
__all__ = ["open", "Run", "FileError", "FORMAT_VERSION", "stats", "forcing", "geojson", "chart", "towing", "__version__"]
