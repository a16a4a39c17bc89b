"""Type stubs of gwn (the functions live in the compiled module gwn._gwn)."""

from os import PathLike
from typing import Any, Callable, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, PathLike[str]]
_Floats = npt.ArrayLike
"""float32/float64 array-like of shape (n, 3) (or (n, 2) in 2D), any strides."""
_Indices = npt.ArrayLike
"""int32/int64/uint32/uint64 array-like of shape (m, 3) (tets: (t, 4))."""
_F64 = npt.NDArray[np.float64]
_I64 = npt.NDArray[np.int64]
_Method = Literal["exact", "direct", "fast", "parity"]
_Ray = Literal["+x", "-x", "+y", "-y", "+z", "-z"]
_Rule = Literal["radius", "box-diagonal", "box-corner", "radius-or-box-corner"]
_Grid = Tuple[_F64, _F64, _F64]

class StepModel:
    """A trimmed B-rep model read from a STEP file by ``load("part.step")``; evaluate it with
    ``WindingNumber(model, tolerance=1e-10)``. Pickles by its path."""

    @property
    def path(self) -> str: ...
    @property
    def info(self) -> dict:
        """Counts as ``gwn info`` prints them (faces, patches, surfaces, edges, boundary_edges,
        cancelled_exact, cancelled_matched, trim_segments, solids, shells, unit)."""
    @property
    def closed(self) -> bool:
        """No surface boundary: w is an exact integer off the surface."""
    @property
    def bounding_box(self) -> Tuple[_F64, _F64]: ...

class PatchSet:
    """(Rational) Bezier patches read from a ``.bpt``/``.rbpt`` file by ``load("teapot.bpt")``;
    evaluate them with ``WindingNumber(patches, tolerance=1e-10)`` (``method="direct"``: the
    surface quadrature), remesh them with ``remesh(patches, res=...)``. Pickles by its path."""

    @property
    def path(self) -> str: ...
    @property
    def info(self) -> dict:
        """``{"patches": n, "rational": bool, "max_degree": (m, n)}``."""
    @property
    def bounding_box(self) -> Tuple[_F64, _F64]: ...
    def __len__(self) -> int: ...

_Curved = Union[StepModel, PatchSet]

