"""Bezier patch sets in Python: ``gwn.load("x.bpt")`` gives a ``gwn.PatchSet``, evaluated by
``gwn.WindingNumber`` and remeshed by ``gwn.remesh`` with the CLI's options and errors. The
inputs are written by the tests (a cube of bilinear patches, its open box, the rational unit
sphere); the shared teapot (``../shared/parametric/teapot.bpt``) skips visibly when absent."""

import math
import pickle
import subprocess
import warnings

import numpy as np
import pytest

import gwn

from conftest import CUBE_F, CUBE_V, OPEN_BOX_F, SHARED

CUBE_QUADS = [  # (corner 00, 01, 10, 11) of each face, outward (row-major 2x2 control points)
    [0, 3, 1, 2],  # z = 0
    [4, 5, 7, 6],  # z = 1
    [0, 1, 4, 5],  # y = 0
    [2, 3, 6, 7],  # y = 1
    [1, 2, 5, 6],  # x = 1
    [3, 0, 7, 4],  # x = 0
]


def write_bpt(path, quads):
    """A .bpt of bilinear patches over CUBE_V's corners."""
    lines = [str(len(quads))]
    for quad in quads:
        lines.append("1 1")
        lines += [" ".join(repr(float(c)) for c in CUBE_V[i]) for i in quad]
    path.write_text("\n".join(lines) + "\n")
    return path


def write_sphere_rbpt(path):
    """The unit sphere as 8 rational biquadratic patches (quarter circles x half meridians),
    outward (as tests/common::rational_sphere_patches)."""
    w = math.sqrt(0.5)
    south = [(0.0, -1.0, 1.0), (1.0, -1.0, w), (1.0, 0.0, 1.0)]
    north = [(1.0, 0.0, 1.0), (1.0, 1.0, w), (0.0, 1.0, 1.0)]
    quarters = [
        [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0)],
        [(0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0)],
        [(-1.0, 0.0), (-1.0, -1.0), (0.0, -1.0)],
        [(0.0, -1.0), (1.0, -1.0), (1.0, 0.0)],
    ]
    cw = [1.0, w, 1.0]
    lines = ["8"]
    for profile in (south, north):
        for quarter in quarters:
            lines.append("2 2")
            for r, z, wp in profile:
                for (x, y), wc in zip(quarter, cw):
                    lines.append(f"{r * x!r} {r * y!r} {z!r} {wp * wc!r}")
    path.write_text("\n".join(lines) + "\n")
    return path


def lattice(lo, hi, n, avoid):
    """An n^3 grid of points in [lo, hi]^3, nudged off the planes in `avoid`."""
    t = np.linspace(lo, hi, n) + 0.0123
    q = np.stack(np.meshgrid(t, t, t, indexing="ij"), -1).reshape(-1, 3)
    return q[np.all(np.abs(q[:, :, None] - np.array(avoid)) > 1e-3, axis=(1, 2))]


@pytest.fixture
def cube_bpt(tmp_path):
    return write_bpt(tmp_path / "cube.bpt", CUBE_QUADS)


def test_load_gives_a_patch_set_and_exact_integers_for_a_closed_one(cube_bpt):
    patches = gwn.load(cube_bpt)
    assert isinstance(patches, gwn.PatchSet)
    assert len(patches) == 6
    assert patches.info == {"patches": 6, "rational": False, "max_degree": (1, 1)}
    lo, hi = patches.bounding_box
    np.testing.assert_array_equal(lo, [0, 0, 0])
    np.testing.assert_array_equal(hi, [1, 1, 1])
    assert str(cube_bpt) in repr(patches)
    wn = gwn.WindingNumber(patches)
    assert wn.method == "exact" and wn.face_count == 6 and wn.boundary_edge_count == 0
    q = lattice(-0.5, 1.5, 9, [0.0, 1.0])
    inside = np.all((q > 0) & (q < 1), axis=1).astype(np.float64)
    # A closed set: exact integers off the surface, certified (no warning), on every ray.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_array_equal(wn(q), inside)
        np.testing.assert_array_equal(wn(q), gwn.WindingNumber(CUBE_V, CUBE_F)(q))
        for ray in ["-x", "+y", "-z"]:
            np.testing.assert_array_equal(gwn.WindingNumber(patches, ray=ray)(q), inside)
    assert wn([0.5, 0.5, 0.5]) == 1.0


