"""Small runs made once per test session with the floedem command under test (ctest gives its
path as FLOEDEM; otherwise build/floedem of this checkout)."""
import os
import subprocess

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
FLOEDEM = os.environ.get("FLOEDEM", os.path.join(ROOT, "build", "floedem"))

# A floe driven by a current onto a fixed wall, a second floe beside it, a velocity-towed
# berg passing through: frames, contacts (all), collisions, tow and loads in 40 steps.
SCENE = """
[run]
duration = 8.0
dt = 0.1
output_every = 4
[output]
contacts = "all"
loads = ["wall"]
[environment]
current = [0.5, 0.0]
[[body]]
name = "wall"
polygon = [[30, -20], [32, -20], [32, 40], [30, 40]]
thickness = 2.0
fixed = true
[[body]]
name = "berg"
kind = "iceberg"
polygon = [[-10, 20], [0, 20], [0, 30], [-10, 30]]
draft = 8.0
sail_height = 2.0
[[body]]
name = "a"
polygon = [[20, 0], [29.5, 0], [29.5, 9], [20, 9]]
thickness = 1.0
velocity = [1.0, 0.0]
[[body]]
name = "b"
polygon = [[5, 0], [15, 0], [12, 8]]
thickness = 0.8
[tow]
mode = "velocity"
body = "berg"
velocity = [1.5, 0.0]
"""


def floedem(*args, check=True):
    r = subprocess.run([FLOEDEM, *args], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"floedem {' '.join(args)}: exit {r.returncode}\n{r.stdout}{r.stderr}")
    return r


@pytest.fixture(scope="session")
def runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("runs")
    scene = d / "scene.toml"
    scene.write_text(SCENE)
    floedem("run", "-q", str(scene), "-o", str(d / "scene.h5"))
    floedem("run", "-q", os.path.join(ROOT, "scenarios", "head_on.toml"), "-o", str(d / "head_on.h5"))
    floedem("field", "--width", "80", "--height", "60", "--concentration", "0.5", "--alpha", "2", "--dmin", "4",
            "--dmax", "20", "--thickness", "1", "--seed", "5", "-o", str(d / "field.h5"))
    return d