class WindingNumber:
    """Winding-number evaluator of one mesh, oriented point cloud, STEP model or patch set, built once.

    ``method``: "exact" (Antipodal method, default), "direct" (solid-angle sum) or "fast"
    (Barnes-Hut with accuracy ``beta``, default 2, and expansion ``order``, default 2).
    ``precision`` (30 or 60 bits, default 60), ``ray`` (default "+z") and ``tolerance`` (default
    1e-10) are options of the exact method; an option the method does not use is a ValueError
    (the library's rules, shared with the ``gwn`` command line). ``tolerance`` (finite, >= 0) is
    the absolute tolerance on w for far boundary clusters, replaced by a multipole expansion with
    a certified error bound (``eval_with_bound``); the integer part is always exact, 0 is the
    flat exact loop. Calls release the GIL; one object may be used from several Python threads
    at once. Picklable (rebuilt from its arrays and options).

    ``WindingNumber(model, tolerance=1e-10)`` with a ``StepModel``: the trimmed B-rep evaluator
    of ``gwn eval part.step`` (``tolerance > 0``; the other options do not apply). Uncertified
    values (on or near the surface or an edge) raise a ``RuntimeWarning``; see
    ``eval_with_status``. ``WindingNumber(patches)`` with a ``PatchSet``: the exact method
    (``ray`` and ``tolerance`` apply, its uncertified values warn the same way) or
    ``method="direct"`` (the surface quadrature, ``tolerance`` only).
    """

    def __init__(
        self,
        V: Union[_Floats, _Curved],
        F: Optional[_Indices] = None,
        method: _Method = "exact",
        beta: Optional[float] = None,
        order: Optional[int] = None,
        precision: Optional[int] = None,
        ray: Optional[_Ray] = None,
        tolerance: Optional[float] = None,
        rule: Optional[_Rule] = None,
    ) -> None: ...
    @staticmethod
    def from_point_cloud(
        P: _Floats,
        N: _Floats,
        A: Optional[_Floats] = None,
        beta: float = 2.3,
        order: int = 2,
        rule: Optional[_Rule] = None,
    ) -> "WindingNumber":
        """Barnes-Hut evaluator of an oriented point cloud; areas estimated when ``A`` is None."""
    @overload
    def __call__(self, Q: Tuple[float, float, float], threads: Optional[int] = None) -> float: ...
    @overload
    def __call__(self, Q: _Floats, threads: Optional[int] = None) -> _F64:
        """Winding numbers at the rows of ``Q`` (n, 3): float64 (n,); a float for one (3,) point."""
    def eval(self, Q: _Floats, threads: Optional[int] = None) -> Union[_F64, float]:
        """``self(Q)`` under a name that carries the docstring at run time."""
    def gradient(self, Q: _Floats, threads: Optional[int] = None) -> _F64:
        """Gradients at the rows of ``Q``: float64 (n, 3). Exact and direct methods only."""
    def parts(self, Q: _Floats, threads: Optional[int] = None) -> Tuple[_I64, _F64]:
        """``(chi, fraction)`` with ``chi + fraction == self(Q)`` bit for bit. Exact method only."""
    def eval_with_bound(self, Q: _Floats, threads: Optional[int] = None) -> Tuple[_F64, _F64]:
        """``(w, bound)``, float64 (n,) each: ``w == self(Q)`` and a certified bound on
        ``|w - w_flat|`` (the flat loop, tolerance 0), ``0 <= bound <= tolerance``. Exact only."""
    def eval_with_status(
        self, Q: _Floats, threads: Optional[int] = None
    ) -> Tuple[_F64, _F64, npt.NDArray[np.bool_]]:
        """STEP models and patch sets (exact): ``(w, error_estimate, uncertified)`` at the rows of ``Q``, no warning."""
    @property
    def method(self) -> _Method:
        """The evaluation method."""
    @property
    def tolerance(self) -> Optional[float]:
        """The exact method's boundary tolerance (None for the other methods)."""
    @property
    def face_count(self) -> int:
        """Number of triangles (0 for a point cloud)."""
    @property
    def boundary_edge_count(self) -> Optional[int]:
        """Signed boundary edges of the exact method (None for the other methods)."""

@overload
def winding_number(
    V: _Floats,
    F: _Indices,
    O: Tuple[float, float, float],
    threads: Optional[int] = None,
    *,
    tolerance: float = 1e-10,
) -> float: ...
@overload
def winding_number(
    V: _Floats,
    F: _Indices,
    O: _Floats,
    threads: Optional[int] = None,
    *,
    tolerance: float = 1e-10,
) -> _F64:
    """Exact winding numbers of mesh (V, F) at the rows of O; drop-in for igl.winding_number."""

@overload
def fast_winding_number(
    V: _Floats,
    F: _Indices,
    Q: _Floats,
    expansion_order_: int = 2,
    beta_: float = 2.0,
    /,
    *,
    beta: Optional[float] = None,
    order: Optional[int] = None,
    expansion_order: Optional[int] = None,
    threads: Optional[int] = None,
    rule: Optional[_Rule] = None,
) -> _F64: ...
@overload
def fast_winding_number(
    P: _Floats,
    N: _Floats,
    A: Optional[_Floats],
    Q: _Floats,
    expansion_order_: int = 2,
    beta_: float = 2.0,
    /,
    *,
    beta: Optional[float] = None,
    order: Optional[int] = None,
    expansion_order: Optional[int] = None,
    threads: Optional[int] = None,
    rule: Optional[_Rule] = None,
) -> _F64:
    """Barnes-Hut winding numbers of a mesh (V, F, Q) or point cloud (P, N, A, Q); libigl's forms,
    with libigl's positional ``expansion_order, beta`` (default 2, 2.0) after the arrays."""

def voxelize(
    V: Union[_Floats, _Curved],
    F: Optional[_Indices] = None,
    res: int = 64,
    *,
    dims: Optional[Tuple[int, int, int]] = None,
    bounds: Optional[Tuple[float, float, float, float, float, float]] = None,
    margin: float = 0.05,
    method: Literal["exact", "direct", "fast", "parity"] = "exact",
    beta: Optional[float] = None,
    order: Optional[int] = None,
    tolerance: Optional[float] = None,
    threads: Optional[int] = None,
) -> _Grid:
    """Winding numbers (exact by default) on a voxel grid: (values (D, H, W) indexed [z, y, x], origin, spacing); voxelize(model, res=...) of a StepModel or PatchSet takes no F."""

