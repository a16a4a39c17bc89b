"""Benchmarks of the Python package (results recorded in docs/benchmarks.md, "Python").

1. Overhead: `gwn.winding_number(V, F, Q)` (and a prebuilt `WindingNumber`) on the 32³ grid of
   `gwn bench` against the Rust `WindingNumber::new` + `eval_batch` for the same mesh and points
   (the example `rust_eval_batch` of the python crate), all cores.
2. Peers, 1 thread, in one run: exact `gwn` against `igl.fast_winding_number` (prebuilt
   `FastWindingNumberBVH`, the peers benchmark's setting, and the one-shot call) and
   `igl.winding_number` on the shared open meshes with 0 < B < F/20.
3. Two Python threads querying one `WindingNumber` (threads=1 each) against one thread.
4. Pickling: build time, `pickle.dumps` size and time, `pickle.loads` (the rebuild) time.

Run from the repository root after `scripts/test` (which builds the package into .venv-test)
and `pip install libigl==2.6.3` into that environment:

    cargo build --release --manifest-path python/Cargo.toml --example rust_eval_batch
    .venv-test/bin/python python/bench/bench.py [--reps 7] [--section overhead,overhead1,peers,threads,pickling]
"""

import argparse
import json
import os
import pathlib
import subprocess
import threading
import time

# libigl reads its thread count when first used; the peers section is single-threaded.
os.environ.setdefault("IGL_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import gwn  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[2]
MESHES = REPO.parent / "shared" / "meshes"
RUST_EXAMPLE = REPO / "python" / "target" / "release" / "examples" / "rust_eval_batch"
# docs/benchmarks.md, "Peers": the 13 shared open meshes with 0 < B < F/20.
OPEN_FEW_BOUNDARY = [
    "assimp-3DSMaxExport.STL", "assimp-box_longline.obj", "assimp-sphereWithHole.stl",
    "cgal-ChineseDragon-10kv.off", "cgal-blade.off", "cgal-holes.off", "cgal-lion-head.off",
    "cgal-mannequin-devil.off", "cgal-mech-holes-shark.off", "cgal-three_peaks.off",
    "cura-UltimakerRobot_support.stl", "cura-deltacomb_dc30.stl",
    "pymeshlab-bunny10k_textured.obj",
]
OVERHEAD_MESHES = ["cgal-lion-head.off", "cgal-mannequin-devil.off", "cgal-holes.off",
                   "cura-UltimakerRobot_support.stl"]


def grid32(v):
    """The cell centres of `gwn bench`'s 32³ grid, x fastest, with GridSpec's arithmetic."""
    lo, hi = v.min(axis=0), v.max(axis=0)
    pad = 0.1 * max(float((hi - lo).max()), 1e-300)
    lo, hi = lo - pad, hi + pad
    h = (hi - lo) / 32
    c = [lo[k] + (np.arange(32) + 0.5) * h[k] for k in range(3)]
    z, y, x = np.meshgrid(c[2], c[1], c[0], indexing="ij")
    return np.ascontiguousarray(np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1))


def best_of(reps, f):
    best = float("inf")
    for _ in range(reps):
        t = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t)
    return best


def best_cpu_of(reps, f):
    """The smallest process CPU time (all threads) of `reps` runs."""
    best = float("inf")
    for _ in range(reps):
        t = time.process_time()
        f()
        best = min(best, time.process_time() - t)
    return best


