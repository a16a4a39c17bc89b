//! `RemeshOptions::planar_levels`: cells up to `2^N` resolution cells wide stay whole where the
//! input in them is flat and `w` is an integer at their corners, and are cut down to the
//! resolution's cell everywhere else, with the transition split between levels. Flat faces then
//! cost cells by their area in large cells; every guarantee (closed, manifold, oriented, no
//! self-intersection) holds on any labelling; where the input is not flat (a sphere) or `w` is
//! not an integer (an open box) the output stays as close as at the resolution alone.

use gwn::Mesh;
use gwn::eval::antipodal::WindingNumber;
use gwn::products::remesh::crossings::SegmentBvh;
use gwn::products::remesh::report::{hausdorff_distance, occupancy_agreement};
use gwn::products::remesh::{RemeshError, RemeshOptions, Remeshed, remesh_guided};
use proptest::prelude::*;

use crate::remesh::{assert_closed_manifold, assert_guarantees_on, run_with, sphere};

/// All `planar` levels, whatever the flatness probe would find.
fn with_planar(res: usize, planar: u32) -> RemeshOptions {
    RemeshOptions {
        planar_levels: planar,
        probe_flatness: false,
        ..RemeshOptions::with_resolution(res)
    }
}

/// `mesh` rotated about z by `a` and about x by `b`.
fn rotated(mesh: &Mesh, a: f64, b: f64) -> Mesh {
    let (sa, ca, sb, cb) = (a.sin(), a.cos(), b.sin(), b.cos());
    let v: Vec<[f64; 3]> = mesh
        .positions()
        .iter()
        .map(|q| {
            let r = [ca * q[0] - sa * q[1], sa * q[0] + ca * q[1], q[2]];
            [r[0], cb * r[1] - sb * r[2], sb * r[1] + cb * r[2]]
        })
        .collect();
    Mesh::new(v, mesh.triangles().to_vec()).unwrap()
}

/// Hausdorff distance in cells and occupancy agreement of an output against its input.
fn distance_and_agreement(mesh: &Mesh, out: &Remeshed) -> (f64, f64) {
    let out_mesh = Mesh::new(out.positions.clone(), out.triangles.clone()).unwrap();
    let d = hausdorff_distance(mesh, &out_mesh, 20_000, 5).unwrap() / out.cell_size;
    let wi = WindingNumber::new(mesh).unwrap();
    let wo = WindingNumber::new(&out_mesh).unwrap();
    let a = occupancy_agreement(&wi, &wo, mesh.bounding_box().unwrap(), 20_000, 9).unwrap();
    (d, a)
}

/// A tilted box (no face on a lattice plane): its six faces stay in large cells, only the cells
/// along its edges are cut to the resolution's, so the band holds far fewer cells (3 levels at
/// res 64: a quarter), and the output is as close (every vertex on the input within a tick, whatever the
/// cell's size) and as closed.
#[test]
fn a_tilted_box_keeps_large_cells_on_its_faces() {
    let mesh = rotated(&crate::common::unit_cube(), 0.4, 0.7);
    let (flat, flat_report) = run_with(&mesh, &with_planar(64, 0));
    let (coarse, coarse_report) = run_with(&mesh, &with_planar(64, 3));
    for r in [&flat_report, &coarse_report] {
        assert_closed_manifold(r);
        assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
    }
    assert_eq!(
        (flat.stats.planar_levels, coarse.stats.planar_levels),
        (0, 3)
    );
    assert!(
        coarse.stats.band_cells * 3 < flat.stats.band_cells,
        "{} band cells with 3 planar levels, {} without",
        coarse.stats.band_cells,
        flat.stats.band_cells
    );
    // Same unit: the report's cell is the resolution's either way.
    assert_eq!(flat.cell_size, coarse.cell_size);
    let (d0, a0) = distance_and_agreement(&mesh, &flat);
    let (d3, a3) = distance_and_agreement(&mesh, &coarse);
    assert!(
        d3 < 0.5 && d3 < d0 + 0.25,
        "{d3} cells with planar levels, {d0} without"
    );
    assert!(
        a3 > 0.999 && a3 >= a0 - 0.0005,
        "{a3} with planar levels, {a0} without"
    );
}

