"""Agreement with libigl within libigl's own error (skipped when `igl` is not installed)."""

import numpy as np
import pytest

import gwn
from conftest import random_points

try:
    import igl
except ImportError:
    igl = None
    print("skipping: libigl is not installed (pip install libigl to run these)")

pytestmark = pytest.mark.skipif(igl is None, reason="libigl is not installed (pip install libigl)")


@pytest.fixture(scope="module")
def lion_queries(lion):
    v, _ = lion
    lo, hi = v.min(axis=0), v.max(axis=0)
    return lo + (hi - lo) * random_points(3000, lo=-0.1, hi=1.1, seed=40)


def test_exact_against_igl_winding_number(lion, lion_queries):
    v, f = lion
    ours = gwn.winding_number(v, f, lion_queries)
    theirs = igl.winding_number(v, f, lion_queries)
    # libigl sums solid angles in double precision: agreement to rounding, far from integers.
    np.testing.assert_allclose(ours, theirs, atol=1e-9)


def test_fast_against_igl_fast_winding_number(lion, lion_queries):
    v, f = lion
    exact = gwn.winding_number(v, f, lion_queries)
    theirs = igl.fast_winding_number(v, f, lion_queries)
    ours = gwn.fast_winding_number(v, f, lion_queries)
    # Both are Barill et al.'s order-2, beta-2 approximation: each within its documented error of
    # the exact value (docs/benchmarks.md: libigl fast max error 7.5e-3 on the open meshes).
    assert np.abs(theirs - exact).max() < 2e-2
    assert np.abs(ours - exact).max() < 2e-2
    np.testing.assert_allclose(ours, theirs, atol=2e-2)


def test_point_cloud_against_igl():
    n = 3000
    i = np.arange(n) + 0.5
    phi = np.arccos(1 - 2 * i / n)
    theta = np.pi * (1 + 5**0.5) * i
    p = np.stack([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)], axis=1)
    a = np.full(n, 4 * np.pi / n)
    q = random_points(500, lo=-1.5, hi=1.5, seed=41)
    # Away from the sampled surface, where both expansions converge.
    q = q[np.abs(np.linalg.norm(q, axis=1) - 1) > 0.1]
    theirs = igl.fast_winding_number(p, p, a, q)
    ours = gwn.fast_winding_number(p, p, a, q)
    np.testing.assert_allclose(ours, theirs, atol=1e-2)
