"""floedem.open: the layout as numpy arrays, and every bad file refused with the file and the
dataset named."""
import os
import shutil

import h5py
import numpy as np
import pytest

import floedem


def test_a_run_as_arrays(runs):
    with floedem.open(runs / "scene.h5") as r:
        assert r.format_version == floedem.FORMAT_VERSION == 2
        assert r.status == "complete" and r.engine == "native"
        assert list(r.bodies.name) == ["wall", "berg", "a", "b"]
        n, t = 4, len(r.time)
        assert t == 8.0 / 0.1 / 4 + 1
        assert r.position.shape == (t, n, 2) and r.angle.shape == (t, n)
        assert r.velocity.shape == (t, n, 2) and r.angular_velocity.shape == (t, n)
        assert list(r.bodies.fixed) == [1, 0, 0, 0]
        # The mass of a floe: rho h A.
        assert r.bodies.mass[2] == pytest.approx(900.0 * 1.0 * 9.5 * 9.0, rel=1e-12)
        # Tables with rows.
        assert len(r.contacts) > 0 and r.contacts.point.shape == (len(r.contacts), 2)
        assert len(r.collisions) > 0 and np.all(r.collisions.peak_force > 0)
        assert r.tow.force_mean.shape == (len(r.tow), 2) and r.tow.attrs["body"] == "berg"
        assert r.loads.force.shape == (len(r.loads), 1, 2) and list(r.loads.body) == [0]
        assert r.summary["steps"] == 80
        assert "velocity_iterations" in r.engine_info
        # Velocity towing: the berg on its path.
        assert r.velocity[-1, 1, 0] == pytest.approx(1.5, abs=1e-12)


def test_world_polygons_are_the_local_ones_turned_and_moved(runs):
    with floedem.open(runs / "scene.h5") as r:
        local = r.local_polygons()
        for k in (0, r.frames // 2, -1):
            world = r.polygons(k)
            stacked = r.world_vertices(k)
            kk = r.frame_index(k)
            for i, p in enumerate(world):
                c, s = np.cos(r.angle[kk, i]), np.sin(r.angle[kk, i])
                expect = np.column_stack([c * local[i][:, 0] - s * local[i][:, 1],
                                          s * local[i][:, 0] + c * local[i][:, 1]]) + r.position[kk, i]
                np.testing.assert_allclose(p, expect, rtol=0, atol=1e-12)
                o = r.polygon_offsets
                np.testing.assert_array_equal(stacked[o[i]:o[i + 1]], p)
        # At t = 0 the outline is the scenario's polygon.
        np.testing.assert_allclose(r.polygons(0)[3], [[5, 0], [15, 0], [12, 8]], atol=1e-12)


def test_a_field_file(runs):
    with floedem.open(runs / "field.h5") as r:
        assert len(r.time) == 1 and r.engine.startswith("none")
        assert r.provenance["field"]["floes"] == len(r.bodies)
        assert r.contacts is None or len(r.contacts) == 0


def damaged(runs, tmp_path, edit):
    path = tmp_path / "damaged.h5"
    shutil.copy(runs / "scene.h5", path)
    with h5py.File(path, "r+") as f:
        edit(f)
    return path


@pytest.mark.parametrize("what, edit, needle", [
    ("newer format", lambda f: f.attrs.__setitem__("format_version", np.int64(3)),
     "/@format_version: is 3, this package reads 2: a newer floedem wrote it"),
    ("no format", lambda f: f.attrs.__delitem__("format_version"), "/@format_version: missing"),
    ("no bodies", lambda f: f.__delitem__("bodies"), "/bodies: missing"),
    ("offsets not from 0", lambda f: f["bodies/polygon_offsets"].__setitem__(0, 1), "/bodies/polygon_offsets"),
    ("positions of another shape", lambda f: (f.__delitem__("bodies/position"),
                                              f.create_dataset("bodies/position", data=np.zeros((3, 4)))),
     "/bodies/position: has shape [3, 4]"),
    ("a table short of rows", lambda f: (f.__delitem__("contacts/normal"),
                                         f.create_dataset("contacts/normal", data=np.zeros((1, 2)))),
     "contacts/normal: has 1 rows"),
])
def test_bad_files_are_refused_naming_file_and_dataset(runs, tmp_path, what, edit, needle):
    path = damaged(runs, tmp_path, edit)
    with pytest.raises(floedem.FileError) as e:
        floedem.open(path)
    assert str(path) in str(e.value) and needle in str(e.value), (what, str(e.value))


def test_not_floedem_files(tmp_path):
    with pytest.raises(floedem.FileError, match="no such file"):
        floedem.open(tmp_path / "none.h5")
    (tmp_path / "text.h5").write_text("not hdf5")
    with pytest.raises(floedem.FileError, match="not an HDF5 file"):
        floedem.open(tmp_path / "text.h5")


def test_frame_out_of_range(runs):
    with floedem.open(runs / "head_on.h5") as r:
        with pytest.raises(floedem.FileError, match=r"frame 500 is out of range; the file has 201 frames"):
            r.polygons(500)
        assert len(r.polygons(-201)) == 2


def test_a_format_1_file_is_read(tmp_path):
    # A run written by a floedem of format 1 (variable-length strings), kept in the repository:
    # read as a format 2 one is, its strings the same.
    import gzip
    from conftest import ROOT
    path = tmp_path / "run.h5"
    with gzip.open(os.path.join(ROOT, "tests", "io", "format1", "run.h5.gz")) as src, open(path, "wb") as dst:
        shutil.copyfileobj(src, dst)
    with floedem.open(path) as r:
        assert r.format_version == 1 and r.status == "complete" and r.engine == "native"
        assert all(isinstance(n, str) and n for n in r.bodies.name)
        assert "[run]" in r.attrs["scenario"]
