"""Values known in closed form, through every entry point."""

import numpy as np
import pytest

import gwn
from conftest import CUBE_F, CUBE_V, OPEN_BOX_F, TET_F, TET_V, random_points


def inside_unit_cube(q):
    return np.all((q > 0) & (q < 1), axis=1)


def test_cube_is_exact_parity():
    q = random_points(2000)
    w = gwn.winding_number(CUBE_V, CUBE_F, q)
    np.testing.assert_array_equal(w, inside_unit_cube(q).astype(np.float64))


def test_flipped_cube_is_minus_one_inside():
    q = random_points(500, seed=1)
    w = gwn.winding_number(CUBE_V, CUBE_F[:, ::-1], q)
    np.testing.assert_array_equal(w, -inside_unit_cube(q).astype(np.float64))


def test_tetrahedron():
    q = np.array([[0.1, 0.1, 0.1], [0.2, 0.3, 0.1], [1.0, 1.0, 1.0], [-0.1, 0.2, 0.2]])
    np.testing.assert_array_equal(gwn.winding_number(TET_V, TET_F, q), [1.0, 1.0, 0.0, 0.0])


@pytest.mark.parametrize("method", ["exact", "direct"])
def test_open_box_centre_is_five_sixths(method):
    wn = gwn.WindingNumber(CUBE_V, OPEN_BOX_F, method=method)
    assert abs(wn([[0.5, 0.5, 0.5]])[0] - 5 / 6) < 1e-14


def test_open_box_centre_fast_within_barill_accuracy():
    w = gwn.fast_winding_number(CUBE_V, OPEN_BOX_F, np.array([[0.5, 0.5, 0.5]]))
    assert abs(w[0] - 5 / 6) < 1e-2


def test_open_box_parts_integer_plus_fraction():
    wn = gwn.WindingNumber(CUBE_V, OPEN_BOX_F)
    q = random_points(300, seed=2)
    chi, frac = wn.parts(q)
    assert chi.dtype == np.int64
    # The same sum the evaluator forms, so bit-identical.
    np.testing.assert_array_equal(chi + frac, wn(q))


def test_closed_mesh_parts_have_no_fraction():
    chi, frac = gwn.WindingNumber(CUBE_V, CUBE_F).parts(random_points(300, seed=3))
    np.testing.assert_array_equal(frac, 0.0)


@pytest.mark.parametrize("method", ["exact", "direct"])
def test_gradient_matches_finite_differences(method):
    wn = gwn.WindingNumber(CUBE_V, OPEN_BOX_F, method=method)
    q = np.array([[0.3, 0.6, 0.4], [0.5, 0.5, 1.7], [1.4, -0.2, 0.8]])
    h = 1e-6
    fd = np.stack(
        [(wn(q + h * e) - wn(q - h * e)) / (2 * h) for e in np.eye(3)], axis=1
    )
    np.testing.assert_allclose(wn.gradient(q), fd, atol=1e-6)


def test_exact_and_direct_agree_on_open_box():
    q = random_points(1000, seed=4)
    exact = gwn.WindingNumber(CUBE_V, OPEN_BOX_F)(q)
    direct = gwn.WindingNumber(CUBE_V, OPEN_BOX_F, method="direct")(q)
    np.testing.assert_allclose(exact, direct, atol=1e-12)


def test_point_cloud_of_a_sphere_is_one_inside():
    # Fibonacci sphere with exact areas 4*pi/n and outward normals.
    n = 4000
    i = np.arange(n) + 0.5
    phi = np.arccos(1 - 2 * i / n)
    theta = np.pi * (1 + 5**0.5) * i
    p = np.stack([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)], axis=1)
    a = np.full(n, 4 * np.pi / n)
    q = np.array([[0.0, 0.0, 0.0], [0.2, -0.3, 0.1], [3.0, 0.0, 0.0]])
    w = gwn.fast_winding_number(p, p, a, q)
    np.testing.assert_allclose(w, [1.0, 1.0, 0.0], atol=2e-2)
    # Estimated areas are less exact but still separate inside from outside.
    w_est = gwn.fast_winding_number(p, p, q)
    assert w_est[0] > 0.8 and w_est[1] > 0.8 and abs(w_est[2]) < 0.2


