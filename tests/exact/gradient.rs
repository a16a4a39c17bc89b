//! Gradients: the exact evaluator's (Biot–Savart over the signed boundary edges) against the
//! direct Biot–Savart gradient over all triangle edges and against central finite differences of
//! the exact value.

use crate::common;

use gwn::Mesh;
use gwn::RayAxis;
use gwn::eval::antipodal::{Options, WindingNumber};
use gwn::eval::direct::winding_number_gradient_direct;

/// The exact evaluator of `mesh` with `ray` and the other options at their defaults.
fn with_ray(mesh: &Mesh, ray: RayAxis) -> WindingNumber {
    WindingNumber::with_options(
        mesh,
        Options {
            ray,
            ..Default::default()
        },
    )
    .unwrap()
}

fn check(mesh: &Mesh, queries: &[[f64; 3]], h: f64) {
    for ray in [RayAxis::PosZ, RayAxis::NegX] {
        let wn = with_ray(mesh, ray);
        for &q in queries {
            let g = wn.gradient(q);
            let gd = winding_number_gradient_direct(mesh, q);
            let scale = gd.iter().map(|v| v.abs()).fold(1e-3, f64::max);
            for k in 0..3 {
                assert!(
                    (g[k] - gd[k]).abs() <= 1e-9 * scale,
                    "{ray:?} {q:?}: {g:?} vs direct {gd:?}"
                );
                let mut a = q;
                let mut b = q;
                a[k] += h;
                b[k] -= h;
                let fd = (wn.eval(a) - wn.eval(b)) / (2.0 * h);
                assert!(
                    (g[k] - fd).abs() <= 1e-5 * scale,
                    "{ray:?} {q:?} axis {k}: {} vs FD {fd}",
                    g[k]
                );
            }
        }
    }
}

#[test]
fn open_cube_gradient_matches_direct_and_finite_differences() {
    let m = common::open_cube();
    let mut rng = common::Rng(11);
    let qs: Vec<[f64; 3]> = (0..200)
        .map(|_| {
            [
                rng.range(-0.5, 1.5),
                rng.range(-0.5, 1.5),
                rng.range(-0.5, 1.5),
            ]
        })
        .filter(|q| {
            q.iter()
                .all(|c| (c - 0.0).abs() > 0.02 && (c - 1.0).abs() > 0.02)
        })
        .collect();
    assert!(qs.len() > 100);
    check(&m, &qs, 1e-6);
    // A closed mesh has zero gradient off the surface.
    let wn = WindingNumber::new(&common::unit_cube()).unwrap();
    assert_eq!(wn.gradient([0.3, 0.4, 0.5]), [0.0; 3]);
}

#[test]
fn lion_head_gradient_matches_direct_and_finite_differences() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/lion-head.off");
    let mesh = gwn::io::load_mesh(&path).unwrap().mesh;
    let b = mesh.bounding_box().unwrap().enlarged(0.05);
    let mut rng = common::Rng(5);
    let wn = WindingNumber::new(&mesh).unwrap();
    // Keep queries where the field is smooth at the FD scale (away from the surface).
    let qs: Vec<[f64; 3]> = (0..400)
        .map(|_| std::array::from_fn(|k| rng.range(b.min[k], b.max[k])))
        .filter(|&q| {
            let g = wn.gradient(q);
            g.iter().map(|v| v.abs()).fold(0.0, f64::max) < 50.0
        })
        .take(60)
        .collect();
    check(&mesh, &qs, 1e-6 * b.diagonal());
}