def overhead(reps, threads=None, rounds=3):
    """Rust and Python alternate for `rounds` rounds of best-of-`reps`; the minimum of each is
    kept, so that a burst of load from other processes hits both sides alike."""
    label = "all cores" if threads is None else f"{threads} thread"
    print(f"## Overhead: gwn.winding_number vs Rust eval_batch ({label}, 32³ grid)\n")
    paths = [MESHES / m for m in OVERHEAD_MESHES if (MESHES / m).is_file()]
    env = {**os.environ, "REPS": str(reps)}
    if threads is not None:
        env["THREADS"] = str(threads)
    meshes = {p.name: gwn.load(p) for p in paths}
    grids = {name: grid32(v) for name, (v, _) in meshes.items()}
    keys = ["build_and_eval_s", "eval_batch_s", "build_and_eval_cpu_s", "eval_batch_cpu_s"]
    rust = {name: dict.fromkeys(keys, float("inf")) for name in meshes}
    py = {name: dict.fromkeys(keys, float("inf")) for name in meshes}
    for _ in range(rounds):
        out = subprocess.run([str(RUST_EXAMPLE), *map(str, paths)], check=True,
                             capture_output=True, text=True, env=env).stdout
        for r in map(json.loads, out.splitlines()):
            b = rust[pathlib.Path(r["mesh"]).name]
            for k in keys:
                b[k] = min(b[k], r[k])
        for name, (v, f) in meshes.items():
            q = grids[name]
            wn = gwn.WindingNumber(v, f)
            b = py[name]
            one_shot = lambda: gwn.winding_number(v, f, q, threads=threads)  # noqa: E731
            prebuilt = lambda: wn(q, threads=threads)  # noqa: E731
            for k, fn, timer in [("build_and_eval_s", one_shot, best_of),
                                 ("eval_batch_s", prebuilt, best_of),
                                 ("build_and_eval_cpu_s", one_shot, best_cpu_of),
                                 ("eval_batch_cpu_s", prebuilt, best_cpu_of)]:
                b[k] = min(b[k], timer(reps, fn))
    for clock, suffix in [("wall clock", "_s"), ("process CPU time", "_cpu_s")]:
        print(f"{clock}, best of {rounds} × {reps}:\n")
        print("| mesh | F | Rust new+eval_batch ms | gwn.winding_number ms | ratio |"
              " Rust eval_batch ms | WindingNumber(Q) ms | ratio |")
        print("|---|---|---|---|---|---|---|---|")
        for name, (v, f) in meshes.items():
            r1, p1 = rust[name]["build_and_eval" + suffix], py[name]["build_and_eval" + suffix]
            r2, p2 = rust[name]["eval_batch" + suffix], py[name]["eval_batch" + suffix]
            print(f"| {name} | {len(f)} | {r1 * 1e3:.2f} | {p1 * 1e3:.2f} | {p1 / r1:.3f} |"
                  f" {r2 * 1e3:.2f} | {p2 * 1e3:.2f} | {p2 / r2:.3f} |")
        print()


