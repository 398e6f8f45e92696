"""floedem export --xdmf: read back by ParaView's own reader, and floedem animate: a film."""
import hashlib
import os
import shutil
import subprocess

import numpy as np
import pytest

import floedem
from conftest import HERE, ROOT, floedem as run_floedem


def digest(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


@pytest.fixture(scope="module")
def towing(tmp_path_factory):
    """The paper's towing case (5 200 floes), its first minute."""
    d = tmp_path_factory.mktemp("towing")
    out = d / "towing.h5"
    run_floedem("run", "-q", os.path.join(ROOT, "scenarios", "towing_paper.toml"), "-o", str(out),
                "--set", "run.duration=60", "--set", "run.output_every=50")
    return out


@pytest.mark.parametrize("reader", ["XDMFReader", "Xdmf3ReaderS", "Xdmf3ReaderT"])
def test_export_reads_back_through_paraview(towing, tmp_path, reader):
    # Each of ParaView's three XDMF readers, run from the directory above the files, which it
    # names by a relative path: every cell attribute of every frame read, the values the run's.
    pvbatch = shutil.which("pvbatch")
    if pvbatch is None:
        pytest.skip("no pvbatch (Debian package python3-paraview, which scripts/setup.sh installs)")
    run = tmp_path / "out" / "towing.h5"
    run.parent.mkdir()
    shutil.copy(towing, run)
    before = digest(run)
    r = run_floedem("export", str(run), "--xdmf")
    assert r.stdout.strip().endswith("towing.xdmf")
    assert digest(run) == before  # the run's own file is only read
    assert (run.parent / "towing.xdmf").exists() and (run.parent / "towing.xdmf.h5").exists()
    assert not list(run.parent.glob("*.partial"))
    frames = [0, 6, 12]
    npz = tmp_path / "read.npz"
    p = subprocess.run([pvbatch, os.path.join(HERE, "xdmf_readback.py"), reader, os.path.join("out", "towing.xdmf"),
                        str(npz)] + [str(k) for k in frames], capture_output=True, text=True, timeout=300,
                       cwd=tmp_path)
    assert p.returncode == 0, p.stdout + p.stderr
    assert "ERR" not in p.stdout + p.stderr and "Skipping" not in p.stdout + p.stderr, p.stdout + p.stderr
    got = np.load(npz)
    with floedem.open(run) as r:
        np.testing.assert_array_equal(got["times"], r.time)
        sizes = np.diff(r.polygon_offsets)
        for k in frames:
            # Every vertex where the run's frame puts it (ParaView adds z = 0): within 1e-9 m.
            points = got[f"bodies_{k}_points"]
            np.testing.assert_allclose(points[:, :2], r.world_vertices(k), rtol=0, atol=1e-9)
            assert np.all(points[:, 2] == 0.0)
            np.testing.assert_array_equal(got[f"bodies_{k}_cell_sizes"], sizes)
            assert set(got[f"bodies_{k}_cell_types"]) == {7}  # VTK_POLYGON
            np.testing.assert_array_equal(got[f"bodies_{k}_cell_velocity"][:, :2], r.velocity[k])
            np.testing.assert_array_equal(got[f"bodies_{k}_cell_angular_velocity"], r.angular_velocity[k])
            np.testing.assert_array_equal(got[f"bodies_{k}_cell_mass"], r.bodies.mass)
            np.testing.assert_array_equal(got[f"bodies_{k}_cell_thickness"], r.bodies.thickness)
            np.testing.assert_array_equal(got[f"bodies_{k}_cell_density"], r.bodies.density)
            np.testing.assert_array_equal(got[f"bodies_{k}_cell_fixed"], r.bodies.fixed)
        if reader == "XDMFReader":
            # The collisions, one point each, with their columns (a grid of its own, which the
            # Xdmf3 readers leave out: they give the first grid).
            assert len(got["collisions_0_points"]) == len(r.collisions) > 0
            np.testing.assert_array_equal(got["collisions_0_point_peak_force"], r.collisions.peak_force)


def test_export_refuses_bad_input(runs, tmp_path):
    bad = run_floedem("export", str(tmp_path / "none.h5"), "--xdmf", check=False)
    assert bad.returncode == 2 and bad.stderr.strip().count("\n") == 0 and "none.h5: no such file" in bad.stderr
    text = tmp_path / "t.h5"
    text.write_text("x")
    bad = run_floedem("export", str(text), "--xdmf", check=False)
    assert bad.returncode == 2 and "not an HDF5 file" in bad.stderr
    out = run_floedem("export", str(runs / "head_on.h5"), "--xdmf", "--out", "/nonexistent/dir/x.xdmf", check=False)
    assert out.returncode == 3 and "/nonexistent/dir/x.xdmf" in out.stderr


def test_animate_writes_a_film(runs, tmp_path):
    if shutil.which("ffmpeg") is None:
        pytest.skip("no ffmpeg (Debian package ffmpeg, which scripts/setup.sh installs)")
    film = tmp_path / "scene.mp4"
    r = run_floedem("animate", str(runs / "scene.h5"), "--out", str(film), "--colour", "force")
    assert "animate: frame 21/21" in r.stderr
    data = film.read_bytes()
    assert len(data) > 1000 and data[4:8] == b"ftyp"  # an MP4 container
    assert not list(tmp_path.glob("*.partial"))
    # Unwritable: exit 3, one line, nothing left; a run without contact rows cannot colour by force.
    bad = run_floedem("animate", str(runs / "scene.h5"), "--out", "/nonexistent/x.mp4", "-q", check=False)
    assert bad.returncode == 3 and bad.stderr.count("\n") == 1
    field = run_floedem("animate", str(runs / "field.h5"), "--out", str(tmp_path / "f.mp4"), "--colour", "force",
                        check=False)
    assert field.returncode == 2 and "/contacts" in field.stderr and not (tmp_path / "f.mp4").exists()