#[test]
fn far_gradients_keep_their_relative_accuracy_and_never_overflow() {
    // Straight below and beside an open mesh, along and across the ray: the antipodal paper's
    // Alg. 3 (used before) was wrong here by orders of magnitude from ~1e6 mesh sizes (its
    // formula divides by 1 + A·x1, which vanishes when the boundary is seen along the ray).
    let mesh = common::open_cube();
    for ray in [RayAxis::PosZ, RayAxis::NegZ, RayAxis::PosX] {
        let wn = with_ray(&mesh, ray);
        for d in [1e2, 1e4, 1e6, 1e8, 1e12] {
            for q in [[0.3, 0.6, -d], [0.3, 0.6, d], [d, 0.4, 0.5], [0.7, -d, 0.2]] {
                let g = wn.gradient(q);
                let gd = winding_number_gradient_direct(&mesh, q);
                let scale = gd.iter().map(|v| v.abs()).fold(0.0, f64::max);
                assert!(scale > 0.0);
                for k in 0..3 {
                    assert!(
                        (g[k] - gd[k]).abs() <= 1e-6 * scale,
                        "{ray:?} {q:?}: {g:?} vs direct {gd:?}"
                    );
                }
            }
        }
        for q in [
            [0.3, 0.6, -1e300],
            [1e300, 0.0, 0.0],
            [-f64::MAX, f64::MAX, 1.0],
        ] {
            let g = wn.gradient(q);
            assert!(
                g.iter().all(|v| v.is_finite() && v.abs() < 1e-200),
                "{q:?}: {g:?}"
            );
        }
    }
}

/// A small open cap (radius ~5, 24 boundary edges) beside a closed tetrahedron at `1e15`, which
/// sets the extent (60-bit cell `2^-8`): the gradient's offsets are the exact inputs', so it
/// matches the direct Biot–Savart gradient to 1e-10 relative at 0.01 … 30 units from the cap.
/// With the lattice points' offsets (up to `2^6` cells off) it was wrong in the first digit.
#[test]
fn gradients_of_small_parts_in_huge_meshes_are_accurate() {
    let mut rng = common::Rng(52);
    let ring = 24;
    let (mesh, p) = common::cap_beside_far_tetrahedron(&mut rng, ring, (4.0, 6.0), 1e15);
    for ray in [RayAxis::PosZ, RayAxis::NegX, RayAxis::PosY] {
        let wn = with_ray(&mesh, ray);
        assert!(wn.snapping().cell >= 2f64.powi(-9), "{:?}", wn.snapping());
        for _ in 0..100 {
            let d = 10f64.powf(rng.range(-2.0, 1.5));
            let dir: [f64; 3] = std::array::from_fn(|_| rng.range(-1.0, 1.0));
            let len = dir.iter().map(|c| c * c).sum::<f64>().sqrt();
            let k = 1 + rng.next_u64() as usize % ring;
            let q: [f64; 3] = std::array::from_fn(|j| p[k][j] + d * dir[j] / len);
            let g = wn.gradient(q);
            let gd = winding_number_gradient_direct(&mesh, q);
            let scale = gd.iter().map(|v| v.abs()).fold(0.0, f64::max);
            for j in 0..3 {
                assert!(
                    (g[j] - gd[j]).abs() <= 1e-10 * scale,
                    "{ray:?} {q:?}: {g:?} vs direct {gd:?}"
                );
            }
        }
    }
}

/// Next to a vertex of an open triangle, down to `1e-300` from it: the gradient is finite and
/// matches central differences of the exact value with steps of `10^-3` of the distance (`w` is
/// homogeneous of degree 0 about the vertex, so the relative error is `~10^-6` at any scale).
/// Below `~1e-70` the textbook Biot–Savart form's `|ra|²|rb|²` underflowed to 0 and the gradient
/// was NaN (a third of the off-surface queries next to mixed-magnitude edges in a seeded
/// search).
#[test]
fn gradients_next_to_a_vertex_are_finite_at_any_distance() {
    let mesh = Mesh::from_slices(
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[[0, 1, 2]],
    )
    .unwrap();
    let wn = WindingNumber::new(&mesh).unwrap();
    for d in [1e-30, 1e-150, 1e-268, 1e-300] {
        let q = [0.3 * d, 0.2 * d, 0.5 * d];
        let g = wn.gradient(q);
        let h = 1e-3 * d;
        let fd: [f64; 3] = std::array::from_fn(|k| {
            let (mut a, mut b) = (q, q);
            a[k] += h;
            b[k] -= h;
            (wn.eval(a) - wn.eval(b)) / (2.0 * h)
        });
        let size = fd.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for k in 0..3 {
            assert!(
                g[k].is_finite() && (g[k] - fd[k]).abs() <= 1e-5 * size,
                "d = {d:e}: {g:?} vs {fd:?}"
            );
        }
    }
}

