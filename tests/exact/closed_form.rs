//! Closed-form cases for the direct sum and the exact evaluator (foundation + kernel issues).

use crate::common;

use common::{open_cube, unit_cube};
use gwn::Precision;
use gwn::RayAxis;
use gwn::eval::antipodal::{Options, WindingNumber};
use gwn::eval::direct::winding_number_direct;

#[test]
fn cube_direct_inside_outside_far_corner_face() {
    let c = unit_cube();
    assert!((winding_number_direct(&c, [0.5, 0.5, 0.5]) - 1.0).abs() < 1e-15);
    assert!(winding_number_direct(&c, [1.5, 0.5, 0.5]).abs() < 1e-15);
    assert!(winding_number_direct(&c, [1000.0, 0.0, 0.0]).abs() < 1e-10);
    // On-surface semantics of the direct sum: the local solid-angle fraction.
    assert!((winding_number_direct(&c, [0.0, 0.0, 0.0]) - 0.125).abs() < 1e-14);
    assert!((winding_number_direct(&c, [1.0, 1.0, 1.0]) - 0.125).abs() < 1e-14);
    assert!((winding_number_direct(&c, [0.5, 0.5, 0.0]) - 0.5).abs() < 1e-14);
    assert!((winding_number_direct(&c, [0.3, 0.0, 0.7]) - 0.5).abs() < 1e-14);
    assert!((winding_number_direct(&c, [0.5, 0.0, 0.0]) - 0.25).abs() < 1e-14);
    for q in [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.5, 0.5, 0.0]] {
        assert!(!winding_number_direct(&c, q).is_nan());
    }
}

#[test]
fn open_cube_closed_form_values() {
    let m = open_cube();
    // From the centre the missing face subtends 4π/6: w = 1 − 1/6.
    let w = winding_number_direct(&m, [0.5, 0.5, 0.5]);
    assert!((w - 5.0 / 6.0).abs() < 1e-14, "{w}");
    // Centre of the missing face: by symmetry of the closed cube (1/2 on a face) w = 1/2.
    let w = winding_number_direct(&m, [0.5, 0.5, 1.0]);
    assert!((w - 0.5).abs() < 1e-14, "{w}");
    let wn = WindingNumber::new(&m).unwrap();
    assert!((wn.eval([0.5, 0.5, 0.5]) - 5.0 / 6.0).abs() < 1e-14);
    assert!((wn.eval([0.5, 0.5, 1.0]) - 0.5).abs() < 1e-14);
}

#[test]
fn exact_cube_is_integer_everywhere_off_and_on_the_surface() {
    let c = unit_cube();
    for precision in [Precision::Bits30, Precision::Bits60] {
        for ray in RayAxis::ALL {
            let wn = WindingNumber::with_options(
                &c,
                Options {
                    precision,
                    ray,
                    ..Default::default()
                },
            )
            .unwrap();
            assert_eq!(wn.boundary_edge_count(), 0);
            assert_eq!(wn.eval([0.5, 0.5, 0.5]), 1.0);
            assert_eq!(wn.eval([1.5, 0.5, 0.5]), 0.0);
            assert_eq!(wn.eval([1000.0, 0.0, 0.0]), 0.0);
            assert_eq!(wn.eval([0.5, 0.5, -1000.0]), 0.0);
            // On the surface: the value at the perturbed point, an integer.
            for q in [
                [0.0, 0.0, 0.0],
                [0.5, 0.5, 0.0],
                [1.0, 1.0, 1.0],
                [0.5, 0.0, 0.0],
                [0.25, 0.75, 1.0],
            ] {
                let w = wn.eval(q);
                assert!(w == 0.0 || w == 1.0, "{ray:?} {q:?} {w}");
            }
            // With the +z frame the perturbation points to +x first: (0,·,·) faces go inside,
            // (1,·,·) faces go outside.
            if ray == RayAxis::PosZ {
                assert_eq!(wn.eval([0.0, 0.5, 0.5]), 1.0);
                assert_eq!(wn.eval([1.0, 0.5, 0.5]), 0.0);
                assert_eq!(wn.eval([0.0, 0.0, 0.0]), 1.0);
            }
        }
    }
}

