#!/usr/bin/env python3
"""libigl's fast winding number (`FastWindingNumberBVH`, order 2, accuracy_scale 2) timed in
process CPU time, on the 32^3 grid of `gwn bench` (the points `examples/fast_vs_igl_cpu.rs` uses),
so that it reads side by side with gwn's `fast_vs_igl_cpu` example on a shared machine.

    IGL_NUM_THREADS=1 OMP_NUM_THREADS=1 benches/peers/.venv/bin/python \
        benches/peers/igl_fast_cpu.py MESH... [--reps 3] [--accuracy-scale 2]

Prints one markdown row per mesh: faces, build ms (CPU), queries/s (CPU). With more than one
thread, CPU time sums over the threads: divide by wall clock yourself (also printed).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from peers import grid_points  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("meshes", nargs="+")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--accuracy-scale", type=float, default=2.0)
    ap.add_argument("--min-cpu", type=float, default=0.5)
    args = ap.parse_args()
    import igl

    print("| mesh | faces | igl build ms (cpu) | igl build ms (wall) | igl queries/s (cpu) | igl queries/s (wall) |")
    print("|---|---:|---:|---:|---:|---:|")
    for path in args.meshes:
        V, F = igl.read_triangle_mesh(path)
        V = np.ascontiguousarray(V, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.int64)
        P = np.ascontiguousarray(grid_points(V, F, 32))
        build = build_wall = float("inf")
        for _ in range(args.reps):
            bvh = igl.FastWindingNumberBVH()
            c, t = time.process_time(), time.perf_counter()
            bvh.init(V, F, 2)
            build = min(build, time.process_time() - c)
            build_wall = min(build_wall, time.perf_counter() - t)
        best_cpu = best_wall = float("inf")
        for _ in range(args.reps):
            c, t = time.process_time(), time.perf_counter()
            rounds = 0
            while True:
                bvh.winding_number(P, args.accuracy_scale)
                rounds += 1
                if time.process_time() - c >= args.min_cpu:
                    break
            best_cpu = min(best_cpu, (time.process_time() - c) / rounds)
            best_wall = min(best_wall, (time.perf_counter() - t) / rounds)
        print(
            f"| {Path(path).name} | {len(F)} | {build * 1e3:.1f} | {build_wall * 1e3:.1f} | {len(P) / best_cpu:.4g} |"
            f" {len(P) / best_wall:.4g} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
