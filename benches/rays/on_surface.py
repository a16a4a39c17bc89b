"""How many of the points of a CSV lie exactly on a triangle of an OFF mesh (rational arithmetic:
the ray-dependent values there are the documented perturbation, not errors). Slow (every
triangle per point): for the few points where rays disagree.

usage: python on_surface.py MESH.off POINTS.csv
"""
import sys
from fractions import Fraction

from ulp_points import load_off


def on_triangle(q, a, b, c):
    sub = lambda x, y: [x[k] - y[k] for k in range(3)]
    cross = lambda x, y: [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]
    dot = lambda x, y: sum(x[k] * y[k] for k in range(3))
    n = cross(sub(b, a), sub(c, a))
    if dot(n, sub(q, a)) != 0:
        return False
    s = [dot(cross(sub(y, x), sub(q, x)), n) for x, y in ((a, b), (b, c), (c, a))]
    return all(t >= 0 for t in s) or all(t <= 0 for t in s)


def main():
    v, f = load_off(sys.argv[1])
    v = [[Fraction(float(x)) for x in p] for p in v]
    on = off = 0
    for line in open(sys.argv[2]):
        if not line.strip():
            continue
        q = [Fraction(float(x)) for x in line.split(",")]
        if any(on_triangle(q, v[i], v[j], v[k]) for i, j, k in f):
            on += 1
        else:
            off += 1
            print("off the surface:", line.strip())
    print(f"{sys.argv[2]}: {on} on the surface, {off} off")


if __name__ == "__main__":
    main()
