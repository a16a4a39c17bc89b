#!/usr/bin/env bash
# Six-ray agreement at points 1-3 ulps from a mesh's surface (docs/benchmarks.md, "Queries ulps
# from the surface, six rays"): prints the points where the rays spread by more than 1e-9 and
# whether each lies exactly on the surface (where the value is the ray's perturbation).
# usage: benches/rays/ulp_rays.sh GWN MESH.off [N] [SEED]   (python3 with numpy on PATH)
set -euo pipefail
gwn=$1; mesh=$2; n=${3:-3000}; seed=${4:-11}
here=$(cd "$(dirname "$0")" && pwd)
dir=$(mktemp -d)
python3 "$here/ulp_points.py" "$mesh" "$dir/q.csv" "$n" "$seed"
for r in +z -z +x -x +y -y; do "$gwn" --threads 1 eval "$mesh" --points "$dir/q.csv" --ray "$r" --out "$dir/w$r.csv"; done
python3 - "$dir" <<'PY'
import sys, numpy as np
d = sys.argv[1]
q = np.loadtxt(f"{d}/q.csv", delimiter=",")
w = np.array([np.loadtxt(f"{d}/w{r}.csv", delimiter=",").ravel() for r in ["+z", "-z", "+x", "-x", "+y", "-y"]])
bad = np.where(w.max(0) - w.min(0) > 1e-9)[0]
np.savetxt(f"{d}/bad.csv", q[bad].reshape(-1, 3), delimiter=",", fmt="%.17g")
print(f"{w.shape[1]} points, rays spread > 1e-9 at {len(bad)}")
PY
if [ -s "$dir/bad.csv" ]; then PYTHONPATH="$here" python3 "$here/on_surface.py" "$mesh" "$dir/bad.csv" | tail -4; fi
rm -r "$dir"
