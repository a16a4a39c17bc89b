//! `RemeshOptions::sub_cell_levels`: cells that an input triangle crosses while their corners
//! agree are cut below the resolution, with the transition split between levels. Parts thinner
//! than a cell come back; every guarantee (closed, manifold, oriented, no self-intersection)
//! holds on any labelling, refined or not.

use gwn::Mesh;
use gwn::eval::antipodal::WindingNumber;
use gwn::products::remesh::crossings::SegmentBvh;
use gwn::products::remesh::report::hausdorff_distance;
use gwn::products::remesh::{RemeshError, RemeshOptions, remesh, remesh_guided};
use proptest::prelude::*;

use crate::remesh::{
    assert_closed_manifold, assert_guarantees_on, run_with, sphere, with_flipped_faces,
};

fn with_levels(res: usize, levels: u32) -> RemeshOptions {
    RemeshOptions {
        sub_cell_levels: levels,
        ..RemeshOptions::with_resolution(res)
    }
}

/// A box of edges `size`, rotated about z by `a` and about x by `b`, centred at `c`.
fn tilted_box(size: [f64; 3], a: f64, b: f64, c: [f64; 3]) -> Mesh {
    let cube = crate::common::unit_cube();
    let (sa, ca, sb, cb) = (a.sin(), a.cos(), b.sin(), b.cos());
    let v: Vec<[f64; 3]> = cube
        .positions()
        .iter()
        .map(|p| {
            let q = [0, 1, 2].map(|k| (p[k] - 0.5) * size[k]);
            let r = [ca * q[0] - sa * q[1], sa * q[0] + ca * q[1], q[2]];
            let s = [r[0], cb * r[1] - sb * r[2], sb * r[1] + cb * r[2]];
            [s[0] + c[0], s[1] + c[1], s[2] + c[2]]
        })
        .collect();
    Mesh::new(v, cube.triangles().to_vec()).unwrap()
}

/// A ball and, beside it, a tilted plate half a cell thick (no lattice plane follows it): at the
/// resolution alone the plate comes out in pieces where a corner happens to fall inside it, more
/// than a cell from much of it; two levels below find it all, within a cell. Both outputs keep
/// every guarantee (checked exactly by `run_with`).
#[test]
fn a_plate_thinner_than_a_cell_comes_back_with_sub_cell_levels() {
    let res = 32;
    let ball = sphere([0.0, 0.0, 0.0], 1.0, 24, false);
    // The box is about 4.4 wide: cells of ~0.14; the plate is 0.07 thick.
    let cell = 4.4 / res as f64;
    let plate = tilted_box([1.6, 1.4, 0.5 * cell], 0.5, 0.7, [2.3, 0.3, 0.1]);
    let mesh = ball.concatenated(&plate).unwrap();
    let mut distances = Vec::new();
    for levels in [0, 2] {
        let (out, report) = run_with(&mesh, &with_levels(res, levels));
        assert_closed_manifold(&report);
        let out_mesh = Mesh::new(out.positions.clone(), out.triangles.clone()).unwrap();
        let d = hausdorff_distance(&mesh, &out_mesh, 20_000, 3).unwrap() / out.cell_size;
        distances.push((levels, d, out.stats.refined_cells, report.components));
    }
    let (_, coarse, none_refined, _) = distances[0];
    let (_, fine, refined, components) = distances[1];
    assert_eq!(none_refined, 0);
    assert!(coarse > 1.5, "{distances:?}");
    assert!(fine < 1.0, "{distances:?}");
    assert!(refined > 0, "{distances:?}");
    // The ball and the plate, in one piece each.
    assert_eq!(components, 2, "{distances:?}");
}

/// Away from thin parts nothing changes much: a ball refines few cells (where the sphere bulges
/// into a cell between its corners), keeps its shape within a cell, and sub-cell levels in the
/// options without the input triangles (no guide) refine nothing.
#[test]
fn a_ball_refines_few_cells() {
    let ball = sphere([0.0; 3], 1.0, 32, false);
    let (out, report) = run_with(&ball, &with_levels(32, 2));
    assert_closed_manifold(&report);
    assert_eq!((report.euler_characteristic, report.components), (2, 1));
    assert!(
        out.stats.refined_cells * 10 < out.stats.band_cells,
        "{:?}",
        out.stats
    );
    let out_mesh = Mesh::new(out.positions.clone(), out.triangles.clone()).unwrap();
    assert!(hausdorff_distance(&ball, &out_mesh, 4000, 1).unwrap() < out.cell_size);
    let wn = WindingNumber::new(&ball).unwrap();
    let unguided = remesh(&wn, ball.bounding_box().unwrap(), &with_levels(32, 2)).unwrap();
    assert_eq!(unguided.stats.refined_cells, 0);
    assert_eq!(
        remesh(&wn, ball.bounding_box().unwrap(), &with_levels(32, 4)),
        Err(RemeshError::BadSubCellLevels { levels: 4 })
    );
}