@overload
def remesh(
    V: Union[_Floats, _Curved],
    F: Optional[_Indices] = None,
    res: int = 128,
    *,
    bisect: int = 8,
    simplify: bool = True,
    method: Literal["exact", "direct", "fast", "parity"] = "exact",
    beta: Optional[float] = None,
    order: Optional[int] = None,
    tolerance: Optional[float] = None,
    threads: Optional[int] = None,
    thicken: Optional[float] = None,
    refine_plates: bool = True,
    sub_cell_levels: int = 1,
    planar_levels: int = 3,
    report: Literal[False] = False,
    samples: int = 10000,
    time_limit: Optional[float] = None,
    always_remesh: bool = False,
) -> Tuple[_F64, _I64]:
    """A closed, manifold, oriented surface of the solid w > 1/2 as (V float64 (n, 3), F int64 (m, 3)); simplify=False: the raw marching-tetrahedra surface; refine_plates=False keeps the lattice of res alone; a mesh that already is such a surface bounding w > 1/2 (exact tests) comes back as it is unless always_remesh; an empty output of a mesh with faces comes with a UserWarning saying why (inward winding: method="parity"; no volume: thicken=). remesh(model, res=...) of a StepModel or PatchSet takes no F."""

@overload
def remesh(
    V: Union[_Floats, _Curved],
    F: Optional[_Indices] = None,
    res: int = 128,
    *,
    bisect: int = 8,
    simplify: bool = True,
    method: Literal["exact", "direct", "fast", "parity"] = "exact",
    beta: Optional[float] = None,
    order: Optional[int] = None,
    tolerance: Optional[float] = None,
    threads: Optional[int] = None,
    thicken: Optional[float] = None,
    refine_plates: bool = True,
    sub_cell_levels: int = 1,
    planar_levels: int = 3,
    report: Literal[True],
    samples: int = 10000,
    time_limit: Optional[float] = None,
    always_remesh: bool = False,
) -> Tuple[_F64, _I64, dict]:
    """(V, F, report): the report a dict of what ``gwn remesh --report`` writes (closed, edge_manifold, vertex_manifold, oriented, euler_characteristic, components, self_intersections, hausdorff_boundary_cells, occupancy_agreement, seconds, ...); samples per surface and in the box for the distance and the agreement (0: neither)."""

def sdf(
    V: _Floats,
    F: _Indices,
    res: int = 64,
    *,
    dims: Optional[Tuple[int, int, int]] = None,
    bounds: Optional[Tuple[float, float, float, float, float, float]] = None,
    margin: float = 0.05,
    tolerance: float = 1e-10,
    threads: Optional[int] = None,
) -> _Grid:
    """Signed distance on a voxel grid, negative where w > 1/2; same layout as voxelize."""

def signed_distance(
    V: _Floats,
    F: _Indices,
    Q: _Floats,
    threads: Optional[int] = None,
    *,
    tolerance: float = 1e-10,
) -> _F64:
    """Signed distance at the rows of Q, negative where w > 1/2."""

def slice(
    V: Union[_Floats, _Curved],
    F: Optional[_Indices] = None,
    axis: Literal["x", "y", "z"] = "z",
    at: float = 0.5,
    *,
    at_coord: Optional[float] = None,
    res: int = 1024,
    margin: float = 0.1,
    outline: bool = False,
    method: Literal["exact", "direct", "fast", "parity"] = "exact",
    beta: Optional[float] = None,
    order: Optional[int] = None,
    tolerance: Optional[float] = None,
    threads: Optional[int] = None,
) -> Tuple[_F64, bytes]:
    """Winding numbers on an axis-aligned plane: (image (height, width), PNG bytes); slice(model, axis=...) of a StepModel or PatchSet takes no F."""

def classify(
    VA: _Floats,
    FA: _Indices,
    VB: Union[_Floats, _Curved],
    FB: Optional[_Indices] = None,
    *,
    method: Literal["exact", "direct", "fast", "parity"] = "exact",
    beta: Optional[float] = None,
    order: Optional[int] = None,
    tolerance: Optional[float] = None,
    threads: Optional[int] = None,
) -> _F64:
    """Winding number (exact by default) of mesh B (or a StepModel or PatchSet VB, no FB) at each face centroid of mesh A."""

