"""tolerance= (certified far-boundary expansion of the exact method) and eval_with_bound."""

import pickle

import numpy as np
import pytest

import gwn
from conftest import CUBE_F, CUBE_V, OPEN_BOX_F, random_points

TOLERANCES = (1e-3, 1e-6)


def holey_surface(n=60, holes=0.15, seed=40):
    """A wavy height field over [0, 1]^2, n x n cells of two triangles, with a random `holes`
    fraction of its triangles removed: an open mesh with thousands of boundary edges."""
    x = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(x, x, indexing="xy")
    Z = 0.1 * np.sin(3.0 * X) * np.cos(2.0 * Y)
    V = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="xy")
    a = (j * (n + 1) + i).ravel()
    b, c, d = a + 1, a + n + 2, a + n + 1
    F = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])]).astype(np.int64)
    keep = np.random.default_rng(seed).random(len(F)) >= holes
    return V, F[keep]


@pytest.fixture(scope="module")
def surface():
    return holey_surface()


@pytest.fixture(scope="module")
def far_queries():
    """Points at 3 to 10 times the mesh size (1) from its centre, in random directions."""
    rng = np.random.default_rng(41)
    d = rng.normal(size=(400, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.array([0.5, 0.5, 0.0]) + d * rng.uniform(3.0, 10.0, size=(400, 1))


@pytest.fixture(scope="module")
def near_queries():
    """Points in and around the mesh's box, and points just above and below the surface."""
    rng = np.random.default_rng(42)
    box = rng.uniform([-0.2, -0.2, -0.4], [1.2, 1.2, 0.4], size=(400, 3))
    xy = rng.uniform(0.0, 1.0, size=(200, 2))
    z = 0.1 * np.sin(3.0 * xy[:, 0]) * np.cos(2.0 * xy[:, 1])
    close = np.column_stack([xy, z + rng.choice([-1.0, 1.0], 200) * rng.uniform(1e-3, 0.05, 200)])
    return np.vstack([box, close])


def test_surface_has_many_boundary_edges(surface):
    assert gwn.WindingNumber(*surface).boundary_edge_count >= 1000


@pytest.mark.parametrize("tolerance", TOLERANCES)
@pytest.mark.parametrize("where", ["far", "near"])
def test_bound_is_certified(surface, far_queries, near_queries, tolerance, where):
    q = far_queries if where == "far" else near_queries
    w_flat = gwn.WindingNumber(*surface, tolerance=0.0)(q)
    wn = gwn.WindingNumber(*surface, tolerance=tolerance)
    assert wn.tolerance == tolerance
    w, bound = wn.eval_with_bound(q)
    assert w.dtype == np.float64 and bound.dtype == np.float64
    assert w.shape == bound.shape == (len(q),)
    assert np.all(bound >= 0.0)
    assert np.all(bound <= tolerance)
    assert np.all(np.abs(w - w_flat) <= bound + 1e-13)
    # The value is the evaluator's own, bit for bit, on any number of threads.
    np.testing.assert_array_equal(w, wn(q))
    w1, bound1 = wn.eval_with_bound(q, threads=1)
    np.testing.assert_array_equal(w1, w)
    np.testing.assert_array_equal(bound1, bound)


def test_far_queries_use_the_hierarchy(surface, far_queries):
    w_flat = gwn.WindingNumber(*surface, tolerance=0.0)(far_queries)
    w, bound = gwn.WindingNumber(*surface, tolerance=1e-3).eval_with_bound(far_queries)
    assert np.count_nonzero(bound > 0.0) > len(far_queries) // 2
    # Bounds beyond the default tolerance: 1e-3 reached the evaluator.
    assert bound.max() > 1e-6
    # Expanded values are not the flat loop's bits (else the test would not test anything).
    assert np.any(w != w_flat)


def test_tolerance_zero_is_the_flat_loop(surface, far_queries, near_queries):
    q = np.vstack([far_queries, near_queries])
    wn = gwn.WindingNumber(*surface, tolerance=0)
    w, bound = wn.eval_with_bound(q)
    assert np.all(bound == 0.0)
    np.testing.assert_array_equal(w, wn(q))


def test_default_tolerance(surface, far_queries):
    wn = gwn.WindingNumber(*surface)
    assert wn.tolerance == 1e-10
    w, bound = wn.eval_with_bound(far_queries)
    assert np.all(bound <= 1e-10)
    w_flat = gwn.WindingNumber(*surface, tolerance=0.0)(far_queries)
    assert np.all(np.abs(w - w_flat) <= bound + 1e-13)


def test_integer_part_is_exact(surface, near_queries):
    chi_flat, _ = gwn.WindingNumber(*surface, tolerance=0.0).parts(near_queries)
    chi, _ = gwn.WindingNumber(*surface, tolerance=1e-3).parts(near_queries)
    np.testing.assert_array_equal(chi, chi_flat)


def test_one_shot_and_products_pass_the_tolerance(surface, far_queries):
    v, f = surface
    tol = 1e-3
    wn = gwn.WindingNumber(v, f, tolerance=tol)
    np.testing.assert_array_equal(gwn.winding_number(v, f, far_queries, tolerance=tol),
                                  wn(far_queries))
    assert np.any(gwn.winding_number(v, f, far_queries, tolerance=0.0) != wn(far_queries))
    bounds = (-10.0, -10.0, -10.0, 11.0, 11.0, 10.0)
    flat, _, _ = gwn.voxelize(v, f, dims=(6, 6, 5), bounds=bounds, tolerance=0.0)
    coarse, _, _ = gwn.voxelize(v, f, dims=(6, 6, 5), bounds=bounds, tolerance=tol)
    assert np.all(np.abs(coarse - flat) <= tol + 1e-13)
    assert np.any(coarse != flat)


def test_closed_mesh_has_zero_bound():
    w, bound = gwn.WindingNumber(CUBE_V, CUBE_F, tolerance=1e-3).eval_with_bound(
        random_points(300, seed=43))
    assert np.all(bound == 0.0)
    assert set(np.unique(w)) <= {0.0, 1.0}


@pytest.mark.parametrize("method, name", [("direct", "direct"), ("fast", "fast")])
def test_eval_with_bound_needs_the_exact_method(method, name):
    wn = gwn.WindingNumber(CUBE_V, OPEN_BOX_F, method=method)
    assert wn.tolerance is None
    with pytest.raises(ValueError, match=f"eval_with_bound is not available with the {name} method"):
        wn.eval_with_bound(random_points(5))


def test_eval_with_bound_rejects_a_point_cloud():
    p = np.random.default_rng(44).normal(size=(50, 3))
    with pytest.raises(ValueError, match="not available with the fast point-cloud method"):
        gwn.WindingNumber.from_point_cloud(p, p).eval_with_bound(p)


def test_eval_with_bound_checks_queries():
    wn = gwn.WindingNumber(CUBE_V, OPEN_BOX_F)
    with pytest.raises(ValueError, match=r"Q must have shape \(n, 3\)"):
        wn.eval_with_bound(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="is not finite"):
        wn.eval_with_bound([[0.0, np.nan, 0.0]])
    w, bound = wn.eval_with_bound(np.zeros((0, 3)))
    assert w.shape == bound.shape == (0,)
    # float32 and Fortran-ordered queries are converted like everywhere else.
    q = random_points(20, seed=45)
    w64, b64 = wn.eval_with_bound(q)
    w_f, b_f = wn.eval_with_bound(np.asfortranarray(q))
    np.testing.assert_array_equal(w_f, w64)
    np.testing.assert_array_equal(b_f, b64)
    w32, _ = wn.eval_with_bound(q.astype(np.float32))
    np.testing.assert_array_equal(w32, wn(q.astype(np.float32)))


BAD_TOLERANCES = [-1.0, float("nan"), float("inf"), -float("inf")]
CALLS = {
    "WindingNumber": lambda t: gwn.WindingNumber(CUBE_V, OPEN_BOX_F, tolerance=t),
    "winding_number": lambda t: gwn.winding_number(CUBE_V, OPEN_BOX_F, [[0.5] * 3], tolerance=t),
    "voxelize": lambda t: gwn.voxelize(CUBE_V, OPEN_BOX_F, 4, tolerance=t),
    "sdf": lambda t: gwn.sdf(CUBE_V, OPEN_BOX_F, 4, tolerance=t),
    "signed_distance": lambda t: gwn.signed_distance(CUBE_V, OPEN_BOX_F, [[0.5] * 3],
                                                     tolerance=t),
    "slice": lambda t: gwn.slice(CUBE_V, OPEN_BOX_F, res=8, tolerance=t),
    "classify": lambda t: gwn.classify(CUBE_V, OPEN_BOX_F, CUBE_V, OPEN_BOX_F, tolerance=t),
    "filter_tets": lambda t: gwn.filter_tets(CUBE_V, OPEN_BOX_F, CUBE_V, [[0, 1, 2, 4]],
                                             tolerance=t),
}


@pytest.mark.parametrize("tolerance", BAD_TOLERANCES)
@pytest.mark.parametrize("call", CALLS.values(), ids=CALLS.keys())
def test_bad_tolerance(call, tolerance):
    with pytest.raises(ValueError, match="tolerance must be a finite number >= 0") as info:
        call(tolerance)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("method", ["direct", "fast"])
def test_tolerance_is_an_exact_option(method):
    """The library's rule (and the CLI's): an option the method does not use is an error."""
    with pytest.raises(ValueError, match=f"tolerance does not apply to the {method} method"):
        gwn.WindingNumber(CUBE_V, OPEN_BOX_F, method=method, tolerance=1e-6)
    # A bad value is reported as such first, whatever the method.
    with pytest.raises(ValueError, match="tolerance must be a finite number >= 0"):
        gwn.WindingNumber(CUBE_V, OPEN_BOX_F, method=method, tolerance=float("nan"))


@pytest.mark.parametrize("call", CALLS.values(), ids=CALLS.keys())
def test_good_tolerances(call):
    for tolerance in (0, 0.0, 1e-12, 0.5):
        call(tolerance)


@pytest.mark.parametrize("tolerance", [0.0, 1e-3])
def test_pickle_keeps_the_tolerance(surface, far_queries, tolerance):
    wn = gwn.WindingNumber(*surface, tolerance=tolerance)
    back = pickle.loads(pickle.dumps(wn))
    assert back.tolerance == tolerance
    w, bound = wn.eval_with_bound(far_queries)
    w_back, bound_back = back.eval_with_bound(far_queries)
    np.testing.assert_array_equal(w_back, w)
    np.testing.assert_array_equal(bound_back, bound)
    if tolerance:
        assert np.any(bound > 1e-10), "a lost tolerance (back to 1e-10) would go unnoticed"


@pytest.mark.parametrize("ray", ["+z", "-x", "+y"])
def test_numpy_grid_points_equal_point_by_point(surface, ray):
    # A numpy grid listed with the ray's axis last is evaluated line by line (one ray and one
    # shared boundary loop per line): the same bits as one point at a time.
    V, F = surface
    axes = [np.linspace(-0.3, 1.3, 9), np.linspace(-0.2, 1.2, 7), np.linspace(-0.5, 0.5, 33)]
    last = {"x": 0, "y": 1, "z": 2}[ray[1]]
    order = [k for k in range(3) if k != last] + [last]
    mesh = np.meshgrid(*[axes[k] for k in order], indexing="ij")
    Q = np.empty((mesh[0].size, 3))
    for i, k in enumerate(order):
        Q[:, k] = mesh[i].ravel()
    wn = gwn.WindingNumber(V, F, ray=ray)
    batch = wn(Q)
    single = np.array([wn(Q[i:i + 1])[0] for i in range(len(Q))])
    assert np.array_equal(batch.view(np.int64), single.view(np.int64))
