"""`gwn remesh` side by side with pymeshfix and point-cloud-utils' make_mesh_watertight.

    python benches/remesh/peers.py --gwn target/release/gwn --res 64 MESH [MESH ...]

Not part of CI. Needs numpy, pymeshfix, point-cloud-utils and manifold3d (pip, any venv) and
the gwn wheel (its loader reads every input: OBJ/OFF polygons are fan-triangulated). Per
mesh and tool: output faces, closed + edge-manifold + consistently oriented (from the edge
census), vertex count of non-manifold vertices is not checked here (gwn's own report does),
accepted by manifold3d (an independent manifold check: `Manifold(Mesh(...)).status()` is
NoError and the result is not empty), occupancy agreement with the input (the same label
w > 1/2, exact winding numbers of both, at 10^4 uniform points of the input's box) and wall
time. gwn's exact self-intersection count comes from its JSON report. Prints a Markdown table.
"""

import argparse
import json
import os
import subprocess
import tempfile
import time

import gwn
import manifold3d
import numpy as np
import point_cloud_utils as pcu
import pymeshfix


def census(F):
    """(faces, closed and oriented and edge-manifold)."""
    F = np.asarray(F, dtype=np.int64)
    if len(F) == 0:
        return 0, False
    directed = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    once = len(np.unique(directed, axis=0)) == len(directed)
    _, counts = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    return len(F), bool(once and np.all(counts == 2))


def manifold_ok(V, F):
    if len(F) == 0:
        return False
    try:
        mesh = manifold3d.Mesh(
            vert_properties=np.asarray(V, dtype=np.float32),
            tri_verts=np.asarray(F, dtype=np.uint32),
        )
        m = manifold3d.Manifold(mesh)
        return m.status() == manifold3d.Error.NoError and not m.is_empty()
    except Exception:  # noqa: BLE001 - any refusal is a "no"
        return False


def agreement(V, F, Vo, Fo, q):
    """Fraction of the points q with the same label w > 1/2 (exact winding numbers) on input and output."""
    if len(Fo) == 0:
        return float("nan")
    wi = gwn.winding_number(V, F, q) > 0.5
    wo = gwn.winding_number(np.asarray(Vo, dtype=np.float64), np.asarray(Fo, dtype=np.int64), q) > 0.5
    return float(np.mean(wi == wo))


def cell(ok):
    return "yes" if ok else "NO"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gwn", default="target/release/gwn")
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--pcu-resolution", type=int, default=20_000)
    ap.add_argument("meshes", nargs="+")
    a = ap.parse_args()
    print(
        "| mesh | faces | gwn faces | gwn closed+manifold+oriented | gwn manifold3d | gwn self-int | "
        "gwn agreement | gwn s | pymeshfix faces | pymeshfix c+m+o | pymeshfix manifold3d | "
        "pymeshfix agreement | pymeshfix s | pcu faces | pcu c+m+o | pcu manifold3d | "
        "pcu agreement | pcu s |"
    )
    print("|---|" + "---:|" * 2 + "---|---|---:|---:|---:|---:|---|---|---:|---:|---:|---|---|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for path in a.meshes:
            name = os.path.basename(path)
            V, F = gwn.load(path)
            V = np.asarray(V, dtype=np.float64)
            F = np.asarray(F, dtype=np.int64)
            row = [name, str(len(F))]
            rng = np.random.default_rng(0)
            q = rng.uniform(V.min(axis=0), V.max(axis=0), size=(10_000, 3))
            out, rep = os.path.join(tmp, "out.ply"), os.path.join(tmp, "r.json")
            t = time.perf_counter()
            r = subprocess.run(
                [a.gwn, "--threads", "2", "remesh", path, "--res", str(a.res), "--out", out,
                 "--report", rep],
                capture_output=True, text=True,
            )
            gwn_s = time.perf_counter() - t
            if r.returncode != 0:
                row += ["error", "", "", "", "", f"{gwn_s:.2f}"]
            else:
                j = json.load(open(rep))
                Vg, Fg = gwn.load(out)
                n, ok = census(Fg)
                row += [str(n), cell(ok), cell(manifold_ok(Vg, Fg)),
                        str(j.get("self_intersections", "-")),
                        f"{100 * agreement(V, F, Vg, Fg, q):.2f} %", f"{gwn_s:.2f}"]
            t = time.perf_counter()
            try:
                mf = pymeshfix.MeshFix(V, F.astype(np.int32))
                mf.repair()
                Vp = getattr(mf, "points", None)
                Vp, Fp = (mf.v, mf.f) if Vp is None else (Vp, mf.faces)
            except Exception:  # noqa: BLE001
                Vp, Fp = np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
            s = time.perf_counter() - t
            n, ok = census(Fp)
            row += [str(n), cell(ok), cell(manifold_ok(Vp, Fp)),
                    f"{100 * agreement(V, F, Vp, Fp, q):.2f} %", f"{s:.2f}"]
            t = time.perf_counter()
            try:
                Vw, Fw = pcu.make_mesh_watertight(V, F.astype(np.int32), a.pcu_resolution)
            except Exception:  # noqa: BLE001
                Vw, Fw = np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
            s = time.perf_counter() - t
            n, ok = census(Fw)
            row += [str(n), cell(ok), cell(manifold_ok(Vw, Fw)),
                    f"{100 * agreement(V, F, Vw, Fw, q):.2f} %", f"{s:.2f}"]
            print("| " + " | ".join(row) + " |", flush=True)


if __name__ == "__main__":
    main()