def filter_tets(
    V: _Floats,
    F: _Indices,
    points: _Floats,
    tets: _Indices,
    threshold: float = 0.5,
    *,
    method: Literal["exact", "direct", "fast", "parity"] = "exact",
    beta: Optional[float] = None,
    order: Optional[int] = None,
    tolerance: Optional[float] = None,
    threads: Optional[int] = None,
) -> npt.NDArray[np.bool_]:
    """Mask of the tets whose centroid has winding number (exact by default) above threshold."""

@overload
def gauwn(
    polygon: Union[_Floats, Sequence[_Floats]],
    sigma: float,
    Q: _Floats,
    *,
    gradient: Literal[False] = False,
    threads: Optional[int] = None,
) -> _F64: ...
@overload
def gauwn(
    polygon: Union[_Floats, Sequence[_Floats]],
    sigma: float,
    Q: _Floats,
    *,
    gradient: Literal[True],
    threads: Optional[int] = None,
) -> Tuple[_F64, _F64]:
    """Gaussian-smoothed winding number of a polygon at the rows of Q (k, 2) (and its gradient)."""

@overload
def load(path: _Path, weld: Optional[bool] = None) -> Tuple[_F64, _I64]:
    """Reads a mesh (OBJ, STL, OFF, PLY, glTF/GLB) as (V float64 (n, 3), F int64 (m, 3))."""
@overload
def load(path: _Path, weld: None = None) -> _Curved:
    """A ``.step``/``.stp`` path gives a ``StepModel``, a ``.bpt``/``.rbpt`` path a ``PatchSet``."""

def load_point_cloud(path: _Path) -> Tuple[_F64, _F64, Optional[_F64]]:
    """Reads an oriented point cloud as (P, N, A or None)."""

def load_points(path: _Path) -> _F64:
    """Reads query points (text or .npy) as float64 (n, 3)."""

def load_tets(path: _Path) -> Tuple[_F64, _I64, _I64]:
    """Reads a tet mesh (MEDIT .mesh, TetGen .node/.ele) as (points, tets, refs)."""

def load_polygon(path: _Path) -> list[_F64]:
    """Reads a 2D polygon (text or SVG) as a list of float64 (n_i, 2) loops."""

def common_root(paths: Sequence[_Path]) -> str:
    """The deepest folder holding every path (absolute): the default root of a dataset."""

def label_dataset(
    paths: Sequence[_Path],
    out_dir: _Path,
    *,
    root: Optional[_Path] = None,
    uniform: int = 50_000,
    near: int = 50_000,
    sigmas: Sequence[float] = (0.005, 0.05),
    padding: float = 0.05,
    seed: int = 0,
    time_limit: Optional[float] = None,
    weld: Optional[bool] = None,
    threads: Optional[int] = None,
    progress: Union[None, bool, Callable[[dict], Any]] = None,
) -> list[dict]:
    """Labels meshes (w, occupancy, sdf at seeded sample points), one .npz per mesh and
    manifest.jsonl in out_dir, like `gwn label`; returns the manifest rows in input order.
    progress: None = a bar on stderr when it is a terminal, True/False = always/never, or a
    callable given each finished row."""

def remesh_dataset(
    paths: Sequence[_Path],
    out_dir: _Path,
    res: int = 128,
    *,
    root: Optional[_Path] = None,
    format: str = "ply",
    samples: int = 10_000,
    thicken_cells: Optional[float] = None,
    weld: Optional[bool] = None,
    time_limit: Optional[float] = None,
    bisect: Optional[int] = None,
    simplify: bool = True,
    refine_plates: bool = True,
    sub_cell_levels: Optional[int] = None,
    planar_levels: Optional[int] = None,
    always_remesh: bool = False,
    parity_where_flipped: bool = False,
    threads: Optional[int] = None,
    progress: Union[None, bool, Callable[[dict], Any]] = None,
) -> list[dict]:
    """Remeshes meshes at w = 1/2 (closed, manifold, oriented surfaces), one file per mesh and
    manifest.jsonl in out_dir, like `gwn remesh-dataset`; returns the manifest rows in input
    order. progress as in label_dataset."""
