"""gwn.remesh: a closed, manifold, oriented surface of w > 1/2 (closed forms on cubes)."""

import json
import subprocess
import warnings

import numpy as np
import pytest

import gwn
from conftest import CUBE_F, CUBE_V, FIXTURES, OPEN_BOX_F, random_points


def edge_census(F):
    """(every directed edge appears once, every undirected edge twice): closed and oriented."""
    directed = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    unique_directed = np.unique(directed, axis=0)
    undirected, counts = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    return len(unique_directed) == len(directed), bool(np.all(counts == 2)), len(undirected)


def volume(V, F):
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0


def test_cube_gives_a_closed_oriented_sphere_of_the_right_volume():
    # The remesher's path: the clean cube itself is kept as it is without always_remesh (below).
    V, F = gwn.remesh(CUBE_V, CUBE_F, res=16, always_remesh=True)
    assert V.dtype == np.float64 and V.shape[1] == 3
    assert F.dtype == np.int64 and F.shape[1] == 3 and len(F) > 0
    once, twice, edges = edge_census(F)
    assert once and twice
    assert len(np.unique(F)) - edges + len(F) == 2  # Euler characteristic of a sphere
    # Cut corners and edges lose at most about a cell's worth of volume.
    assert 0.85 < volume(V, F) <= 1.0 + 1e-9
    # Away from the surface the output's own winding number agrees with the cube's.
    q = random_points(2000, seed=3)
    far = np.min(np.minimum(np.abs(q), np.abs(q - 1)), axis=1) > 2.0 / 16
    w_in = gwn.winding_number(CUBE_V, CUBE_F, q[far])
    w_out = gwn.winding_number(V, F, q[far])
    np.testing.assert_array_equal(w_in > 0.5, w_out > 0.5)


def test_disjoint_cubes_stay_two_solids_and_open_box_closes():
    V2 = np.concatenate([CUBE_V, CUBE_V + [2.0, 0.0, 0.0]])
    F2 = np.concatenate([CUBE_F, CUBE_F + len(CUBE_V)])
    V, F = gwn.remesh(V2, F2, res=24, threads=1, always_remesh=True)
    once, twice, edges = edge_census(F)
    assert once and twice
    assert len(np.unique(F)) - edges + len(F) == 4
    V, F = gwn.remesh(CUBE_V, OPEN_BOX_F, res=12)
    once, twice, _ = edge_census(F)
    assert once and twice and len(F) > 0


def test_simplify_false_gives_the_raw_surface_with_more_faces():
    V, F = gwn.remesh(CUBE_V, CUBE_F, res=16, always_remesh=True)
    Vr, Fr = gwn.remesh(CUBE_V, CUBE_F, res=16, simplify=False)
    for V_, F_ in ((V, F), (Vr, Fr)):
        once, twice, edges = edge_census(F_)
        assert once and twice
        assert len(np.unique(F_)) - edges + len(F_) == 2
    assert len(F) * 3 < len(Fr)
    # The simplified vertices are vertices of the raw surface, moved by at most half a cell
    # (cell 1/16) towards the planes they replace, plus the rounding to the fixed point (a tick
    # is 1/512 cell).
    kept = V[np.unique(F)]
    nearest = np.sqrt(((kept[:, None, :] - Vr[None, :, :]) ** 2).sum(axis=2)).min(axis=1)
    assert nearest.max() <= (0.5 + 2 / 512) / 16


def test_bad_arguments_are_value_errors():
    with pytest.raises(ValueError, match="resolution"):
        gwn.remesh(CUBE_V, CUBE_F, res=0)
    with pytest.raises(ValueError, match="bisection"):
        gwn.remesh(CUBE_V, CUBE_F, res=8, bisect=99)
    with pytest.raises(ValueError):
        gwn.remesh(CUBE_V, CUBE_F, res=8, method="nope")
    with pytest.raises(ValueError, match="above the limit 10000000"):
        gwn.remesh(CUBE_V, CUBE_F, res=8, report=True, samples=10**11)
    # Without a report, samples= measures nothing and is not looked at.
    assert len(gwn.remesh(CUBE_V, CUBE_F, res=8, samples=10**11)) == 2


