"""Dataset remeshing from Python: the Rust job's files bit for bit (gwn.remesh of the loaded
mesh, the CLI's `gwn remesh-dataset`, gwn.dask.remesh_dataset on a real 2-worker LocalCluster),
resuming, failures as rows."""

import json
import shutil
import subprocess

import numpy as np
import pytest

import gwn
from conftest import FIXTURES, copy_fixtures, files_by_suffix

OPTS = dict(samples=1000)


def make_dataset(tmp_path):
    files = {"a/cube.off": "cube.off", "b/scene.glb": "two_cubes.glb",
             "b/broken.off": "broken_index.off"}
    return copy_fixtures(tmp_path, files)


def surfaces(d):
    return files_by_suffix(d, ".ply")


def test_remesh_dataset_rows_outputs_and_resume(tmp_path, cli):
    paths = make_dataset(tmp_path)
    seen = []
    rows = gwn.remesh_dataset(paths, tmp_path / "out", 24, **OPTS, threads=2,
                              progress=seen.append)
    assert [r["status"] for r in rows] == ["ok", "ok", "failed"]
    assert sorted(r["mesh"] for r in seen) == sorted(r["mesh"] for r in rows)
    cube, scene, broken = rows
    assert cube["output"] == "a/cube.off.ply" and cube["faces"] == 12
    assert cube["valid"] is True and cube["components"] == 1
    assert cube["self_intersections"] == 0
    assert cube["hausdorff_cells"] < 1 and cube["occupancy_agreement"] > 0.99
    assert scene["components"] == 2
    # A clean cube is written as it is; nothing came out empty.
    assert cube["outcome"] == "kept" and cube["empty"] is None
    assert "broken.off" in broken["error"] and broken["output_faces"] is None
    # The file is what gwn.remesh makes of the loaded mesh.
    V, F = gwn.load(tmp_path / "out" / "a" / "cube.off.ply")
    Vr, Fr = gwn.remesh(*gwn.load(paths[0]), res=24)
    np.testing.assert_array_equal(F, Fr)
    np.testing.assert_array_equal(V, Vr)  # the PLY holds float64
    assert cube["output_faces"] == len(F) and cube["output_vertices"] == len(V)
    # The CLI writes the same files and the same rows (but for seconds and paths' spelling).
    subprocess.run([str(cli), "remesh-dataset", str(tmp_path / "in"), "--out",
                    str(tmp_path / "cli"), "--res", "24", "--samples", "1000"], check=True,
                   capture_output=True)
    assert surfaces(tmp_path / "cli") == surfaces(tmp_path / "out")
    manifest = [json.loads(l) for l in
                (tmp_path / "cli" / "manifest.jsonl").read_text().splitlines()]
    by_output = {r["output"]: r for r in manifest}
    for r in rows:
        c = by_output[r["output"]]
        for key in ("status", "faces", "output_faces", "valid", "hausdorff_cells",
                    "occupancy_agreement", "outcome", "empty"):
            assert c[key] == r[key], key
    # Again: nothing to do; another option: redone, and named.
    again = gwn.remesh_dataset(paths, tmp_path / "out", 24, **OPTS)
    assert [r["status"] for r in again] == ["done", "done", "failed"]
    assert again[0]["output_faces"] == cube["output_faces"]
    redone = gwn.remesh_dataset(paths[:1], tmp_path / "out", 24, samples=0,
                                root=tmp_path / "in")
    assert redone[0]["status"] == "ok"
    assert redone[0]["redone"] == "options changed: samples 1000 -> 0"
    assert redone[0]["hausdorff_cells"] is None


def test_remesh_dataset_bad_arguments_are_value_errors(tmp_path):
    paths = make_dataset(tmp_path)
    with pytest.raises(ValueError, match="expected obj, ply, stl or glb"):
        gwn.remesh_dataset(paths, tmp_path / "o", format="step")
    with pytest.raises(ValueError, match="at least one finest cell"):
        gwn.remesh_dataset(paths, tmp_path / "o", thicken_cells=0.5)
    with pytest.raises(ValueError, match="both be written"):
        gwn.remesh_dataset([paths[0], paths[0]], tmp_path / "o")
    with pytest.raises(ValueError, match="time_limit must be a positive"):
        gwn.remesh_dataset(paths, tmp_path / "o", time_limit=-1)
    assert not (tmp_path / "o").exists()
    # A limit no mesh can meet: timeout rows (the broken file fails first), no outputs.
    rows = gwn.remesh_dataset(paths, tmp_path / "t", 24, time_limit=1e-6)
    assert [r["status"] for r in rows] == ["timeout", "timeout", "failed"]
    assert rows[0]["error"].startswith("time limit of 0.000 s exceeded while ")
    assert not list((tmp_path / "t").rglob("*.ply"))


