#!/usr/bin/env python3
"""A small open part in a huge box (docs/benchmarks.md, "Exact magnitudes"): writes
OUT/cap-in-1e15-box.obj (a 40-unit open cap of RING boundary edges beside a closed tetrahedron
at 1e15, which sets the extent), OUT/cap-alone.obj (the cap only) and OUT/near.csv (20,000
queries within 80 units of the cap). Standard library only; seeded, so the files are identical
on every run.

    python3 benches/mixed_magnitude/make.py OUT [RING]
    gwn eval OUT/cap-in-1e15-box.obj --points OUT/near.csv --threads 1 --out exact.csv
    gwn eval OUT/cap-in-1e15-box.obj --points OUT/near.csv --method direct --out direct.csv
"""
import math
import os
import random
import sys


def main():
    out = sys.argv[1]
    ring = int(sys.argv[2]) if len(sys.argv) > 2 else 6000
    os.makedirs(out, exist_ok=True)
    rng = random.Random(7)
    centre = (0.3127, -0.1171, 2.7113)
    vertices = [centre]
    for i in range(ring):
        a = 2 * math.pi * (i + rng.uniform(-0.2, 0.2)) / ring
        r = rng.uniform(40.0, 41.0)
        vertices.append((centre[0] + r * math.cos(a), centre[1] + r * math.sin(a),
                         centre[2] - rng.uniform(0.5, 3.0)))
    cap = [(0, 1 + i, 1 + (i + 1) % ring) for i in range(ring)]
    far = 1e15
    tetra_vertices = [(far, far, far), (far + 1, far, far), (far, far + 1, far), (far, far, far + 1)]
    tetra = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]

    def write(path, vs, fs):
        with open(path, "w") as f:
            for v in vs:
                f.write("v %r %r %r\n" % v)
            for t in fs:
                f.write("f %d %d %d\n" % tuple(i + 1 for i in t))

    n = len(vertices)
    write(os.path.join(out, "cap-in-1e15-box.obj"), vertices + tetra_vertices,
          cap + [tuple(n + i for i in t) for t in tetra])
    write(os.path.join(out, "cap-alone.obj"), vertices, cap)
    rng = random.Random(3)
    with open(os.path.join(out, "near.csv"), "w") as f:
        for _ in range(20000):
            r, a = rng.uniform(0.0, 80.0), rng.uniform(0.0, 6.3)
            f.write("%r,%r,%r\n" % (centre[0] + r * math.cos(a), centre[1] + r * math.sin(a),
                                    centre[2] + rng.uniform(-20.0, 20.0)))


if __name__ == "__main__":
    main()