def test_an_empty_output_comes_with_a_warning_that_says_why():
    # Inward: w = -1 inside, {w > 1/2} is empty, and so is the output; parity is the way out.
    inward = np.ascontiguousarray(CUBE_F[:, ::-1])
    with pytest.warns(UserWarning, match="winds inward.*method='parity'"):
        V, F = gwn.remesh(CUBE_V, inward, res=16)
    assert len(F) == 0
    # Remeshed all the same (nothing kept): the reason is still told.
    with pytest.warns(UserWarning, match="winds inward"):
        assert len(gwn.remesh(CUBE_V, inward, res=16, always_remesh=True)[1]) == 0
    assert len(gwn.remesh(CUBE_V, inward, res=16, method="parity")[1]) > 0
    # An open sheet: no volume; thicken= is the way out.
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)
    with pytest.warns(UserWarning, match="without volume.*thicken=EPS"):
        gwn.remesh(square, np.array([[0, 1, 2], [0, 2, 3]]), res=16)
    # A solid: no warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(gwn.remesh(CUBE_V, CUBE_F, res=16)[1]) > 0


def test_thicken_turns_an_open_square_into_a_slab():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)
    F = np.array([[0, 1, 2], [0, 2, 3]])
    V2, F2 = gwn.remesh(V, F, res=24, thicken=0.08)
    once, twice, _ = edge_census(F2)
    assert once and twice and len(F2) > 0
    # A slab of about 1 x 1 x 0.16 (lattice-rounded).
    assert 0.1 < volume(V2, F2) < 0.22
    with pytest.raises(ValueError, match="finest cell"):
        gwn.remesh(V, F, res=24, thicken=0.01)


def test_a_plate_thinner_than_a_cell_gets_finer_cells_across_it():
    # A 1.5-thick 100 x 100 plate on a 40-high pedestal at res 32 (cubes of 3.125): placed
    # between two lattice planes, the plate is lost without refine_plates (and without
    # sub-cell levels, whose default one level finds most of it too), kept with it.
    def box(lo, hi):
        return lo + CUBE_V * (np.asarray(hi) - np.asarray(lo))

    z0 = 25.8  # the lattice is centred on the box: planes at 24.6875 and 27.8125
    V = np.vstack([box([40, 40, 0], [60, 60, 40]), box([0, 0, z0], [100, 100, z0 + 1.5])])
    F = np.vstack([CUBE_F, CUBE_F + 8])
    want = 20 * 20 * 40 + 100 * 100 * 1.5 - 20 * 20 * 1.5
    V1, F1 = gwn.remesh(V, F, res=32, always_remesh=True)
    assert edge_census(F1)[:2] == (True, True)
    assert abs(volume(V1, F1) / want - 1) < 0.02
    V0, F0 = gwn.remesh(V, F, res=32, refine_plates=False, sub_cell_levels=0,
                        always_remesh=True)
    assert edge_census(F0)[:2] == (True, True)
    assert volume(V0, F0) < 0.7 * want


def test_sub_cell_levels_keep_a_tilted_plate_thinner_than_a_cell():
    # A unit cube and, beside it, a 1.2 x 1.0 plate 0.04 thick, tilted so that no lattice plane
    # follows it: at res 24 (cells of ~0.124) a third of a cell thick, so lattice points fall
    # in it only here and there; two levels below (cells of ~0.031) hold all of it.
    a, b = 0.5, 0.7
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, np.cos(b), -np.sin(b)], [0, np.sin(b), np.cos(b)]])
    rot = rx @ rz
    centre = np.array([2.2, 0.5, 0.5])
    plate = ((CUBE_V - 0.5) * [1.2, 1.0, 0.04]) @ rot.T + centre
    V = np.vstack([CUBE_V, plate])
    F = np.vstack([CUBE_F, CUBE_F + 8])
    u, v = np.meshgrid(np.linspace(-0.45, 0.45, 30), np.linspace(-0.35, 0.35, 30))
    mid_plane = np.stack([u.ravel(), v.ravel(), np.zeros(u.size)], axis=1) @ rot.T + centre
    kept = {}
    for levels in (0, 2):
        # The cube and the plate are clean and apart: kept as they are without always_remesh.
        Vo, Fo = gwn.remesh(V, F, res=24, sub_cell_levels=levels, always_remesh=True)
        assert edge_census(Fo)[:2] == (True, True)
        kept[levels] = np.mean(gwn.winding_number(Vo, Fo, mid_plane) > 0.5)
    assert kept[0] < 0.5 and kept[2] > 0.98, kept
    with pytest.raises(ValueError, match="sub-cell levels"):
        gwn.remesh(V, F, res=24, sub_cell_levels=4)


