"""`gwn.load*` read every format the CLI reads, with the CLI's errors."""

import numpy as np
import pytest

import gwn
from conftest import FIXTURES, LION_HEAD, SHARED_MESHES, shared_mesh

CUBES = ["cube.obj", "cube.off", "cube_ascii.ply", "cube_binary_le.ply", "cube_binary_be.ply",
         "cube_ascii.stl", "cube_binary.stl"]


@pytest.mark.parametrize("name", CUBES)
def test_cube_fixtures_are_closed_unit_solids(name):
    v, f = gwn.load(FIXTURES / name)
    assert v.dtype == np.float64 and f.dtype == np.int64 and v.shape[1] == 3 and f.shape[1] == 3
    w = gwn.winding_number(v, f, np.array([[0.5, 0.5, 0.5], [2, 2, 2]]) * (v.max() - v.min()) + v.min())
    np.testing.assert_array_equal(np.abs(w), [1.0, 0.0])


def test_stl_is_welded_by_default():
    v, _ = gwn.load(FIXTURES / "cube_binary.stl")
    unwelded, _ = gwn.load(FIXTURES / "cube_binary.stl", weld=False)
    assert len(v) == 8 and len(unwelded) == 36


@pytest.mark.parametrize("name, words", [
    ("broken_index.obj", "references vertex"),
    ("broken_nan.off", "non-finite"),
    ("broken_truncated.off", "truncated"),
    ("broken_empty.stl", "no triangles"),
])
def test_broken_fixtures_are_value_errors(name, words):
    with pytest.raises(ValueError, match=words):
        gwn.load(FIXTURES / name)


def test_lion_head():
    v, f = gwn.load(LION_HEAD)
    assert len(f) > 1000


def test_points_and_clouds(tmp_path):
    q = gwn.load_points(FIXTURES / "points.csv")
    assert q.ndim == 2 and q.shape[1] == 3
    np.save(tmp_path / "q.npy", q.astype(np.float32))
    np.testing.assert_array_equal(gwn.load_points(tmp_path / "q.npy"), q.astype(np.float32))
    (tmp_path / "c.xyz").write_text("0 0 0 0 0 2 0.5\n1 0 0 0 3 0 0.25\n")
    p, n, a = gwn.load_point_cloud(tmp_path / "c.xyz")
    np.testing.assert_array_equal(n, [[0, 0, 1], [0, 1, 0]])
    np.testing.assert_array_equal(a, [0.5, 0.25])
    (tmp_path / "d.xyz").write_text("0 0 0 0 0 1\n")
    assert gwn.load_point_cloud(tmp_path / "d.xyz")[2] is None


def test_tets_and_polygons(tmp_path):
    (tmp_path / "t.node").write_text("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n")
    (tmp_path / "t.ele").write_text("1 4 0\n1 1 2 3 4\n")
    points, tets, refs = gwn.load_tets(tmp_path / "t.ele")
    assert points.shape == (4, 3)
    np.testing.assert_array_equal(tets, [[0, 1, 2, 3]])
    np.testing.assert_array_equal(refs, [0])
    (tmp_path / "p.txt").write_text("0 0\n1 0\n1 1\n0 1\n\n3 0\n4 0\n4 1\n")
    loops = gwn.load_polygon(tmp_path / "p.txt")
    assert [len(l) for l in loops] == [4, 3]
    np.testing.assert_allclose(gwn.gauwn(loops, 0.01, [[0.5, 0.5]]), [1.0], atol=1e-12)
    with pytest.raises(OSError):
        gwn.load_polygon(tmp_path / "missing.txt")
    with pytest.raises(OSError):
        gwn.load_tets(tmp_path / "missing.mesh")


def test_every_shared_mesh_loads_or_fails_cleanly():
    shared_mesh("manifest.csv")
    loaded = 0
    for path in sorted(SHARED_MESHES.iterdir()):
        if path.suffix.lower() not in {".obj", ".stl", ".off", ".ply"}:
            continue
        try:
            v, f = gwn.load(path)
        except ValueError as e:
            assert "\n" not in str(e)
            continue
        assert v.shape[1] == 3 and (f < len(v)).all()
        loaded += 1
    assert loaded > 50
