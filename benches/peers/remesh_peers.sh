#!/usr/bin/env bash
# `gwn remesh` side by side with PyMeshFix and point-cloud-utils, manifold3d as the check
# (issue 26; docs/benchmarks.md, "Remeshing against PyMeshFix and point-cloud-utils").
#
#   benches/peers/remesh_peers.sh [remesh_peers.py options] MESH_OR_DIR...
#
# Creates benches/peers/.venv-remesh with requirements-remesh.txt, builds the gwn tool in release
# (honours CARGO_TARGET_DIR) and runs remesh_peers.py with it.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
venv="$here/.venv-remesh"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --disable-pip-version-check -r "$here/requirements-remesh.txt"
(cd "$repo" && cargo build --release -p gwn-cli)
target="${CARGO_TARGET_DIR:-$repo/target}"
exec "$venv/bin/python" "$here/remesh_peers.py" --gwn "$target/release/gwn" "$@"