def peers(reps):
    import igl

    print("## Peers from Python, 1 thread (32³ grid; igl exact on a subset)\n")
    print("| mesh | F | B | gwn WindingNumber(Q) q/s | igl FastWindingNumberBVH q/s | ÷ |"
          " gwn.winding_number q/s | igl.fast_winding_number q/s | ÷ | igl.winding_number q/s | ÷ |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    ratios = {"bvh": [], "oneshot_fast": [], "exact": []}
    for name in OPEN_FEW_BOUNDARY:
        p = MESHES / name
        if not p.is_file():
            print(f"| {name} | skipped: absent |")
            continue
        v, f = gwn.load(p)
        q = grid32(v)
        wn = gwn.WindingNumber(v, f)
        t_gwn = best_of(reps, lambda: wn(q, threads=1))
        t_gwn_one = best_of(reps, lambda: gwn.winding_number(v, f, q, threads=1))
        bvh = igl.FastWindingNumberBVH()
        bvh.init(v, f, 2)
        t_bvh = best_of(reps, lambda: bvh.winding_number(q, 2.0))
        t_igl_one = best_of(reps, lambda: igl.fast_winding_number(v, f, q))
        # libigl's exact call is O(F) per query: time an evenly spaced subset of ~2 s of work.
        step = max(1, int(len(q) * len(f) / 2e8))
        s = np.ascontiguousarray(q[::step])
        t_exact = best_of(max(1, reps // 3), lambda: igl.winding_number(v, f, s))
        n = len(q)
        r_bvh = t_bvh / t_gwn
        r_one = t_igl_one / t_gwn_one
        r_ex = (t_exact / len(s)) / (t_gwn / n)
        ratios["bvh"].append(r_bvh)
        ratios["oneshot_fast"].append(r_one)
        ratios["exact"].append(r_ex)
        print(f"| {name} | {len(f)} | {wn.boundary_edge_count} | {n / t_gwn / 1e6:.2f} M |"
              f" {n / t_bvh / 1e6:.2f} M | {r_bvh:.2f}× | {n / t_gwn_one / 1e6:.2f} M |"
              f" {n / t_igl_one / 1e6:.2f} M | {r_one:.2f}× | {len(s) / t_exact / 1e3:.1f} k |"
              f" {r_ex:.0f}× |")
    gm = {k: float(np.exp(np.mean(np.log(r)))) for k, r in ratios.items() if r}
    print(f"\nGeometric means over {len(ratios['bvh'])} meshes: ÷ igl fast (prebuilt BVH) "
          f"{gm.get('bvh', float('nan')):.2f}×, one-shot ÷ one-shot igl.fast_winding_number "
          f"{gm.get('oneshot_fast', float('nan')):.2f}×, ÷ igl.winding_number "
          f"{gm.get('exact', float('nan')):.0f}×.\n")


def threads(reps):
    print("## Two Python threads on one WindingNumber (threads=1 each)\n")
    print("| mesh | 1 Python thread q/s | 2 Python threads q/s | speed-up |")
    print("|---|---|---|---|")
    for name in ["cgal-lion-head.off", "cgal-mannequin-devil.off"]:
        p = MESHES / name
        if not p.is_file():
            continue
        v, f = gwn.load(p)
        q = grid32(v)
        wn = gwn.WindingNumber(v, f)

        def one():
            wn(q, threads=1)

        def two():
            ts = [threading.Thread(target=one) for _ in range(2)]
            for t in ts:
                t.start()
            for t in ts:
                t.join()

        t1 = best_of(reps, one)
        t2 = best_of(reps, two)
        print(f"| {name} | {len(q) / t1 / 1e6:.2f} M | {2 * len(q) / t2 / 1e6:.2f} M |"
              f" {2 * t1 / t2:.2f}× |")
    print()


def pickling(reps):
    import pickle

    print("## Pickling a WindingNumber (rebuilt from its arrays on unpickling)\n")
    print("| mesh | F | build ms | pickle.dumps ms | bytes | pickle.loads ms (= rebuild) |")
    print("|---|---|---|---|---|---|")
    for name in ["cgal-lion-head.off", "cgal-mannequin-devil.off", "cura-UltimakerRobot_support.stl"]:
        p = MESHES / name
        if not p.is_file():
            continue
        v, f = gwn.load(p)
        t_build = best_of(reps, lambda: gwn.WindingNumber(v, f))
        wn = gwn.WindingNumber(v, f)
        blob = pickle.dumps(wn)
        t_dumps = best_of(reps, lambda: pickle.dumps(wn))
        t_loads = best_of(reps, lambda: pickle.loads(blob))
        print(f"| {name} | {len(f)} | {t_build * 1e3:.2f} | {t_dumps * 1e3:.2f} | {len(blob)} |"
              f" {t_loads * 1e3:.2f} |")
    print()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=7)
    ap.add_argument("--section", default="overhead,overhead1,peers,threads,pickling")
    args = ap.parse_args()
    print(f"gwn {gwn.__version__}, numpy {np.__version__}, {os.cpu_count()} CPUs, "
          f"load average {os.getloadavg()[0]:.1f} at start\n")
    for s in args.section.split(","):
        sections = {"overhead": overhead, "overhead1": lambda r: overhead(r, threads=1),
                    "peers": peers, "threads": threads, "pickling": pickling}
        sections[s](args.reps)


if __name__ == "__main__":
    main()
