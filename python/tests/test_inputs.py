"""Array dtypes, layouts and bad input: clear exceptions, never a crash."""

import numpy as np
import pytest

import gwn
from conftest import CUBE_F, CUBE_V, OPEN_BOX_F, random_points

Q = random_points(200, seed=10)


def reference():
    return gwn.winding_number(CUBE_V, OPEN_BOX_F, Q)


@pytest.mark.parametrize("fdtype", [np.int32, np.int64, np.uint32, np.uint64])
@pytest.mark.parametrize("vdtype", [np.float32, np.float64])
def test_dtypes(vdtype, fdtype):
    # The cube's coordinates and Q rounded to float32 are exact in both, so values must match.
    q = Q.astype(np.float32).astype(vdtype)
    w = gwn.winding_number(CUBE_V.astype(vdtype), OPEN_BOX_F.astype(fdtype), q)
    assert w.dtype == np.float64
    np.testing.assert_array_equal(
        w, gwn.winding_number(CUBE_V, OPEN_BOX_F, Q.astype(np.float32).astype(np.float64))
    )


def test_strided_and_fortran_arrays_equal_contiguous():
    wide = np.zeros((len(Q), 6))
    wide[:, ::2] = Q
    strided = wide[:, ::2]
    assert not strided.flags.c_contiguous
    np.testing.assert_array_equal(gwn.winding_number(CUBE_V, OPEN_BOX_F, strided), reference())
    np.testing.assert_array_equal(
        gwn.winding_number(np.asfortranarray(CUBE_V), np.asfortranarray(OPEN_BOX_F),
                           np.asfortranarray(Q)),
        reference(),
    )
    np.testing.assert_array_equal(gwn.winding_number(CUBE_V, OPEN_BOX_F, Q[::-1])[::-1],
                                  reference())


def test_lists_are_accepted():
    w = gwn.winding_number(CUBE_V.tolist(), OPEN_BOX_F.tolist(), [[0.5, 0.5, 0.5]])
    assert abs(w[0] - 5 / 6) < 1e-14


def test_empty_query():
    w = gwn.winding_number(CUBE_V, OPEN_BOX_F, np.zeros((0, 3)))
    assert w.shape == (0,) and w.dtype == np.float64


def test_inputs_are_not_modified():
    q = Q.copy()
    v = CUBE_V.copy()
    gwn.WindingNumber(v, OPEN_BOX_F)(q)
    np.testing.assert_array_equal(q, Q)
    np.testing.assert_array_equal(v, CUBE_V)


