#!/usr/bin/env python3
"""Max error of libigl's fast winding number and of gwn's fast evaluator, side by side, on the
points of the accuracy test (`tests/fast_vs_libigl.rs`), and the Rust table of libigl's errors that
the test compares gwn against (so that the test needs no libigl).

Points: the 32^3 grid of `gwn bench` (cell centres of the bounding box of the referenced vertices,
enlarged by 10 % of its largest extent per side), every `step`-th point in grid order with
`step = ceil(N / want)`, `want = min(N, max(256, budget // F))`, without the points closer than
1e-6 * diagonal to the surface (libigl's point-mesh distance here, gwn's in the test). Reference:
`gwn eval --method direct` (compensated direct sum). libigl: `FastWindingNumberBVH` of order 2,
`winding_number(points, accuracy_scale)`.

    benches/peers/.venv/bin/python benches/peers/fast_accuracy.py [MESH_OR_DIR ...]
        [--gwn target/release/gwn] [--betas 2,2.35] [--budget 1e7] [--grid 32] [--rust]

Meshes libigl cannot read (its reader crashes on pymeshlab-face000.ply) are reported and skipped.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
sys.path.insert(0, str(HERE))
from peers import EXTS, grid_points  # noqa: E402


def subset(P: np.ndarray, faces: int, budget: float) -> np.ndarray:
    want = int(min(len(P), max(256, budget // faces)))
    step = max(1, -(-len(P) // want))
    return np.arange(0, len(P), step)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("paths", nargs="*")
    ap.add_argument("--gwn", default=str(REPO / "target" / "release" / "gwn"))
    ap.add_argument("--betas", default="2,2.35")
    ap.add_argument("--accuracy-scale", type=float, default=2.0)
    ap.add_argument("--budget", type=float, default=1e7)
    ap.add_argument("--max-faces", type=int, default=1_100_000)
    ap.add_argument("--rust", action="store_true", help="print the Rust table of libigl's errors")
    ap.add_argument("--grid", type=int, default=32,
                    help="grid points per axis (32: the test's points; another value gives a held-out set)")
    args = ap.parse_args()
    import igl

    paths = args.paths or [str(REPO.parent / "shared" / "meshes")]
    files: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            files += sorted(f for f in p.iterdir() if f.is_file() and f.suffix.lower() in EXTS)
        else:
            files.append(p)
    betas = [float(b) for b in args.betas.split(",")]
    rows = []
    print("| mesh | F | points | max err libigl | " + " | ".join(f"max err gwn β={b:g}" for b in betas) + " |")
    print("|---|---:|---:|---:|" + "---:|" * len(betas))
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for f in files:
            npz = tmp / "m.npz"
            r = subprocess.run([sys.executable, str(HERE / "peers.py"), "--_load", str(f), str(npz)],
                               capture_output=True, text=True)
            if r.returncode != 0 or not npz.exists():
                print(f"<!-- skipped {f.name}: libigl cannot read it (exit {r.returncode}) -->", flush=True)
                continue
            d = np.load(npz)
            V, F = d["V"], d["F"]
            npz.unlink()
            if len(F) == 0 or len(F) > args.max_faces:
                continue
            P = grid_points(V, F, args.grid)
            S = P[subset(P, len(F), args.budget)]
            R = V[np.unique(F.ravel())]
            diag = float(np.linalg.norm(R.max(0) - R.min(0)))
            sq, _, _ = igl.point_mesh_squared_distance(S, V, F)
            keep = np.sqrt(sq) > 1e-6 * diag
            bvh = igl.FastWindingNumberBVH()
            bvh.init(V, F, 2)
            wi = np.asarray(bvh.winding_number(S, args.accuracy_scale), dtype=np.float64)
            np.save(tmp / "S.npy", S)
            subprocess.run([args.gwn, "eval", str(f), "--points", str(tmp / "S.npy"), "--out",
                            str(tmp / "wd.npy"), "--method", "direct"], check=True, capture_output=True)
            wd = np.load(tmp / "wd.npy")
            e_igl = float(np.max(np.abs(wi - wd)[keep])) if keep.any() else 0.0
            e_gwn = []
            for b in betas:
                subprocess.run([args.gwn, "eval", str(f), "--points", str(tmp / "S.npy"), "--out",
                                str(tmp / "wf.npy"), "--method", "fast", "--beta", str(b), "--order", "2"],
                               check=True, capture_output=True)
                wf = np.load(tmp / "wf.npy")
                e_gwn.append(float(np.max(np.abs(wf - wd)[keep])) if keep.any() else 0.0)
            rows.append((f.name, len(F), e_igl, e_gwn))
            print(f"| {f.name} | {len(F)} | {int(keep.sum())} | {e_igl:.2e} | "
                  + " | ".join(f"{e:.2e}" + (" **>**" if e > e_igl else "") for e in e_gwn) + " |", flush=True)
    for i, b in enumerate(betas):
        worse = [r for r in rows if r[3][i] > r[2]]
        print(f"\nβ = {b:g}: gwn's max error ≤ libigl's on {len(rows) - len(worse)} of {len(rows)} meshes"
              + (f"; larger on {', '.join(r[0] for r in worse)}" if worse else ""))
    if args.rust:
        print("\n// (mesh, faces, libigl's max error)")
        for name, nf, e, _ in rows:
            # repr: the shortest decimal that reads back as the same f64.
            print(f'    ("{name}", {nf}, {e!r}),')


if __name__ == "__main__":
    main()
