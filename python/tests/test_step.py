"""Trimmed B-rep STEP models in Python: ``gwn.load("part.step")`` and ``gwn.WindingNumber`` on
them, with the CLI's options and errors. Bundled fixtures (tests/fixtures/step, CC0) always run;
the shared reference models (``../shared/parametric/step``, or ``$GWN_SHARED_DIR``) skip
visibly when absent."""

import math
import pickle
import subprocess
import warnings

import numpy as np
import pytest

import gwn

from conftest import FIXTURES, REPO, SHARED

STEP = FIXTURES / "step"
SHARED_STEP = SHARED / "parametric" / "step"


def plate_on_axis(h):
    """w on the axis of the plate [-1,1]^2 with a hole of radius 0.5 (normal +z)."""
    a = abs(h)
    square = 4.0 * math.asin(1.0 / (1.0 + a * a))
    disk = 2.0 * math.pi * (1.0 - a / math.sqrt(a * a + 0.25))
    return -math.copysign(1.0, h) * (square - disk) / (4.0 * math.pi)


def cylinder_lattice():
    """Points around the capped unit cylinder (z in [0, 2]) away from its surface, and 0/1."""
    g = np.stack(np.meshgrid(np.arange(9), np.arange(9), np.arange(7), indexing="ij"), -1).reshape(-1, 3)
    q = np.column_stack([-1.6 + 0.4 * g[:, 0] + 0.013, -1.6 + 0.4 * g[:, 1] + 0.007,
                         -0.45 + 0.5 * g[:, 2] + 0.011])
    r = np.hypot(q[:, 0], q[:, 1])
    keep = (np.abs(r - 1) > 1e-3) & (np.abs(q[:, 2]) > 1e-3) & (np.abs(q[:, 2] - 2) > 1e-3)
    q = q[keep]
    r = r[keep]
    inside = (r < 1) & (q[:, 2] > 0) & (q[:, 2] < 2)
    return q, inside.astype(np.float64)


def test_load_gives_a_model_and_exact_integers_for_a_solid():
    model = gwn.load(STEP / "capped_cylinder.step")
    assert isinstance(model, gwn.StepModel)
    info = model.info
    assert info["faces"] == 3 and info["boundary_edges"] == 0 and info["solids"] == 1
    assert info["unit"] == "millimetre"
    assert model.closed
    lo, hi = model.bounding_box
    assert np.all(lo <= [-1, -1, 0]) and np.all(hi >= [1, 1, 2])
    wn = gwn.WindingNumber(model)
    assert wn.face_count == 3 and wn.boundary_edge_count == 0 and wn.tolerance == 1e-10
    q, expected = cylinder_lattice()
    assert len(q) > 400
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        w = wn(q)
    np.testing.assert_array_equal(w, expected)
    assert isinstance(wn([0.0, 0.0, 1.0]), float) and wn([0.0, 0.0, 1.0]) == 1.0
    np.testing.assert_array_equal(wn.eval(q, threads=1), w)


def test_stp_extension_and_an_open_model_match_the_closed_form():
    model = gwn.load(str(STEP / "plate_with_hole.stp"))
    assert not model.closed and model.info["boundary_edges"] == 5
    wn = gwn.WindingNumber(model, tolerance=1e-12)
    hs = [2.0, 0.7, 0.1, 1e-3, -1e-3, -0.4, -3.0]
    w = wn(np.array([[0.0, 0.0, h] for h in hs]))
    for h, v in zip(hs, w):
        assert abs(v - plate_on_axis(h)) < 1e-9, (h, v)
    values, error, uncertified = wn.eval_with_status(np.array([[0.0, 0.0, h] for h in hs]))
    np.testing.assert_array_equal(values, w)
    assert error.dtype == np.float64 and np.all(error >= 0) and np.all(error < 1e-9)
    assert uncertified.dtype == np.bool_ and not uncertified.any()


def test_values_agree_with_the_cli_bit_for_bit(cli, tmp_path):
    q = np.array([[0.0, 0.0, h] for h in (0.5, -0.25, 1e-4)] + [[0.75, 0.1, 0.3], [1.5, 0, 0]])
    np.save(tmp_path / "q.npy", q)
    for tol in (1e-6, 1e-10):
        subprocess.run([str(cli), "eval", str(STEP / "plate_with_hole.stp"), "--points",
                        str(tmp_path / "q.npy"), "--out", str(tmp_path / "w.npy"),
                        "--tolerance", repr(tol)], check=True, capture_output=True)
        expected = np.load(tmp_path / "w.npy")
        got = gwn.WindingNumber(gwn.load(STEP / "plate_with_hole.stp"), tolerance=tol)(q)
        np.testing.assert_array_equal(got, expected)


def test_uncertified_values_warn_and_are_flagged(cli, tmp_path):
    wn = gwn.WindingNumber(gwn.load(STEP / "capped_cylinder.step"))
    # On the side, on the rim, on the cap: on the surface, no ray can be certified.
    on = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 2.0], [0.2, 0.1, 0.0], [0.0, 0.0, 1.0]])
    with pytest.warns(RuntimeWarning, match="3 of 4 values uncertified"):
        wn(on)
    values, _, uncertified = wn.eval_with_status(on)
    np.testing.assert_array_equal(uncertified, [True, True, True, False])
    assert values[3] == 1.0
    # The CLI says the same.
    np.save(tmp_path / "q.npy", on)
    run = subprocess.run([str(cli), "eval", str(STEP / "capped_cylinder.step"), "--points",
                          str(tmp_path / "q.npy"), "--out", str(tmp_path / "w.npy")],
                         check=True, capture_output=True, text=True)
    assert "3 of 4 values uncertified" in run.stderr
    np.testing.assert_array_equal(np.load(tmp_path / "w.npy"), values)


