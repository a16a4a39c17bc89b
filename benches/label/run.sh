#!/usr/bin/env bash
# Labelling benchmark: `gwn label` (1 and 2 threads) and the same job with trimesh and libigl,
# side by side in one run, with label error counts against the exact answer.
#
#   benches/label/run.sh [MESH_OR_DIR ...] [--uniform N] [--near N] [--write-docs]
#
# Default input: ../shared/meshes. Creates benches/label/.venv from requirements.txt, builds gwn
# and examples/mesh_arrays in release, and runs label_bench.py (which documents what is measured).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
venv="$here/.venv"
py="${PYTHON:-}"
if [ -z "$py" ]; then
  if command -v python3.11 >/dev/null; then py=python3.11; else py=python3; fi
fi
if [ ! -x "$venv/bin/python" ]; then
  "$py" -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --disable-pip-version-check -r "$here/requirements.txt"
(cd "$repo" && cargo build --release --quiet --bin gwn --features examples --example mesh_arrays)
target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in /*) ;; *) target="$repo/$target" ;; esac
args=("$@")
has_path=0
for a in "$@"; do if [ -e "$a" ]; then has_path=1; fi; done
if [ "$has_path" = 0 ]; then args=("$repo/../shared/meshes" "${args[@]}"); fi
cd "$repo"
export LABEL_BENCH_COMMAND="benches/label/run.sh${*:+ $*}"
exec "$venv/bin/python" "$here/label_bench.py" --gwn "$target/release/gwn" \
  --mesh-arrays "$target/release/examples/mesh_arrays" "${args[@]}"
