#!/usr/bin/env bash
# libigl's fast winding number against two builds of gwn's `fast_speed` example (before and after
# a change), gwn at its libigl-matched setting (radius-or-box-corner, β = 2.8), 1 thread, process
# CPU time, the 32³ grid of `gwn bench`; per mesh the best of 3 rounds of (libigl, before, after),
# so that the three see the same machine. One table row per mesh (docs/benchmarks.md, "Near leaves
# listed and prefetched"). Needs the peers venv (benches/peers/run.sh creates it).
#
#   cargo build --release --features examples --example fast_speed
#   cp target/release/examples/fast_speed /tmp/fast_speed_after   # and a build of the old commit
#   benches/peers/fast_before_after.sh /tmp/fast_speed_before /tmp/fast_speed_after MESH...
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
py="$here/.venv/bin/python"
before="$1"
after="$2"
shift 2
# The sixth column of the last table row (libigl's script and fast_speed print the same columns);
# 0 when the tool failed on the mesh (the loop goes on).
rate() { local r; r=$(grep '^| ' | tail -1 | cut -d'|' -f6 | tr -d ' '); echo "${r:-0}"; }
best() { python3 -c "import sys; print(max(float(x) for x in sys.argv[1:]))" "$@"; }
echo "| mesh | libigl q/s | before ÷ libigl | after ÷ libigl | after ÷ before | load |"
echo "|---|---:|---:|---:|---:|---|"
for m in "$@"; do
  i=(0) b=(0) a=(0)
  for _ in 1 2 3; do
    i+=("$( (IGL_NUM_THREADS=1 OMP_NUM_THREADS=1 "$py" "$here/igl_fast_cpu.py" --reps 2 "$m" 2>&1 || true) | rate)")
    b+=("$( ("$before" --reps 2 --beta 2.8 --rule radius-or-box-corner "$m" 2>&1 || true) | rate)")
    a+=("$( ("$after" --reps 2 --beta 2.8 --rule radius-or-box-corner "$m" 2>&1 || true) | rate)")
  done
  python3 - "$(basename "$m")" "$(best "${i[@]}")" "$(best "${b[@]}")" "$(best "${a[@]}")" "$(cut -d' ' -f1 /proc/loadavg)" <<'PY'
import sys
name, igl, before, after, load = sys.argv[1], *map(float, sys.argv[2:5]), sys.argv[5]
ratio = lambda x, y: f"{x / y:.2f}×" if y > 0 else "-"
print(f"| {name} | {igl:.4g} | {ratio(before, igl)} | {ratio(after, igl)} | {ratio(after, before)} | {load} |")
PY
done
