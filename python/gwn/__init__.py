"""gwn: robust generalized winding numbers of triangle meshes, numpy-native.

Exact (Antipodal method: never off by an integer, also on the surface), direct (solid-angle
sum) and fast (Barnes-Hut) evaluators; voxel grids, signed distance, slices, face
classification, tet filtering; 2D Gaussian-smoothed winding numbers. ``winding_number`` and
``fast_winding_number`` take the same arguments as libigl's functions of the same name.

All evaluation runs in Rust with the GIL released; ``threads=`` limits the worker threads of a
call (default: all cores). See docs/python.md for the API.
"""

import json as _json
import os as _os

from ._gwn import (
    WindingNumber,
    __version__,
    classify,
    common_root,
    fast_winding_number,
    filter_tets,
    gauwn,
    load,
    load_point_cloud,
    load_points,
    load_polygon,
    load_tets,
    sdf,
    signed_distance,
    slice,
    voxelize,
    winding_number,
)

# pyo3 exposes `__call__` as a type slot, whose run-time docstring is Python's generic "Call
# self as a function."; calls go through `eval` instead (same code, with the docstring), so that
# `help(WindingNumber.__call__)` documents the call.
WindingNumber.__call__ = WindingNumber.eval

__all__ = [
    "WindingNumber",
    "__version__",
    "classify",
    "common_root",
    "label_dataset",
    "fast_winding_number",
    "filter_tets",
    "gauwn",
    "load",
    "load_point_cloud",
    "load_points",
    "load_polygon",
    "load_tets",
    "sdf",
    "signed_distance",
    "slice",
    "voxelize",
    "winding_number",
]


def label_dataset(paths, out_dir, *, root=None, uniform=50_000, near=50_000,
                  sigmas=(0.005, 0.05), padding=0.05, seed=0, time_limit=None, weld=None,
                  threads=None):
    """Labels a dataset of meshes for learning, exactly as ``gwn label`` does.

    Per mesh: ``uniform`` points in the bounding box padded by ``padding`` x diagonal and
    ``near`` points near the surface (area-weighted, Gaussian offsets of ``sigmas`` x diagonal),
    labelled with the exact winding number ``w``, ``occupancy`` (w > 1/2) and ``sdf`` (negative
    where w > 1/2). Writes ``out_dir/<path below root>.npz`` (arrays ``points``, ``source``,
    ``w``, ``occupancy``, ``sdf``) and ``out_dir/manifest.jsonl``. Reproducible byte for byte
    (``seed`` and the path below ``root`` fix a mesh's points); resumable (existing outputs are
    skipped); broken files and ``time_limit`` (seconds per mesh) overruns are manifest rows.
    Runs in Rust on ``threads`` threads (default: all cores) with the GIL released.

    Returns the manifest rows (dicts with ``mesh``, ``output``, ``status`` in ``ok``/``done``/
    ``failed``/``timeout``, ``error``, ``faces``, ``vertices``, ``points``, ``inside``,
    ``seconds``), in input order. For a cluster, see ``gwn.dask.label_dataset``.
    """
    from . import _gwn

    rows = _gwn.label_dataset(
        [_os.fspath(p) for p in paths], _os.fspath(out_dir),
        root=None if root is None else _os.fspath(root), uniform=uniform, near=near,
        sigmas=list(sigmas), padding=padding, seed=seed, time_limit=time_limit, weld=weld,
        threads=threads)
    return [_json.loads(r) for r in rows]
