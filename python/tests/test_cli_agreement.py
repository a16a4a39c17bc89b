"""Bit-for-bit agreement with the `gwn` command-line tool (same library calls, same values)."""

import json
import subprocess

import numpy as np
import pytest

import gwn
from conftest import LION_HEAD, random_points


def run(cli, *args):
    subprocess.run([str(cli), *map(str, args)], check=True, capture_output=True)


@pytest.fixture(scope="module")
def queries(tmp_path_factory, lion):
    v, _ = lion
    lo, hi = v.min(axis=0), v.max(axis=0)
    q = lo + (hi - lo) * random_points(2000, lo=-0.1, hi=1.1, seed=30)
    path = tmp_path_factory.mktemp("q") / "q.npy"
    np.save(path, q)
    return q, path


@pytest.mark.parametrize(
    "method, cli_args, kwargs",
    [
        ("exact", [], {}),
        ("exact", ["--precision", "30", "--ray", "-x"], {"precision": 30, "ray": "-x"}),
        ("exact", ["--tolerance", "1e-3"], {"tolerance": 1e-3}),
        ("exact", ["--tolerance", "0"], {"tolerance": 0.0}),
        ("direct", [], {}),
        ("fast", ["--beta", "2.5", "--order", "1"], {"beta": 2.5, "order": 1}),
        ("fast", ["--beta", "2.8", "--rule", "radius-or-box-corner"],
         {"beta": 2.8, "rule": "radius-or-box-corner"}),
        ("fast", ["--beta", "2.4", "--rule", "box-corner"], {"beta": 2.4, "rule": "box-corner"}),
    ],
)
def test_eval(cli, tmp_path, lion, queries, method, cli_args, kwargs):
    q, qpath = queries
    out = tmp_path / "w.npy"
    run(cli, "eval", LION_HEAD, "--points", qpath, "--out", out, "--method", method, *cli_args)
    wn = gwn.WindingNumber(*lion, method=method, **kwargs)
    np.testing.assert_array_equal(wn(q), np.load(out))


def test_one_shot_calls_equal_cli(cli, tmp_path, lion, queries):
    q, qpath = queries
    run(cli, "eval", LION_HEAD, "--points", qpath, "--out", tmp_path / "e.npy")
    run(cli, "eval", LION_HEAD, "--points", qpath, "--out", tmp_path / "f.npy", "--method", "fast")
    np.testing.assert_array_equal(gwn.winding_number(*lion, q), np.load(tmp_path / "e.npy"))
    np.testing.assert_array_equal(gwn.fast_winding_number(*lion, q), np.load(tmp_path / "f.npy"))
    run(cli, "eval", LION_HEAD, "--points", qpath, "--out", tmp_path / "r.npy", "--method", "fast",
        "--beta", "2.8", "--rule", "radius-or-box-corner")
    np.testing.assert_array_equal(
        gwn.fast_winding_number(*lion, q, beta=2.8, rule="radius-or-box-corner"),
        np.load(tmp_path / "r.npy"),
    )


@pytest.mark.parametrize("method", ["exact", "direct"])
def test_gradient(cli, tmp_path, lion, queries, method):
    q, qpath = queries
    out = tmp_path / "g.npy"
    run(cli, "eval", LION_HEAD, "--points", qpath, "--out", tmp_path / "w.npy", "--method", method,
        "--gradient", "--gradient-out", out)
    np.testing.assert_array_equal(gwn.WindingNumber(*lion, method=method).gradient(q), np.load(out))


def test_point_cloud(cli, tmp_path):
    rng = np.random.default_rng(31)
    p = rng.normal(size=(800, 3))
    n = p + rng.normal(scale=0.1, size=p.shape)
    cloud = tmp_path / "cloud.xyz"
    cloud.write_text("".join(" ".join(repr(float(c)) for c in row) + "\n" for row in np.hstack([p, n])))
    q = random_points(300, lo=-2, hi=2, seed=32)
    np.save(tmp_path / "q.npy", q)
    run(cli, "eval", cloud, "--points", tmp_path / "q.npy", "--out", tmp_path / "w.npy")
    np.testing.assert_array_equal(gwn.fast_winding_number(p, n, q), np.load(tmp_path / "w.npy"))
    np.testing.assert_array_equal(
        gwn.WindingNumber.from_point_cloud(p, n, beta=2.0)(q), np.load(tmp_path / "w.npy")
    )


