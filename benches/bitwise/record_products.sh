#!/usr/bin/env bash
# Usage: record_products.sh GWN OUTDIR [MESHDIR]: sdf, slice and classify on five meshes and a
# point-cloud eval, for a bitwise before/after diff.
set -uo pipefail
GWN=$1; OUT=$2; M=${3:-$(dirname "$0")/../../../shared/meshes}
mkdir -p "$OUT"
for f in cgal-cow.off cgal-lion-head.off prusa-bunny.stl pymeshlab-face000.ply cgal-holes.off; do
  $GWN sdf $M/$f --res 12 --dtype f64 --out "$OUT/$f.sdf.npy" > /dev/null 2>&1 || echo fail > "$OUT/$f.sdf.err"
  $GWN slice $M/$f --res 64 --outline --out "$OUT/$f.slice.png" > /dev/null 2>&1 || echo fail > "$OUT/$f.slice.err"
done
$GWN classify $M/cgal-cow.off $M/cgal-holes.off --out "$OUT/classify.csv" >/dev/null 2>&1
python3 - > "$OUT/cloud.xyz" <<'PY'
import math
n=400
for i in range(n):
    z=1-2*(i+0.5)/n; r=math.sqrt(1-z*z); t=i*2.399963229728653
    x,y=r*math.cos(t),r*math.sin(t); print(repr(x),repr(y),repr(z),repr(x),repr(y),repr(z))
PY
python3 - > "$OUT/cloudq.csv" <<'PY'
for i in range(50): print(repr(-1.5+3*i/49), repr(0.1), repr(0.2))
PY
$GWN eval "$OUT/cloud.xyz" --points "$OUT/cloudq.csv" > "$OUT/cloud.w" 2>&1
