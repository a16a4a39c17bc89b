"""Summary of benches/remesh/keep_sweep.sh: per kept input, the check against the remesh of
the same input (validity, manifold3d, agreement, distance, seconds, the time goal), the same for
inputs kept in part, then the face target's estimate against the dense marching-cubes count the
remesh reports.
Usage: python3 benches/remesh/keep_summary.py OUT MESH_DIR"""
import json, sys, os, glob
import numpy as np
out, meshes = sys.argv[1], sys.argv[2]
rows = []
for f in sorted(glob.glob(f'{out}/*.kept.json')):
    name = os.path.basename(f)[:-len('.kept.json')]
    k = json.load(open(f))
    r = json.load(open(f'{out}/{name}.re.json')) if os.path.exists(f'{out}/{name}.re.json') else None
    rows.append((name, k, r))
kept = [x for x in rows if x[1].get('input') == 'kept']
print(f"meshes {len(rows)}, kept {len(kept)}")
try:
    import manifold3d, trimesh
except ImportError:
    manifold3d = trimesh = None
not_kept = {}
for name, k, r in rows:
    if k.get('input') in ('remeshed', 'partly kept'):
        reason = k.get('input_not_kept', '').split(' (')[0]
        not_kept[reason] = not_kept.get(reason, 0) + 1
for reason, n in sorted(not_kept.items(), key=lambda x: -x[1]):
    print(f"  not kept whole: {n:3d}  {reason}")
goal_k = goal_r = 0
tot_k = tot_r = 0.0
for name, k, r in rows:
    fi = k['faces']
    goal = 10.0 * fi / 1e5
    if k.get('input') != 'kept':
        continue
    valid = k['closed'] and k['edge_manifold'] and k['vertex_manifold'] and k['oriented'] and k['self_intersections'] == 0
    m3 = ''
    if manifold3d is not None:
        mesh = trimesh.load(f'{out}/{name}.kept.ply', process=False)
        mm = manifold3d.Manifold(manifold3d.Mesh(np.asarray(mesh.vertices, dtype=np.float32), np.asarray(mesh.faces, dtype=np.uint32)))
        m3 = str(mm.status()).split('.')[-1]
    ks, rs = k['seconds'], (r['seconds'] if r else float('nan'))
    tot_k += ks; tot_r += rs if r else 0
    goal_k += ks <= goal; goal_r += (rs <= goal) if r else 0
    print(f"{name:45s} faces {fi:7d} kept {ks:7.3f}s remesh {rs:7.2f}s  goal {goal:7.3f}s  valid {valid} m3 {m3}  "
          f"agree {k.get('occupancy_agreement')} / {r.get('occupancy_agreement') if r else None}  "
          f"haus {k.get('hausdorff_boundary_cells', float('nan')):.2e} / {r.get('hausdorff_boundary_cells', float('nan')) if r else None}  "
          f"out faces {k['faces']} / {r['faces'] if r else None}")
print(f"sum seconds kept {tot_k:.2f} remesh {tot_r:.2f}; time goal met kept {goal_k} remesh {goal_r}")
# Inputs whose clean components were kept and the rest remeshed, against --always-remesh.
partly = [x for x in rows if x[1].get('input') == 'partly kept']
print(f"partly kept: {len(partly)}")
for name, k, r in partly:
    valid = k['closed'] and k['edge_manifold'] and k['vertex_manifold'] and k['oriented'] and k['self_intersections'] == 0
    print(f"{name:45s} components {k['input_kept_components']}/{k['input_components']} faces kept {k['input_kept_faces']:6d}  "
          f"seconds {k['seconds']:7.2f} / {r['seconds'] if r else float('nan'):7.2f}  valid {valid}  "
          f"agree {k.get('occupancy_agreement')} / {r.get('occupancy_agreement') if r else None}  "
          f"haus {k.get('hausdorff_boundary_cells', float('nan')):.3f} / {r.get('hausdorff_boundary_cells', float('nan')) if r else float('nan'):.3f}  "
          f"out faces {k['faces']} / {r['faces'] if r else None}")
# The face estimate of keep_input against the dense marching cubes count the remesh reports.
if trimesh is None:
    sys.exit(0)
print("estimate of dense marching cubes faces vs reported:")
ratios = []
for name, k, r in rows:
    if not r:
        continue
    try:
        mesh = trimesh.load(os.path.join(meshes, name), process=False, force='mesh')
    except Exception:
        continue
    h = r['cell_sizes']
    V, F = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    est = 2 * 0.5 * (np.abs(n[:, 0]).sum() / (h[1] * h[2]) + np.abs(n[:, 1]).sum() / (h[2] * h[0]) + np.abs(n[:, 2]).sum() / (h[0] * h[1]))
    ratios.append(est / r['marching_cubes_faces'])
    print(f"  {name:45s} estimate {est:10.0f} reported {r['marching_cubes_faces']:10d} ratio {est / r['marching_cubes_faces']:.3f}")
if ratios:
    print(f"  ratio median {np.median(ratios):.3f} min {min(ratios):.3f} max {max(ratios):.3f}")