@pytest.mark.parametrize(
    "call, exc, words",
    [
        (lambda: gwn.winding_number(CUBE_V[:, :2], CUBE_F, Q), ValueError, "V must have shape (n, 3)"),
        (lambda: gwn.winding_number(CUBE_V, CUBE_F[:, :2], Q), ValueError, "F must have shape (n, 3)"),
        (lambda: gwn.winding_number(CUBE_V, CUBE_F, Q[:, :2]), ValueError, "O must have shape (n, 3), got (200, 2)"),
        # One (3,) point is libigl's single query (a float, test_robust_calls.py); (2,) is not.
        (lambda: gwn.winding_number(CUBE_V, CUBE_F, Q[0, :2]), ValueError, "O must have shape (n, 3), got (2,)"),
        (lambda: gwn.winding_number(CUBE_V, CUBE_F.astype(float), Q), TypeError, "F must be an integer array"),
        (lambda: gwn.winding_number(CUBE_V.astype(np.int64), CUBE_F, Q), TypeError, "V must be float32 or float64"),
        (lambda: gwn.winding_number(CUBE_V, CUBE_F, Q.astype(np.complex128)), TypeError, "O must be float32 or float64"),
        (lambda: gwn.winding_number(CUBE_V, CUBE_F + 8, Q), ValueError, "references vertex 8, but the mesh has 8 vertices"),
        (lambda: gwn.winding_number(CUBE_V, -CUBE_F, Q), ValueError, "not a valid vertex index"),
        (lambda: gwn.winding_number(CUBE_V, CUBE_F.astype(np.int64) + 2**32, Q), ValueError, "not a valid vertex index"),
        (lambda: gwn.winding_number(np.where(CUBE_V == 1, np.nan, CUBE_V), CUBE_F, Q), ValueError, "non-finite coordinate"),
        (lambda: gwn.winding_number(CUBE_V, CUBE_F, [[0.0, np.inf, 0.0]]), ValueError, "O[0] = [0.0, inf, 0.0] is not finite"),
        (lambda: gwn.winding_number(CUBE_V, CUBE_F, [[1, 2], [3]]), TypeError, "O: not convertible"),
        (lambda: gwn.WindingNumber(CUBE_V, CUBE_F, method="approx"), ValueError, "method must be"),
        (lambda: gwn.WindingNumber(CUBE_V, CUBE_F, precision=32), ValueError, "precision must be 30 or 60"),
        (lambda: gwn.WindingNumber(CUBE_V, CUBE_F, ray="+w"), ValueError, "ray must be one of"),
        (lambda: gwn.WindingNumber(CUBE_V, CUBE_F, method="fast", beta=float("nan")), ValueError, "beta must be"),
        (lambda: gwn.fast_winding_number(CUBE_V, CUBE_F, Q, order=3), ValueError, "order must be 0, 1 or 2"),
        (lambda: gwn.fast_winding_number(CUBE_V, CUBE_F, Q, rule="corner"), ValueError, "rule must be \"radius\""),
        (lambda: gwn.WindingNumber(CUBE_V, CUBE_F, rule="box-corner"), ValueError, "rule does not apply to the exact method"),
        (lambda: gwn.fast_winding_number(CUBE_V, CUBE_F, Q, order=1, expansion_order=1), TypeError, "not both"),
        (lambda: gwn.fast_winding_number(CUBE_V, Q), TypeError, "takes (V, F, Q) or (P, N, A, Q)"),
        (lambda: gwn.fast_winding_number(CUBE_V, CUBE_V, np.ones(7), Q), ValueError, "A must have shape (8,)"),
        (lambda: gwn.WindingNumber(CUBE_V, CUBE_F, method="fast").gradient(Q), ValueError, "gradient is not available with the fast method"),
        (lambda: gwn.WindingNumber(CUBE_V, CUBE_F, method="direct").parts(Q), ValueError, "parts is not available with the direct method"),
        (lambda: gwn.WindingNumber(CUBE_V, CUBE_F)(Q, threads=0), ValueError, "threads must be between 1 and 1024"),
        (lambda: gwn.voxelize(CUBE_V, CUBE_F, dims=(0, 1, 1)), ValueError, "bad grid"),
        (lambda: gwn.voxelize(CUBE_V, CUBE_F, dims=(2**11, 2**11, 2**10)), ValueError, "too large"),
        (lambda: gwn.voxelize(CUBE_V, CUBE_F[:0]), ValueError, "no triangles"),
        (lambda: gwn.voxelize(CUBE_V, CUBE_F, margin=-1.0), ValueError, "margin"),
        (lambda: gwn.slice(CUBE_V, CUBE_F, axis="w"), ValueError, "axis must be"),
        (lambda: gwn.slice(CUBE_V, CUBE_F, res=0), ValueError, "res must be between"),
        (lambda: gwn.filter_tets(CUBE_V, CUBE_F, CUBE_V, [[0, 1, 2, 9]]), ValueError, "references a point beyond"),
        (lambda: gwn.gauwn([[0, 0], [1, 0], [1, 1]], 0.0, [[0.5, 0.5]]), ValueError, "sigma must be"),
        (lambda: gwn.gauwn([[0.0, 0.0], [0.0, 0.0]], 0.1, [[0.5, 0.5]]), ValueError, "loop 0 has 1 distinct vertices"),
        (lambda: gwn.gauwn([[0, 0], [1, 0], [1, 1]], 0.1, [[0.5, 0.5]]), TypeError, "polygon must be float32 or float64"),
        (lambda: gwn.gauwn([[0.0, 0], [1, 0], [1, 1]], 0.1, [[0.5, 0.5, 0.5]]), ValueError, "Q must have shape (n, 2)"),
        (lambda: gwn.load("/nonexistent/mesh.obj"), OSError, "cannot read"),
    ],
)
def test_bad_input(call, exc, words):
    with pytest.raises(exc) as info:
        call()
    assert words in str(info.value)
    assert "\n" not in str(info.value)
