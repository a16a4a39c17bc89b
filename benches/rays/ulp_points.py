"""Query points 1-3 ulps from a mesh's vertices, edge points and face points, moved along every
axis (docs/benchmarks.md, "Queries ulps from the surface, six rays"). Next to coordinates at 0
the ulps are subnormals. Needs numpy.

usage: python ulp_points.py MESH.off OUT.csv N SEED
"""
import sys

import numpy as np


def load_off(path):
    """Vertices and triangles (polygons fanned) of an OFF file (CGAL's '#' comments allowed)."""
    t = " ".join(line.split("#")[0] for line in open(path)).split()
    nv, nf = int(t[1]), int(t[2])
    v = np.array(t[4 : 4 + 3 * nv], float).reshape(-1, 3)
    f, i = [], 4 + 3 * nv
    for _ in range(nf):
        k = int(t[i])
        idx = [int(x) for x in t[i + 1 : i + 1 + k]]
        f.extend([idx[0], idx[j], idx[j + 1]] for j in range(1, k - 1))
        i += 1 + k
    return v, np.array(f)


def main():
    v, f = load_off(sys.argv[1])
    n, rng = int(sys.argv[3]), np.random.default_rng(int(sys.argv[4]))
    points = []
    for _ in range(n):
        tri = v[f[rng.integers(len(f))]]
        kind = rng.integers(3)
        if kind == 0:
            p = tri[rng.integers(3)].copy()
        elif kind == 1:
            e = rng.integers(3)
            p = tri[e] + rng.random() * (tri[(e + 1) % 3] - tri[e])
        else:
            p = rng.dirichlet([1, 1, 1]) @ tri
        steps = rng.integers(1, 4, size=3) * rng.choice([-1, 1], size=3)
        for a in range(3):
            for _ in range(abs(steps[a])):
                p[a] = np.nextafter(p[a], np.inf if steps[a] > 0 else -np.inf)
        points.append(p)
    np.savetxt(sys.argv[2], np.array(points), delimiter=",", fmt="%.17g")


if __name__ == "__main__":
    main()