/// With planar levels (and sub-cell levels) every edge places its vertex on one grid, the
/// largest cubes' ticks, whatever its own level: on the raw surface of a box, the vertices of
/// each side (away from its edges) lie on one plane of the fixed-point grid, although the
/// side's cells are of several sizes (with a grid per level they were a fraction of a tick
/// apart, and no vertex star across levels was flat for the simplification; with sub-cell
/// levels the grid was the planar cubes', not the largest cubes', until 2026-12-05).
#[test]
fn the_vertices_of_a_side_lie_on_one_plane_at_every_level() {
    let cube = crate::common::unit_cube().translated([0.013, -0.021, 0.007]);
    for sub_cell_levels in [0, 1, 2] {
        let (raw, report) = run_with(
            &cube,
            &RemeshOptions {
                simplify: None,
                sub_cell_levels,
                ..with_planar(48, 3)
            },
        );
        assert_closed_manifold(&report);
        assert!(raw.stats.planar_levels >= 2, "{}", raw.stats.planar_levels);
        let (lo, hi) = ([0.013, -0.021, 0.007], [1.013, 0.979, 1.007]);
        let h = raw.cell_size;
        for axis in 0..3 {
            for side in [lo[axis], hi[axis]] {
                let mut planes = std::collections::BTreeMap::new();
                for (p, f) in raw.positions.iter().zip(&raw.fixed) {
                    let inner = (0..3)
                        .filter(|&a| a != axis)
                        .all(|a| p[a] > lo[a] + 2.0 * h && p[a] < hi[a] - 2.0 * h);
                    if inner && (p[axis] - side).abs() < 0.5 * h {
                        *planes.entry(f[axis]).or_insert(0) += 1;
                    }
                }
                assert_eq!(
                    planes.len(),
                    1,
                    "{sub_cell_levels} sub-cell levels, side {side} on axis {axis}: vertices on \
                     planes {planes:?}"
                );
                assert!(planes.values().sum::<usize>() > 100, "{planes:?}");
            }
        }
    }
}

/// A sphere is nowhere flat within a tenth of a cell at this resolution: its band is cut to the
/// resolution's cells, and the output stays within a cell, one closed genus-0 piece.
#[test]
fn a_sphere_is_cut_to_the_resolution() {
    let ball = sphere([0.1, -0.2, 0.3], 1.0, 32, false);
    let (out, report) = run_with(&ball, &with_planar(48, 2));
    assert_closed_manifold(&report);
    assert_eq!((report.euler_characteristic, report.components), (2, 1));
    let (d, a) = distance_and_agreement(&ball, &out);
    assert!(d < 1.0, "{d}");
    assert!(a > 0.999, "{a}");
}

/// An open box: `w` is not an integer anywhere near its hole, so no cell there stays whole, and
/// the film across the hole comes out as at the resolution alone.
#[test]
fn an_open_box_is_cut_where_w_is_not_an_integer() {
    let mesh = rotated(&crate::common::open_cube(), 0.3, 0.5);
    let (flat, flat_report) = run_with(&mesh, &with_planar(40, 0));
    let (coarse, coarse_report) = run_with(&mesh, &with_planar(40, 2));
    assert_closed_manifold(&flat_report);
    assert_closed_manifold(&coarse_report);
    let (_, a0) = distance_and_agreement(&mesh, &flat);
    let (_, a2) = distance_and_agreement(&mesh, &coarse);
    assert!(a2 >= a0 - 0.001, "{a2} with planar levels, {a0} without");
    assert_eq!(coarse_report.components, flat_report.components);
}

