"""Query points near a mesh's surface for the six-ray accuracy check (docs/benchmarks.md,
"Near-edge tube"): for each of N draws, one point on a random face's edge and one inside a random
face, each moved 1e-2 to 1e-9 of the extent in a random direction. Needs numpy.

usage: python near_surface_points.py MESH.off OUT.csv [N]
"""
import sys

import numpy as np


def load_off(path):
    # CGAL's OFF files start with '#' comments.
    t = " ".join(line.split("#")[0] for line in open(path)).split()
    assert t[0] == "OFF", path
    nv, nf = int(t[1]), int(t[2])
    v = np.array(t[4 : 4 + 3 * nv], float).reshape(-1, 3)
    f, i = [], 4 + 3 * nv
    for _ in range(nf):
        k = int(t[i])
        f.append([int(x) for x in t[i + 1 : i + 1 + k]])
        i += 1 + k
    return v, np.array(f)


def main():
    v, f = load_off(sys.argv[1])
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 3000
    rng = np.random.default_rng(1)
    extent = np.ptp(v, axis=0).max()
    points = []
    for _ in range(n):
        tri = v[f[rng.integers(len(f))]]
        e = rng.integers(3)
        a, b = tri[e], tri[(e + 1) % 3]
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        points.append(a + rng.random() * (b - a) + d * extent * 10.0 ** (-rng.uniform(2, 9)))
        w = rng.dirichlet([1, 1, 1])
        points.append(w @ tri + d * extent * 10.0 ** (-rng.uniform(2, 9)))
    np.savetxt(sys.argv[2], np.array(points), delimiter=",")


if __name__ == "__main__":
    main()
