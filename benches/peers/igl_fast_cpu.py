#!/usr/bin/env python3
"""libigl's fast winding number timed in process CPU time, side by side with gwn's
`examples/fast_speed.rs` on a shared machine.

Meshes: `FastWindingNumberBVH` (order 2, accuracy_scale 2), build then queries.
Point clouds (`--cloud FILE.npy`, N x 7 `x y z nx ny nz area` as written by
`fast_speed --cloud N --dump-cloud FILE.npy`): the one-shot `igl.fast_winding_number(P, N, A, Q,
order, beta)`, expansion order `--order` (2), `--beta` (2, libigl's default). Build and query are
split by timing it on Q and on Q twice (the difference is the queries' time, the rest the build).
`--precomputed` times instead `igl.octree` + `igl.fast_winding_number_precompute` (the build) and
the precomputed `igl.fast_winding_number(P, N, A, point_indices, CH, CM, R, EC, Q, beta)`: the
per-cell index lists then cross into Python, which dominates (10 s for 200k points; at 1M points
the process was killed after reaching 24 GB).

Query points: the 32^3 grid of `gwn bench` (default), or `--points FILE.npy` (N x 3 float64, as
written by `fast_speed --dump-points FILE.npy`, e.g. its seeded random points).

    IGL_NUM_THREADS=1 OMP_NUM_THREADS=1 benches/peers/.venv/bin/python \
        benches/peers/igl_fast_cpu.py MESH [--points Q.npy] [--cloud C.npy] [--reps 3] \
        [--accuracy-scale 2] [--accuracy K]

Prints one markdown row per mesh: elements, build ms (CPU and wall), queries/s (CPU and wall),
the one-shot call (`igl.fast_winding_number(V, F, Q)`, or `(P, N, A, Q, order, beta)` for a
cloud: build and queries in one C++ call, as Python users call it) in ms, and with `--accuracy K` the max |libigl - direct| over K of the points, strided as in
`fast_speed` (direct: `igl.winding_number` for meshes, the dipole sum for clouds). With more
than one thread, CPU time sums over the threads.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from peers import grid_points  # noqa: E402


def best_of(reps: int, min_cpu: float, f) -> tuple[float, float]:
    """Best (CPU, wall) seconds per call of f over reps repetitions of >= min_cpu CPU seconds."""
    best_cpu = best_wall = float("inf")
    for _ in range(reps):
        c, t = time.process_time(), time.perf_counter()
        rounds = 0
        while True:
            f()
            rounds += 1
            if time.process_time() - c >= min_cpu:
                break
        best_cpu = min(best_cpu, (time.process_time() - c) / rounds)
        best_wall = min(best_wall, (time.perf_counter() - t) / rounds)
    return best_cpu, best_wall


def strided(n: int, k: int) -> np.ndarray:
    """The subset `fast_speed --accuracy K` compares: every (n // k)-th point, k of them."""
    return np.arange(0, n, max(n // k, 1))[:k]


def dipole_direct(P: np.ndarray, AN: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """The exact dipole sum sum_i a_i (p_i - q).n_i / (4 pi |p_i - q|^3), in chunks."""
    out = np.empty(len(Q))
    for j, q in enumerate(Q):
        r = P - q
        d2 = np.einsum("ij,ij->i", r, r)
        num = np.einsum("ij,ij->i", r, AN)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(d2 > 0, num / (d2 * np.sqrt(d2)), 0.0)
        out[j] = t.sum() / (4 * np.pi)
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("meshes", nargs="+")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--accuracy-scale", type=float, default=2.0)
    ap.add_argument("--min-cpu", type=float, default=0.5)
    ap.add_argument("--points", help="query points, N x 3 float64 .npy (default: the 32^3 grid)")
    ap.add_argument("--cloud", help="point cloud, N x 7 float64 .npy (x y z nx ny nz area)")
    ap.add_argument("--order", type=int, default=2, help="point-cloud expansion order")
    ap.add_argument("--beta", type=float, default=2.0, help="point-cloud beta")
    ap.add_argument(
        "--precomputed",
        action="store_true",
        help="clouds: time igl.octree + fast_winding_number_precompute and the precomputed query"
        " (its per-cell index lists cross into Python: 10 s and 24 GB at 1M points)",
    )
    ap.add_argument("--accuracy", type=int, default=0, help="max error over K strided points")
    args = ap.parse_args()
    if (args.points or args.cloud) and len(args.meshes) != 1:
        ap.error("--points / --cloud belong to one mesh: give one")
    import igl

    head = (
        "| input | elements | igl build ms (cpu) | igl build ms (wall) | igl queries/s (cpu) | igl queries/s (wall) |"
        " igl one-shot ms (cpu) | igl one-shot ms (wall) |"
    )
    rule = "|---|---:|---:|---:|---:|---:|---:|---:|"
    if args.accuracy:
        head += " igl max error |"
        rule += "---:|"
    print(head)
    print(rule)
    for path in args.meshes:
        V, F = igl.read_triangle_mesh(path)
        V = np.ascontiguousarray(V, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.int64)
        if args.points:
            Q = np.ascontiguousarray(np.load(args.points), dtype=np.float64)
            if Q.ndim != 2 or Q.shape[1] != 3:
                sys.exit(f"{args.points}: expected N x 3 points, got shape {Q.shape}")
        else:
            Q = np.ascontiguousarray(grid_points(V, F, 32))
        name = Path(path).name
        if args.cloud:
            C = np.load(args.cloud)
            if C.ndim != 2 or C.shape[1] != 7:
                sys.exit(f"{args.cloud}: expected N x 7 (x y z nx ny nz area), got shape {C.shape}")
            P, N = np.ascontiguousarray(C[:, :3]), np.ascontiguousarray(C[:, 3:6])
            A = np.ascontiguousarray(C[:, 6])
            Q2 = np.ascontiguousarray(np.vstack([Q, Q]))

            def one_shot() -> np.ndarray:
                return igl.fast_winding_number(P, N, A, Q, args.order, args.beta)

            if args.precomputed:
                built = {}

                def build() -> None:
                    point_indices, CH, _, _ = igl.octree(P)
                    CM, R, EC = igl.fast_winding_number_precompute(P, N, A, point_indices, CH, args.order)
                    built.update(pi=point_indices, CH=CH, CM=CM, R=R, EC=EC)

                def query() -> np.ndarray:
                    b = built
                    return igl.fast_winding_number(P, N, A, b["pi"], b["CH"], b["CM"], b["R"], b["EC"], Q, args.beta)

            else:
                # The one-shot call on Q and on Q twice: the difference is the queries' time,
                # the rest the build, both inside libigl's C++ (see the module docs).
                build = query = None

            label, elements = f"{name} (cloud)", len(P)
        else:
            built = {}

            def build() -> None:
                bvh = igl.FastWindingNumberBVH()
                bvh.init(V, F, 2)
                built["bvh"] = bvh

            def query() -> np.ndarray:
                return built["bvh"].winding_number(Q, args.accuracy_scale)

            def one_shot() -> np.ndarray:
                return igl.fast_winding_number(V, F, Q)

            label, elements = name, len(F)
        once_cpu, once_wall = best_of(args.reps, args.min_cpu, one_shot)
        if build is None:
            twice_cpu, twice_wall = best_of(
                args.reps, args.min_cpu, lambda: igl.fast_winding_number(P, N, A, Q2, args.order, args.beta)
            )
            query_cpu, query_wall = twice_cpu - once_cpu, twice_wall - once_wall
            build_cpu, build_wall = once_cpu - query_cpu, once_wall - query_wall
        else:
            # A build is repeated until min_cpu / 5 CPU seconds have passed (the best of reps such runs).
            build_cpu, build_wall = best_of(args.reps, args.min_cpu / 5, build)
            query_cpu, query_wall = best_of(args.reps, args.min_cpu, query)
        row = (
            f"| {label} | {elements} | {build_cpu * 1e3:.1f} | {build_wall * 1e3:.1f} | {len(Q) / query_cpu:.4g} |"
            f" {len(Q) / query_wall:.4g} | {once_cpu * 1e3:.1f} | {once_wall * 1e3:.1f} |"
        )
        if args.accuracy:
            pick = strided(len(Q), args.accuracy)
            W = (query() if query is not None else one_shot())[pick]
            if args.cloud:
                exact = dipole_direct(P, N * A[:, None], Q[pick])
            else:
                exact = igl.winding_number(V, F, Q[pick])
            row += f" {np.abs(W - exact).max():.3e} ({len(pick)} points) |"
        print(row, flush=True)


if __name__ == "__main__":
    main()
