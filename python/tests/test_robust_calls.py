"""Issue 22: no crash and no unbounded work from Python, and libigl's call patterns.

Calls that used to kill the interpreter (stack overflow, out-of-memory abort) or ignore Ctrl-C
run in a subprocess, so that a regression fails this test instead of the whole session.
"""

import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import gwn
from conftest import CUBE_F, CUBE_V, OPEN_BOX_F, TET_F, TET_V


def run_python(code, timeout=60, **kwargs):
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=timeout, **kwargs)


# ------------------------------------------------------------------ no crash, no unbounded work


def test_svg_with_20000_nested_groups_is_a_value_error(tmp_path):
    # Before: SIGSEGV (usvg's recursion overflowed the stack).
    svg = tmp_path / "deep.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">'
                   + "<g>" * 20000 + '<rect x="1" y="1" width="2" height="2"/>'
                   + "</g>" * 20000 + "</svg>")
    r = run_python(f"""
        import gwn
        try:
            gwn.load_polygon({str(svg)!r})
        except ValueError as e:
            print("ValueError:", e)
    """)
    assert r.returncode == 0, (r.returncode, r.stderr)
    assert "ValueError:" in r.stdout and "nest" in r.stdout, r.stdout


def _mem_available():
    try:
        for line in pathlib.Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


@pytest.mark.parametrize("call", ["voxelize", "sdf"])
def test_grids_larger_than_memory_are_refused_up_front(call):
    # Before: the process aborted allocating 1290^3 float64 (or the OOM killer ended it). The
    # subprocess gets a 4 GiB address-space limit so that a regression cannot exhaust the machine.
    have = _mem_available()
    if have is None or have > 1290**3 * 21:
        pytest.skip("needs /proc/meminfo and less than 45 GB of available memory")
    r = run_python(f"""
        import resource, numpy as np, gwn
        resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))
        from conftest import CUBE_V, CUBE_F
        try:
            gwn.{call}(CUBE_V, CUBE_F, res=1290)
        except (ValueError, MemoryError) as e:
            print(type(e).__name__, e)
    """, cwd=pathlib.Path(__file__).parent)
    assert r.returncode == 0, (r.returncode, r.stderr[-2000:])
    assert "GiB" in r.stdout, r.stdout


def test_ctrl_c_interrupts_a_long_evaluation():
    # Before: SIGINT was only seen after the whole call returned (64 s on a large direct sum).
    code = """
        import numpy as np, gwn, signal, sys
        from conftest import CUBE_V, CUBE_F
        # Python leaves SIGINT ignored when it starts with it ignored (a job started in the
        # background by a non-interactive shell, as some CI runners do): Ctrl-C's handler here.
        signal.signal(signal.SIGINT, signal.default_int_handler)
        rng = np.random.default_rng(0)
        V = rng.uniform(size=(3000, 3)); F = rng.integers(0, 3000, size=(20000, 3))
        Q = rng.uniform(size=(2_000_000, 3))
        wn = gwn.WindingNumber(V, F, method="direct")
        print("ready", flush=True)
        try:
            wn(Q, threads=1)
            print("finished")
        except KeyboardInterrupt:
            print("interrupted")
    """
    p = subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, cwd=pathlib.Path(__file__).parent)
    try:
        assert p.stdout.readline().strip() == "ready"
        time.sleep(1.0)
        t0 = time.monotonic()
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=20)
        assert "interrupted" in out, (out, err)
        assert time.monotonic() - t0 < 10
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()


def test_2d_queries_beyond_1e100_are_refused():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64)
    assert np.isfinite(gwn.gauwn(square, 0.1, [[1e100, 0.0]])).all()
    with pytest.raises(ValueError, match="1e100"):
        gwn.gauwn(square, 0.1, [[0.5, 0.5], [1e101, 0.0]])


def test_signed_distance_of_huge_and_tiny_meshes_is_finite():
    for s in [1e200, 1e-200]:
        d = gwn.signed_distance(CUBE_V * s, CUBE_F, np.array([[0.5, 0.5, 0.25]]) * s)
        np.testing.assert_allclose(d / s, [-0.25], rtol=1e-12)


# ------------------------------------------------------------------ libigl call patterns