def test_planar_levels_keep_a_box_closed_and_on_its_faces():
    # A unit cube at res 64: its faces are flat, so the default keeps cells up to 8x larger
    # whole there; the output is as closed and its vertices as close (on the cube within a
    # tick) as with planar_levels=0, the resolution's cells everywhere.
    for levels in (0, 3):
        Vo, Fo = gwn.remesh(CUBE_V, CUBE_F, res=64, planar_levels=levels, always_remesh=True)
        assert edge_census(Fo)[:2] == (True, True)
        assert abs(volume(Vo, Fo) - 1.0) < 1e-3, volume(Vo, Fo)
        # Every vertex on the cube's surface: one coordinate at 0 or 1.
        off = np.min(np.minimum(np.abs(Vo), np.abs(Vo - 1.0)), axis=1)
        assert off.max() < 1e-3, off.max()
    with pytest.raises(ValueError, match="planar levels"):
        gwn.remesh(CUBE_V, CUBE_F, res=64, planar_levels=4)


def test_a_step_model_remeshes_like_the_cli(cli, tmp_path):
    """gwn.remesh(model) of a gwn.StepModel: the capped cylinder (radius 1, height 2) comes out
    closed, oriented, genus 0 and within a cell of the cylinder, the same surface as `gwn
    remesh`; F, thicken= and fast methods are refused."""
    path = FIXTURES / "step" / "capped_cylinder.step"
    model = gwn.load(path)
    V, F = gwn.remesh(model, res=12)
    once, twice, edges = edge_census(F)
    assert once and twice and len(F) > 0
    assert len(np.unique(F)) - edges + len(F) == 2
    cell = 2.0 / 12
    wall = np.abs(np.hypot(V[:, 0], V[:, 1]) - 1.0)
    caps = np.minimum(np.abs(V[:, 2]), np.abs(V[:, 2] - 2.0))
    assert np.all(np.minimum(wall, caps) <= cell)
    assert abs(volume(V, F) - 2.0 * np.pi) < 0.1 * 2.0 * np.pi
    out = tmp_path / "o.ply"
    subprocess.run([str(cli), "remesh", str(path), "--res", "12", "--samples", "0", "--out",
                    str(out)], check=True, capture_output=True)
    Vc, Fc = gwn.load(out)
    np.testing.assert_array_equal(Fc, F)
    np.testing.assert_array_equal(Vc, V)  # the PLY holds float64
    # The report against the model's trimmed tessellation, as the CLI's.
    json_path = tmp_path / "o.json"
    subprocess.run([str(cli), "remesh", str(path), "--res", "12", "--samples", "2000", "--out",
                    str(out), "--report", str(json_path)], check=True, capture_output=True)
    _, Fr, report = gwn.remesh(model, res=12, report=True, samples=2000)
    np.testing.assert_array_equal(Fr, F)
    want = json.loads(json_path.read_text())
    for timing in ["seconds", "phase_seconds"]:
        report.pop(timing), want.pop(timing)
    assert report == want
    assert report["hausdorff_reference_segment_cells"] <= 0.5
    assert report["hausdorff_boundary_cells"] < 1 and report["closed"]
    with pytest.raises(ValueError, match="takes no F"):
        gwn.remesh(model, F)
    with pytest.raises(ValueError, match="thicken"):
        gwn.remesh(model, res=8, thicken=0.5)
    with pytest.raises(ValueError):
        gwn.remesh(model, res=8, method="fast")
    with pytest.raises(ValueError, match="F is required"):
        gwn.remesh(V)


