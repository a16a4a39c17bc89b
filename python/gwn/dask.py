"""Dataset jobs on a Dask cluster (labelling, remeshing): one task per mesh, same files as the
serial job.

``label_dataset(paths, out_dir, client=...)`` maps ``gwn._gwn.label_file`` over the meshes on a
``dask.distributed`` client, then writes ``out_dir/manifest.jsonl`` (input order) from the rows the
tasks return. ``out_dir`` must be a folder every worker can write (a shared file system on a
multi-machine cluster). The ``.npz`` files are byte-identical to ``gwn.label_dataset`` and
``gwn label``: a mesh's points depend only on ``seed`` and its path below ``root``, which is
computed once here from the whole list. See docs/python.md ("Dataset labelling on Dask").
"""

from __future__ import annotations

import json
import os

from . import _gwn


def _label_one(path, out_dir, root, options):
    # One mesh per task, one thread per task: Dask's worker threads are the parallelism.
    return _gwn.label_file(path, out_dir, root, **options)


def label_dataset(paths, out_dir, client=None, *, root=None, uniform=50_000, near=50_000,
                  sigmas=(0.005, 0.05), padding=0.05, seed=0, time_limit=None, weld=None,
                  threads_per_task=1, progress=None):
    """Labels ``paths`` into ``out_dir`` on a Dask cluster (``client``: a
    ``dask.distributed.Client``; default: the current one). Options and ``progress`` as in
    ``gwn.label_dataset``; ``threads_per_task`` is the Rust thread count inside each task.

    Returns the manifest rows (dicts) in input order, after writing ``manifest.jsonl``.
    """
    options = dict(uniform=uniform, near=near, sigmas=list(sigmas), padding=padding, seed=seed,
                   time_limit=time_limit, weld=weld, threads=threads_per_task)
    return _run(_label_one, paths, out_dir, client, root, "npz", progress, "label",
                options=options)


def _run(task, paths, out_dir, client, root, extension, progress, name, **task_args):
    """Maps ``task(path, out_dir=..., root=..., **task_args)`` over ``paths`` on the client and
    writes ``manifest.jsonl`` (input order) from the rows the tasks return."""
    from dask.distributed import as_completed, default_client

    from . import _progress_callback

    client = client if client is not None else default_client()
    paths = [os.path.abspath(os.fspath(p)) for p in paths]
    out_dir = os.path.abspath(os.fspath(out_dir))
    root = os.fspath(root) if root is not None else os.fspath(_gwn.common_root(paths))
    # Checked here, once, before any task runs: two meshes must not share an output.
    _gwn.plan_outputs(paths, root, extension)
    os.makedirs(out_dir, exist_ok=True)
    _gwn.remove_partial_files(out_dir)
    futures = client.map(task, paths, out_dir=out_dir, root=root, pure=False, **task_args)
    callback = _progress_callback(progress, len(paths), name)
    if callback is not None:
        for future in as_completed(futures):
            callback(json.loads(future.result()))
    lines = client.gather(futures)
    manifest = os.path.join(out_dir, "manifest.jsonl")
    # The name `remove_partial_files` recognizes, should this process be killed here.
    tmp = os.path.join(out_dir, f".manifest.jsonl.partial-{os.getpid()}-0")
    with open(tmp, "w", encoding="utf-8") as f:
        for line in lines:
            f.write(line + "\n")
    os.replace(tmp, manifest)
    return [json.loads(line) for line in lines]


def _remesh_one(path, out_dir, root, res, options):
    return _gwn.remesh_file(path, out_dir, root, res, **options)


def remesh_dataset(paths, out_dir, client=None, res=128, *, root=None, format="ply",
                   samples=10_000, thicken_cells=None, weld=None, time_limit=None, bisect=None,
                   simplify=True, refine_plates=True, sub_cell_levels=None, planar_levels=None,
                   always_remesh=False, parity_where_flipped=False, threads_per_task=1,
                   progress=None):
    """Remeshes ``paths`` into ``out_dir`` on a Dask cluster (``client``: a
    ``dask.distributed.Client``; default: the current one), one task per mesh. Options and
    ``progress`` as in ``gwn.remesh_dataset``; ``threads_per_task`` is the Rust thread count
    inside each task. Each remesh sizes its memory limit by the memory its machine has free when
    it starts: give a worker's tasks room (fewer worker threads, more ``threads_per_task``) on
    large meshes or high ``res``. Outputs byte-identical to ``gwn.remesh_dataset``.

    Returns the manifest rows (dicts) in input order, after writing ``manifest.jsonl``.
    """
    from . import _remesh_job_options

    options = _remesh_job_options(
        format=format, samples=samples, thicken_cells=thicken_cells, weld=weld,
        time_limit=time_limit, bisect=bisect, simplify=simplify, refine_plates=refine_plates, sub_cell_levels=sub_cell_levels,
        planar_levels=planar_levels, always_remesh=always_remesh,
        parity_where_flipped=parity_where_flipped)
    options["threads"] = threads_per_task
    return _run(_remesh_one, paths, out_dir, client, root, format.lower(), progress, "remesh",
                res=res, options=options)