def test_winding_number_of_a_single_point_is_a_float():
    w = gwn.winding_number(CUBE_V, CUBE_F, np.array([0.5, 0.5, 0.5]))
    assert isinstance(w, float) and w == 1.0
    assert gwn.winding_number(CUBE_V, CUBE_F, [2.0, 0.5, 0.5]) == 0.0
    wn = gwn.WindingNumber(CUBE_V, CUBE_F)
    assert isinstance(wn(np.array([0.5, 0.5, 0.5])), float)
    assert gwn.winding_number(CUBE_V, CUBE_F, np.array([[0.5, 0.5, 0.5]])).shape == (1,)


def test_fast_winding_number_takes_libigls_positional_order():
    rng = np.random.default_rng(3)
    p = rng.normal(size=(400, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    a = np.full(400, 4 * np.pi / 400)
    q = np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    # libigl: fast_winding_number(P, N, A, Q, expansion_order=2, beta=2.0)
    positional = gwn.fast_winding_number(p, p, a, q, 2, 2.0)
    named = gwn.fast_winding_number(p, p, a, q, expansion_order=2, beta=2.0)
    np.testing.assert_array_equal(positional, named)
    low = gwn.fast_winding_number(p, p, a, q, 0, 1.0)
    np.testing.assert_array_equal(low, gwn.fast_winding_number(p, p, a, q, order=0, beta=1.0))
    v, f = TET_V, TET_F
    soup = gwn.fast_winding_number(v, f, [[0.1, 0.1, 0.1]], 2, 2.0)
    np.testing.assert_allclose(soup, [1.0], atol=1e-12)


def test_big_endian_arrays_are_converted():
    v = CUBE_V.astype(">f8")
    f = CUBE_F.astype(">i8")
    q = np.array([[0.5, 0.5, 0.5], [2.0, 0.5, 0.5]], dtype=">f4")
    np.testing.assert_array_equal(gwn.winding_number(v, f, q), [1.0, 0.0])
    np.testing.assert_array_equal(gwn.WindingNumber(v, f)(q), [1.0, 0.0])


def test_negative_threads_names_the_argument():
    with pytest.raises(ValueError, match="threads"):
        gwn.winding_number(CUBE_V, CUBE_F, [[0.5, 0.5, 0.5]], threads=-1)
    with pytest.raises(ValueError, match="threads"):
        gwn.WindingNumber(CUBE_V, CUBE_F)([[0.5, 0.5, 0.5]], threads=-1)


def test_missing_files_are_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        gwn.load(tmp_path / "absent.obj")
    with pytest.raises(FileNotFoundError):
        gwn.load_points(tmp_path / "absent.npy")
    with pytest.raises(FileNotFoundError):
        gwn.load_polygon(tmp_path / "absent.svg")
    with pytest.raises(FileNotFoundError):
        gwn.load_tets(tmp_path / "absent.mesh")
    gltf = tmp_path / "m.gltf"
    gltf.write_text('{"asset": {"version": "2.0"}, "buffers": [{"uri": "m.bin", "byteLength": 36}],'
                    ' "bufferViews": [{"buffer": 0, "byteLength": 36}],'
                    ' "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3,'
                    ' "type": "VEC3"}],'
                    ' "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}]}')
    with pytest.raises(OSError) as e:
        gwn.load(gltf)
    assert isinstance(e.value, FileNotFoundError), repr(e.value)
    assert "m.bin" in str(e.value)


def test_call_has_a_docstring_at_run_time():
    doc = gwn.WindingNumber.__call__.__doc__ or ""
    assert "Winding numbers at" in doc, doc


def test_on_surface_rule_is_documented():
    docs = (pathlib.Path(__file__).resolve().parents[2] / "docs" / "python.md").read_text()
    assert "On-surface values differ from libigl's, by design" in docs
    assert "`q = (0.5, 0.5, 0)`" in docs
    # The rule the docs state: on a face of a closed mesh, the exact method gives the value of
    # the perturbed point (an integer), the direct sum 1/2.
    q = np.array([[0.5, 0.5, 0.0]])
    assert gwn.winding_number(CUBE_V, CUBE_F, q)[0] in (0.0, 1.0)
    assert gwn.WindingNumber(CUBE_V, CUBE_F, method="direct")(q)[0] == 0.5
    _ = OPEN_BOX_F
