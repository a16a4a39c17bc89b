"""Labelling benchmark: `gwn label` vs trimesh (`contains` + `proximity.signed_distance`) vs libigl
(`fast_winding_number` + `signed_distance` with the fast-winding-number sign), in one run.

Run through benches/label/run.sh (creates the venv, builds gwn). Steps:

1. `gwn label` on every mesh of the corpus, once pinned to one core (`taskset -c 0`,
   `--threads 1`) and once with `--threads 2`: wall time, meshes/s, points/s.
2. Every mesh as gwn loaded it (V, F from `examples/mesh_arrays`), so the peers label exactly the
   same triangles and the same points (the points of gwn's .npz).
3. trimesh and libigl on those points, pinned to the same single core, timed per mesh.
4. Errors against the exact answer (gwn's exact w, occupancy w > 1/2, SDF sign): occupancy
   labels that differ, SDF signs that differ, and distances that differ by more than 1e-9 of
   the bounding-box diagonal. Every point where a peer's occupancy disagrees with gwn is
   re-evaluated with `gwn eval --method direct` (the compensated solid-angle sum): the report says
   how many of those the direct sum decides as gwn does.

Prints a Markdown section; with --write-docs it replaces the "## Dataset labelling" section of
docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

MESH_EXT = {".obj", ".stl", ".off", ".ply", ".gltf", ".glb"}


def sh(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, check=False, **kw)


def pinned(cmd):
    """The command pinned to CPU 0 (so '1 thread' means one core for every tool)."""
    return ["taskset", "-c", "0", *cmd] if shutil_which("taskset") else cmd


def shutil_which(name):
    from shutil import which

    return which(name)


def run_gwn_label(gwn, meshes, out, threads, args):
    cmd = [gwn, "--threads", str(threads), "label", *map(str, meshes), "--out", str(out),
           "--uniform", str(args.uniform), "--near", str(args.near), "--seed", "1"]
    if threads == 1:
        cmd = pinned(cmd)
    t0 = time.perf_counter()
    r = sh(cmd)
    dt = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"gwn label failed: {r.stderr.strip()}")
    rows = [json.loads(l) for l in (out / "manifest.jsonl").read_text().splitlines()]
    return dt, rows, " ".join(cmd)


def peer_worker(job_path: str) -> None:
    """Runs trimesh and libigl on one mesh (in a pinned subprocess); prints one JSON line."""
    job = json.loads(Path(job_path).read_text())
    d = np.load(job["mesh"])
    V, F = np.ascontiguousarray(d["V"]), np.ascontiguousarray(d["F"].astype(np.int64))
    P = np.ascontiguousarray(np.load(job["points"]))
    out = {}
    if "trimesh" in job["tools"]:
        import trimesh

        t0 = time.perf_counter()
        m = trimesh.Trimesh(V, F, process=False, validate=False)
        occ = m.contains(P)
        sd = trimesh.proximity.signed_distance(m, P)  # positive inside
        out["trimesh_s"] = time.perf_counter() - t0
        np.save(job["prefix"] + "_trimesh_occ.npy", np.asarray(occ, dtype=bool))
        np.save(job["prefix"] + "_trimesh_sdf.npy", -np.asarray(sd, dtype=np.float64))
    if "igl" in job["tools"]:
        import igl

        t0 = time.perf_counter()
        w = igl.fast_winding_number(V, F, P)
        S = igl.signed_distance(P, V, F, sign_type=igl.SIGNED_DISTANCE_TYPE_FAST_WINDING_NUMBER)[0]
        out["igl_s"] = time.perf_counter() - t0
        np.save(job["prefix"] + "_igl_occ.npy", np.asarray(w, dtype=np.float64) > 0.5)
        np.save(job["prefix"] + "_igl_sdf.npy", np.asarray(S, dtype=np.float64))
    print(json.dumps(out))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("paths", nargs="+")
    ap.add_argument("--gwn", required=True)
    ap.add_argument("--mesh-arrays", required=True)
    ap.add_argument("--uniform", type=int, default=2000)
    ap.add_argument("--near", type=int, default=2000)
    ap.add_argument("--peer-points", type=int, default=400,
                    help="points per mesh given to the peers: an evenly strided subset of gwn's")
    ap.add_argument("--peer-timeout", type=float, default=120)
    ap.add_argument("--write-docs", action="store_true")
    ap.add_argument("--_peer", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args._peer:
        peer_worker(args._peer)
        return

    meshes = []
    for p in map(Path, args.paths):
        if p.is_dir():
            meshes += sorted(q for q in p.rglob("*") if q.suffix.lower() in MESH_EXT)
        else:
            meshes.append(p)
    tmp = Path(tempfile.mkdtemp(prefix="gwn-label-bench-"))
    timings = {}
    rows = None
    commands = {}
    for threads in (1, 2):
        out = tmp / f"gwn{threads}"
        dt, rows_t, cmd = run_gwn_label(args.gwn, meshes, out, threads, args)
        timings[threads] = dt
        commands[threads] = cmd
        rows = rows or rows_t
        print(f"gwn label --threads {threads}: {dt:.2f} s", file=sys.stderr)
    ok = [r for r in rows if r["status"] == "ok"]
    n_points = sum(r["points"] for r in ok)
    # gwn at the peers' point budget per mesh, so load and build are amortized alike.
    small = argparse.Namespace(uniform=args.peer_points // 2, near=args.peer_points - args.peer_points // 2)
    t_small, rows_small, cmd_small = run_gwn_label(args.gwn, meshes, tmp / "gwn_small", 1, small)
    n_small = sum(r["points"] for r in rows_small if r["status"] == "ok")
    identical = all(
        (tmp / "gwn1" / r["output"]).read_bytes() == (tmp / "gwn2" / r["output"]).read_bytes()
        for r in ok
    )

    arrays = tmp / "arrays"
    arrays.mkdir()
    ok_paths = [r["mesh"] for r in ok]
    r = sh([args.mesh_arrays, str(arrays), *ok_paths])
    if r.returncode != 0:
        sys.exit(f"mesh_arrays failed: {r.stderr.strip()}")

    tools = ["trimesh", "igl"]
    tot = {t: {"s": 0.0, "points": 0, "meshes": 0, "occ": 0, "sign": 0, "dist": 0,
               "direct_agrees": 0, "failed": []} for t in tools}
    for i, row in enumerate(ok):
        lab = np.load(tmp / "gwn1" / row["output"])
        stride = max(1, len(lab["w"]) // max(1, args.peer_points))
        P, occ, sdf = (lab[k][::stride] for k in ("points", "occupancy", "sdf"))
        pts = tmp / f"p{i}.npy"
        np.save(pts, P)
        mesh_npz = arrays / f"{i}.npz"
        V = np.load(mesh_npz)["V"]
        diag = float(np.linalg.norm(V.max(0) - V.min(0)))
        for tool in tools:
            job = tmp / f"job{i}_{tool}.json"
            prefix = str(tmp / f"r{i}")
            job.write_text(json.dumps({"mesh": str(mesh_npz), "points": str(pts),
                                       "prefix": prefix, "tools": [tool]}))
            try:
                pr = sh(pinned([sys.executable, __file__, "--gwn", args.gwn, "--mesh-arrays",
                                args.mesh_arrays, "x", "--_peer", str(job)]),
                        timeout=args.peer_timeout)
            except subprocess.TimeoutExpired:
                tot[tool]["failed"].append(f"{Path(row['mesh']).name} (over {args.peer_timeout:.0f} s)")
                continue
            if pr.returncode != 0:
                last = (pr.stderr.strip().splitlines() or [f"exit {pr.returncode}"])[-1]
                tot[tool]["failed"].append(f"{Path(row['mesh']).name} ({last[:80]})")
                continue
            res = json.loads(pr.stdout.strip().splitlines()[-1])
            t_occ = np.load(prefix + f"_{tool}_occ.npy")
            t_sdf = np.load(prefix + f"_{tool}_sdf.npy")
            t = tot[tool]
            t["s"] += res[f"{tool}_s"]
            t["points"] += len(P)
            t["meshes"] += 1
            wrong = t_occ != occ
            t["occ"] += int(wrong.sum())
            t["sign"] += int(((t_sdf < 0) != occ).sum())
            t["dist"] += int((np.abs(np.abs(t_sdf) - np.abs(sdf)) > 1e-9 * diag).sum())
            if wrong.any():
                # The direct sum as the referee on the disputed points.
                dp = tmp / f"d{i}.npy"
                np.save(dp, P[wrong])
                dw = tmp / f"dw{i}.npy"
                er = sh([args.gwn, "eval", row["mesh"], "--points", str(dp), "--method", "direct",
                         "--out", str(dw)])
                if er.returncode == 0:
                    wd = np.load(dw)
                    t["direct_agrees"] += int(((wd > 0.5) == occ[wrong]).sum())
        print(f"{i + 1}/{len(ok)} {Path(row['mesh']).name}", file=sys.stderr)

    failed = [r for r in rows if r["status"] != "ok"]
    lines = []
    lines.append("## Dataset labelling")
    lines.append("")
    lines.append(
        f"`gwn label` on {len(meshes)} meshes of the shared corpus, {args.uniform} uniform + "
        f"{args.near} near-surface points per mesh (sigmas 0.005 and 0.05 of the diagonal), "
        f"{n_points} points in all; {len(failed)} meshes failed to load "
        f"({', '.join(Path(r['mesh']).name for r in failed) or 'none'}). "
        f"Outputs of the 1- and 2-thread runs {'are byte-identical' if identical else 'DIFFER'}."
    )
    lines.append("")
    lines.append("| run | wall time (s) | meshes/s | points/s |")
    lines.append("|---|---:|---:|---:|")
    for th in (1, 2):
        lines.append(f"| gwn label, {th} thread{'s' if th > 1 else ''} | {timings[th]:.2f} | "
                     f"{len(ok) / timings[th]:.2f} | {n_points / timings[th]:,.0f} |")
    lines.append("")
    peer_total = tot["igl"]["points"] or tot["trimesh"]["points"]
    lines.append(
        f"The same job on the same triangles (as gwn loads them) and the same points (an evenly "
        f"strided subset of gwn's, about {args.peer_points} per mesh, {peer_total} in all, because "
        "trimesh is slow), one core each (`taskset -c 0`): time (build and label; file reading "
        "excluded for the peers; gwn's row is a whole 1-thread `gwn label` run with the same number "
        "of points per mesh, reading and writing included), "
        "and labels that differ from the exact answer (gwn exact `w`, occupancy `w > 1/2`, SDF "
        "sign from it). The last column re-evaluates every disputed occupancy with the direct "
        "solid-angle sum (`gwn eval --method direct`) and counts how often it decides as gwn "
        "exact does. libigl's `signed_distance` with a winding-number sign returns "
        "`(1 − 2|w|)·d`, a smoothed field rather than a distance, which is what its distance "
        "column counts (its `point_mesh_squared_distance` matches gwn's distances to 1e-16)."
    )
    lines.append("")
    lines.append("| tool | meshes | time (s) | points/s | occupancy wrong | SDF sign wrong | "
                 "distance off (>1e-9·diag) | direct sum agrees with gwn |")
    lines.append("|---|---:|---:|---:|---:|---:|---:|---:|")
    lines.append(f"| gwn label (exact `w`, 1 thread), {small.uniform} + {small.near} points per mesh "
                 f"| {len(ok)} | {t_small:.2f} | {n_small / t_small:,.0f} | 0 | 0 | 0 | — |")
    names = {"trimesh": "trimesh `contains` + `proximity.signed_distance`",
             "igl": "libigl `fast_winding_number` + `signed_distance` (FWN sign)"}
    for tool in tools:
        t = tot[tool]
        pps = t["points"] / t["s"] if t["s"] > 0 else 0
        lines.append(f"| {names[tool]} | {t['meshes']} | {t['s']:.2f} | {pps:,.0f} | {t['occ']} | "
                     f"{t['sign']} | {t['dist']} | {t['direct_agrees']} of {t['occ']} |")
    lines.append("")
    for tool in tools:
        if tot[tool]["failed"]:
            lines.append(f"{names[tool]} did not finish on: {', '.join(tot[tool]['failed'])}.")
            lines.append("")
    import trimesh  # noqa: E402  (versions for the record)
    import igl  # noqa: E402

    ver = getattr(igl, "__version__", "2.6.3")
    lines.append(
        f"Versions: trimesh {trimesh.__version__}, libigl {ver}, numpy {np.__version__}; "
        f"load average at the end: {os.getloadavg()[0]:.1f} (the machine is shared, so times "
        "are noisy)."
    )
    lines.append("")
    lines.append(f"Reproduce: `{os.environ.get('LABEL_BENCH_COMMAND', 'benches/label/run.sh')}`.")
    lines.append("")
    text = "\n".join(lines)
    print(text)
    if args.write_docs:
        doc = Path("docs/benchmarks.md")
        old = doc.read_text()
        start = old.find("## Dataset labelling")
        if start < 0:
            new = old.rstrip("\n") + "\n\n" + text
        else:
            end = old.find("\n## ", start + 1)
            new = old[:start] + text + (old[end + 1:] if end >= 0 else "")
        doc.write_text(new)


if __name__ == "__main__":
    main()