/// `∇w(q)` by central differences with steps `h` and `h/2`, Richardson-extrapolated: the
/// truncation error is `O((h/d)^4)` at distance `d` from the boundary.
fn richardson_gradient(wn: &WindingNumber, q: [f64; 3], h: f64) -> [f64; 3] {
    std::array::from_fn(|k| {
        let central = |h: f64| {
            let (mut a, mut b) = (q, q);
            a[k] += h;
            b[k] -= h;
            (wn.eval(a) - wn.eval(b)) / (2.0 * h)
        };
        (4.0 * central(0.5 * h) - central(h)) / 3.0
    })
}

/// Beside a boundary edge's interior, from `1e-6` down to `1e-300` from it: the gradient
/// matches Richardson-extrapolated central differences of the exact value (steps of `10^-3`
/// of the distance) within `1e-8`. The edge runs through the origin (`b = −2a`), so queries
/// that close exist in `f64`. Two defects of the Biot–Savart term from offsets rounded once:
/// its denominator `|ra||rb| + ra·rb` cancels like the square of the angle (relative error
/// `3.5e-5` at `1e-9` from an edge of cgal-blobby-shuffled), and within `~1e-16` of the edge
/// the rounded offsets are exactly antiparallel (NaN; a little farther, the wrong direction).
#[test]
fn gradients_beside_an_edge_are_accurate_at_any_distance() {
    let mesh = Mesh::from_slices(
        &[[0.6, 0.35, -0.2], [-1.2, -0.7, 0.4], [0.1, 0.9, 0.3]],
        &[[0, 1, 2]],
    )
    .unwrap();
    for ray in [RayAxis::PosZ, RayAxis::NegX] {
        let wn = with_ray(&mesh, ray);
        for d in [1e-6, 1e-9, 1e-12, 1e-20, 1e-100, 1e-200, 1e-300] {
            for n in [[0.3, -0.5, 0.2], [-0.1, 0.2, 0.9]] {
                let q = n.map(|c| c * d);
                let g = wn.gradient(q);
                let gd = winding_number_gradient_direct(&mesh, q);
                let fd = richardson_gradient(&wn, q, 1e-3 * d);
                let size = fd.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                for k in 0..3 {
                    assert!(
                        g[k].is_finite() && (g[k] - fd[k]).abs() <= 1e-8 * size,
                        "{ray:?} d = {d:e}, {n:?}: {g:?} vs {fd:?}"
                    );
                    assert!(
                        gd[k].is_finite() && (gd[k] - fd[k]).abs() <= 1e-8 * size,
                        "direct, d = {d:e}, {n:?}: {gd:?} vs {fd:?}"
                    );
                }
            }
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 64, ..Default::default() })]

    /// Random open triangles whose edge `a → b` runs through the origin, and queries `d·n`
    /// beside it from `1e-6` to `1e-300` (`n` away from the triangle's plane and from the
    /// edge's direction): the gradient matches Richardson-extrapolated differences of the exact
    /// `w` within `1e-7`, on two rays.
    #[test]
    fn gradients_beside_random_edges_match_differences_of_the_exact_value(
        case in crate::beside_edge::beside_edge(),
    ) {
        proptest::prop_assume!(case.off_plane > 0.1);
        let q = case.n.map(|x| x * case.d);
        for ray in [RayAxis::PosZ, RayAxis::NegX] {
            let wn = with_ray(&case.mesh, ray);
            let g = wn.gradient(q);
            let fd = richardson_gradient(&wn, q, 1e-3 * case.d);
            let size = fd.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for k in 0..3 {
                proptest::prop_assert!(
                    g[k].is_finite() && (g[k] - fd[k]).abs() <= 1e-7 * size,
                    "{ray:?} {q:?}: {g:?} vs {fd:?}"
                );
            }
        }
    }
}