def test_voxelize_grid_layout():
    w, origin, spacing = gwn.voxelize(CUBE_V, CUBE_F, dims=(4, 5, 6), bounds=(-1, -1, -1, 2, 2, 2))
    assert w.shape == (6, 5, 4)
    np.testing.assert_allclose(spacing, [3 / 4, 3 / 5, 3 / 6])
    np.testing.assert_allclose(origin, [-1 + 3 / 8, -1 + 3 / 10, -1 + 3 / 12])
    k, j, i = np.meshgrid(range(6), range(5), range(4), indexing="ij")
    pts = origin + np.stack([i, j, k], axis=-1) * spacing
    np.testing.assert_array_equal(w, inside_unit_cube(pts.reshape(-1, 3)).reshape(6, 5, 4))


def test_sdf_of_cube():
    d, origin, spacing = gwn.sdf(CUBE_V, CUBE_F, dims=(2, 2, 2), bounds=(0, 0, 0, 1, 1, 1))
    np.testing.assert_allclose(d, -0.25)  # cell centres at 1/4, 3/4: 1/4 from the nearest face
    q = np.array([[0.5, 0.5, 0.5], [2.0, 0.5, 0.5]])
    np.testing.assert_allclose(gwn.signed_distance(CUBE_V, CUBE_F, q), [-0.5, 1.0])


def test_slice_image_and_png():
    img, png = gwn.slice(CUBE_V, CUBE_F, axis="z", at=0.5, res=40, margin=0.5)
    assert img.shape == (40, 40)
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    # Region [-0.5, 1.5]^2 at 20 px per unit: pixels 10..29 are inside.
    expected = np.zeros((40, 40))
    expected[10:30, 10:30] = 1.0
    np.testing.assert_array_equal(img, expected)


def test_classify_and_filter_tets():
    small = CUBE_V * 0.5 + 0.25
    far = CUBE_V + 5.0
    np.testing.assert_array_equal(gwn.classify(small, CUBE_F, CUBE_V, CUBE_F), 1.0)
    np.testing.assert_array_equal(gwn.classify(far, CUBE_F, CUBE_V, CUBE_F), 0.0)
    points = np.vstack([TET_V * 0.5 + 0.1, TET_V + 3.0])
    tets = np.array([[0, 1, 2, 3], [4, 5, 6, 7]])
    np.testing.assert_array_equal(gwn.filter_tets(CUBE_V, CUBE_F, points, tets), [True, False])


def test_gauwn_square():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    q = np.array([[0.5, 0.5], [3.0, 3.0], [0.0, 0.5]])
    w, g = gwn.gauwn(square, 0.01, q, gradient=True)
    np.testing.assert_allclose(w, [1.0, 0.0, 0.5], atol=1e-12)
    # At the middle of the left edge the field rises into the square at 1/(sigma sqrt(2 pi)).
    np.testing.assert_allclose(g[2], [1 / (0.01 * np.sqrt(2 * np.pi)), 0.0], rtol=1e-9, atol=1e-9)
    h = 1e-6
    q2 = np.array([[0.2, 0.995]])
    fd = [(gwn.gauwn(square, 0.01, q2 + h * e) - gwn.gauwn(square, 0.01, q2 - h * e))[0] / (2 * h)
          for e in np.eye(2)]
    np.testing.assert_allclose(gwn.gauwn(square, 0.01, q2, gradient=True)[1][0], fd, rtol=1e-5, atol=1e-6)


def test_gauwn_two_loops_add():
    a = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    b = a + [3.0, 0.0]
    q = np.array([[0.5, 0.5], [3.5, 0.5]])
    np.testing.assert_allclose(gwn.gauwn([a, b], 0.02, q), [1.0, 1.0], atol=1e-12)
