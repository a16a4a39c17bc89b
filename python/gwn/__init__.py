"""gwn: robust generalized winding numbers of triangle meshes, numpy-native.

Exact (Antipodal method: never off by an integer, also on the surface), direct (solid-angle
sum) and fast (Barnes-Hut) evaluators; voxel grids, signed distance, slices, face
classification, tet filtering; 2D Gaussian-smoothed winding numbers. ``winding_number`` and
``fast_winding_number`` take the same arguments as libigl's functions of the same name.

All evaluation runs in Rust with the GIL released; ``threads=`` limits the worker threads of a
call (default: all cores). See docs/python.md for the API.
"""

from ._gwn import (
    WindingNumber,
    __version__,
    classify,
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

__all__ = [
    "WindingNumber",
    "__version__",
    "classify",
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
