#!/usr/bin/env bash
# Peer benchmark of gwn: libigl (and Open3D) side by side with `gwn bench`, in one run.
#
#   benches/peers/run.sh [MESH_OR_DIR ...] [--quick] [peers.py options]
#
# peers.py options of note: --threads 1,2, --beta 2 --order 2 (gwn fast = libigl accuracy_scale /
# order), --soups a.off,b.off (also measure those meshes with every vertex un-shared), --sections
# peers,fast (which sections of docs/benchmarks.md to rewrite). The "## Fast (Barnes–Hut)" section
# was produced with:
#
#   PEERS_NO_OPEN3D=1 benches/peers/run.sh M/cgal-anchor.off M/cgal-hand.off ... \
#       --soups cgal-hand.off,cgal-fandisk.off,cgal-armadillo.off --match-beta 2.5 --sections fast
#
# (the full command, with the mesh list, is recorded in that section; --match-beta also times gwn
# fast at a second beta, matched to libigl's accuracy).
#
# Creates benches/peers/.venv, installs requirements.txt (and requirements-open3d.txt when
# possible; set PEERS_NO_OPEN3D=1 to skip it), builds gwn in release for this CPU
# (PEERS_PORTABLE=1: the portable build; honours CARGO_TARGET_DIR)
# and runs peers.py, which rewrites the "## Peers" and "## Fast (Barnes–Hut)" sections of
# docs/benchmarks.md (see --sections).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
venv="$here/.venv"

py="${PYTHON:-}"
if [ -z "$py" ]; then
  if command -v python3.11 >/dev/null; then py=python3.11; else py=python3; fi
fi
if [ ! -x "$venv/bin/python" ]; then
  echo "creating $venv with $($py --version)" >&2
  "$py" -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --disable-pip-version-check -r "$here/requirements.txt"

extra=()
if [ "${PEERS_NO_OPEN3D:-0}" = 1 ]; then
  extra+=(--no-open3d)
else
  if ! "$venv/bin/python" -m pip install -q --disable-pip-version-check -r "$here/requirements-open3d.txt"; then
    echo "note: open3d could not be installed; Open3D is skipped" >&2
  elif ! "$venv/bin/python" -c "import open3d" 2>/dev/null; then
    # Open3D's wheel links libusb-1.0, which minimal systems lack.
    if "$venv/bin/python" -c "import open3d" 2>&1 | grep -q libusb && [ "$(id -u)" = 0 ] \
        && command -v apt-get >/dev/null; then
      echo "installing libusb-1.0-0 (needed by open3d)" >&2
      (DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libusb-1.0-0 >/dev/null 2>&1 \
        || { apt-get update -qq >/dev/null 2>&1 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libusb-1.0-0 >/dev/null 2>&1; }) \
        || echo "note: could not install libusb-1.0-0; Open3D is skipped" >&2
    else
      echo "note: open3d does not import here; Open3D is skipped" >&2
    fi
  fi
fi

# gwn is built for this CPU (`-C target-cpu=native`, in its own target directory so the
# portable build is not invalidated): Open3D's Embree picks AVX2/AVX-512 at run time, and gwn's
# `wide` SIMD types are chosen at compile time. PEERS_PORTABLE=1 times the portable build.
if [ "${PEERS_PORTABLE:-0}" = 1 ]; then
  target="${CARGO_TARGET_DIR:-$repo/target}"
  export GWN_BUILD="portable x86-64 build"
  (cd "$repo" && cargo build --release --quiet --bin gwn)
else
  target="${CARGO_TARGET_DIR:-$repo/target}/native"
  export GWN_BUILD="RUSTFLAGS='-C target-cpu=native'"
  (cd "$repo" && CARGO_TARGET_DIR="$target" RUSTFLAGS="-C target-cpu=native" cargo build --release --quiet --bin gwn)
fi
gwn="$target/release/gwn"
case "$gwn" in /*) ;; *) gwn="$repo/$gwn" ;; esac

cd "$repo"
export PEERS_COMMAND="benches/peers/run.sh${*:+ $*}"
exec "$venv/bin/python" "$here/peers.py" --gwn "$gwn" "${extra[@]}" "$@"
