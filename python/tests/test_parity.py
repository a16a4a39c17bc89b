"""The parity method from Python: ``method="parity"`` gives 1 where a ray crosses a closed mesh
an odd number of times, whatever its faces' orientations, in ``WindingNumber``, the grid products
and ``remesh``; open meshes are refused with the number of odd edges."""

import numpy as np
import pytest

import gwn

from conftest import CUBE_F, CUBE_V, OPEN_BOX_F

# The unit cube with every other face flipped: closed, not oriented (w is fractional inside).
FLIPPED_F = np.array([f[::-1] if k % 2 else f for k, f in enumerate(CUBE_F)], dtype=np.int64)


def grid_points(n=7):
    t = (np.arange(n) + 0.5) / n * 1.6 - 0.3  # -0.3 .. 1.3, off the cube's planes
    return np.stack(np.meshgrid(t, t, t, indexing="ij"), -1).reshape(-1, 3)


def test_parity_is_the_enclosed_solid_where_w_is_not():
    q = grid_points()
    inside = np.all((q > 0) & (q < 1), axis=1).astype(np.float64)
    for ray in ["+x", "-y", "+z"]:
        p = gwn.WindingNumber(CUBE_V, FLIPPED_F, method="parity", ray=ray)(q)
        np.testing.assert_array_equal(p, inside)
    w = gwn.WindingNumber(CUBE_V, FLIPPED_F)(q)
    assert np.any(np.abs(w[inside == 1] - 1) > 0.1)  # w alone is not the solid here
    W, origin, spacing = gwn.voxelize(CUBE_V, FLIPPED_F, res=8, margin=0.5, method="parity")
    k, j, i = np.meshgrid(*(np.arange(n) for n in W.shape), indexing="ij")
    centres = origin + np.stack([i, j, k], -1).reshape(-1, 3) * spacing
    expected = np.all((centres > 0) & (centres < 1), axis=1).astype(np.float64)
    np.testing.assert_array_equal(W.reshape(-1), expected)
    assert 0 < expected.sum() < len(expected)


def rotated_to_least(F):
    """Each face's vertices rotated to start at its least (the same face, the same way round)."""
    return np.array([np.roll(f, -int(np.argmin(f))) for f in F])


def test_remesh_with_parity_encloses_the_cube():
    # Kept: the cube's own faces, the six flipped ones turned back, no lattice.
    V, F, report = gwn.remesh(CUBE_V, FLIPPED_F, res=16, method="parity", report=True)
    assert report["input"] == "reoriented" and report["input_turned_faces"] == 6
    np.testing.assert_array_equal(V, CUBE_V)
    np.testing.assert_array_equal(rotated_to_least(F), rotated_to_least(CUBE_F))
    assert report["hausdorff_cells"] == 0
    # Remeshed on request: the lattice surface of the same solid.
    V, F, report = gwn.remesh(
        CUBE_V, FLIPPED_F, res=16, method="parity", report=True, always_remesh=True
    )
    assert "input" not in report and report["classified_points"] > 0
    assert report["closed"] and report["oriented"] and report["components"] == 1
    # Volume by the divergence theorem: the unit cube's, within the placement's precision.
    a, b, c = (V[F[:, k]] for k in range(3))
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6
    assert abs(volume - 1) < 1e-3, volume
    assert report["hausdorff_cells"] < 1


def test_remesh_of_a_flipped_closed_mesh_warns_and_names_parity():
    # The exact method's w is fractional inside: said, with what parity would do.
    with pytest.warns(UserWarning, match=r"closed but not consistently oriented \(\d+ signed "
                      r"boundary edges\).*method='parity' keeps it with 6 of its faces turned"):
        gwn.remesh(CUBE_V, FLIPPED_F, res=8)
    # Nothing to say about a consistently oriented cube.
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gwn.remesh(CUBE_V, CUBE_F, res=8)


def test_the_parity_evaluator_pickles_with_its_ray_and_has_no_gradient():
    import pickle

    wn = gwn.WindingNumber(CUBE_V, FLIPPED_F, method="parity", ray="-y")
    back = pickle.loads(pickle.dumps(wn))
    assert back.method == "parity"
    q = grid_points()
    np.testing.assert_array_equal(back(q), wn(q))
    with pytest.raises(ValueError, match="gradient is not available with the parity method"):
        wn.gradient(q[:1])


def test_open_meshes_and_options_are_refused():
    with pytest.raises(ValueError, match="parity method needs a closed mesh, but 4 edges"):
        gwn.WindingNumber(CUBE_V, OPEN_BOX_F, method="parity")
    with pytest.raises(ValueError, match="tolerance does not apply to the parity method"):
        gwn.WindingNumber(CUBE_V, CUBE_F, method="parity", tolerance=1e-6)
