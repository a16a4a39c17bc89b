#!/usr/bin/env python3
"""Peer benchmark: `gwn` (exact, direct, fast) against libigl and Open3D, side by side in one run.

For every mesh, on the same 32^3 grid of cell centres over the bounding box enlarged by 10 % of
its largest extent per side (the grid of `gwn bench`):

* `gwn bench MESH --grid N --threads-list 1,2 --beta B --order K --markdown`: gwn's own numbers
  (precompute, exact, direct and fast (Barnes-Hut) queries/s, fast tree build), run `--reps`
  times, best kept;
* libigl `FastWindingNumberBVH` (order K, accuracy_scale B; defaults 2 and 2, the same
  admissibility test as gwn fast's Barill beta): tree built once, only the query timed;
* libigl `winding_number` (exact, slow per query on large meshes): timed on an evenly spaced
  subset of the grid;
* Open3D `RaycastingScene.compute_occupancy` (closed meshes, B = 0): scene built and warmed up
  with one query first, only the query timed;
* accuracy on the subset (points farther than 1e-6 * diagonal from the surface):
  max |w_gwn_exact - w_direct|, max (and RMS) |w_gwn_fast - w_direct| and |w_igl_fast - w_direct|,
  with w_direct from `gwn eval --method direct` and w_gwn_fast from `gwn eval --method fast`.

Triangle soups (`--soups NAME,...`): each named mesh is also measured with every vertex
un-shared (3 vertices per face, same faces and corners): gwn reads it from a temporary OFF file,
libigl gets the un-shared arrays.

Sections written to --doc (`--sections`): "## Peers" (gwn exact against the peers) and
"## Fast (Barnes–Hut)" (gwn fast against libigl's fast winding number, with errors).

Thread counts: gwn via `--threads-list`; libigl via IGL_NUM_THREADS (and OMP_NUM_THREADS) in one
worker subprocess per thread count; Open3D via `nthreads=`.

Usage (normally through run.sh):
    python peers.py [MESH_OR_DIR ...] [--quick] [--gwn target/release/gwn] [--doc docs/benchmarks.md]
                    [--soups cgal-hand.off,...] [--sections peers,fast] [--beta 2 --order 2]
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import platform
import re
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
EXTS = {".obj", ".stl", ".off", ".ply"}

# A handful of meshes for --quick: open with B < F/20, closed, and soups.
QUICK = [
    "cgal-holes.off",
    "cgal-lion-head.off",
    "cgal-fandisk.off",
    "npm-dragon_vrip_res4.ply",
    "cura-ultimaker2_platform.obj",
    "assimp-regr01.obj",
]


# --------------------------------------------------------------------------------------------
# Hidden sub-modes (run in subprocesses so that a crashing reader or a thread setting stays
# isolated).
# --------------------------------------------------------------------------------------------


def mode_load(mesh: str, out: str) -> None:
    """Reads a mesh with libigl and stores V, F in an .npz (a libigl reader crash kills only us)."""
    import igl

    V, F = igl.read_triangle_mesh(mesh)
    np.savez(out, V=np.ascontiguousarray(V, dtype=np.float64), F=np.ascontiguousarray(F, dtype=np.int64))


def _best_time(fn, reps: int, budget_s: float = 1e9):
    """Runs fn up to `reps` times (stops early past `budget_s` total); returns (best s, result)."""
    best, res, total = math.inf, None, 0.0
    for _ in range(max(1, reps)):
        t0 = time.perf_counter()
        res = fn()
        dt = time.perf_counter() - t0
        best = min(best, dt)
        total += dt
        if total > budget_s:
            break
    return best, res


def mode_worker(job_path: str) -> None:
    """Times libigl (and Open3D) for one thread count; prints one JSON line."""
    job = json.loads(Path(job_path).read_text())
    import igl

    d = np.load(job["mesh_npz"])
    V, F = d["V"], d["F"]
    P = np.load(job["points"])
    S = np.load(job["subset"])
    reps = job["reps"]
    out: dict = {"threads": job["threads"]}
    save = job.get("save_prefix")

    # libigl fast winding number: prebuilt tree, query only.
    order, beta = int(job.get("order", 2)), float(job.get("beta", 2.0))
    init_best = math.inf
    for _ in range(max(1, reps)):
        bvh = igl.FastWindingNumberBVH()
        t0 = time.perf_counter()
        bvh.init(V, F, order)
        init_best = min(init_best, time.perf_counter() - t0)
    out["igl_fast_init_ms"] = init_best * 1e3
    dt, wf = _best_time(lambda: bvh.winding_number(P, beta), reps, budget_s=20)
    out["igl_fast_qps"] = len(P) / dt

    # libigl exact winding number on the subset.
    dt, we = _best_time(lambda: igl.winding_number(V, F, S), reps, budget_s=6)
    out["igl_exact_qps"] = len(S) / dt
    out["igl_exact_n"] = int(len(S))

    if save:
        np.save(save + "_igl_fast.npy", np.asarray(wf, dtype=np.float64))
        np.save(save + "_igl_exact.npy", np.asarray(we, dtype=np.float64))
        sq, _, _ = igl.point_mesh_squared_distance(S, V, F)
        np.save(save + "_dist.npy", np.sqrt(np.asarray(sq, dtype=np.float64)))

    if job.get("open3d"):
        try:
            import open3d as o3d

            scene = o3d.t.geometry.RaycastingScene()
            scene.add_triangles(
                o3d.core.Tensor(np.ascontiguousarray(V, dtype=np.float32)),
                o3d.core.Tensor(np.ascontiguousarray(F, dtype=np.uint32)),
            )
            Pt = o3d.core.Tensor(np.ascontiguousarray(P, dtype=np.float32))
            # The Embree scene is committed lazily on the first query: warm up outside the timing.
            scene.compute_occupancy(Pt[:1], nthreads=job["threads"])
            dt, occ = _best_time(
                lambda: scene.compute_occupancy(Pt, nthreads=job["threads"]), reps, budget_s=20
            )
            out["o3d_qps"] = len(P) / dt
            if save:
                np.save(save + "_o3d.npy", occ.numpy().astype(np.float64))
        except Exception as e:  # noqa: BLE001 - reported, not fatal
            out["o3d_error"] = f"{type(e).__name__}: {e}"
    print("RESULT " + json.dumps(out), flush=True)


# --------------------------------------------------------------------------------------------
# Driver
# --------------------------------------------------------------------------------------------


def grid_points(V: np.ndarray, F: np.ndarray, n: int) -> np.ndarray:
    """The grid of `gwn bench`, bit for bit (same operations in the same order)."""
    R = V[np.unique(F.ravel())]
    lo, hi = R.min(axis=0), R.max(axis=0)
    ext = max(float((hi - lo).max()), 1e-300)
    pad = 0.1 * ext
    lo, hi = lo - pad, hi + pad
    i = np.arange(n * n * n)
    idx = np.stack([i % n, (i // n) % n, i // (n * n)], axis=1).astype(np.float64)
    return lo + (hi - lo) * (idx + 0.5) / float(n)


def parse_gwn_bench(text: str) -> dict | None:
    rows = [ln for ln in text.splitlines() if ln.startswith("|")]
    if len(rows) < 3:
        return None
    head = [c.strip() for c in rows[0].strip("|").split("|")]
    vals = [c.strip() for c in rows[2].strip("|").split("|")]
    r = dict(zip(head, vals))
    out = {"faces": int(r["faces"]), "boundary": int(r["boundary"]), "pre_ms": float(r["precompute ms"])}
    if "fast build ms" in r:
        out["fast_build_ms"] = float(r["fast build ms"])
    for k, v in r.items():
        m = re.match(r"(exact|direct|fast) q/s \((\d+)t\)", k)
        if m:
            out[f"{m.group(1)}_{m.group(2)}"] = float(v)
    return out


def run(cmd: list[str], env=None, timeout=1800) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)


def group_of(F: int, B: int) -> str:
    if B == 0:
        return "closed"
    if B * 20 < F:
        return "open B<F/20"
    if 2 * B >= F:
        return "soup B≳F"
    return "open other"


def geomean(xs):
    xs = [x for x in xs if x and x > 0 and math.isfinite(x)]
    if not xs:
        return None
    return math.exp(sum(math.log(x) for x in xs) / len(xs))


def fmt_qps(x):
    if x is None:
        return "–"
    if x >= 1e6:
        return f"{x / 1e6:.2f} M"
    if x >= 1e3:
        return f"{x / 1e3:.1f} k"
    return f"{x:.0f}"


def fmt_ratio(x):
    return "–" if x is None else (f"{x:.2f}×" if x < 10 else f"{x:.0f}×")


def fmt_err(x):
    return "–" if x is None else f"{x:.1e}"


def write_soup_off(path: Path, V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Un-shares every vertex (3 per face) and writes the soup as OFF with round-trip precision."""
    Vs = np.ascontiguousarray(V[F].reshape(-1, 3), dtype=np.float64)
    Fs = np.arange(len(Vs), dtype=np.int64).reshape(-1, 3)
    with open(path, "w") as f:
        f.write(f"OFF\n{len(Vs)} {len(Fs)} 0\n")
        np.savetxt(f, Vs, fmt="%.17g")
        np.savetxt(f, np.hstack([np.full((len(Fs), 1), 3, dtype=np.int64), Fs]), fmt="%d")
    return Vs, Fs


