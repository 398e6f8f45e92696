"""floedem's results in Python: `floedem.open(path)` reads a run's output or a field file.

    run = floedem.open("towing_paper.native.h5")
    run.time                     # [T] s
    run.bodies.name, run.bodies.mass, run.bodies.fixed
    run.position[-1]             # [N, 2] m, centroids at the last frame
    run.polygons(-1)             # world polygons at the last frame
    run.collisions.peak_force    # [E] N
    run.tow.ice_force_mean       # [W, 2] N
    floedem.stats.stationary_window(...), floedem.stats.block_standard_error(...)

Files of another layout (format_version) or damaged ones raise floedem.FileError naming the
file, the dataset and what was expected. The layout is docs/output.md of the repository.
"""
from .run import FORMAT_VERSION, FileError, Run, open  # noqa: F401  (open: the module's entry point)
from . import stats  # noqa: F401

__version__ = "0.1.0"
__all__ = ["open", "Run", "FileError", "FORMAT_VERSION", "stats", "__version__"]
