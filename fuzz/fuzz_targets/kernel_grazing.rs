//! Fuzzes the exact kernel on degenerate meshes of the integer grid −4..4 (decoder
//! `gwn::testing::soup_from_bytes`, shared with `tests/exact/exactness.rs`): off the surface, every
//! ray direction must give the same winding number; on and off it, each ray's value must lie
//! within 1e-10 of the rational oracle's narrow interval, and within 2e-3 of the direct sum at
//! the perturbed point; a column through the query (grids) gives the
//! query's value to the bit. Run: `cargo fuzz run --sanitizer none kernel_grazing -- -max_total_time=60`.
#![no_main]

use gwn::RayAxis;
use gwn::eval::antipodal::{Options, WindingNumber};
use gwn::testing::{on_surface, soup_from_bytes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let case = soup_from_bytes(data);
    let base = WindingNumber::new(&case.mesh).unwrap();
    let bad = gwn::testing::oracle_disagreements(&case.mesh, &case.queries, 1e-10);
    assert!(bad.is_empty(), "the oracle: {bad:?}");
    for &q in &case.queries {
        let w0 = base.eval(q);
        assert!(w0.is_finite());
        let on = on_surface(&case.mesh, q);
        for ray in RayAxis::ALL {
            let wn = WindingNumber::with_options(
                &case.mesh,
                Options {
                    ray,
                    ..Default::default()
                },
            )
            .unwrap();
            let w = wn.eval(q);
            // Columns (grids) share the crossing ray and the boundary loop's x, y work: the
            // same bits as the point on its own, on and off the lattice along the column.
            let axis = ray.map()[2].0;
            let column = wn.eval_column(q, &[q[axis] - 1.5, q[axis], q[axis] + 0.25]);
            assert_eq!(column[1].to_bits(), w.to_bits(), "{ray:?} {q:?}: column");
            if !on {
                assert!((w - w0).abs() < 1e-10, "{ray:?} {q:?}: {w} vs {w0}");
            }
            let want = gwn::testing::direct_at_perturbed(&case.mesh, q, ray, 1.0);
            assert!(
                (w - want).abs() < 2e-3,
                "{ray:?} {q:?}: {w} vs perturbed direct {want}"
            );
        }
    }
});