def bench_mesh(path: Path, args, tmp: Path, log, soup: bool = False) -> dict:
    name = path.name + (" (soup)" if soup else "")
    res: dict = {"mesh": name, "soup": soup}
    npz = tmp / "mesh.npz"
    r = run([sys.executable, str(Path(__file__).resolve()), "--_load", str(path), str(npz)], timeout=600)
    if r.returncode != 0 or not npz.exists():
        err = (r.stderr.strip().splitlines() or ["exit code %d" % r.returncode])[-1]
        res["skip"] = f"libigl cannot read it ({err[:120]}; exit {r.returncode})"
        return res
    d = np.load(npz)
    V, F = d["V"], d["F"]
    if len(F) == 0:
        res["skip"] = "no triangles"
        return res
    if soup:
        # The same faces with every vertex un-shared: gwn reads the OFF, libigl gets the arrays.
        path = tmp / "soup.off"
        V, F = write_soup_off(path, V, F)
        np.savez(npz, V=V, F=F)
    P = grid_points(V, F, args.grid)
    N = len(P)
    # Subset for the O(F)-per-query methods: evenly spaced, about `exact_budget` triangle visits.
    want = int(min(N, max(args.min_subset, args.exact_budget // len(F))))
    step = max(1, -(-N // want))
    sub_idx = np.arange(0, N, step)
    S = P[sub_idx]
    np.save(tmp / "P.npy", P)
    np.save(tmp / "S.npy", S)
    threads = ",".join(str(t) for t in args.threads)

    # gwn bench: best of reps.
    best: dict | None = None
    for _ in range(args.reps):
        r = run(
            [args.gwn, "bench", str(path), "--grid", str(args.grid), "--threads-list", threads,
             "--beta", str(args.beta), "--order", str(args.order), "--markdown"]
        )
        if r.returncode != 0:
            res["skip"] = f"gwn bench failed: {r.stderr.strip()[:200]}"
            return res
        b = parse_gwn_bench(r.stdout)
        if b is None:
            res["skip"] = "gwn bench printed no row (empty mesh?)"
            return res
        if best is None:
            best = b
        else:
            for k, v in b.items():
                if k in ("pre_ms", "fast_build_ms"):
                    best[k] = min(best[k], v)
                elif k not in ("faces", "boundary"):
                    best[k] = max(best[k], v)
    res.update(best)
    res["igl_faces"] = int(len(F))
    res["group"] = group_of(res["faces"], res["boundary"])

    # gwn values: exact on the whole grid, direct (reference) on the subset.
    r1 = run([args.gwn, "eval", str(path), "--points", str(tmp / "P.npy"), "--out", str(tmp / "we.npy"), "--method", "exact"])
    r2 = run([args.gwn, "eval", str(path), "--points", str(tmp / "S.npy"), "--out", str(tmp / "wd.npy"), "--method", "direct"])
    r3 = run(
        [args.gwn, "eval", str(path), "--points", str(tmp / "P.npy"), "--out", str(tmp / "wf.npy"),
         "--method", "fast", "--beta", str(args.beta), "--order", str(args.order)]
    )
    if r1.returncode != 0 or r2.returncode != 0 or r3.returncode != 0:
        res["skip"] = f"gwn eval failed: {(r1.stderr + r2.stderr + r3.stderr).strip()[:200]}"
        return res
    we = np.load(tmp / "we.npy")
    wd = np.load(tmp / "wd.npy")
    wgf = np.load(tmp / "wf.npy")

    # gwn fast at a second beta (matched accuracy), fast columns only.
    if args.match_beta:
        mb: dict = {}
        for _ in range(args.reps):
            r = run(
                [args.gwn, "bench", str(path), "--grid", str(args.grid), "--threads-list", threads,
                 "--beta", str(args.match_beta), "--order", str(args.order), "--skip-exact", "--markdown"]
            )
            b = parse_gwn_bench(r.stdout) if r.returncode == 0 else None
            if b is None:
                break
            for key, v in b.items():
                if key == "fast_build_ms":
                    mb[key] = min(mb.get(key, math.inf), v)
                elif key.startswith("fast_"):
                    mb[key] = max(mb.get(key, 0.0), v)
        res.update({"m" + key: v for key, v in mb.items()})
        r4 = run(
            [args.gwn, "eval", str(path), "--points", str(tmp / "P.npy"), "--out", str(tmp / "wm.npy"),
             "--method", "fast", "--beta", str(args.match_beta), "--order", str(args.order)]
        )
        wgm = np.load(tmp / "wm.npy") if r4.returncode == 0 else None
    else:
        wgm = None

    # Peers, one worker per thread count.
    res["peers"] = {}
    for i, t in enumerate(args.threads):
        job = {
            "mesh_npz": str(npz),
            "points": str(tmp / "P.npy"),
            "subset": str(tmp / "S.npy"),
            "threads": t,
            "reps": args.reps,
            "beta": args.igl_accuracy_scale if args.igl_accuracy_scale else args.beta,
            "order": args.order,
            "open3d": bool(args.open3d and res["boundary"] == 0),
            "save_prefix": str(tmp / "v") if i == 0 else None,
        }
        (tmp / "job.json").write_text(json.dumps(job))
        env = dict(os.environ, IGL_NUM_THREADS=str(t), OMP_NUM_THREADS=str(t), TBB_NUM_THREADS=str(t))
        r = run([sys.executable, str(Path(__file__).resolve()), "--_worker", str(tmp / "job.json")], env=env)
        line = [ln for ln in r.stdout.splitlines() if ln.startswith("RESULT ")]
        if r.returncode != 0 or not line:
            res["peers"][t] = {"error": f"worker exit {r.returncode}: {r.stderr.strip()[-200:]}"}
            continue
        res["peers"][t] = json.loads(line[0][7:])

    # Accuracy on the subset, away from the surface.
    dist_p = tmp / "v_dist.npy"
    if dist_p.exists():
        R = V[np.unique(F.ravel())]
        diag = float(np.linalg.norm(R.max(0) - R.min(0)))
        dist = np.load(dist_p)
        keep = dist > 1e-6 * diag
        res["acc_n"] = int(keep.sum())
        res["acc_excluded"] = int((~keep).sum())
        if keep.any():
            res["err_gwn_exact"] = float(np.max(np.abs(we[sub_idx][keep] - wd[keep])))
            e_igl = np.abs(np.load(tmp / "v_igl_fast.npy")[sub_idx][keep] - wd[keep])
            e_gwn = np.abs(wgf[sub_idx][keep] - wd[keep])
            res["err_igl_fast"] = float(np.max(e_igl))
            res["rms_igl_fast"] = float(np.sqrt(np.mean(e_igl**2)))
            res["err_gwn_fast"] = float(np.max(e_gwn))
            res["rms_gwn_fast"] = float(np.sqrt(np.mean(e_gwn**2)))
            if wgm is not None:
                e_m = np.abs(wgm[sub_idx][keep] - wd[keep])
                res["err_gwn_mfast"] = float(np.max(e_m))
                res["rms_gwn_mfast"] = float(np.sqrt(np.mean(e_m**2)))
            res["err_igl_exact"] = float(np.max(np.abs(np.load(tmp / "v_igl_exact.npy")[keep] - wd[keep])))
        o3d_p = tmp / "v_o3d.npy"
        if o3d_p.exists():
            occ = np.load(o3d_p)
            parity = np.mod(np.rint(we), 2)
            res["o3d_mismatch"] = int(np.sum(occ != parity))
            res["o3d_n"] = int(len(occ))
    for f in tmp.iterdir():
        f.unlink()
    return res


def collect(paths: list[str], quick: bool) -> list[Path]:
    if not paths:
        paths = [str(REPO.parent / "shared" / "meshes")]
    files: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            v = sorted(f for f in p.iterdir() if f.is_file() and f.suffix.lower() in EXTS)
            if quick:
                v = [f for f in v if f.name in QUICK]
            files.extend(v)
        elif p.exists():
            files.append(p)
        else:
            print(f"warning: {p} does not exist, skipped", file=sys.stderr)
    return files


def versions(gwn: str) -> dict:
    import importlib.metadata as md

    v = {"python": platform.python_version()}
    for pkg in ("libigl", "numpy", "open3d"):
        try:
            v[pkg] = md.version(pkg)
        except md.PackageNotFoundError:
            v[pkg] = None
    v["gwn"] = run([gwn, "--version"]).stdout.strip()
    try:
        v["rustc"] = run(["rustc", "--version"]).stdout.strip() + ", " + os.environ.get("GWN_BUILD", "build flags unknown")
    except OSError:
        v["rustc"] = "?"
    try:
        v["git"] = run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"]).stdout.strip()
    except OSError:
        v["git"] = "?"
    return v


def machine() -> dict:
    model = "?"
    try:
        for ln in Path("/proc/cpuinfo").read_text().splitlines():
            if ln.startswith("model name"):
                model = ln.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"nproc": os.cpu_count(), "nproc_cmd": run(["nproc"]).stdout.strip(), "cpu": model}


def loadavg() -> str:
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "?"


def auto_notes(ok, args, meta) -> list[str]:
    """Plain statements derived from the numbers (so that a re-run keeps them true)."""
    notes = []
    try:
        load = float(meta["load_start"].split()[0])
        nproc = int(meta["machine"]["nproc_cmd"])
    except (ValueError, KeyError, IndexError):
        load, nproc = 0.0, 0
    if nproc and load > nproc:
        notes.append(
            f"- **Load.** The machine was shared with other work during this run (load average {load:.1f} on"
            f" {nproc} cores at the start): absolute throughputs are lower and noisier than on an idle"
            " machine, and 2 threads often do not beat 1. Each mesh is measured by all tools within a few"
            " seconds of each other (best of the repetitions), so the ratios are fairer than the absolute"
            " numbers, but they carry that noise too."
        )
    t = args.threads[0]
    ns = [
        (1e9 / (r[f"exact_{t}"] * r["boundary"]), r)
        for r in ok
        if r["boundary"] >= 100 and r.get(f"exact_{t}")
    ]
    if ns:
        v = sorted(x for x, _ in ns)
        med = v[len(v) // 2]
        notes.append(
            f"- **Where gwn exact loses.** Its cost per query is one ray plus O(B): on the {len(ns)} meshes"
            f" with B ≥ 100 it spends {v[0]:.0f}–{v[-1]:.0f} ns (median {med:.0f} ns) per boundary edge per"
            f" query ({t} thread, wall clock, including the ray). libigl's fast winding number costs"
            " O(log F) per query whatever B is, so meshes with hundreds of boundary edges already favour"
            " it, and soups (B ≈ 3F) favour every peer."
        )
    open_small = [r for r in ok if r["group"] == "open B<F/20"]
    lose = [
        r["mesh"]
        for r in open_small
        if r["peers"].get(t, {}).get("igl_fast_qps") and r[f"exact_{t}"] < 3 * r["peers"][t]["igl_fast_qps"]
    ]
    if open_small:
        notes.append(
            f"- Open meshes with B < F/20 below the 3× target against libigl fast ({t} thread): {len(lose)} of"
            f" {len(open_small)}" + (f" ({', '.join(lose)})." if lose else ".")
        )
    closed = [r for r in ok if r["group"] == "closed" and r["peers"].get(t, {}).get("o3d_qps")]
    if closed:
        lose = [r["mesh"] for r in closed if r[f"exact_{t}"] < r["peers"][t]["o3d_qps"]]
        notes.append(
            f"- Closed meshes slower than Open3D occupancy ({t} thread): {len(lose)} of {len(closed)}"
            + (f" ({', '.join(lose)})." if lose else ".")
        )
        mism = [(r["mesh"], r["o3d_mismatch"]) for r in closed if r.get("o3d_mismatch")]
        if mism:
            notes.append(
                "- Open3D occupancy disagrees with the parity of gwn's exact value on "
                + ", ".join(f"{m} ({k} points)" for m, k in mism)
                + " (out of the full grid each; not investigated further: Open3D rounds the points and"
                " the mesh to float32 and casts a single ray per point, nsamples=1, so points near the"
                " surface, rays through edges or vertices and duplicated or overlapping faces are the"
                " usual suspects)."
            )
    return notes


def render(results, args, meta) -> str:
    ok = [r for r in results if "skip" not in r]
    skipped = [r for r in results if "skip" in r]
    L: list[str] = []
    w = L.append
    w("## Peers")
    w("")
    w("Exact `gwn` against libigl's fast winding number (prebuilt `FastWindingNumberBVH`, order 2,")
    w("accuracy_scale 2), libigl's exact `winding_number` and, on closed meshes, Open3D's")
    w("`RaycastingScene.compute_occupancy`, measured side by side in one run of")
    w("`benches/peers/peers.py`. Generated by that script; re-run it to refresh this section.")
    w("gwn's fast (Barnes–Hut) evaluator against libigl's is in \"Fast (Barnes–Hut)\" below.")
    w("")
    w(f"- **Date:** {meta['date']}; run took {meta['elapsed_min']:.1f} min.")
    w(f"- **Machine:** {meta['machine']['cpu']}, `nproc` = {meta['machine']['nproc_cmd']}.")
    w(f"  Load average (1/5/15 min) at start {meta['load_start']}, at end {meta['load_end']}.")
    w(f"- **Command:** `{meta['command']}`")
    w(
        "- **Reproduce:** `benches/peers/run.sh [MESHES…] [--quick]` creates `benches/peers/.venv`, installs"
        " `requirements.txt` (libigl, numpy) and, when it can, `requirements-open3d.txt` (open3d; its wheel"
        " needs the system library libusb-1.0, which run.sh installs with apt-get when run as root;"
        " otherwise Open3D is skipped with a note), builds `gwn` in release and runs `peers.py`."
    )
    v = meta["versions"]
    w(
        f"- **Versions:** {v['gwn']} (git {v['git']}, {v['rustc']}), Python {v['python']}, "
        f"libigl {v['libigl']}, numpy {v['numpy']}, open3d {v['open3d'] or 'not installed'}."
    )
    if meta.get("o3d_note"):
        w(f"- **Open3D:** {meta['o3d_note']}")
    w(
        f"- **Points:** the {args.grid}³ grid of `gwn bench` (cell centres of the bounding box enlarged by"
        f" 10 % of its largest extent per side) for gwn exact, libigl fast and Open3D; an evenly spaced"
        f" subset of it (about {args.exact_budget:.0e} triangle visits, at least {args.min_subset} points)"
        f" for libigl's exact `winding_number`, whose cost per query grows with the mesh (`gwn bench`"
        f" times gwn direct on 256 grid points of its own). Meshes are read from the top level of the"
        f" folder only (`fossil/` is not included)."
    )
    w(
        f"- **Timing:** queries only (trees, Embree scenes and gwn's precomputation are built before the"
        f" clock starts; gwn's precompute and libigl's tree build are listed separately). Every number is"
        f" the best of {args.reps} repetitions. gwn threads: `--threads-list`; libigl: `IGL_NUM_THREADS`"
        f" in a worker process per thread count; Open3D: `nthreads=`."
    )
    w(
        "- **Accuracy:** on the subset, excluding points closer than 1e-6·diagonal to the surface, against"
        " `gwn eval --method direct` (compensated direct sum). `igl exact` is listed as a check that both"
        " sides read the same mesh. Open3D: points whose occupancy differs from the parity of gwn's exact"
        " (integer) value."
    )
    w(
        "- **Groups:** closed: B = 0; open B<F/20: 0 < B < F/20; soup B≳F: B ≥ F/2; open other: the rest"
        " (B = boundary edges as counted by gwn, F = faces)."
    )
    w("")

    # Geometric means.
    groups = ["open B<F/20", "closed", "soup B≳F", "open other"]
    w("### Geometric means per group")
    w("")
    w("Ratios are gwn exact queries/s divided by the peer's, same thread count, same run.")
    w("")
    w("| group | meshes | threads | gwn exact q/s | ÷ igl fast | ÷ igl exact | ÷ Open3D occupancy | max err gwn exact | max err igl fast |")
    w("|---|---|---|---|---|---|---|---|---|")
    summary = {}
    for g in groups:
        rs = [r for r in ok if r["group"] == g]
        if not rs:
            continue
        for t in args.threads:
            def ratio(r, key):
                p = r["peers"].get(t, {})
                return r[f"exact_{t}"] / p[key] if p.get(key) else None

            gq = geomean([r.get(f"exact_{t}") for r in rs])
            rf = geomean([ratio(r, "igl_fast_qps") for r in rs])
            rx = geomean([ratio(r, "igl_exact_qps") for r in rs])
            ro = geomean([ratio(r, "o3d_qps") for r in rs])
            errs_g = [r["err_gwn_exact"] for r in rs if "err_gwn_exact" in r]
            errs_f = [r["err_igl_fast"] for r in rs if "err_igl_fast" in r]
            summary[(g, t)] = (rf, rx, ro, max(errs_g) if errs_g else None, max(errs_f) if errs_f else None)
            w(
                f"| {g} | {len(rs)} | {t} | {fmt_qps(gq)} | {fmt_ratio(rf)} | {fmt_ratio(rx)} | {fmt_ratio(ro)} |"
                f" {fmt_err(summary[(g, t)][3])} | {fmt_err(summary[(g, t)][4])} |"
            )
    w("")

    # Targets.
    w("### Targets of the kernel issue")
    w("")

    def verdict(x, target):
        if x is None:
            return "not measured"
        return f"**{'met' if x >= target else 'missed'}** ({x:.3g}× vs ≥ {target}×)"

    for t in args.threads:
        s = summary.get(("open B<F/20", t))
        if s:
            w(f"- {t} thread(s), open meshes with B < F/20: exact gwn ≥ 3× igl fast winding number: {verdict(s[0], 3)};"
              f" ≥ 20× igl exact: {verdict(s[1], 20)}; max error {fmt_err(s[3])} (target ≤ 1e-10) vs igl fast {fmt_err(s[4])}.")
        s = summary.get(("closed", t))
        if s:
            w(f"- {t} thread(s), closed meshes: exact gwn ≥ Open3D occupancy throughput: {verdict(s[2], 1)};"
              f" max error {fmt_err(s[3])}.")
        s = summary.get(("soup B≳F", t))
        if s:
            w(f"- {t} thread(s), soups (B ≳ F), no target (the fast issue's job): exact gwn is {fmt_ratio(s[0])} igl fast"
              f" and {fmt_ratio(s[1])} igl exact.")
    w("")
    for n in auto_notes(ok, args, meta):
        w(n)
    w("")

    # Per-mesh tables.
    for t in args.threads:
        w(f"### Throughput per mesh, {t} thread(s)")
        w("")
        w("| mesh | group | F | B | gwn pre ms | igl tree ms | gwn exact q/s | gwn direct q/s | igl fast q/s | igl exact q/s | Open3D q/s | ÷ igl fast | ÷ igl exact | ÷ Open3D |")
        w("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for r in ok:
            p = r["peers"].get(t, {})
            ex = r.get(f"exact_{t}")
            cell = lambda k: p.get(k)  # noqa: E731
            rr = lambda k: (ex / p[k]) if p.get(k) else None  # noqa: E731
            note = f" ({p['error'][:60]})" if "error" in p else ""
            w(
                f"| {r['mesh']}{note} | {r['group']} | {r['faces']} | {r['boundary']} | {r['pre_ms']:.1f} |"
                f" {('%.1f' % p['igl_fast_init_ms']) if 'igl_fast_init_ms' in p else '–'} |"
                f" {fmt_qps(ex)} | {fmt_qps(r.get(f'direct_{t}'))} | {fmt_qps(cell('igl_fast_qps'))} |"
                f" {fmt_qps(cell('igl_exact_qps'))} | {fmt_qps(cell('o3d_qps'))} |"
                f" {fmt_ratio(rr('igl_fast_qps'))} | {fmt_ratio(rr('igl_exact_qps'))} | {fmt_ratio(rr('o3d_qps'))} |"
            )
        w("")
    w("### Accuracy per mesh")
    w("")
    w("| mesh | subset points | near surface, excluded | max err gwn exact | max err igl fast | max err igl exact | Open3D mismatches |")
    w("|---|---|---|---|---|---|---|")
    for r in ok:
        o3 = f"{r['o3d_mismatch']} / {r['o3d_n']}" if "o3d_mismatch" in r else "–"
        w(
            f"| {r['mesh']} | {r.get('acc_n', '–')} | {r.get('acc_excluded', '–')} | {fmt_err(r.get('err_gwn_exact'))} |"
            f" {fmt_err(r.get('err_igl_fast'))} | {fmt_err(r.get('err_igl_exact'))} | {o3} |"
        )
    w("")
    if skipped:
        w("### Skipped")
        w("")
        for r in skipped:
            w(f"- `{r['mesh']}`: {r['skip']}")
        w("")
    return "\n".join(L) + "\n"


def render_fast(results, args, meta) -> str:
    """The "## Fast (Barnes–Hut)" section: gwn fast against libigl's fast winding number."""
    ok = [r for r in results if "skip" not in r and any(r.get(f"fast_{t}") for t in args.threads)]
    L: list[str] = []
    w = L.append
    b, k = args.beta, args.order
    a = getattr(args, "igl_accuracy_scale", 0) or b
    mb = getattr(args, "match_beta", 0) or 0
    w("## Fast (Barnes–Hut)")
    w("")
    w(f"`gwn`'s fast evaluator (`FastWindingNumber`, Barill β = {b:g}, order {k}) against libigl's")
    w(f"`FastWindingNumberBVH` (order {k}, accuracy_scale {a:g}), same points, same thread count, same run.")
    w("Generated by `benches/peers/peers.py` (its `fast` section); re-run it to refresh this section.")
    w("")
    w(
        "**Same β is not the same accuracy.** Both open a node unless ‖q − p̃‖ > β·ρ, but gwn's ρ is r, the"
        " exact largest distance from the area-weighted centre p̃ to the node's triangle corners, while"
        " libigl (Houdini's `UT_SolidAngle`) uses the distance from p̃ to the farthest corner of the node's"
        " bounding box, an upper bound on r. At the same nominal β libigl therefore opens more nodes and is"
        " more accurate. Both query trees are 4-wide with a float32 far field (gwn's near field is float64;"
        " gwn visits two of its 4-wide nodes at a time, eight float32 lanes);"
        " gwn's `Admissibility::BoxCorner` reproduces libigl's rule, but on gwn's tree it still does not match"
        " libigl's error at the same β on every mesh, so the comparison uses the radius rule."
        + (
            f" The second table compares at matched accuracy: gwn at β = {mb:g} (`--match-beta`), the"
            f" smallest β of a scan (2, 2.35, 2.5, …, 2.8) at which gwn's max error was at most libigl's"
            f" (accuracy_scale {a:g}) on every mesh of the shared corpus that libigl reads (98 meshes;"
            f" `benches/peers/fast_accuracy.py`, checked by `tests/fast_vs_libigl.rs`); at β = 2.35, 10 of"
            f" the 98 were above libigl's, at 2.5 two (prusa-aqp_bed.stl, pymeshlab-bunny.obj)."
            if mb
            else ""
        )
    )
    w("")
    w(f"- **Date:** {meta['date']}; run took {meta['elapsed_min']:.1f} min.")
    w(f"- **Machine:** {meta['machine']['cpu']}, `nproc` = {meta['machine']['nproc_cmd']}.")
    w(f"  Load average (1/5/15 min) at start {meta['load_start']}, at end {meta['load_end']}.")
    w("  The machine was shared with other work: absolute throughputs are noisy; compare the ratios,"
      " which come from measurements a few seconds apart.")
    w(f"- **Command:** `{meta['command']}`")
    v = meta["versions"]
    w(f"- **Versions:** {v['gwn']} (git {v['git']}, {v['rustc']}), Python {v['python']}, libigl {v['libigl']}.")
    w(
        f"- **Points:** the {args.grid}³ grid of `gwn bench` (cell centres of the bounding box enlarged by 10 %"
        " of its largest extent per side). Throughput: queries only, best of"
        f" {args.reps} repetitions, with the tree built beforehand (build times listed; gwn's build is"
        " single-threaded). `end-to-end` divides libigl's build + all grid queries by gwn's."
    )
    w(
        "- **Error:** max and RMS of |w − w_direct| on an evenly spaced subset of the grid (points closer than"
        " 1e-6·diagonal to the surface excluded), w_direct from `gwn eval --method direct` (compensated"
        " direct sum); gwn's values from `gwn eval --method fast`."
    )
    w(
        "- **Soups:** `(soup)` rows are the same faces with every vertex un-shared (3 per face): gwn reads"
        " them from a temporary OFF file, libigl gets the un-shared arrays. B = boundary edges (gwn)."
    )
    w("")

    def ratio(r, t, pre=""):
        p = r["peers"].get(t, {})
        q = r.get(f"{pre}fast_{t}")
        return q / p["igl_fast_qps"] if p.get("igl_fast_qps") and q else None

    def e2e(r, t, pre=""):
        p = r["peers"].get(t, {})
        q = r.get(f"{pre}fast_{t}")
        if not (p.get("igl_fast_qps") and q and f"{pre}fast_build_ms" in r):
            return None
        n = args.grid**3
        tg = r[f"{pre}fast_build_ms"] / 1e3 + n / q
        ti = p["igl_fast_init_ms"] / 1e3 + n / p["igl_fast_qps"]
        return ti / tg

    variants = [("", b)] + ([("m", mb)] if mb and any("mfast_build_ms" in r for r in ok) else [])
    w("### Summary")
    w("")
    w(
        "| gwn β | inputs | threads | rows | geomean gwn ÷ igl q/s | min – max | rows gwn ≥ igl |"
        " geomean end-to-end | worst max err gwn / igl | rows with gwn max err ≤ igl's |"
    )
    w("|---|---|---|---|---|---|---|---|---|---|")
    for pre, beta in variants:
        for label, sel in (("meshes", lambda r: not r.get("soup")), ("soups", lambda r: r.get("soup"))):
            rs = [r for r in ok if sel(r)]
            if not rs:
                continue
            for t in args.threads:
                rr = [x for x in (ratio(r, t, pre) for r in rs) if x]
                ee = [x for x in (e2e(r, t, pre) for r in rs) if x]
                eg = [r[f"err_gwn_{pre}fast"] for r in rs if f"err_gwn_{pre}fast" in r]
                ei = [r["err_igl_fast"] for r in rs if "err_igl_fast" in r]
                better = sum(
                    1 for r in rs if f"err_gwn_{pre}fast" in r and r[f"err_gwn_{pre}fast"] <= r["err_igl_fast"]
                )
                w(
                    f"| {beta:g} | {label} | {t} | {len(rs)} | {fmt_ratio(geomean(rr))} |"
                    f" {fmt_ratio(min(rr) if rr else None)} – {fmt_ratio(max(rr) if rr else None)} |"
                    f" {sum(1 for x in rr if x >= 1)} of {len(rr)} | {fmt_ratio(geomean(ee))} |"
                    f" {fmt_err(max(eg) if eg else None)} / {fmt_err(max(ei) if ei else None)} |"
                    f" {better} of {len(rs)} |"
                )
    w("")
    for pre, beta in variants:
        for t in args.threads:
            slow = [
                f"{r['mesh']} ({fmt_ratio(ratio(r, t, pre))})"
                for r in ok
                if ratio(r, t, pre) is not None and ratio(r, t, pre) < 1
            ]
            w(
                f"- gwn β = {beta:g}, {t} thread(s): gwn fast is at least as fast as libigl's on"
                f" {sum(1 for r in ok if (ratio(r, t, pre) or 0) >= 1)} of {len(ok)} rows"
                + (f"; slower on {', '.join(slow)}." if slow else ".")
            )
        worse = [
            f"{r['mesh']} ({fmt_err(r[f'err_gwn_{pre}fast'])} vs {fmt_err(r['err_igl_fast'])})"
            for r in ok
            if f"err_gwn_{pre}fast" in r and r[f"err_gwn_{pre}fast"] > r["err_igl_fast"]
        ]
        w(
            f"- gwn β = {beta:g}: gwn's max error is ≤ libigl's on"
            f" {sum(1 for r in ok if f'err_gwn_{pre}fast' in r and r[f'err_gwn_{pre}fast'] <= r['err_igl_fast'])}"
            f" of {len(ok)} rows" + (f"; larger on {', '.join(worse)}." if worse else ".")
        )
    w("")
    pre, beta = variants[-1]
    for t in args.threads:
        met = [r["mesh"] for r in ok if (ratio(r, t, pre) or 0) >= 1]
        w(
            f"- **Target of the fast issue** (gwn fast at least as fast as libigl's at the same accuracy,"
            f" equal threads), gwn β = {beta:g}, {t} thread(s): **met on {len(met)} of {len(ok)} rows**"
            + (f" ({', '.join(met)})" if met else "")
            + f"; geomean {fmt_ratio(geomean([ratio(r, t, pre) for r in ok]))}."
        )
    w("")
    for pre, beta in variants:
        w(f"### Per mesh, gwn β = {beta:g} vs libigl accuracy_scale {a:g}")
        w("")
        w(
            "| mesh | F | B | threads | gwn build ms | igl build ms | gwn fast q/s | igl fast q/s | gwn ÷ igl |"
            " end-to-end | gwn exact q/s | max err gwn fast | max err igl fast | RMS gwn fast | RMS igl fast |"
        )
        w("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for r in ok:
            for t in args.threads:
                p = r["peers"].get(t, {})
                bm = r.get(f"{pre}fast_build_ms")
                w(
                    f"| {r['mesh']} | {r['faces']} | {r['boundary']} | {t} | {'–' if bm is None else f'{bm:.1f}'} |"
                    f" {('%.1f' % p['igl_fast_init_ms']) if 'igl_fast_init_ms' in p else '–'} |"
                    f" {fmt_qps(r.get(f'{pre}fast_{t}'))} | {fmt_qps(p.get('igl_fast_qps'))} |"
                    f" {fmt_ratio(ratio(r, t, pre))} | {fmt_ratio(e2e(r, t, pre))} | {fmt_qps(r.get(f'exact_{t}'))} |"
                    f" {fmt_err(r.get(f'err_gwn_{pre}fast'))} | {fmt_err(r.get('err_igl_fast'))} |"
                    f" {fmt_err(r.get(f'rms_gwn_{pre}fast'))} | {fmt_err(r.get('rms_igl_fast'))} |"
                )
        w("")
    skipped = [r for r in results if "skip" in r]
    if skipped:
        w("Skipped: " + "; ".join(f"`{r['mesh']}` ({r['skip']})" for r in skipped) + ".")
        w("")
    return "\n".join(L) + "\n"


def write_doc(doc: Path, section: str, title: str = "Peers") -> None:
    if doc.exists():
        text = doc.read_text()
    else:
        text = "# Benchmarks\n\n"
    m = re.search(r"^## " + re.escape(title) + r"[ \t]*\n", text, flags=re.M)
    if m:
        nxt = re.search(r"^## ", text[m.end():], flags=re.M)
        end = m.end() + nxt.start() if nxt else len(text)
        text = text[: m.start()] + section + ("\n" if nxt else "") + text[end:]
    else:
        if not text.endswith("\n"):
            text += "\n"
        if not text.endswith("\n\n"):
            text += "\n"
        text += section
    doc.parent.mkdir(parents=True, exist_ok=True)
    doc.write_text(text)


def main() -> None:
    if len(sys.argv) >= 2 and sys.argv[1] == "--_load":
        mode_load(sys.argv[2], sys.argv[3])
        return
    if len(sys.argv) >= 2 and sys.argv[1] == "--_worker":
        mode_worker(sys.argv[2])
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("paths", nargs="*", help="mesh files or folders (default: ../shared/meshes from the repo root)")
    ap.add_argument("--quick", action="store_true", help=f"only {', '.join(QUICK)} from the folders")
    ap.add_argument("--gwn", default=str(REPO / "target" / "release" / "gwn"), help="gwn binary")
    ap.add_argument("--grid", type=int, default=32)
    ap.add_argument("--threads", type=lambda s: [int(x) for x in s.split(",")], default=[1, 2])
    ap.add_argument("--reps", type=int, default=3, help="repetitions per timing, best kept")
    ap.add_argument("--exact-budget", type=float, default=5e7, help="triangle visits for libigl exact's subset")
    ap.add_argument("--min-subset", type=int, default=256)
    ap.add_argument("--no-open3d", dest="open3d", action="store_false")
    ap.add_argument("--beta", type=float, default=2.0, help="gwn fast beta = libigl accuracy_scale")
    ap.add_argument("--order", type=int, default=2, help="expansion order of both fast methods")
    ap.add_argument(
        "--igl-accuracy-scale", type=float, default=0.0,
        help="libigl's accuracy_scale (default: --beta)",
    )
    ap.add_argument(
        "--match-beta", type=float, default=0.0,
        help="also time gwn fast at this beta (e.g. the one matching libigl's error); 0 = off",
    )
    ap.add_argument(
        "--soups", type=lambda s: [x for x in s.split(",") if x], default=[],
        help="comma-separated mesh file names also measured as soups (every vertex un-shared)",
    )
    ap.add_argument(
        "--sections", type=lambda s: [x for x in s.split(",") if x], default=["peers", "fast"],
        help="sections of --doc to rewrite: peers, fast (default both)",
    )
    ap.add_argument("--doc", default=str(REPO / "docs" / "benchmarks.md"), help="Markdown file to update ('' = none)")
    ap.add_argument("--json", default="", help="also write raw results here")
    ap.add_argument("--render-json", default="", help="only re-render the doc from a --json file")
    args = ap.parse_args()
    args.exact_budget = int(args.exact_budget)
    if args.render_json:
        data = json.loads(Path(args.render_json).read_text())
        for r in data["results"]:
            if "peers" in r:
                r["peers"] = {int(k): v for k, v in r["peers"].items()}
        for k, v in data["meta"].get("args", {}).items():
            setattr(args, k, v)
        emit(data["results"], args, data["meta"])
        return

    meta = {
        "date": _dt.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z"),
        "machine": machine(),
        "versions": versions(args.gwn),
        "command": os.environ.get("PEERS_COMMAND")
        or "python benches/peers/peers.py " + " ".join(shlex.quote(a) for a in sys.argv[1:]),
        "load_start": loadavg(),
        "args": {
            k: getattr(args, k)
            for k in (
                "grid", "threads", "reps", "exact_budget", "min_subset", "beta", "order", "soups",
                "igl_accuracy_scale", "match_beta",
            )
        },
        "notes": [],
    }
    if args.open3d:
        r = run([sys.executable, "-c", "import open3d"])
        if r.returncode != 0:
            args.open3d = False
            msg = (r.stderr.strip().splitlines() or ["?"])[-1]
            meta["o3d_note"] = f"not measured: `import open3d` failed here ({msg})."
            print(f"note: Open3D unavailable: {msg}", file=sys.stderr)
    else:
        meta["o3d_note"] = "not measured (--no-open3d)."

    files = [(f, False) for f in collect(args.paths, args.quick)]
    by_name = {f.name: f for f, _ in files}
    for name in args.soups:
        f = by_name.get(name) or next(iter(collect([name], False)), None)
        if f is None:
            print(f"warning: soup {name} not found, skipped", file=sys.stderr)
        else:
            files.append((f, True))
    t_start = time.time()
    results = []
    with tempfile.TemporaryDirectory(prefix="gwn-peers-") as td:
        tmp = Path(td)
        for k, (f, soup) in enumerate(files):
            t0 = time.time()
            try:
                r = bench_mesh(f, args, tmp, None, soup=soup)
            except subprocess.TimeoutExpired as e:
                r = {"mesh": f.name + (" (soup)" if soup else ""), "skip": f"timed out: {e}"}
            except Exception as e:  # noqa: BLE001 - one bad mesh must not stop the run
                r = {"mesh": f.name + (" (soup)" if soup else ""), "skip": f"{type(e).__name__}: {e}"}
            for x in tmp.iterdir():
                x.unlink()
            results.append(r)
            if "skip" in r:
                print(f"[{k + 1}/{len(files)}] {r['mesh']}: skipped: {r['skip']}", file=sys.stderr, flush=True)
            else:
                p1 = r["peers"].get(args.threads[0], {})
                ex = r.get(f"exact_{args.threads[0]}")
                print(
                    f"[{k + 1}/{len(files)}] {r['mesh']} ({time.time() - t0:.1f}s): F={r['faces']} B={r['boundary']}"
                    f" {r['group']}; {args.threads[0]}t exact {fmt_qps(ex)}"
                    f" igl fast {fmt_qps(p1.get('igl_fast_qps'))} igl exact {fmt_qps(p1.get('igl_exact_qps'))}"
                    f" o3d {fmt_qps(p1.get('o3d_qps'))}; err {fmt_err(r.get('err_gwn_exact'))}"
                    f" / igl fast {fmt_err(r.get('err_igl_fast'))}; gwn fast"
                    f" {fmt_qps(r.get(f'fast_{args.threads[0]}'))} err {fmt_err(r.get('err_gwn_fast'))}",
                    file=sys.stderr,
                    flush=True,
                )
    meta["elapsed_min"] = (time.time() - t_start) / 60
    meta["load_end"] = loadavg()
    if args.json:
        Path(args.json).write_text(json.dumps({"meta": meta, "results": results}, indent=1, default=str))
    emit(results, args, meta)


def emit(results, args, meta) -> None:
    """Renders the requested sections and writes them into --doc (or prints them)."""
    for key, title, fn in (("peers", "Peers", render), ("fast", "Fast (Barnes–Hut)", render_fast)):
        if key not in args.sections:
            continue
        section = fn(results, args, meta)
        if args.doc:
            write_doc(Path(args.doc), section, title)
            print(f"wrote the {title} section of {args.doc}", file=sys.stderr)
        else:
            sys.stdout.write(section)


if __name__ == "__main__":
    main()