def test_report_measures_the_surface_it_returns():
    V, F, report = gwn.remesh(CUBE_V, CUBE_F, res=16, report=True, samples=4000,
                              always_remesh=True)
    once, twice, edges = edge_census(F)
    assert (report["faces"], report["vertices"], report["edges"]) == (len(F), len(V), edges)
    assert report["closed"] and report["edge_manifold"] and report["vertex_manifold"]
    assert report["oriented"] and report["euler_characteristic"] == 2
    assert report["components"] == 1 and report["self_intersections"] == 0
    phases = report["phase_seconds"]
    assert list(phases) == ["probes", "classify", "extract", "place", "simplify"]
    assert all(s >= 0 for s in phases.values()) and sum(phases.values()) <= report["seconds"] + 0.01
    cell = report["cell_size"]
    assert abs(cell - 1 / 16) < 1e-12 and report["resolution"] == 16
    # Every cube face bounds the solid; the output's chords stay within a cell of it.
    assert report["hausdorff_boundary_fraction"] == 1.0
    assert report["hausdorff"] == report["hausdorff_boundary"] < cell
    assert abs(report["hausdorff_cells"] * cell - report["hausdorff"]) < 1e-15
    assert report["occupancy_agreement"] > 0.99 and report["occupancy_samples"] == 4000
    assert report["method"] == "exact" and report["simplified"] is True
    # The same call without a report gives the same surface.
    V2, F2 = gwn.remesh(CUBE_V, CUBE_F, res=16, always_remesh=True)
    np.testing.assert_array_equal(V, V2)
    np.testing.assert_array_equal(F, F2)


def test_report_distances_see_cavities_and_inner_faces():
    # Two nested cubes, the inner one flipped: w is 0 inside it, so the output is a shell
    # with a cavity (two components, Euler characteristic 4), and its distance to the input
    # where it bounds the solid is small; with samples=0 neither is measured.
    inner = 0.25 + 0.5 * CUBE_V
    V = np.vstack([CUBE_V, inner])
    F = np.vstack([CUBE_F, CUBE_F[:, ::-1] + 8])
    _, _, report = gwn.remesh(V, F, res=24, report=True, samples=2000)
    assert report["components"] == 2 and report["euler_characteristic"] == 4
    assert report["hausdorff_boundary_cells"] < 1 and report["occupancy_agreement"] > 0.99
    # The inner cube not flipped: w = 2 inside it, the same solid as the outer cube alone;
    # the inner faces bound nothing, so the plain distance sees them and the boundary one not.
    F_same = np.vstack([CUBE_F, CUBE_F + 8])
    _, _, same = gwn.remesh(V, F_same, res=24, report=True, samples=2000)
    assert same["components"] == 1 and same["euler_characteristic"] == 2
    assert same["hausdorff_cells"] > 5 and same["hausdorff_boundary_cells"] < 1
    assert 0.4 < same["hausdorff_boundary_fraction"] < 0.9
    _, _, bare = gwn.remesh(V, F_same, res=24, report=True, samples=0)
    assert "hausdorff" not in bare and "occupancy_agreement" not in bare
    assert bare["self_intersections"] == 0


def test_report_of_thickened_sheets_counts_the_whole_input():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)
    F = np.array([[0, 1, 2], [0, 2, 3]])
    _, F2, report = gwn.remesh(V, F, res=24, thicken=0.08, report=True, samples=2000)
    assert report["thicken"] == 0.08 and report["faces"] == len(F2)
    # The slab's faces are EPS off the sheet: the plain distance, no boundary part.
    assert "hausdorff_boundary" not in report
    assert 0.05 < report["hausdorff"] < 0.2


