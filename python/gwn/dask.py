"""Dataset labelling on a Dask cluster: one task per mesh, same files as the serial job.

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
    from dask.distributed import as_completed, default_client

    from . import _progress_callback

    client = client if client is not None else default_client()
    paths = [os.path.abspath(os.fspath(p)) for p in paths]
    out_dir = os.path.abspath(os.fspath(out_dir))
    root = os.fspath(root) if root is not None else os.fspath(_gwn.common_root(paths))
    # Checked here, once, before any task runs: two meshes must not share an output.
    _gwn.plan_outputs(paths, root)
    options = dict(uniform=uniform, near=near, sigmas=list(sigmas), padding=padding, seed=seed,
                   time_limit=time_limit, weld=weld, threads=threads_per_task)
    os.makedirs(out_dir, exist_ok=True)
    _gwn.remove_partial_files(out_dir)
    futures = client.map(_label_one, paths, out_dir=out_dir, root=root, options=options,
                         pure=False)
    callback = _progress_callback(progress, len(paths))
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
