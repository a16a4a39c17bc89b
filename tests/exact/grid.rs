//! Voxel grids with ray reuse: identical to per-point evaluation, perturbation rule on faces.

use crate::common;

use gwn::BoundingBox;
use gwn::RayAxis;
use gwn::eval::antipodal::{Options, WindingNumber};
use gwn::grid::{GridSpec, evaluate, evaluate_per_point};

/// Grid vs per-point: every sample bit-identical (the column loop shares the `x, y` work of the
/// boundary term and the ray of the crossings, but not a single rounding); returns the count.
fn assert_grid_matches(wn: &WindingNumber, spec: &GridSpec, what: &str) -> usize {
    let grid = evaluate(wn, spec);
    let pts = spec.points();
    let reference = evaluate_per_point(wn, spec);
    assert_eq!(grid.len(), spec.len());
    for (i, (&g, &r)) in grid.iter().zip(&reference).enumerate() {
        assert_eq!(
            g.to_bits(),
            r.to_bits(),
            "{what}: sample {i} at {:?}: grid {g} vs per-point {r}",
            pts[i]
        );
    }
    grid.len()
}

/// The unit cube sampled at 0, 0.25, …, 1 on every axis: the cell centres of a 5³ grid over
/// [−0.125, 1.125]³ (all exact binary fractions), so 61 of 125 samples lie on the surface.
fn aligned_cube_grid() -> GridSpec {
    GridSpec::new(
        BoundingBox {
            min: [-0.125; 3],
            max: [1.125; 3],
        },
        [5, 5, 5],
    )
    .unwrap()
}

#[test]
fn aligned_grid_samples_are_exactly_on_the_faces() {
    let g = aligned_cube_grid();
    for i in 0..5 {
        assert_eq!(g.coord(0, i), i as f64 * 0.25);
    }
}

#[test]
fn unit_cube_on_face_samples_follow_the_perturbation_rule() {
    // Default ray +z: a sample on a face gets w at q + (ε1, ε2, ε3), towards +x, then +y, then +z.
    // So a sample is inside iff every coordinate is in [0, 1): 4 of the 5 values per axis.
    let cube = common::unit_cube();
    let wn = WindingNumber::new(&cube).unwrap();
    let g = aligned_cube_grid();
    let w = evaluate(&wn, &g);
    let inside = w.iter().filter(|&&v| v == 1.0).count();
    let outside = w.iter().filter(|&&v| v == 0.0).count();
    assert_eq!((inside, outside), (64, 61));
    for k in 0..5 {
        for j in 0..5 {
            for i in 0..5 {
                let want = if i < 4 && j < 4 && k < 4 { 1.0 } else { 0.0 };
                assert_eq!(w[g.index(i, j, k)], want, "({i}, {j}, {k})");
            }
        }
    }
    assert_eq!(assert_grid_matches(&wn, &g, "cube +z"), g.len());
}

#[test]
fn every_ray_axis_gives_the_per_point_values_on_and_off_the_surface() {
    let cube = common::unit_cube();
    let open = common::open_cube();
    for mesh in [&cube, &open] {
        for ray in RayAxis::ALL {
            let wn = WindingNumber::with_options(
                mesh,
                Options {
                    ray,
                    ..Options::default()
                },
            )
            .unwrap();
            assert_grid_matches(&wn, &aligned_cube_grid(), &format!("{ray:?}"));
            // A non-cubic grid, so that a wrong column/axis mapping cannot pass.
            let g = GridSpec::new(
                BoundingBox {
                    min: [-0.3, -0.2, -0.1],
                    max: [1.2, 1.4, 1.1],
                },
                [7, 5, 9],
            )
            .unwrap();
            assert_grid_matches(&wn, &g, &format!("{ray:?} 7x5x9"));
        }
    }
    // The open cube: fractional values inside, the closed cube: 1.
    let wn = WindingNumber::new(&open).unwrap();
    let g = GridSpec::new(
        BoundingBox {
            min: [0.0; 3],
            max: [1.0; 3],
        },
        [1, 1, 1],
    )
    .unwrap();
    assert!((evaluate(&wn, &g)[0] - 5.0 / 6.0).abs() < 1e-14);
}

#[test]
fn grid_equals_per_point_on_shared_meshes() {
    let Some(dir) = common::shared_meshes() else {
        return;
    };
    let manifest = std::fs::read_to_string(dir.join("manifest.csv")).unwrap();
    let mut meshes = 0;
    let mut samples = 0;
    let mut identical = 0;
    for line in manifest.lines().skip(1) {
        let name = line.split(',').next().unwrap();
        let loaded = match gwn::io::load_mesh(dir.join(name)) {
            Ok(l) => l,
            Err(e) => panic!("{name}: {e}"),
        };
        let mesh = loaded.mesh;
        let Some(bbox) = mesh.bounding_box() else {
            continue;
        };
        let wn = WindingNumber::new(&mesh).unwrap();
        // 12³ over the box grown by 10 %, and 8³ over the exact box: with an even number of
        // cells the middle planes hit mid-box coordinates, and with odd the vertex-bearing planes
        // of axis-aligned models (boxes, platforms) are sampled exactly.
        let big = GridSpec::new(bbox.enlarged(0.1), [12, 12, 12]).unwrap();
        let tight = GridSpec::new(bbox, [8, 7, 9]).unwrap();
        for g in [big, tight] {
            identical += assert_grid_matches(&wn, &g, name);
            samples += g.len();
        }
        meshes += 1;
    }
    eprintln!("{meshes} meshes, {samples} samples, {identical} bit-identical");
    assert_eq!(identical, samples);
    assert!(meshes >= 50);
}

#[test]
fn resolution_keeps_cells_nearly_cubic() {
    let b = BoundingBox {
        min: [0.0; 3],
        max: [4.0, 2.0, 1.0],
    };
    let g = GridSpec::with_resolution(b, 64).unwrap();
    assert_eq!(g.dims, [64, 32, 16]);
    assert_eq!(g.shape(), [16, 32, 64]);
    assert!(GridSpec::with_resolution(b, 0).is_err());
}
