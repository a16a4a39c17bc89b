"""gwn: robust generalized winding numbers of triangle meshes (and Bezier patches and trimmed STEP models), numpy-native.

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
    PatchSet,
    StepModel,
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
    remesh,
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
    "PatchSet",
    "StepModel",
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
    "remesh",
    "remesh_dataset",
    "sdf",
    "signed_distance",
    "slice",
    "voxelize",
    "winding_number",
]


class _ProgressBar:
    """A one-line text bar on stderr: ``label [=====     ] 3/10 path``, redrawn per mesh."""

    def __init__(self, total, stream, name="label"):
        self.total, self.done, self.stream, self.name = total, 0, stream, name

    def __call__(self, row):
        self.done += 1
        width = 30
        filled = width * self.done // max(self.total, 1)
        self.stream.write("\r%s [%s%s] %d/%d %s\x1b[K" % (
            self.name, "=" * filled, " " * (width - filled), self.done, self.total, row["mesh"]))
        if self.done == self.total:
            self.stream.write("\n")
        self.stream.flush()


def _progress_callback(progress, total, name="label"):
    """``progress`` as a function of one row (dict), or None: a callable is used as is,
    ``True`` draws a bar on stderr, ``None`` draws it only when stderr is a terminal, ``False``
    draws nothing."""
    import sys

    if callable(progress):
        return progress
    if progress is None:
        stream = sys.stderr
        progress = stream is not None and hasattr(stream, "isatty") and stream.isatty()
    if progress is True:
        return _ProgressBar(total, sys.stderr, name)
    if progress is False:
        return None
    raise TypeError("progress must be None, True, False or a callable taking a row dict, got %r"
                    % (progress,))


def label_dataset(paths, out_dir, *, root=None, uniform=50_000, near=50_000,
                  sigmas=(0.005, 0.05), padding=0.05, seed=0, time_limit=None, weld=None,
                  threads=None, progress=None):
    """Labels a dataset of meshes for learning, exactly as ``gwn label`` does.

    Per mesh: ``uniform`` points in the bounding box padded by ``padding`` x diagonal and
    ``near`` points near the surface (area-weighted, Gaussian offsets of ``sigmas`` x diagonal),
    labelled with the exact winding number ``w``, ``occupancy`` (w > 1/2) and ``sdf`` (negative
    where w > 1/2). Writes ``out_dir/<path below root>.npz`` (arrays ``points``, ``source``,
    ``w``, ``occupancy``, ``sdf``) and ``out_dir/manifest.jsonl``. Reproducible byte for byte
    (``seed`` and the path below ``root`` fix a mesh's points); resumable (an existing output is
    reused only when it was made with the same options from the same input, else redone and
    ``redone`` says why); broken files, FIFOs and ``time_limit`` (seconds per mesh) overruns are
    manifest rows; two inputs with one output are a ``ValueError`` before anything is written.
    Runs in Rust on ``threads`` threads (default: all cores) with the GIL released.

    ``progress``: ``None`` (default) draws a progress bar on stderr when stderr is a terminal,
    ``True`` always, ``False`` never; a callable is called with each finished mesh's row (a dict,
    in completion order) on the calling thread.

    Returns the manifest rows (dicts with ``mesh``, ``output``, ``status`` in ``ok``/``done``/
    ``failed``/``timeout``, ``error``, ``faces``, ``vertices``, ``points``, ``inside``,
    ``seconds``, ``redone``), in input order. For a cluster, see ``gwn.dask.label_dataset``.
    """
    from . import _gwn

    paths = [_os.fspath(p) for p in paths]
    callback = _progress_callback(progress, len(paths))
    rows = _gwn.label_dataset(
        paths, _os.fspath(out_dir),
        root=None if root is None else _os.fspath(root), uniform=uniform, near=near,
        sigmas=list(sigmas), padding=padding, seed=seed, time_limit=time_limit, weld=weld,
        threads=threads,
        progress=None if callback is None else (lambda line: callback(_json.loads(line))))
    return [_json.loads(r) for r in rows]


def remesh_dataset(paths, out_dir, res=128, *, root=None, format="ply", samples=10_000,
                   thicken_cells=None, weld=None, time_limit=None, bisect=None, simplify=True,
                   refine_plates=True, sub_cell_levels=None, planar_levels=None,
                   always_remesh=False, parity_where_flipped=False, threads=None, progress=None):
    """Remeshes a dataset at w = 1/2, exactly as ``gwn remesh-dataset`` does.

    Per input: the closed, edge- and vertex-manifold, oriented surface ``gwn remesh`` makes at
    ``res`` (meshes and soups: exact w, the input triangles as the guide; STEP models and patch
    sets: their own evaluator; oriented point clouds: the fast evaluator; the same bytes
    ``gwn remesh`` writes), written to ``out_dir/<path below root>.<format>`` (``obj``, ``ply``,
    ``stl`` or ``glb``), and ``out_dir/manifest.jsonl``. ``samples`` report samples per input
    measure the Hausdorff distance and the occupancy agreement (0: neither); ``thicken_cells``
    closes open sheets of meshes into slabs of that half-thickness in finest cells; an input
    past ``time_limit`` seconds is a ``timeout`` row. Inputs run one after the other, each on
    ``threads`` threads (default: all cores), with the GIL released. Resumable (an existing
    output is reused only when it was made with the same options from the same input, else
    redone and ``redone`` says why); broken files and FIFOs are manifest rows; two inputs with
    one output are a ``ValueError`` before anything is written. ``sub_cell_levels`` and
    ``planar_levels`` and ``bisect``: ``None`` for ``gwn remesh``'s defaults. A mesh that already
    is a closed, manifold, oriented surface without self-intersections bounding ``w > 1/2``
    (exact tests) is written as it is (the row's ``kept``) unless ``always_remesh``; otherwise its
    clean components can be (``kept_faces``: the input's faces written as they are).
    ``parity_where_flipped`` remeshes meshes that are closed but not consistently oriented
    (flipped faces, where w is fractional) by ray parity, the solid they enclose, as
    ``gwn.remesh(..., method="parity")`` (written with their faces turned where that is proved:
    ``reoriented``); the row's ``method`` says which (``exact``, ``parity``, ``fast``).

    ``progress`` as in ``gwn.label_dataset``. Returns the manifest rows (dicts with ``mesh``,
    ``output``, ``status`` in ``ok``/``done``/``failed``/``timeout``, ``error``, ``input`` (the
    kind: ``mesh``, ``point cloud``, ``patch set``, ``STEP model``), ``faces`` (triangles,
    patches or B-rep faces), ``vertices`` (mesh vertices or points), ``output_faces``,
    ``method``, ``kept``, ``outcome`` (``kept``, ``reoriented``, ``cut``, ``partly kept``,
    ``remeshed`` or ``bounds nothing``),
    ``kept_faces``, ``empty`` (``None``, or why an empty output is empty: ``winds inward`` or
    ``no volume``), ``output_vertices``, ``valid`` (closed, manifold, oriented, no exact
    self-intersection),
    ``components``, ``self_intersections``, ``hausdorff_cells``, ``occupancy_agreement``,
    ``seconds``, ``redone``), in input order. For a cluster, see ``gwn.dask.remesh_dataset``.
    """
    from . import _gwn

    paths = [_os.fspath(p) for p in paths]
    callback = _progress_callback(progress, len(paths), "remesh")
    rows = _gwn.remesh_dataset(
        paths, _os.fspath(out_dir), res,
        root=None if root is None else _os.fspath(root), **_remesh_job_options(
            format=format, samples=samples, thicken_cells=thicken_cells, weld=weld,
            time_limit=time_limit,
            bisect=bisect, simplify=simplify, refine_plates=refine_plates,
            sub_cell_levels=sub_cell_levels, planar_levels=planar_levels,
            always_remesh=always_remesh, parity_where_flipped=parity_where_flipped),
        threads=threads,
        progress=None if callback is None else (lambda line: callback(_json.loads(line))))
    return [_json.loads(r) for r in rows]


def _remesh_job_options(**options):
    """The keyword arguments of ``_gwn.remesh_dataset``/``remesh_file``: ``None`` bisection
    steps and levels left out, so the library's defaults apply."""
    return {k: v for k, v in options.items()
            if v is not None or k not in ("bisect", "sub_cell_levels", "planar_levels")}

