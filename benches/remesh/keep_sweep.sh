#!/usr/bin/env bash
# Inputs kept as they are (docs/benchmarks.md, "Inputs kept as they are"): per mesh, `gwn remesh`
# at res 256 with the default (the input kept when it provably is the surface, else its clean
# components kept and the rest remeshed) and, when it was kept whole or in part, again with
# --always-remesh; 2 threads, 10^5 report samples, JSON reports in OUT.
# Then: python3 benches/remesh/keep_summary.py OUT MESH_DIR (numpy; trimesh and manifold3d for
# the face estimate and the independent check, skipped when absent).
# Usage: benches/remesh/keep_sweep.sh GWN OUT MESH...
set -uo pipefail
GWN=$1; OUT=$2; shift 2
mkdir -p "$OUT"
for m in "$@"; do
  b=$(basename "$m")
  timeout 300 "$GWN" --threads 2 remesh "$m" --res 256 --out "$OUT/$b.kept.ply" --samples 100000 \
    --report "$OUT/$b.kept.json" > /dev/null 2>&1 || echo "$b: the default run failed"
  if grep -q '"input": "\(partly \)\?kept"' "$OUT/$b.kept.json" 2>/dev/null; then
    timeout 300 "$GWN" --threads 2 remesh "$m" --res 256 --out "$OUT/$b.re.ply" --samples 100000 \
      --report "$OUT/$b.re.json" --always-remesh > /dev/null 2>&1 || echo "$b: --always-remesh failed"
  fi
done
