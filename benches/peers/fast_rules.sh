#!/usr/bin/env bash
# libigl's fast winding number against gwn fast under three admissibility rules at matched
# accuracy (radius 2.8, radius-or-box-corner 2.8, box-corner 2.4), 1 thread, process CPU time,
# the 32³ grid of `gwn bench`, one table row per mesh (docs/benchmarks.md, "Either admissibility
# test"). Needs the peers venv (benches/peers/run.sh creates it).
#
#   [REPS=5] benches/peers/fast_rules.sh MESH...
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
cd "$repo"
cargo build --release --features examples --example fast_speed --quiet
bin="${CARGO_TARGET_DIR:-$repo/target}/release/examples/fast_speed"
py="$here/.venv/bin/python"
reps="${REPS:-5}"   # best of this many timings per tool and mesh
# The sixth column of the last table row (libigl's script and fast_speed print the same columns);
# "-" when the tool failed on the mesh (the loop goes on).
rate() { local r; r=$(grep '^| ' | tail -1 | cut -d'|' -f6 | tr -d ' '); echo "${r:--}"; }
echo "| mesh | libigl q/s | radius 2.8 | radius-or-box-corner 2.8 | box-corner 2.4 | load |"
echo "|---|---:|---:|---:|---:|---|"
for m in "$@"; do
  igl=$( (IGL_NUM_THREADS=1 OMP_NUM_THREADS=1 "$py" "$here/igl_fast_cpu.py" --reps "$reps" "$m" 2>&1 || true) | rate)
  r=$( ("$bin" --reps "$reps" --beta 2.8 "$m" 2>&1 || true) | rate)
  e=$( ("$bin" --reps "$reps" --beta 2.8 --rule radius-or-box-corner "$m" 2>&1 || true) | rate)
  c=$( ("$bin" --reps "$reps" --beta 2.4 --rule box-corner "$m" 2>&1 || true) | rate)
  echo "| $(basename "$m") | $igl | $r | $e | $c | $(cut -d' ' -f1 /proc/loadavg) |"
done