#[test]
fn flip_translate_concatenate() {
    let m = open_cube();
    let q = [0.2, 0.7, 0.4];
    let w = WindingNumber::new(&m).unwrap().eval(q);
    let wf = WindingNumber::new(&m.flipped()).unwrap().eval(q);
    assert!((w + wf).abs() < 1e-15);
    let off = [123.25, -7.5, 1e3];
    let mt = m.translated(off);
    let wt = WindingNumber::new(&mt)
        .unwrap()
        .eval([q[0] + off[0], q[1] + off[1], q[2] + off[2]]);
    assert!((w - wt).abs() < 1e-12, "{w} {wt}");
    let d = winding_number_direct(&mt, [q[0] + off[0], q[1] + off[1], q[2] + off[2]]);
    assert!((w - d).abs() < 1e-12);
    let twice = m.concatenated(&m).unwrap();
    let w2 = WindingNumber::new(&twice).unwrap().eval(q);
    assert!((w2 - 2.0 * w).abs() < 1e-14);
    assert!((winding_number_direct(&twice, q) - 2.0 * winding_number_direct(&m, q)).abs() < 1e-14);
    assert!((winding_number_direct(&m.flipped(), q) + winding_number_direct(&m, q)).abs() < 1e-15);
}

#[test]
fn empty_mesh_and_nan_query() {
    let e = gwn::Mesh::default();
    let wn = WindingNumber::new(&e).unwrap();
    assert_eq!(wn.eval([0.0; 3]), 0.0);
    assert_eq!(winding_number_direct(&e, [0.0; 3]), 0.0);
    assert!(
        WindingNumber::new(&unit_cube())
            .unwrap()
            .eval([f64::NAN, 0.0, 0.0])
            .is_nan()
    );
}

#[test]
fn query_on_boundary_vertices_and_edges_equals_the_perturbed_limit() {
    let m = open_cube();
    for ray in RayAxis::ALL {
        let wn = WindingNumber::with_options(
            &m,
            Options {
                ray,
                ..Default::default()
            },
        )
        .unwrap();
        for q in [
            [0.0, 0.0, 1.0],
            [0.5, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 0.5, 1.0],
            [1.0, 0.25, 1.0],
            [0.5, 0.5, 1.0],
            [0.0, 0.0, 0.5],
        ] {
            let w = wn.eval(q);
            let want = common::direct_at_perturbed(&m, q, ray, 1.0);
            assert!(
                (w - want).abs() < 1e-3,
                "{ray:?} {q:?}: {w} vs limit {want}"
            );
        }
    }
}

#[test]
fn astronomically_far_queries_are_finite_and_vanish() {
    // Once w was NaN beyond ~1e76 along the ray axis (the boundary products overflowed).
    let open = open_cube();
    let closed = unit_cube();
    let mut far = Vec::new();
    for big in [1e12, 1e100, 1e300, f64::MAX] {
        for axis in 0..3 {
            for sign in [-1.0, 1.0] {
                let mut q = [0.3, 0.6, 0.2];
                q[axis] = sign * big;
                far.push(q);
            }
        }
        far.push([big, -big, big]);
    }
    for precision in [Precision::Bits30, Precision::Bits60] {
        for ray in [RayAxis::PosZ, RayAxis::NegX] {
            let opts = Options {
                precision,
                ray,
                ..Default::default()
            };
            let wo = WindingNumber::with_options(&open, opts).unwrap();
            let wc = WindingNumber::with_options(&closed, opts).unwrap();
            for &q in &far {
                let v = wo.eval(q);
                assert!(v.abs() < 1e-15, "open cube at {q:?}: {v}");
                assert_eq!(wc.eval(q), 0.0, "closed cube at {q:?}");
                // ±1e200 along the ray axis: still far whichever coordinate of q was.
                let col = wo.eval_column(q, &[1e200, -1e200, f64::MAX]);
                assert!(
                    col.iter().all(|v| v.abs() < 1e-15),
                    "column at {q:?}: {col:?}"
                );
            }
        }
    }
}