/// Overlapping parts: the faces of each box inside the other cross many cells whose corners
/// all agree (inside), but `w` is above ½ on both sides of them, so they hide nothing and cut
/// no cell; only what each box alone cuts (where an edge of a box pokes into a cell between
/// its corners) is cut. Without the probe on both sides of the crossing triangles, each inner
/// face would cut every cell it crosses.
#[test]
fn inner_faces_of_overlapping_parts_cut_no_cells() {
    let res = 24;
    let a = tilted_box([2.0, 1.6, 1.2], 0.4, 0.3, [0.0, 0.0, 0.0]);
    let b = tilted_box([1.8, 1.4, 1.6], -0.3, 0.6, [0.6, 0.3, 0.2]);
    let both = a.concatenated(&b).unwrap();
    let refined = |mesh: &Mesh| {
        let (out, report) = run_with(mesh, &with_levels(res, 2));
        assert_closed_manifold(&report);
        (out.stats.refined_cells, out.stats.band_cells)
    };
    let (alone_a, _) = refined(&a);
    let (alone_b, _) = refined(&b);
    let (overlapping, band) = refined(&both);
    assert!(
        overlapping <= alone_a + alone_b,
        "{overlapping} cells cut for the union, {alone_a} + {alone_b} for the boxes alone \
         ({band} band cells)"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Every generator of the testing kit (soups, boxes, polycubes, T-junctions, open and
    /// inconsistent meshes, fans, tets) as the guide, with its own winding number or with noise
    /// as the field: at any sub-cell level the surface is closed, manifold, oriented and free of
    /// self-intersections (exact), simplified or not.
    #[test]
    fn sub_cell_levels_keep_every_guarantee(
        case in gwn::testing::strategies::any_case(),
        levels in 1u32..=3,
        noise in any::<bool>(),
        simplify in any::<bool>(),
        res in 6usize..14,
    ) {
        let mut options = with_levels(res, levels);
        if !simplify {
            options.simplify = None;
        }
        assert_guarantees_on(&case.mesh, &options, noise.then_some(res as f64 * 0.9));
    }
}

/// A gently wavy open sheet: `w` is near ½ on its inner side, and the level set ½ folds on and
/// off the sheet wherever it bends, making blisters thinner than a cell all over it. They are
/// no solid that the input bounds (`w` there is far from 0 and 1), so no cell is cut for them
/// (`octree::THIN_PART_MARGIN`); without the margin, 1,146 cells were cut at res 48 and the
/// output had 100 components instead of 14.
#[test]
fn a_wavy_open_sheet_cuts_no_cells() {
    let n = 40;
    let positions: Vec<[f64; 3]> = (0..=n)
        .flat_map(|j| {
            (0..=n).map(move |i| {
                let (x, y) = (
                    -1.0 + 2.0 * i as f64 / n as f64,
                    -1.0 + 2.0 * j as f64 / n as f64,
                );
                [x, y, 0.08 * (4.0 * x).sin() * (4.0 * y).sin()]
            })
        })
        .collect();
    let triangles: Vec<[u32; 3]> = (0..n)
        .flat_map(|j| {
            (0..n).flat_map(move |i| {
                let a = (j * (n + 1) + i) as u32;
                let (b, c) = (a + 1, a + n as u32 + 1);
                [[a, b, c + 1], [a, c + 1, c]]
            })
        })
        .collect();
    let sheet = Mesh::new(positions, triangles).unwrap();
    let (flat, report) = run_with(&sheet, &with_levels(48, 0));
    assert_closed_manifold(&report);
    // The blisters are there at the resolution: the level set does leave the sheet.
    assert!(report.components > 1, "{report:?}");
    let (out, report) = run_with(&sheet, &with_levels(48, 2));
    assert_closed_manifold(&report);
    assert_eq!(out.stats.refined_cells, 0, "{:?}", out.stats);
    assert_eq!(out.triangles.len(), flat.triangles.len());
}

/// An inconsistently oriented input (a ball with every other face flipped: half its edges on
/// the signed boundary) beside a thin tilted plate: the thin-part probes are screened by the
/// Barnes–Hut approximation (`SegmentBvh::of_field_mesh`) and the exact field is evaluated only
/// where it leaves a hidden part possible. The screen must find every cell the exact probes
/// find: the same cells cut, the same output, bit for bit, as with the unscreened guide.
#[test]
fn screened_probes_cut_the_cells_exact_probes_cut() {
    let res = 32;
    let ball = with_flipped_faces(&sphere([0.0, 0.0, 0.0], 1.0, 24, false), |i| i % 2 == 1);
    let cell = 4.4 / res as f64;
    let plate = tilted_box([1.6, 1.4, 0.5 * cell], 0.5, 0.7, [2.3, 0.3, 0.1]);
    let mesh = ball.concatenated(&plate).unwrap();
    let wn = WindingNumber::new(&mesh).unwrap();
    let options = with_levels(res, 2);
    let run = |guide: &SegmentBvh| {
        remesh_guided(
            &wn,
            Some(guide),
            mesh.bounding_box().unwrap(),
            &options,
            &|_| {},
        )
        .unwrap()
    };
    let screened_guide = SegmentBvh::of_field_mesh(&mesh);
    assert!(screened_guide.approximate_winding_number().is_some());
    let exact = run(&SegmentBvh::of_mesh(&mesh));
    let screened = run(&screened_guide);
    assert!(exact.stats.refined_cells > 0, "{:?}", exact.stats);
    assert_eq!(screened.stats.refined_cells, exact.stats.refined_cells);
    assert_eq!(screened.positions, exact.positions);
    assert_eq!(screened.triangles, exact.triangles);
    // A consistently oriented input is not screened: its exact probes are cheap.
    assert!(
        SegmentBvh::of_field_mesh(&plate)
            .approximate_winding_number()
            .is_none()
    );
}
