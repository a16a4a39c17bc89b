#!/usr/bin/env bash
# Six-ray agreement and the difference from the direct sum near a mesh's surface
# (docs/benchmarks.md, "Near-edge tube"). usage: benches/rays/six_rays.sh GWN MESH.off [N]
set -euo pipefail
gwn=$1; mesh=$2; n=${3:-3000}
dir=$(mktemp -d)
python3 "$(dirname "$0")/near_surface_points.py" "$mesh" "$dir/q.csv" "$n"
for r in +z -z +x -x +y -y; do "$gwn" eval "$mesh" --points "$dir/q.csv" --ray "$r" --out "$dir/w$r.csv"; done
"$gwn" eval "$mesh" --points "$dir/q.csv" --method direct --out "$dir/direct.csv"
python3 - "$dir" <<'PY'
import sys, numpy as np
d = sys.argv[1]
ref = np.loadtxt(f"{d}/direct.csv", delimiter=",").ravel()
w = np.array([np.loadtxt(f"{d}/w{r}.csv", delimiter=",").ravel() for r in ["+z", "-z", "+x", "-x", "+y", "-y"]])
print(f"{w.shape[1]} points: six-ray spread {np.max(w.max(0) - w.min(0)):.2e}, largest difference from direct {np.max(np.abs(w - ref)):.2e}")
PY
rm -r "$dir"