@pytest.mark.parametrize("kwargs, message", [
    # The library's messages (gwn::spec), the same as `gwn eval part.step`'s.
    ({"tolerance": 0.0}, "tolerance must be positive for a STEP model"),
    ({"tolerance": float("nan")}, "tolerance must be a finite number >= 0, got NaN"),
    ({"method": "fast"}, r"the fast method does not apply to a STEP model \(use exact\)"),
    ({"method": "direct"}, r"the direct method does not apply to a STEP model \(use exact\)"),
    ({"ray": "-x"}, r"ray does not apply to the exact method on a STEP model \(its evaluator "
                    r"chooses a ray per query\)"),
    ({"precision": 30}, "precision does not apply to the exact method on a STEP model"),
    ({"beta": 1.0}, r"beta does not apply to the exact method \(it is an option of the fast method\)"),
    ({"F": np.zeros((1, 3), dtype=np.int64)}, "F does not apply to a STEP model"),
])
def test_options_that_do_not_apply_are_refused(kwargs, message):
    model = gwn.load(STEP / "capped_cylinder.step")
    with pytest.raises(ValueError, match=message):
        gwn.WindingNumber(model, **kwargs)


def test_mesh_queries_and_errors_of_other_evaluators():
    model = gwn.load(STEP / "capped_cylinder.step")
    wn = gwn.WindingNumber(model)
    for call in (wn.gradient, wn.parts, wn.eval_with_bound):
        with pytest.raises(ValueError, match="not available"):
            call(np.zeros((1, 3)))
    mesh = gwn.WindingNumber(*gwn.load(FIXTURES / "cube.off"))
    with pytest.raises(ValueError, match="eval_with_status is not available"):
        mesh.eval_with_status(np.zeros((1, 3)))
    with pytest.raises(ValueError, match="F .* is required"):
        gwn.WindingNumber(np.zeros((3, 3)))


def test_load_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.step"):
        gwn.load(tmp_path / "missing.step")
    with pytest.raises(ValueError, match="weld does not apply to STEP models"):
        gwn.load(STEP / "capped_cylinder.step", weld=True)
    bad = tmp_path / "bad.stp"
    bad.write_text("ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1=CARTESIAN_POINT('',(0.,0.,0.));\n"
                   "#2=OFFSET_SURFACE('',#1,1.,.F.);\n#3=ADVANCED_FACE('',(),#2,.T.);\n"
                   "#4=OPEN_SHELL('',(#3));\nENDSEC;\nEND-ISO-10303-21;\n")
    with pytest.raises(ValueError, match=r"#2 OFFSET_SURFACE: not supported"):
        gwn.load(bad)
    truncated = tmp_path / "truncated.step"
    truncated.write_text("ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1=CARTESIAN_POINT('',(0.,")
    with pytest.raises(ValueError, match="line"):
        gwn.load(truncated)


def test_pcurves_trim_the_faces():
    # The 3D edges of this fixture lie 1e-3 outside the faces; the pcurves give the true circles
    # (tests/patches/step_fixtures.rs has the details).
    model = gwn.load(STEP / "capped_cylinder_pcurves.step")
    info = model.info
    assert (info["pcurve_uses"], info["pcurves_rejected"], info["pcurves_unreadable"]) == (6, 0, 0)
    wn = gwn.WindingNumber(model)
    values = wn(np.array([[1.0005, 0.0, 1.9999], [0.9995, 0.0, 1.9999]]))
    np.testing.assert_array_equal(values, [0.0, 1.0])


def test_pickling_reads_the_file_again():
    model = gwn.load(STEP / "plate_with_hole.stp")
    wn = gwn.WindingNumber(model, tolerance=1e-8)
    again = pickle.loads(pickle.dumps(wn))
    q = np.array([[0.1, 0.2, 0.3], [0.9, -0.9, -0.01]])
    np.testing.assert_array_equal(again(q), wn(q))
    assert again.tolerance == 1e-8
    assert pickle.loads(pickle.dumps(model)).info == model.info
    assert "plate_with_hole.stp" in repr(wn) and "faces=1" in repr(model)


@pytest.mark.parametrize("name, closed", [
    ("tet", True), ("sliced_cylinder", True), ("boxed_sphere", True),
    ("open_cylinder", False), ("spring", False),
])
def test_shared_models_match_their_references(name, closed):
    path = SHARED_STEP / f"{name}.step"
    ref = SHARED_STEP / f"{name}_ref"
    if not (path.exists() and (ref / "queries.npy").exists()):
        print(f"skipping: {path} or its references are absent")
        pytest.skip(f"{path} or its references are absent")
    q = np.load(ref / "queries.npy")
    expected = np.load(ref / "ref.npy")
    err = np.load(ref / "err.npy")
    model = gwn.load(path)
    assert model.closed == closed
    # eval_with_status: the same values without the warning (open_cylinder has one query on
    # its surface within rounding).
    w, _, uncertified = gwn.WindingNumber(model).eval_with_status(q)
    assert uncertified.sum() <= 1
    allowed = np.full(len(q), 1e-9) if closed else np.maximum(1e-7, 3 * err)
    bad = np.flatnonzero(~(np.abs(w - expected) <= allowed))
    assert bad.size == 0, [(int(i), w[i], expected[i]) for i in bad[:10]]
