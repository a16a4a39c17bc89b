#!/usr/bin/env bash
# Usage: benches/bitwise/record.sh GWN OUTDIR [MESHDIR]; then `diff -r` two OUTDIRs (before/after).
# Per mesh of the corpus (default ../shared/meshes): values at 200 fixed points (exact with
# gradient, direct with gradient, fast, exact 30-bit along -x) and a 16^3 voxel grid (f64), all
# written with round-trip formatting; then sdf, slice, classify and a point cloud
# (record_products.sh).
set -uo pipefail
GWN=$1; OUT=$2; M=${3:-$(dirname "$0")/../../../shared/meshes}
mkdir -p "$OUT"
for f in $(ls $M | grep -Ei '\.(obj|stl|off|ply)$'); do
  p=$M/$f
  info=$($GWN info "$p" 2>/dev/null) || { echo "$f: load error" > "$OUT/$f.err"; continue; }
  lo=$(echo "$info" | sed -n 's/^bbox min *\[\(.*\)\]/\1/p'); hi=$(echo "$info" | sed -n 's/^bbox max *\[\(.*\)\]/\1/p')
  [ -z "$lo" ] && continue
  python3 - "$lo" "$hi" > "$OUT/$f.pts.csv" <<'PY'
import sys
lo=[float(x) for x in sys.argv[1].split(',')]; hi=[float(x) for x in sys.argv[2].split(',')]
s=12345
def r():
    global s; s=(s*6364136223846793005+1442695040888963407)%(1<<64); return (s>>11)/float(1<<53)
for i in range(200):
    print(' '.join(repr(l-0.25*(h-l)+1.5*(h-l)*r()) for l,h in zip(lo,hi)))
PY
  $GWN eval "$p" --points "$OUT/$f.pts.csv" --gradient > "$OUT/$f.exact" 2>&1
  $GWN eval "$p" --points "$OUT/$f.pts.csv" --method direct --gradient > "$OUT/$f.direct" 2>&1
  $GWN eval "$p" --points "$OUT/$f.pts.csv" --method fast > "$OUT/$f.fast" 2>&1
  $GWN eval "$p" --points "$OUT/$f.pts.csv" --precision 30 --ray -x > "$OUT/$f.exact30" 2>&1
  $GWN voxelize "$p" --res 16 --dtype f64 --out "$OUT/$f.vox.npy" > /dev/null 2>&1 || echo fail > "$OUT/$f.vox.err"
done
"$(dirname "$0")/record_products.sh" "$GWN" "$OUT/products" "$M"
