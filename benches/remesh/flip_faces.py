"""Reverse a seeded fraction of an OFF mesh's faces: an inconsistently oriented input, as
ShapeNet-style meshes are, for the remesher's benchmarks (docs/benchmarks.md, "Decisive
values" and "Each caller's own levels").

    python3 benches/remesh/flip_faces.py IN.off OUT.off FRACTION SEED

Standard library only. Each face is reversed with probability FRACTION, drawn from Python's
`random.Random(SEED)` in face order, so a seed gives the same mesh on every machine.
"""

import random
import sys


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    src, dst, fraction, seed = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
    if not 0.0 <= fraction <= 1.0:
        sys.exit(f"{src}: the fraction must be within [0, 1], not {fraction}")
    with open(src) as f:
        lines = [l for l in f.read().split("\n") if l.strip() and not l.startswith("#")]
    if not lines or lines[0].strip() != "OFF":
        sys.exit(f"{src}: not an OFF file (plain 'OFF' header expected)")
    nv, nf = (int(x) for x in lines[1].split()[:2])
    if len(lines) < 2 + nv + nf:
        sys.exit(f"{src}: truncated ({nv} vertices and {nf} faces declared)")
    vertices = lines[2 : 2 + nv]
    rng = random.Random(seed)
    faces = []
    for line in lines[2 + nv : 2 + nv + nf]:
        p = line.split()
        n = int(p[0])
        if rng.random() < fraction:
            p = [p[0]] + p[1 : 1 + n][::-1] + p[1 + n :]
        faces.append(" ".join(p))
    with open(dst, "w") as f:
        f.write(f"OFF\n{nv} {nf} 0\n" + "\n".join(vertices) + "\n" + "\n".join(faces) + "\n")


if __name__ == "__main__":
    main()