def test_voxelize_and_sdf(cli, tmp_path, lion):
    run(cli, "voxelize", LION_HEAD, "--res", 20, "--dtype", "f64", "--out", tmp_path / "w.npy")
    w, origin, spacing = gwn.voxelize(*lion, 20)
    np.testing.assert_array_equal(w, np.load(tmp_path / "w.npy"))
    run(cli, "sdf", LION_HEAD, "--dims", 7, 9, 11, "--margin", 0.2, "--dtype", "f64",
        "--out", tmp_path / "s.npy")
    d, _, _ = gwn.sdf(*lion, dims=(7, 9, 11), margin=0.2)
    np.testing.assert_array_equal(d, np.load(tmp_path / "s.npy"))


def test_slice_png_bytes(cli, tmp_path, lion):
    out = tmp_path / "s.png"
    run(cli, "slice", LION_HEAD, "--axis", "x", "--at", 0.4, "--res", 96, "--outline", "--out", out)
    img, png = gwn.slice(*lion, axis="x", at=0.4, res=96, outline=True)
    assert png == out.read_bytes()
    assert np.isfinite(img).all()


def test_classify(cli, tmp_path, lion):
    v, f = lion
    shifted = tmp_path / "b.off"
    vb = v * 0.9 + v.mean(axis=0) * 0.1
    shifted.write_text(
        "OFF\n%d %d 0\n" % (len(vb), len(f))
        + "".join("%r %r %r\n" % tuple(map(float, p)) for p in vb)
        + "".join("3 %d %d %d\n" % tuple(t) for t in f)
    )
    run(cli, "classify", LION_HEAD, shifted, "--out", tmp_path / "c.npy")
    np.testing.assert_array_equal(gwn.classify(v, f, vb, f), np.load(tmp_path / "c.npy"))


def test_filter_tets(cli, tmp_path, lion):
    v, f = lion
    lo, hi = v.min(axis=0), v.max(axis=0)
    points = lo + (hi - lo) * random_points(400, lo=0, hi=1, seed=33)
    tets = np.random.default_rng(34).integers(0, len(points), size=(300, 4))
    path = tmp_path / "t.mesh"
    path.write_text(
        "MeshVersionFormatted 1\nDimension 3\nVertices\n%d\n" % len(points)
        + "".join("%r %r %r 0\n" % tuple(map(float, p)) for p in points)
        + "Tetrahedra\n%d\n" % len(tets)
        + "".join("%d %d %d %d 0\n" % tuple(t + 1) for t in tets)
        + "End\n"
    )
    run(cli, "filter-tets", LION_HEAD, path, "--out", tmp_path / "kept.mesh")
    kept_points, kept_tets, _ = gwn.load_tets(tmp_path / "kept.mesh")
    mask = gwn.filter_tets(v, f, points, tets)
    assert mask.dtype == np.bool_
    np.testing.assert_array_equal(kept_points[kept_tets], points[tets[mask]])
    p2, t2, _ = gwn.load_tets(path)
    np.testing.assert_array_equal(gwn.filter_tets(v, f, p2, t2), mask)


@pytest.mark.parametrize(
    "method,cli_args,kwargs",
    [
        ("direct", ["--method", "direct"], {"method": "direct"}),
        ("fast", ["--method", "fast", "--beta", "2.5", "--order", "1"],
         {"method": "fast", "beta": 2.5, "order": 1}),
    ],
)
def test_products_take_any_method(cli, tmp_path, lion, method, cli_args, kwargs):
    """Grids and products use any evaluator (the library's Evaluator trait), like the CLI."""
    v, f = lion
    run(cli, "voxelize", LION_HEAD, "--res", 10, "--dtype", "f64", "--out", tmp_path / "w.npy",
        *cli_args)
    w, _, _ = gwn.voxelize(v, f, 10, **kwargs)
    np.testing.assert_array_equal(w, np.load(tmp_path / "w.npy"))
    exact, _, _ = gwn.voxelize(v, f, 10)
    tol = 1e-9 if method == "direct" else 0.05
    assert np.abs(w - exact).max() < tol
    out = tmp_path / "s.png"
    run(cli, "slice", LION_HEAD, "--axis", "y", "--res", 48, "--out", out, *cli_args)
    _, png = gwn.slice(v, f, axis="y", res=48, **kwargs)
    assert png == out.read_bytes()
    run(cli, "classify", LION_HEAD, LION_HEAD, "--out", tmp_path / "c.npy", *cli_args)
    np.testing.assert_array_equal(gwn.classify(v, f, v, f, **kwargs), np.load(tmp_path / "c.npy"))


