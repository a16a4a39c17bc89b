//! Property tests of the patch evaluator: closed patch sets split and perturbed at random stay
//! integer-valued off the surface, for every ray (exact integers when every edge has its twin);
//! random open patches agree with tessellations.

use crate::common;
use gwn::RayAxis;
use gwn::eval::antipodal::WindingNumber;
use gwn::patch::tessellate::tessellate;
use gwn::patch::{Options, Patch, PatchSet, PatchWindingNumber};

use proptest::prelude::*;

/// The unit sphere as 8 rational biquadratic patches, outward (shared with `tests/patches.rs`).
fn sphere() -> Vec<Patch> {
    common::rational_sphere_patches()
}

/// The unit cube's six faces as planar bicubic patches, outward.
fn cube() -> Vec<Patch> {
    let faces = [
        ([0., 0., 0.], [0., 1., 0.], [1., 0., 0.]),
        ([0., 0., 1.], [1., 0., 0.], [0., 1., 0.]),
        ([0., 0., 0.], [0., 0., 1.], [0., 1., 0.]),
        ([1., 0., 0.], [0., 1., 0.], [0., 0., 1.]),
        ([0., 0., 0.], [1., 0., 0.], [0., 0., 1.]),
        ([0., 1., 0.], [0., 0., 1.], [1., 0., 0.]),
    ];
    faces
        .iter()
        .map(|&(o, a, b)| {
            let mut pts = Vec::new();
            for i in 0..4 {
                for j in 0..4 {
                    // Every coordinate is 0, 1 or i/3 computed the same way on both faces of
                    // an edge, so shared edges have the same bits (and perturb together).
                    let (s, t) = (f64::from(i) / 3.0, f64::from(j) / 3.0);
                    pts.push([0, 1, 2].map(|c| o[c] + t * a[c] + s * b[c]));
                }
            }
            Patch::polynomial(3, 3, pts).unwrap()
        })
        .collect()
}

/// Moves every control point by a deterministic function of its bits, so that copies of a
/// point shared by several patches move together and the set stays closed.
fn perturb(patches: &[Patch], amount: f64, seed: u64) -> Vec<Patch> {
    let offset = |p: [f64; 3]| {
        let mut h = seed;
        for c in p {
            h ^= (c + 0.0).to_bits();
            h = h.wrapping_mul(0x9e37_79b9_7f4a_7c15).rotate_left(29);
        }
        [0, 1, 2].map(|k| {
            let bits = h.rotate_left(21 * k as u32) >> 11;
            amount * (2.0 * (bits as f64 / (1u64 << 53) as f64) - 1.0)
        })
    };
    patches
        .iter()
        .map(|p| {
            let (m, n) = p.degree();
            let pts = p
                .points()
                .iter()
                .map(|&x| {
                    let o = offset(x);
                    [x[0] + o[0], x[1] + o[1], x[2] + o[2]]
                })
                .collect();
            Patch::rational(m, n, pts, p.weights().to_vec()).unwrap()
        })
        .collect()
}

/// Splits patch `k % len` at `tau` along s or t, `times` times.
fn split_some(mut patches: Vec<Patch>, cuts: &[(usize, bool, f64)]) -> Vec<Patch> {
    for &(k, along_s, tau) in cuts {
        let i = k % patches.len();
        let (a, b) = patches[i].split(along_s, tau);
        patches[i] = a;
        patches.push(b);
    }
    patches
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn split_and_perturbed_closed_sets_stay_integer(
        use_sphere in any::<bool>(),
        seed in any::<u64>(),
        amount in 0.0f64..0.15,
        cuts in prop::collection::vec((0usize..64, any::<bool>(), 0.05f64..0.95), 0..5),
        queries in prop::collection::vec((-1.8f64..1.8, -1.8f64..1.8, -1.8f64..1.8), 6),
    ) {
        let base = if use_sphere { sphere() } else { cube() };
        let set = PatchSet::new(split_some(perturb(&base, amount, seed), &cuts)).unwrap();
        // A tessellation tells which queries are near the surface (skipped: w jumps there).
        let mesh = tessellate(&set, 24).unwrap();
        let near = WindingNumber::new(&mesh).unwrap();
        for (i, &(x, y, z)) in queries.iter().enumerate() {
            let q = [x, y, z];
            let w_mesh = near.eval(q);
            // Off the surface the tessellation is within its O(h²) error of an integer; skip
            // queries where it is not (they are within that error of the surface).
            if (w_mesh - w_mesh.round()).abs() > 1e-3 {
                continue;
            }
            let ray = RayAxis::ALL[i % 6];
            let wn = PatchWindingNumber::with_options(&set, Options { ray, tolerance: 1e-11 }).unwrap();
            let e = wn.evaluate(q);
            let w = e.value;
            prop_assert!((w - w.round()).abs() < 1e-9, "q = {:?}, {:?}: {}", q, ray, w);
            // Unsplit, every edge has its reversed twin (a split leaves T-junctions, which are
            // integrated instead): the set is closed and a certified value the exact integer.
            if cuts.is_empty() {
                prop_assert!(e.certified && w == w.round(), "q = {:?}, {:?}: {:?}", q, ray, e);
            }
        }
    }

    #[test]
    fn random_open_patches_agree_with_tessellations(
        ctrl in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), 16),
        queries in prop::collection::vec((-1.0f64..2.0, -1.0f64..2.0, -1.0f64..2.0), 8),
    ) {
        let pts: Vec<[f64; 3]> = ctrl.iter().map(|&(x, y, z)| [x, y, z]).collect();
        let set = PatchSet::new(vec![Patch::polynomial(3, 3, pts).unwrap()]).unwrap();
        let coarse = WindingNumber::new(&tessellate(&set, 48).unwrap()).unwrap();
        let fine = WindingNumber::new(&tessellate(&set, 96).unwrap()).unwrap();
        for (i, &(x, y, z)) in queries.iter().enumerate() {
            let q = [x, y, z];
            let (a, b) = (coarse.eval(q), fine.eval(q));
            let est = (b - a).abs() / 3.0;
            if est > 1e-5 {
                continue;
            }
            let reference = (4.0 * b - a) / 3.0;
            let ray = RayAxis::ALL[i % 6];
            let wn = PatchWindingNumber::with_options(&set, Options { ray, tolerance: 1e-11 }).unwrap();
            let w = wn.eval(q);
            prop_assert!((w - reference).abs() <= 2.0 * est + 1e-9,
                "q = {:?}: {} vs {} (estimate {:e})", q, w, reference, est);
        }
    }
}
