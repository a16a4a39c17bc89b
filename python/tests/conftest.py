"""Shared meshes and helpers of the pytest suite."""

import os
import pathlib
import shutil

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
# The shared data folder: $GWN_SHARED_DIR when set (a checkout whose ../shared is not the data,
# e.g. a git worktree elsewhere), else ../shared next to the repository (as tests/common does).
SHARED = pathlib.Path(os.environ.get("GWN_SHARED_DIR") or REPO.parent / "shared")
SHARED_MESHES = SHARED / "meshes"
FIXTURES = REPO / "tests" / "fixtures"
LION_HEAD = REPO / "data" / "lion-head.off"

CUBE_V = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    dtype=np.float64,
)
# Outward-oriented unit cube; OPEN_BOX_F is the same without the top face (z = 1).
OPEN_BOX_F = np.array(
    [[0, 2, 1], [0, 3, 2], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6],
     [3, 0, 4], [3, 4, 7]],
    dtype=np.int64,
)
CUBE_F = np.vstack([OPEN_BOX_F, [[4, 5, 6], [4, 6, 7]]])
TET_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
TET_F = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]], dtype=np.int64)


def copy_fixtures(tmp_path, files):
    """Copies fixtures into ``tmp_path/in``: ``files`` maps a path below it to a fixture name.
    Returns the copies' paths, in ``files``' order."""
    paths = []
    for to, src in files.items():
        p = tmp_path / "in" / to
        p.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(FIXTURES / src, p)
        paths.append(p)
    return paths


def files_by_suffix(d, suffix):
    """Every file below ``d`` ending in ``suffix``, as {relative posix path: bytes}."""
    return {p.relative_to(d).as_posix(): p.read_bytes() for p in sorted(d.rglob("*" + suffix))}


def random_points(n, lo=-0.5, hi=1.5, seed=0):
    return np.random.default_rng(seed).uniform(lo, hi, size=(n, 3))


@pytest.fixture(scope="session")
def cli():
    """The `gwn` command-line tool (GWN_CLI, else target/release or target/debug)."""
    candidates = [os.environ.get("GWN_CLI"), REPO / "target" / "release" / "gwn",
                  REPO / "target" / "debug" / "gwn", shutil.which("gwn")]
    for c in candidates:
        if c and pathlib.Path(c).is_file():
            return pathlib.Path(c)
    print("skipping: the gwn CLI is not built (run cargo build or scripts/test)")
    pytest.skip("the gwn CLI is not built (run cargo build or scripts/test)")


@pytest.fixture(scope="session")
def lion():
    import gwn

    return gwn.load(LION_HEAD)


def shared_mesh(name):
    """A mesh of the shared corpus, or a skip with the printed reason."""
    path = SHARED_MESHES / name
    if not path.is_file():
        print(f"skipping: {path} is absent")
        pytest.skip(f"{path} is absent")
    return path