def test_remesh_time_limit_is_a_timeout_error():
    V, F = gwn.load(FIXTURES / "cube.off")
    with pytest.raises(TimeoutError, match="the time limit ran out while "):
        gwn.remesh(V, F, res=64, time_limit=1e-6)
    with pytest.raises(ValueError, match="time_limit must be a positive"):
        gwn.remesh(V, F, res=64, time_limit=0)
    # A limit the run meets changes nothing.
    np.testing.assert_array_equal(gwn.remesh(V, F, res=16, time_limit=3600)[1],
                                  gwn.remesh(V, F, res=16)[1])


def write_flipped_cube(path):
    """The unit cube with every other face flipped (closed, not consistently oriented) as OBJ."""
    from conftest import CUBE_F, CUBE_V
    faces = [f[::-1] if k % 2 else f for k, f in enumerate(CUBE_F)]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in CUBE_V)
                    + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces))
    return path


def test_remesh_dataset_parity_where_flipped(tmp_path):
    """A closed mesh with flipped faces goes by parity on request, kept with its faces turned
    (the faces ``gwn.remesh(method="parity")`` gives); the clean cube stays the exact method's."""
    flipped = write_flipped_cube(tmp_path / "in" / "flipped.obj")
    cube = copy_fixtures(tmp_path, {"cube.off": "cube.off"})[0]
    rows = gwn.remesh_dataset([cube, flipped], tmp_path / "out", 16, samples=0,
                              parity_where_flipped=True)
    assert [r["method"] for r in rows] == ["exact", "parity"]
    assert [r["outcome"] for r in rows] == ["kept", "reoriented"]
    assert rows[1]["valid"] is True and rows[1]["kept_faces"] == 6
    V, F = gwn.load(tmp_path / "out" / "flipped.obj.ply")
    Vr, Fr = gwn.remesh(*gwn.load(flipped), res=16, method="parity")
    np.testing.assert_array_equal(F, Fr)
    np.testing.assert_array_equal(V, Vr)
    off = gwn.remesh_dataset([flipped], tmp_path / "off", 16, samples=0)
    assert off[0]["method"] == "exact" and off[0]["outcome"] == "remeshed"


def test_dask_remesh_matches_serial(tmp_path):
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        print("skipping: dask.distributed is not installed")
        pytest.skip("dask.distributed is not installed")
    import gwn.dask

    paths = make_dataset(tmp_path)
    serial = gwn.remesh_dataset(paths, tmp_path / "serial", 24, **OPTS, format="obj")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        rows = gwn.dask.remesh_dataset(paths, tmp_path / "dask", client, 24, **OPTS,
                                       format="obj")
        flipped = write_flipped_cube(tmp_path / "in" / "flipped.obj")
        parity = gwn.dask.remesh_dataset([flipped], tmp_path / "dask_parity", client, 16,
                                         samples=0, parity_where_flipped=True)
        assert parity[0]["method"] == "parity" and parity[0]["outcome"] == "reoriented"
        with pytest.raises(ValueError, match="both be written"):
            gwn.dask.remesh_dataset([paths[0], paths[0]], tmp_path / "twice", client)
        assert not (tmp_path / "twice").exists()
    assert [r["status"] for r in rows] == [r["status"] for r in serial]
    assert [r["output"] for r in rows] == [r["output"] for r in serial]
    objs = lambda d: {p.relative_to(d).as_posix(): p.read_bytes() for p in d.rglob("*.obj")}
    assert objs(tmp_path / "dask") == objs(tmp_path / "serial")
    assert len(objs(tmp_path / "dask")) == 2
    manifest = (tmp_path / "dask" / "manifest.jsonl").read_text().splitlines()
    assert [json.loads(l)["output"] for l in manifest] == [r["output"] for r in serial]


def test_remesh_dataset_takes_a_step_model(tmp_path):
    """A STEP model is an input like a mesh: its row names the kind and its B-rep faces, and the
    file is what gwn.remesh makes of the model."""
    step = tmp_path / "in" / "capped_cylinder.step"
    step.parent.mkdir(parents=True)
    shutil.copy(FIXTURES / "step" / "capped_cylinder.step", step)
    (row,) = gwn.remesh_dataset([step], tmp_path / "out", 16, samples=0, threads=2)
    assert row["status"] == "ok" and row["input"] == "STEP model" and row["faces"] == 3
    assert row["valid"] is True and row["components"] == 1 and row["vertices"] is None
    V, F = gwn.load(tmp_path / "out" / "capped_cylinder.step.ply")
    Vr, Fr = gwn.remesh(gwn.load(step), res=16)
    np.testing.assert_array_equal(F, Fr)
    np.testing.assert_array_equal(V, Vr)
