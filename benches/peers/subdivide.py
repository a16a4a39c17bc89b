"""Midpoint subdivision of a triangle mesh (each triangle into four), for a mesh near a million faces.

The corpus's largest mesh has 203k faces; issue 25 asks for the fast method at up to a million.
`npm-dragon_vrip_res2.ply` subdivided once has 810,080 faces (docs/benchmarks.md, "The tree build
at 0.8M triangles"):

    benches/peers/.venv/bin/python benches/peers/subdivide.py MESH OUT.ply
"""

import sys

import igl
import numpy as np


def main() -> None:
    V, F = igl.read_triangle_mesh(sys.argv[1])[:2]
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    # One new vertex per undirected edge, at its midpoint.
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    edges, inverse = np.unique(E, axis=0, return_inverse=True)
    mid = inverse.reshape(3, -1).T + len(V)
    V2 = np.concatenate([V, (V[edges[:, 0]] + V[edges[:, 1]]) / 2])
    a, b, c = F.T
    ab, bc, ca = mid.T
    F2 = np.concatenate(
        [np.stack(t, axis=1) for t in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))]
    )
    igl.write_triangle_mesh(sys.argv[2], V2, F2)
    print(f"{len(V2)} vertices, {len(F2)} faces")


if __name__ == "__main__":
    main()
