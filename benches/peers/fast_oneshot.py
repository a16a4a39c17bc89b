#!/usr/bin/env python3
"""One-shot fast winding numbers from Python at default threads: libigl's
`igl.fast_winding_number(V, F, Q)` against gwn's `fast_winding_number` at its default (radius
β = 2), radius β = 2.8 and radius-or-box-corner β = 2.8 (the two settings matched to libigl's
accuracy), tree build included, best of 3 (docs/benchmarks.md, "Either admissibility test").

Query points: the 32³ cell-centre grid over the box grown by 10 % of its largest side, and 10⁶
points uniform in that box (seeded).

    benches/peers/.venv/bin/python benches/peers/fast_oneshot.py MESH...

Needs the peers venv with the gwn module installed in it (`benches/peers/.venv/bin/pip install ./python`).
"""
import os
import sys
import time

import igl
import numpy as np

import gwn


def best(f, reps=3):
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def main(paths):
    print("| mesh | F | points | libigl ms | gwn β 2 | gwn radius 2.8 | gwn either 2.8 |")
    print("|---|---:|---|---:|---:|---:|---:|")
    for path in paths:
        V, F = igl.read_triangle_mesh(path)
        V = np.ascontiguousarray(V, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.int64)
        lo, hi = V.min(0), V.max(0)
        pad = 0.1 * (hi - lo).max()
        lo, hi = lo - pad, hi + pad
        n = 32
        axes = [lo[k] + (hi[k] - lo[k]) * (np.arange(n) + 0.5) / n for k in range(3)]
        grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
        uniform = lo + (hi - lo) * np.random.default_rng(1).random((1_000_000, 3))
        for name, Q in (("32³ grid", grid), ("10⁶ uniform", uniform)):
            ti = best(lambda: igl.fast_winding_number(V, F, Q))
            runs = [
                best(lambda: gwn.fast_winding_number(V, F, Q)),
                best(lambda: gwn.fast_winding_number(V, F, Q, beta=2.8)),
                best(lambda: gwn.fast_winding_number(V, F, Q, beta=2.8, rule="radius-or-box-corner")),
            ]
            cells = " | ".join(f"{t * 1e3:.0f} ({ti / t:.2f}×)" for t in runs)
            print(f"| {os.path.basename(path)} | {len(F)} | {name} | {ti * 1e3:.0f} | {cells} |", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
