//! The parity method (`gwn::eval::parity::CrossingParity`) against closed forms: closed meshes
//! with faces flipped at random, every ray, queries on vertices, edges and faces included.

use gwn::eval::Evaluator;
use gwn::eval::antipodal::{BuildError, Options, WindingNumber};
use gwn::eval::parity::{CrossingParity, EdgeCensus};
use gwn::testing::{Case, strategies};
use gwn::{Mesh, RayAxis};
use proptest::prelude::*;

/// `case`'s mesh with the faces whose bit is set in `flips` (cycled) reversed.
fn flipped(case: &Case, flips: &[bool]) -> Mesh {
    let triangles: Vec<[u32; 3]> = case
        .mesh
        .triangles()
        .iter()
        .enumerate()
        .map(|(f, &[a, b, c])| {
            if flips[f % flips.len()] {
                [a, c, b]
            } else {
                [a, b, c]
            }
        })
        .collect();
    Mesh::new(case.mesh.positions().to_vec(), triangles).unwrap()
}

fn parity_on(mesh: &Mesh, ray: RayAxis) -> CrossingParity {
    CrossingParity::with_options(
        mesh,
        Options {
            ray,
            ..Options::default()
        },
    )
    .unwrap()
}

/// The boxes' union (overlapping boxes: the even-odd rule) with flipped faces: at `q_ε` of every
/// ray the parity is the number of boxes containing it, mod 2, on and off the surface. The same
/// points batched (columns along the ray) give the same bits.
fn check_against_boxes(case: &Case, flips: &[bool]) -> Result<(), TestCaseError> {
    let mesh = flipped(case, flips);
    for ray in RayAxis::ALL {
        let parity = parity_on(&mesh, ray);
        let mut batch = Vec::new();
        for &q in &case.queries {
            let truth = case.box_truth(q, ray).unwrap() % 2;
            let got = parity.eval(q);
            prop_assert_eq!(got, f64::from(truth), "{:?} at {:?}", ray, q);
            batch.push(got);
        }
        prop_assert_eq!(Evaluator::eval_batch(&parity, &case.queries), batch);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn flipped_polycubes_give_the_occupancy(
        case in strategies::polycube(),
        flips in proptest::collection::vec(any::<bool>(), 1..17),
    ) {
        check_against_boxes(&case, &flips)?;
    }

    #[test]
    fn flipped_overlapping_boxes_give_the_even_odd_rule(
        case in strategies::boxes(),
        flips in proptest::collection::vec(any::<bool>(), 1..17),
    ) {
        check_against_boxes(&case, &flips)?;
    }

    /// Tetrahedra on one edge, flat ones included (zero-area faces, the shared edge with 2k
    /// faces): with faces flipped the parity is the oriented mesh's `w` mod 2, ray by ray, at
    /// every query (the same perturbed point: each crossing counts ±1 either way).
    #[test]
    fn flipped_tetrahedra_give_the_oriented_w_mod_2(
        case in strategies::tets(),
        flips in proptest::collection::vec(any::<bool>(), 1..17),
    ) {
        let mesh = flipped(&case, &flips);
        for ray in RayAxis::ALL {
            let oriented = WindingNumber::with_options(&case.mesh, Options { ray, ..Options::default() }).unwrap();
            let parity = parity_on(&mesh, ray);
            for &q in &case.queries {
                let w = oriented.eval(q);
                prop_assert_eq!(w, w.round(), "{:?} at {:?}", ray, q);
                prop_assert_eq!(parity.eval(q), w.rem_euclid(2.0), "{:?} at {:?}", ray, q);
            }
        }
    }

    /// Open meshes are refused with the number of edges that make them open.
    #[test]
    fn open_meshes_are_refused(case in strategies::open()) {
        let census = EdgeCensus::of(&case.mesh, Default::default());
        prop_assert!(census.odd_edges > 0);
        let e = CrossingParity::new(&case.mesh).unwrap_err();
        prop_assert_eq!(e.clone(), BuildError::NotClosed { odd_edges: census.odd_edges });
        prop_assert!(e.to_string().contains("edges have an odd number of faces"));
    }
}

/// The generator of inconsistently oriented polycubes: closed mod 2, a signed boundary, the
/// census says so, and the parity is 0 or 1 everywhere and ray-independent off the surface.
#[test]
fn inconsistent_polycubes_are_the_parity_method_s_case() {
    for seed in 0..40 {
        let case = gwn::testing::Kind::Inconsistent.generate(seed);
        let census = EdgeCensus::of(&case.mesh, Default::default());
        assert!(census.closed_but_not_oriented(), "{seed}: {census:?}");
        let first = parity_on(&case.mesh, RayAxis::PosZ);
        let others: Vec<CrossingParity> = RayAxis::ALL
            .into_iter()
            .map(|r| parity_on(&case.mesh, r))
            .collect();
        for &q in &case.queries {
            // Off the integer planes the faces lie on (queries are multiples of 1/8).
            let q = q.map(|c| c + 0.0625);
            let p = first.eval(q);
            assert!(p == 0.0 || p == 1.0);
            for o in &others {
                assert_eq!(o.eval(q), p, "{seed} {q:?}");
            }
        }
    }
}

#[test]
fn non_finite_queries_are_nan() {
    let case = gwn::testing::Kind::Polycube.generate(3);
    let parity = CrossingParity::new(&case.mesh).unwrap();
    assert!(parity.eval([f64::NAN, 0.0, 0.0]).is_nan());
    assert!(parity.eval([0.0, f64::INFINITY, 0.0]).is_nan());
}