/// The flatness probe (the default) takes levels for a box, none for a finely
/// tessellated sphere (curved in every cell above the resolution's) or an open box (`w` is not
/// an integer next to its faces), and the probe's fractions say why.
#[test]
fn the_flatness_probe_takes_levels_where_they_pay() {
    let probe = |mesh: &Mesh, res: usize| {
        let (out, report) = run_with(mesh, &RemeshOptions::with_resolution(res));
        assert_closed_manifold(&report);
        out.stats
    };
    let tilted = probe(&rotated(&crate::common::unit_cube(), 0.4, 0.7), 64);
    // At res 64 a cell 8 resolution cells wide is an eighth of the box: half of them hold an
    // edge, so the probe takes 2 levels (a band of ~30 % of the uniform one) over 3 (~48 %).
    assert!(tilted.planar_levels >= 2, "{:?}", tilted.flatness);
    assert!(
        tilted.flatness.flat_fraction[1] > 0.8,
        "{:?}",
        tilted.flatness
    );
    let ball = probe(&sphere([0.0; 3], 1.0, 96, false), 64);
    assert_eq!(ball.planar_levels, 0, "{:?}", ball.flatness);
    assert!(ball.flatness.flat_fraction[2] < 0.2, "{:?}", ball.flatness);
    let open = probe(&rotated(&crate::common::open_cube(), 0.3, 0.5), 64);
    assert_eq!(open.planar_levels, 0, "{:?}", open.flatness);
    assert!(open.flatness.flat_fraction[1] < 0.1, "{:?}", open.flatness);
}

/// Planar levels need the input triangles; more than the limit is an error.
#[test]
fn planar_levels_beyond_the_limit_are_refused() {
    let mesh = crate::common::unit_cube();
    let wn = WindingNumber::new(&mesh).unwrap();
    let guide = SegmentBvh::of_mesh(&mesh);
    let bounds = mesh.bounding_box().unwrap();
    assert_eq!(
        remesh_guided(&wn, Some(&guide), bounds, &with_planar(32, 4), &|_| {}).err(),
        Some(RemeshError::BadPlanarLevels { levels: 4 })
    );
    // Without the triangles nothing says where the input is flat: the resolution's lattice.
    let unguided = remesh_guided(&wn, None, bounds, &with_planar(32, 3), &|_| {}).unwrap();
    assert_eq!(unguided.stats.planar_levels, 0);
    // Too coarse a lattice at this resolution: fewer levels.
    let small = remesh_guided(&wn, Some(&guide), bounds, &with_planar(20, 3), &|_| {}).unwrap();
    assert_eq!(small.stats.planar_levels, 1);
}

proptest! {
    // 16 cases: the seeds are random, so runs add coverage up. A noisy field makes a surface in
    // every band cell, which the simplification then takes apart: such cases cost up to 100x a
    // winding number's at the same resolution (one took 23 s of the products binary's 100 at
    // res 37), so noise takes the low third of the resolutions (16..24): the same code paths,
    // on fewer cells.
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// Every generator of the testing kit as the guide, with its own winding number or with
    /// noise (integers everywhere: flat cells keep any labelling) as the field, with planar
    /// levels and sub-cell levels together: the surface is closed, manifold, oriented and free
    /// of self-intersections (exact), simplified or not.
    #[test]
    fn planar_levels_keep_every_guarantee(
        case in gwn::testing::strategies::any_case(),
        planar in 1u32..=3,
        sub in 0u32..=2,
        noise in any::<bool>(),
        simplify in any::<bool>(),
        res in 16usize..40,
    ) {
        let res = if noise { 16 + (res - 16) / 3 } else { res };
        let mut options = RemeshOptions {
            sub_cell_levels: sub,
            ..with_planar(res, planar)
        };
        if !simplify {
            options.simplify = None;
        }
        assert_guarantees_on(&case.mesh, &options, noise.then_some(res as f64 * 0.3));
    }
}