def test_products_take_the_tolerance(cli, tmp_path, lion):
    """tolerance= is the CLI's --tolerance on the products (exact method)."""
    v, f = lion
    run(cli, "voxelize", LION_HEAD, "--res", 10, "--margin", 2.0, "--dtype", "f64",
        "--tolerance", "1e-3", "--out", tmp_path / "w.npy")
    w, _, _ = gwn.voxelize(v, f, 10, margin=2.0, tolerance=1e-3)
    np.testing.assert_array_equal(w, np.load(tmp_path / "w.npy"))
    run(cli, "classify", LION_HEAD, LION_HEAD, "--tolerance", "0", "--out", tmp_path / "c.npy")
    np.testing.assert_array_equal(gwn.classify(v, f, v, f, tolerance=0.0),
                                  np.load(tmp_path / "c.npy"))


def test_products_reject_bad_methods(lion):
    v, f = lion
    with pytest.raises(ValueError, match="method"):
        gwn.voxelize(v, f, 4, method="approximate")
    with pytest.raises(ValueError, match="beta"):
        gwn.classify(v, f, v, f, method="fast", beta=float("nan"))


@pytest.mark.parametrize(
    "cli_args, kwargs",
    [
        (["--method", "exact", "--beta", "2"], {"method": "exact", "beta": 2.0}),
        (["--method", "direct", "--ray", "-x"], {"method": "direct", "ray": "-x"}),
        (["--method", "fast", "--tolerance", "1e-3"], {"method": "fast", "tolerance": 1e-3}),
        (["--method", "fast", "--precision", "30"], {"method": "fast", "precision": 30}),
        (["--tolerance", "nan"], {"tolerance": float("nan")}),
        (["--tolerance", "-1"], {"tolerance": -1.0}),
        (["--method", "fast", "--beta", "-2"], {"method": "fast", "beta": -2.0}),
        (["--method", "fast", "--order", "3"], {"method": "fast", "order": 3}),
    ],
)
def test_same_error_for_the_same_bad_option(cli, tmp_path, cli_args, kwargs):
    """The library's rules and messages (gwn::spec::EvaluatorSpec), from both front ends."""
    np.save(tmp_path / "q.npy", np.zeros((1, 3)))
    done = subprocess.run(
        [str(cli), "eval", str(LION_HEAD), "--points", str(tmp_path / "q.npy"), *cli_args],
        capture_output=True, text=True,
    )
    assert done.returncode != 0
    cli_message = done.stderr.strip().removeprefix("gwn: ")
    with pytest.raises(ValueError) as info:
        gwn.WindingNumber(*gwn.load(LION_HEAD), **kwargs)
    assert str(info.value) == cli_message


def test_remesh_and_its_report_equal_cli(cli, tmp_path, lion):
    # Same surface, same report (the library measures both): every member but the timing.
    out, report_path = tmp_path / "r.ply", tmp_path / "r.json"
    run(cli, "remesh", LION_HEAD, "--res", 32, "--samples", 3000, "--out", out,
        "--report", report_path)
    V, F, report = gwn.remesh(*lion, res=32, report=True, samples=3000)
    Vc, Fc = gwn.load(out)
    np.testing.assert_array_equal(F, Fc)
    np.testing.assert_allclose(V, Vc, rtol=0, atol=1e-9 * np.abs(V).max())
    want = json.loads(report_path.read_text())
    assert report.pop("seconds") > 0
    assert set(report.pop("phase_seconds")) == set(want.pop("phase_seconds"))
    want.pop("seconds")
    assert report == want
    # The lion head is open: the output closes it where w crosses 1/2, off its rim.
    assert report["closed"] and report["self_intersections"] == 0
    assert report["occupancy_samples"] == 3000 and report["hausdorff_boundary_fraction"] > 0.9