def test_a_clean_solid_comes_back_as_it_is():
    """A closed, manifold, oriented mesh without self-intersections that bounds w > 1/2 is its
    own remesh (proved with exact tests); always_remesh=True remeshes it; the report says which
    and why, as ``gwn remesh --report`` does."""
    V, F, report = gwn.remesh(CUBE_V, CUBE_F, res=16, report=True, samples=2000)
    np.testing.assert_array_equal(V, CUBE_V)
    np.testing.assert_array_equal(F, CUBE_F)
    assert report["input"] == "kept" and report["self_intersections"] == 0
    assert report["hausdorff_boundary_cells"] == 0.0 and report["occupancy_agreement"] == 1.0
    Vr, Fr, remeshed = gwn.remesh(CUBE_V, CUBE_F, res=16, report=True, samples=0,
                                  always_remesh=True)
    assert len(Fr) > len(F) and "input" not in remeshed
    # Inward: w = -1 inside, so not its solid's boundary: the solid is empty, proved without
    # a lattice (no point classified).
    with pytest.warns(UserWarning, match="winds inward"):
        Vi, Fi, inward = gwn.remesh(CUBE_V, CUBE_F[:, ::-1], res=16, report=True, samples=0)
    assert inward["input"] == "bounds nothing" and len(Fi) == 0
    assert inward["classified_points"] == 0
    assert "w = 0 outside it and -1 inside" in inward["input_not_kept"]


def test_clean_parts_are_kept_and_the_rest_remeshed():
    """A clean cube beside an open box: the cube comes back as it is, the box's solid is
    remeshed, and the union is proved; the report says which part was kept."""
    far = CUBE_V + np.array([3.0, 0.2, 0.1])
    V = np.vstack([far, CUBE_V])
    F = np.vstack([CUBE_F, OPEN_BOX_F + 8])
    V2, F2, report = gwn.remesh(V, F, res=24, report=True, samples=2000)
    assert report["input"] == "partly kept"
    assert report["input_kept_components"] == 1 and report["input_components"] == 2
    assert report["input_kept_faces"] == 12 and "open" in report["input_not_kept"]
    np.testing.assert_array_equal(V2[:8], far)
    np.testing.assert_array_equal(F2[:12], CUBE_F)
    assert report["closed"] and report["self_intersections"] == 0 and len(F2) > 12


def test_overlapping_solids_are_cut_into_their_union():
    """A cube and a turned copy pushed into it (closed, self-intersecting): cut along their
    intersections and kept where w > 1/2, not remeshed; the result is exactly their union."""
    w, x, y, z = np.array([0.8813, 0.3377, 0.2291, 0.1517]) / np.linalg.norm(
        [0.8813, 0.3377, 0.2291, 0.1517])
    R = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])
    centred = CUBE_V - 0.5
    V = np.vstack([centred, centred @ R.T + np.array([0.6113, 0.3529, 0.2071])])
    F = np.vstack([CUBE_F, CUBE_F + 8])
    V2, F2, report = gwn.remesh(V, F, res=32, report=True, samples=4000)
    assert report["input"] == "cut", report.get("input_not_kept")
    assert report["input_intersecting_pairs"] > 0 and report["input_removed_faces"] > 0
    assert report["closed"] and report["self_intersections"] == 0
    assert report["occupancy_agreement"] == 1.0
    # Inside the union exactly where the input's w > 1/2.
    rng = np.random.default_rng(7)
    Q = rng.uniform(V.min(axis=0), V.max(axis=0), size=(2000, 3))
    before = gwn.winding_number(V, F, Q) > 0.5
    after = gwn.winding_number(V2, F2, Q) > 0.5
    np.testing.assert_array_equal(before, after)


def test_cubes_touching_at_a_corner_are_pulled_apart_and_kept():
    """Two cubes sharing one corner (welded into a vertex with two fans): that vertex becomes
    one per cube, each moved into its own cube by at most a 64th of a cell; every other vertex
    is the input's, bit for bit."""
    V = np.vstack([CUBE_V, CUBE_V + 1.0])
    F = np.vstack([CUBE_F, CUBE_F + 8])
    V2, F2, report = gwn.remesh(V, F, res=32, report=True, samples=4000)
    assert report["input"] == "kept", report.get("input_not_kept")
    assert report["input_separated_vertices"] == 1 and report["input_added_vertices"] == 1
    assert report["input_separated_edges"] == 0
    cell = (V.max() - V.min()) / 32
    assert 0 < report["input_largest_move"] <= cell / 64
    assert report["closed"] and report["vertex_manifold"] and report["self_intersections"] == 0
    assert len(F2) == len(F) and len(V2) == len(V)
    unmoved = {tuple(p) for p in V} & {tuple(p) for p in V2}
    assert len(unmoved) == len(V) - 2