@pytest.mark.parametrize("method", ["exact", "direct"])
def test_an_open_set_equals_the_same_open_mesh(tmp_path, method):
    # Five planar bilinear faces are the open box's ten triangles: the same w everywhere.
    patches = gwn.load(write_bpt(tmp_path / "box.bpt", CUBE_QUADS[:1] + CUBE_QUADS[2:]))
    wn = gwn.WindingNumber(patches, method=method)
    assert wn.method == method
    q = lattice(-0.5, 1.5, 7, [0.0, 1.0])
    want = gwn.WindingNumber(CUBE_V, OPEN_BOX_F)(q)
    assert np.abs(want - np.round(want)).max() > 0.1  # fractional: the boundary term counts
    np.testing.assert_allclose(wn(q), want, rtol=0, atol=1e-8)
    if method == "exact":
        assert wn.boundary_edge_count == 4
        for ray in ["+x", "-y", "-z"]:
            np.testing.assert_allclose(gwn.WindingNumber(patches, ray=ray)(q), want, atol=1e-8)


def test_the_rational_sphere_is_exact_inside_and_outside(tmp_path):
    patches = gwn.load(write_sphere_rbpt(tmp_path / "sphere.rbpt"))
    assert patches.info["rational"] and patches.info["max_degree"] == (2, 2)
    q = lattice(-1.4, 1.4, 8, [])
    r = np.linalg.norm(q, axis=1)
    q = q[np.abs(r - 1) > 1e-3]
    wn = gwn.WindingNumber(patches)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_array_equal(wn(q), (np.linalg.norm(q, axis=1) < 1).astype(np.float64))


def test_uncertified_values_warn_and_are_flagged(cube_bpt):
    wn = gwn.WindingNumber(gwn.load(cube_bpt))
    q = np.array([[0.5, 0.5, 0.5], [0.5, 0.5, 1.0], [2.0, 2.0, 2.0]])
    with pytest.warns(RuntimeWarning, match=r"1 of 3 values uncertified .*docs/patches.md"):
        w = wn(q)
    values, errors, uncertified = wn.eval_with_status(q)
    np.testing.assert_array_equal(values, w)
    assert uncertified.tolist() == [False, True, False]
    assert errors.shape == (3,)
    with pytest.raises(ValueError, match="eval_with_status"):
        gwn.WindingNumber(gwn.load(cube_bpt), method="direct").eval_with_status(q)


def test_options_and_files_are_refused_with_the_cli_messages(tmp_path, cube_bpt):
    patches = gwn.load(cube_bpt)
    with pytest.raises(ValueError, match="F does not apply to a patch set"):
        gwn.WindingNumber(patches, CUBE_F)
    with pytest.raises(ValueError, match="precision"):
        gwn.WindingNumber(patches, precision=30)
    with pytest.raises(ValueError, match="fast"):
        gwn.WindingNumber(patches, method="fast")
    with pytest.raises(ValueError, match="weld does not apply to patch sets"):
        gwn.load(cube_bpt, weld=True)
    with pytest.raises(FileNotFoundError, match="missing.bpt"):
        gwn.load(tmp_path / "missing.bpt")
    bad = tmp_path / "bad.rbpt"
    bad.write_text("1\n1 1\n0 0 0 1\n1 0 0 1\n0 1 0 -2\n1 1 0 1\n")
    with pytest.raises(ValueError, match=r"bad.rbpt: patch 0, control point 2: weight -2"):
        gwn.load(bad)
    truncated = tmp_path / "short.bpt"
    truncated.write_text("2\n1 1\n0 0 0\n")
    with pytest.raises(ValueError, match=r"short.bpt: line"):
        gwn.load(truncated)


def test_patch_sets_and_their_evaluators_pickle(cube_bpt):
    patches = gwn.load(cube_bpt)
    again = pickle.loads(pickle.dumps(patches))
    assert isinstance(again, gwn.PatchSet) and again.path == patches.path
    q = lattice(-0.5, 1.5, 5, [0.0, 1.0])
    for wn in [gwn.WindingNumber(patches, ray="-x", tolerance=1e-8),
               gwn.WindingNumber(patches, method="direct", tolerance=1e-6)]:
        copy = pickle.loads(pickle.dumps(wn))
        assert repr(copy) == repr(wn)
        np.testing.assert_array_equal(copy(q), wn(q))


def test_remesh_of_a_patch_set_is_the_cli_s(tmp_path, cli):
    path = write_sphere_rbpt(tmp_path / "sphere.rbpt")
    patches = gwn.load(path)
    V, F, report = gwn.remesh(patches, res=16, report=True, samples=2000)
    assert report["closed"] and report["edge_manifold"] and report["vertex_manifold"]
    assert report["oriented"] and report["euler_characteristic"] == 2
    assert report["self_intersections"] == 0
    # Vertices on the sphere (placed at the patches' own surface hits), within a cell.
    assert np.abs(np.linalg.norm(V, axis=1) - 1).max() < 2.0 / 16
    out = tmp_path / "sphere.obj"
    subprocess.run([str(cli), "remesh", str(path), "--res", "16", "--samples", "0", "--out",
                    str(out)], check=True, capture_output=True)
    V2, F2 = gwn.load(out)
    assert F2.shape == F.shape and np.abs(V2 - V).max() < 1e-6  # OBJ's decimal round trip
    with pytest.raises(ValueError, match="a patch set takes no F"):
        gwn.remesh(patches, CUBE_F, res=16)
    with pytest.raises(ValueError, match="thicken= needs triangles"):
        gwn.remesh(patches, res=16, thicken=0.2)


