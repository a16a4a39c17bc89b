from os import PathLike
from typing import Any, Callable, Optional, Sequence, Union

_Path = Union[str, PathLike]

def label_dataset(
    paths: Sequence[_Path],
    out_dir: _Path,
    client: Optional[Any] = None,
    *,
    root: Optional[_Path] = None,
    uniform: int = 50_000,
    near: int = 50_000,
    sigmas: Sequence[float] = (0.005, 0.05),
    padding: float = 0.05,
    seed: int = 0,
    time_limit: Optional[float] = None,
    weld: Optional[bool] = None,
    threads_per_task: int = 1,
    progress: Union[None, bool, Callable[[dict], Any]] = None,
) -> list[dict]:
    """gwn.label_dataset with one Dask task per mesh on `client` (default: the current client);
    byte-identical outputs."""

def remesh_dataset(
    paths: Sequence[_Path],
    out_dir: _Path,
    client: Optional[Any] = None,
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
    threads_per_task: int = 1,
    progress: Union[None, bool, Callable[[dict], Any]] = None,
) -> list[dict]:
    """gwn.remesh_dataset with one Dask task per mesh on `client` (default: the current client);
    byte-identical outputs."""
