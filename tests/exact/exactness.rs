//! The kernel issue's oracles: grazing cases on small integer grids (proptest, shrinking),
//! closed self-intersecting shells (exact integer answers), direction independence. The byte
//! decoders live in `gwn::testing` (shared with the `kernel_grazing` fuzz target).

use crate::common;

use gwn::Precision;
use gwn::RayAxis;
use gwn::eval::antipodal::{Options, WindingNumber};
use gwn::testing::{boxes_from_bytes, on_surface, soup_from_bytes as decode};
use proptest::prelude::*;

/// Every ray direction and both precisions, against the certified rational oracle (a narrow
/// interval, within 1e-10) and the direct sum at the perturbed point (2e-3).
fn check_grazing(bytes: &[u8]) -> Result<(), TestCaseError> {
    let case = decode(bytes);
    for precision in [Precision::Bits30, Precision::Bits60] {
        for ray in RayAxis::ALL {
            let oracle = gwn::testing::Oracle::new(&case.mesh, ray);
            let wn = WindingNumber::with_options(
                &case.mesh,
                Options {
                    precision,
                    ray,
                    ..Default::default()
                },
            )
            .unwrap();
            for &q in &case.queries {
                let w = wn.eval(q);
                let certified = oracle.eval(q);
                prop_assert!(
                    certified.is_narrow() && certified.contains(w, 1e-10),
                    "{precision:?} {ray:?} q={q:?}: exact {w} vs certified [{}, {}]\n{:?}",
                    certified.lo,
                    certified.hi,
                    case.mesh
                );
                let want = common::direct_at_perturbed(&case.mesh, q, ray, 1.0);
                prop_assert!(
                    (w - want).abs() < 2e-3,
                    "{precision:?} {ray:?} q={q:?}: exact {w} vs perturbed direct {want}\n{:?}",
                    case.mesh
                );
                // Column evaluation (ray reuse) is bit-identical to per-point evaluation.
                let axis = ray.map()[2].0;
                let col = wn.eval_column(q, &[q[axis] - 1.5, q[axis], q[axis] + 0.5]);
                prop_assert_eq!(col[1].to_bits(), w.to_bits());
            }
        }
    }
    Ok(())
}

/// Off the surface, the value does not depend on the ray direction.
fn check_direction_independence(bytes: &[u8]) -> Result<(), TestCaseError> {
    let case = decode(bytes);
    let base = WindingNumber::new(&case.mesh).unwrap();
    let mut queries = case.queries.clone();
    // Points in general position too: quarter offsets.
    queries.extend(
        case.queries
            .iter()
            .map(|q| [q[0] + 0.25, q[1] - 0.375, q[2] + 0.125]),
    );
    for q in queries {
        if on_surface(&case.mesh, q) {
            continue;
        }
        let w0 = base.eval(q);
        for ray in RayAxis::ALL {
            let w = WindingNumber::with_options(
                &case.mesh,
                Options {
                    ray,
                    ..Default::default()
                },
            )
            .unwrap()
            .eval(q);
            prop_assert!((w - w0).abs() < 1e-10, "{ray:?} q={q:?}: {w} vs {w0}");
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn grazing_queries_equal_the_perturbed_limit(bytes in proptest::collection::vec(any::<u8>(), 0..96)) {
        check_grazing(&bytes)?;
    }

    #[test]
    fn off_surface_values_do_not_depend_on_the_ray(bytes in proptest::collection::vec(any::<u8>(), 0..96)) {
        check_direction_independence(&bytes)?;
    }

    #[test]
    fn unions_of_boxes_give_exact_integers(bytes in proptest::collection::vec(any::<u8>(), 0..40), q in proptest::array::uniform3(-20i32..20)) {
        let case = boxes_from_bytes(&bytes);
        let (mesh, bs) = (case.mesh, case.boxes);
        // Quarter-grid queries: on faces, edges and corners of the boxes whenever q is integral.
        let q = q.map(|v| f64::from(v) * 0.25);
        let off_surface = q.iter().all(|c| c.fract() != 0.0);
        let truth = bs.iter().filter(|(lo, hi)| (0..3).all(|k| lo[k] < q[k] && q[k] < hi[k])).count() as f64;
        for precision in [Precision::Bits30, Precision::Bits60] {
            for ray in RayAxis::ALL {
                let wn = WindingNumber::with_options(&mesh, Options { precision, ray, ..Default::default() }).unwrap();
                let w = wn.eval(q);
                prop_assert_eq!(w.fract(), 0.0, "non-integer {} at {:?}", w, q);
                if off_surface {
                    prop_assert_eq!(w, truth, "{:?} {:?} at {:?}", precision, ray, q);
                } else {
                    // On the surface: the count of boxes containing the perturbed point.
                    let d = ray.to_world([1e-3, 1e-6, 1e-9]);
                    let qe = [q[0] + d[0], q[1] + d[1], q[2] + d[2]];
                    let t = bs.iter().filter(|(lo, hi)| (0..3).all(|k| lo[k] < qe[k] && qe[k] < hi[k])).count() as f64;
                    prop_assert_eq!(w, t, "on-surface {:?} {:?} at {:?}", precision, ray, q);
                }
            }
        }
    }
}

/// Replays the cargo-fuzz corpus of the kernel target on stable, so CI runs it.
#[test]
fn fuzz_corpus_replays() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/kernel_grazing");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        panic!("fuzz corpus {} missing", dir.display());
    };
    let mut n = 0;
    for e in entries {
        let bytes = std::fs::read(e.unwrap().path()).unwrap();
        check_grazing(&bytes).unwrap();
        check_direction_independence(&bytes).unwrap();
        n += 1;
    }
    assert!(n >= 8, "corpus too small: {n}");
}

#[test]
fn precisions_agree_away_from_the_surface() {
    let m = common::open_cube();
    let w30 = WindingNumber::with_options(
        &m,
        Options {
            precision: Precision::Bits30,
            ..Default::default()
        },
    )
    .unwrap();
    let w60 = WindingNumber::new(&m).unwrap();
    let mut rng = common::Rng(7);
    for _ in 0..2000 {
        let q = [
            rng.range(-1.0, 2.0),
            rng.range(-1.0, 2.0),
            rng.range(-1.0, 2.0),
        ];
        // 30-bit snapping moves q by < 3e-9: the value moves by far less than 1e-5 here.
        assert!((w30.eval(q) - w60.eval(q)).abs() < 1e-5);
        assert!((w60.eval(q) - gwn::eval::direct::winding_number_direct(&m, q)).abs() < 1e-12);
    }
}
