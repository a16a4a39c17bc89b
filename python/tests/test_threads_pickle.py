"""Threads (GIL released, one object shared) and pickling (rebuilt from arrays)."""

import pickle
import threading
import time

import numpy as np
import pytest

import gwn
from conftest import CUBE_V, OPEN_BOX_F, random_points


def test_threads_argument_does_not_change_values(lion):
    v, f = lion
    q = random_points(3000, lo=v.min(), hi=v.max(), seed=20)
    wn = gwn.WindingNumber(v, f)
    reference = wn(q)
    for threads in (1, 2, 3):
        np.testing.assert_array_equal(wn(q, threads=threads), reference)


def test_two_python_threads_on_one_object(lion):
    v, f = lion
    wn = gwn.WindingNumber(v, f)
    batches = [random_points(4000, lo=v.min(), hi=v.max(), seed=s) for s in range(8)]
    expected = [wn(b) for b in batches]
    results = {}
    errors = []

    def work(k):
        try:
            for i in range(k, len(batches), 2):
                results[i] = (wn(batches[i], threads=1), wn.gradient(batches[i][:100], threads=1))
        except Exception as e:  # reported by the main thread
            errors.append(e)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    for i, b in enumerate(batches):
        np.testing.assert_array_equal(results[i][0], expected[i])
        np.testing.assert_array_equal(results[i][1], wn.gradient(b[:100]))


def test_gil_is_released_during_evaluation(lion):
    # The main thread needs the GIL to record a time stamp; stamps well inside the worker's call
    # prove that the call released it (a held GIL allows stamps only near its start and end).
    v, f = lion
    wn = gwn.WindingNumber(v, f, method="direct")  # O(F) per query: a long call
    q = random_points(1500, lo=v.min(), hi=v.max(), seed=24)
    span = {}

    def work():
        span["start"] = time.perf_counter()
        wn(q, threads=1)
        span["end"] = time.perf_counter()

    worker = threading.Thread(target=work)
    stamps = []
    worker.start()
    while worker.is_alive():
        stamps.append(time.perf_counter())
        time.sleep(0.001)
    worker.join()
    duration = span["end"] - span["start"]
    assert duration > 0.05, "the call is too short to tell"
    margin = min(0.05, duration / 4)
    inside = [t for t in stamps if span["start"] + margin < t < span["end"] - margin]
    assert len(inside) > 3


@pytest.mark.parametrize("method", ["exact", "direct", "fast"])
def test_pickle_round_trip_is_bit_identical(method):
    fast_options = {"beta": 3.0, "order": 1, "rule": "box-corner"} if method == "fast" else {}
    wn = gwn.WindingNumber(CUBE_V, OPEN_BOX_F, method=method, **fast_options)
    q = random_points(500, seed=21)
    back = pickle.loads(pickle.dumps(wn))
    assert back.method == method
    np.testing.assert_array_equal(back(q), wn(q))


def test_pickle_keeps_exact_options():
    wn = gwn.WindingNumber(CUBE_V, OPEN_BOX_F, precision=30, ray="-x")
    back = pickle.loads(pickle.dumps(wn))
    q = np.array([[0.5, 0.5, 0.0]])  # on the bottom face: the value depends on the ray frame
    np.testing.assert_array_equal(back(q), wn(q))
    assert back.__reduce__()[1][5:] == (30, "-x", 1e-10, None)


def test_pickle_keeps_the_fast_rule():
    wn = gwn.WindingNumber(CUBE_V, OPEN_BOX_F, method="fast", beta=2.8, rule="radius-or-box-corner")
    back = pickle.loads(pickle.dumps(wn))
    assert back.__reduce__()[1][2:5] == ("fast", 2.8, 2)
    assert back.__reduce__()[1][8] == "radius-or-box-corner"
    cloud = gwn.WindingNumber.from_point_cloud(CUBE_V, CUBE_V, beta=2.5, rule="box-corner")
    assert pickle.loads(pickle.dumps(cloud)).__reduce__()[1][3:] == (2.5, 2, "box-corner")


def test_pickle_point_cloud_keeps_estimated_areas():
    rng = np.random.default_rng(22)
    p = rng.normal(size=(500, 3))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    wn = gwn.WindingNumber.from_point_cloud(p, p)
    back = pickle.loads(pickle.dumps(wn))
    q = random_points(200, lo=-1.5, hi=1.5, seed=23)
    np.testing.assert_array_equal(back(q), wn(q))