def test_the_shared_teapot_loads_and_evaluates():
    teapot = SHARED / "parametric" / "teapot.bpt"
    if not teapot.exists():
        pytest.skip(f"{teapot} absent (the shared data folder is not beside the repository)")
    patches = gwn.load(teapot)
    assert len(patches) == 32
    wn = gwn.WindingNumber(patches)
    # Inside the body, above the lid and beside the spout.
    values = wn(np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 5.0], [5.0, 5.0, 1.0]]))
    assert abs(values[0] - 1) < 0.05 and abs(values[1]) < 0.05 and abs(values[2]) < 0.05


def test_voxelize_takes_patch_sets_and_step_models(cube_bpt):
    from conftest import FIXTURES

    patches = gwn.load(cube_bpt)
    W, origin, spacing = gwn.voxelize(patches, res=6, margin=0.25)
    assert W.shape == (6, 6, 6)
    k, j, i = np.meshgrid(*(np.arange(n) for n in W.shape), indexing="ij")
    points = origin + np.stack([i, j, k], -1).reshape(-1, 3) * spacing
    inside = np.all((points > 0) & (points < 1), axis=1).astype(np.float64)
    np.testing.assert_array_equal(W.reshape(-1), inside)  # a closed set: exact integers
    model = gwn.load(FIXTURES / "step" / "capped_cylinder.step")
    W, origin, spacing = gwn.voxelize(model, res=8)
    k, j, i = np.meshgrid(*(np.arange(n) for n in W.shape), indexing="ij")
    points = origin + np.stack([i, j, k], -1).reshape(-1, 3) * spacing
    np.testing.assert_allclose(W.reshape(-1), gwn.WindingNumber(model)(points), atol=1e-12)
    assert W.max() == 1.0 and W.min() == 0.0
    with pytest.raises(ValueError, match="a patch set takes no F"):
        gwn.voxelize(patches, CUBE_F, res=6)
    with pytest.raises(ValueError, match="precision|fast"):
        gwn.voxelize(patches, res=6, method="fast")
    with pytest.raises(ValueError, match="F is required for a mesh"):
        gwn.voxelize(CUBE_V, res=6)


@pytest.mark.parametrize("kind", ["patches", "step"])
def test_slice_of_a_model_is_the_cli_s(tmp_path, cli, cube_bpt, kind):
    from conftest import FIXTURES

    path = cube_bpt if kind == "patches" else FIXTURES / "step" / "capped_cylinder.step"
    model = gwn.load(path)
    image, png = gwn.slice(model, axis="x", at=0.4, res=48)
    subprocess.run([str(cli), "slice", str(path), "--axis", "x", "--at", "0.4", "--res", "48",
                    "--out", str(tmp_path / "s.png")], check=True, capture_output=True)
    assert png == (tmp_path / "s.png").read_bytes()
    # A closed solid cut across its middle: 1 inside the section, 0 around it.
    assert image.max() == 1.0 and image.min() == 0.0
    # Of the box grown by 10 % on each side: the unit square; the cylinder's rectangle at
    # x = -0.2, y within sqrt(0.96) of the axis, z in [0, 2].
    section = 1.0 / 1.2**2 if kind == "patches" else 2 * math.sqrt(0.96) * 2 / 2.4**2
    assert abs(np.mean(image > 0.5) - section) < 0.03, np.mean(image > 0.5)
    with pytest.raises(ValueError, match="outline needs a triangle mesh"):
        gwn.slice(model, outline=True)
    with pytest.raises(ValueError, match="takes no F"):
        gwn.slice(model, "x")


@pytest.mark.parametrize("kind", ["patches", "step"])
def test_classify_against_a_model(cube_bpt, kind):
    from conftest import FIXTURES

    path = cube_bpt if kind == "patches" else FIXTURES / "step" / "capped_cylinder.step"
    model = gwn.load(path)
    # A mesh half in and half out of the model: the cube shifted by half its side.
    VA = np.asarray(CUBE_V, dtype=np.float64) * 0.8 + 0.5
    values = gwn.classify(VA, CUBE_F, model)
    centroids = VA[np.asarray(CUBE_F)].mean(axis=1)
    np.testing.assert_array_equal(values, gwn.WindingNumber(model)(centroids))
    assert 0 < np.sum(values > 0.5) < len(CUBE_F)
    with pytest.raises(ValueError, match="takes no FB"):
        gwn.classify(VA, CUBE_F, model, CUBE_F)
    with pytest.raises(ValueError, match="FB is required for a mesh"):
        gwn.classify(VA, CUBE_F, VA)
