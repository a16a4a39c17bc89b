"""Dataset labelling from Python: the Rust job's files bit for bit (CLI vs gwn.label_dataset vs
gwn.dask.label_dataset on a real 2-worker LocalCluster), closed forms, failures as rows."""

import json

import numpy as np
import pytest

import gwn
from conftest import FIXTURES, copy_fixtures, files_by_suffix

OPTS = dict(uniform=200, near=200, sigmas=(0.01, 0.1), seed=3)


def make_dataset(tmp_path):
    files = {"a/cube.off": "cube.off", "a/cube.obj": "cube.obj", "b/scene.glb": "two_cubes.glb",
             "b/broken.off": "broken_index.off", "b/c/cube.ply": "cube_binary_le.ply"}
    return copy_fixtures(tmp_path, files)


def npz_files(d):
    return files_by_suffix(d, ".npz")


def test_label_dataset_rows_and_closed_form(tmp_path):
    paths = make_dataset(tmp_path)
    rows = gwn.label_dataset(paths, tmp_path / "out", **OPTS, threads=2)
    assert [r["status"] for r in rows] == ["ok", "ok", "ok", "failed", "ok"]
    assert "broken.off" in rows[3]["error"] and "face 1" in rows[3]["error"]
    assert rows[2]["output"] == "b/scene.glb.npz" and rows[2]["faces"] == 24
    lines = (tmp_path / "out" / "manifest.jsonl").read_text().splitlines()
    assert [json.loads(l)["status"] for l in lines] == [r["status"] for r in rows]
    z = np.load(tmp_path / "out" / "a" / "cube.off.npz")
    P, w, occ, sdf = z["points"], z["w"], z["occupancy"], z["sdf"]
    assert P.shape == (400, 3) and z["source"].tolist().count(0) == 200
    inside = np.all((P > 0) & (P < 1), axis=1)
    np.testing.assert_array_equal(w, inside.astype(float))
    np.testing.assert_array_equal(occ, inside)
    assert np.all((sdf < 0) == inside)
    # Resumable: a second run skips everything that succeeded.
    again = gwn.label_dataset(paths, tmp_path / "out", **OPTS)
    assert [r["status"] for r in again] == ["done", "done", "done", "failed", "done"]


def test_same_bytes_as_the_cli(tmp_path, cli):
    import subprocess

    paths = make_dataset(tmp_path)
    gwn.label_dataset(paths, tmp_path / "py", **OPTS)
    subprocess.run([str(cli), "label", str(tmp_path / "in"), "--out", str(tmp_path / "cli"),
                    "--uniform", "200", "--near", "200", "--sigma", "0.01,0.1", "--seed", "3"],
                   check=True, capture_output=True)
    assert npz_files(tmp_path / "py") == npz_files(tmp_path / "cli")


def test_bad_options_are_value_errors(tmp_path):
    with pytest.raises(ValueError, match="sigma"):
        gwn.label_dataset([FIXTURES / "cube.off"], tmp_path, sigmas=[-1.0])
    with pytest.raises(ValueError, match="time_limit"):
        gwn.label_dataset([FIXTURES / "cube.off"], tmp_path, time_limit=-1)


def test_dask_local_cluster_matches_serial(tmp_path):
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        print("skipping: dask.distributed is not installed")
        pytest.skip("dask.distributed is not installed")
    import gwn.dask

    paths = make_dataset(tmp_path)
    serial = gwn.label_dataset(paths, tmp_path / "serial", **OPTS)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        seen = []
        rows = gwn.dask.label_dataset(paths, tmp_path / "dask", client, **OPTS,
                                      progress=seen.append)
        assert sorted(r["mesh"] for r in seen) == sorted(r["mesh"] for r in rows)
        # Two meshes with one output are refused before any task runs.
        with pytest.raises(ValueError, match="both be written"):
            gwn.dask.label_dataset([paths[0], paths[0]], tmp_path / "twice", client, **OPTS)
        assert not (tmp_path / "twice").exists()
        # A real two-process cluster.
        assert len(client.scheduler_info()["workers"]) == 2
    assert [r["status"] for r in rows] == [r["status"] for r in serial]
    assert [r["output"] for r in rows] == [r["output"] for r in serial]
    assert npz_files(tmp_path / "dask") == npz_files(tmp_path / "serial")
    assert len(npz_files(tmp_path / "dask")) == 4


def test_progress_callback_gets_every_row(tmp_path):
    paths = make_dataset(tmp_path)
    seen = []
    rows = gwn.label_dataset(paths, tmp_path / "out", **OPTS, progress=seen.append)
    assert sorted(r["mesh"] for r in seen) == sorted(r["mesh"] for r in rows)
    assert all(isinstance(r, dict) and "status" in r for r in seen)
    # An exception in the callback is raised once the job has finished.
    def boom(row):
        raise RuntimeError("stop")
    with pytest.raises(RuntimeError, match="stop"):
        gwn.label_dataset(paths, tmp_path / "out2", **OPTS, progress=boom)
    assert (tmp_path / "out2" / "manifest.jsonl").exists()


def test_progress_bar_only_on_a_terminal(tmp_path, capsys):
    paths = make_dataset(tmp_path)
    # Under pytest stderr is not a terminal: the default draws nothing.
    gwn.label_dataset(paths, tmp_path / "quiet", **OPTS)
    assert capsys.readouterr().err == ""
    gwn.label_dataset(paths, tmp_path / "bar", **OPTS, progress=True)
    err = capsys.readouterr().err
    assert "5/5" in err and "label [" in err
    gwn.label_dataset(paths, tmp_path / "off", **OPTS, progress=False)
    assert capsys.readouterr().err == ""
    with pytest.raises(TypeError, match="progress"):
        gwn.label_dataset(paths, tmp_path / "x", **OPTS, progress="yes")


def test_shared_outputs_and_changed_options(tmp_path):
    paths = make_dataset(tmp_path)
    with pytest.raises(ValueError, match="both be written"):
        gwn.label_dataset([paths[0], paths[0]], tmp_path / "twice", **OPTS)
    gwn.label_dataset(paths, tmp_path / "out", **OPTS)
    again = gwn.label_dataset(paths, tmp_path / "out", **dict(OPTS, seed=4))
    assert again[0]["status"] == "ok" and "seed 3 -> 4" in again[0]["redone"]
    done = gwn.label_dataset(paths, tmp_path / "out", **dict(OPTS, seed=4))
    assert done[0]["status"] == "done" and done[0]["points"] == 400 and done[0]["faces"] == 12
