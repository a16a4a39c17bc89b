//! The certified boundary hierarchy (issue 12, part 2; docs/boundary.md): with a tolerance τ,
//! the evaluator's answer differs from the flat exact loop (τ = 0) by at most the bound it
//! returns, the bound never exceeds τ, the integer part is never touched — on every shared mesh
//! (1000 random and 1000 near-surface queries each) and on adversarial open meshes (long thin
//! boundary loops, chains that fold back, holes and flipped faces; queries next to boundary
//! vertices and on the ray's line through them), for all six ray directions.

use crate::common;

use gwn::Mesh;
use gwn::RayAxis;
use gwn::eval::antipodal::{Options, WindingNumber};
use proptest::prelude::*;
use rayon::prelude::*;

fn with_tolerance(mesh: &Mesh, tolerance: f64, ray: RayAxis) -> WindingNumber {
    WindingNumber::with_options(
        mesh,
        Options {
            tolerance,
            ray,
            ..Default::default()
        },
    )
    .unwrap()
}

/// Checks every query; returns how many used an expansion (a positive bound).
fn check(flat: &WindingNumber, tree: &WindingNumber, queries: &[[f64; 3]], what: &str) -> usize {
    let tolerance = tree.options().tolerance;
    queries
        .par_iter()
        .map(|&q| {
            let (exact, zero) = flat.eval_with_bound(q);
            assert_eq!(zero, 0.0, "{what}: the flat loop reports a bound at {q:?}");
            let (w, bound) = tree.eval_with_bound(q);
            assert!(
                bound <= tolerance,
                "{what}: bound {bound:e} above the tolerance {tolerance:e} at {q:?}"
            );
            // The flat loop and the hierarchy share every exact term; what is left beyond the
            // bound is the rounding of two long sums (≲ 1e-14 here).
            assert!(
                (w - exact).abs() <= bound + 1e-13,
                "{what}: |{w} − {exact}| = {:e} > bound {bound:e} at {q:?}",
                (w - exact).abs()
            );
            usize::from(bound > 0.0)
        })
        .sum()
}

/// Points on random triangles, moved off along the normal by 1e-4 … 1e-1 of the diagonal.
fn near_surface(mesh: &Mesh, rng: &mut common::Rng, n: usize) -> Vec<[f64; 3]> {
    let p = mesh.positions();
    let t = mesh.triangles();
    let diag = mesh.bounding_box().map_or(1.0, |b| b.diagonal());
    (0..n)
        .map(|_| {
            let tri = t[(rng.next_u64() % t.len() as u64) as usize].map(|i| p[i as usize]);
            let (mut u, mut v) = (rng.f64(), rng.f64());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let e1: [f64; 3] = std::array::from_fn(|k| tri[1][k] - tri[0][k]);
            let e2: [f64; 3] = std::array::from_fn(|k| tri[2][k] - tri[0][k]);
            let nrm = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            let len = (nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2])
                .sqrt()
                .max(f64::MIN_POSITIVE);
            let off =
                diag * 10f64.powf(rng.range(-4.0, -1.0)) * if rng.f64() < 0.5 { -1.0 } else { 1.0 };
            std::array::from_fn(|k| tri[0][k] + u * e1[k] + v * e2[k] + off * nrm[k] / len)
        })
        .collect()
}

#[test]
fn error_never_exceeds_the_bound_on_the_shared_corpus() {
    let Some((dir, files)) = common::shared_mesh_files() else {
        return;
    };
    let mut expanded = [0usize; 2];
    let mut meshes = 0;
    for (fi, file) in files.iter().enumerate() {
        let mesh = gwn::io::load_mesh(dir.join(file)).unwrap().mesh;
        let Some(bbox) = mesh.bounding_box() else {
            continue;
        };
        let flat = with_tolerance(&mesh, 0.0, RayAxis::PosZ);
        if flat.boundary_edge_count() == 0 {
            continue;
        }
        meshes += 1;
        let mut rng = common::Rng(7000 + fi as u64);
        // Random queries in the box grown by 150 % on every side: near and far.
        let big = bbox.enlarged(1.5);
        let mut queries: Vec<[f64; 3]> = (0..1000)
            .map(|_| std::array::from_fn(|k| rng.range(big.min[k], big.max[k])))
            .collect();
        queries.extend(near_surface(&mesh, &mut rng, 1000));
        for (slot, tolerance) in [1e-3, 1e-10].into_iter().enumerate() {
            let tree = with_tolerance(&mesh, tolerance, RayAxis::PosZ);
            expanded[slot] += check(&flat, &tree, &queries, &format!("{file} τ={tolerance:e}"));
        }
    }
    eprintln!(
        "{meshes} open meshes; queries with an expansion: τ=1e-3 {}, τ=1e-10 {}",
        expanded[0], expanded[1]
    );
    // The test means something only if the hierarchy ran.
    assert!(
        expanded[0] > 10_000,
        "only {} expanded queries at 1e-3",
        expanded[0]
    );
    assert!(
        expanded[1] > 1_000,
        "only {} expanded queries at 1e-10",
        expanded[1]
    );
}

#[test]
fn the_hierarchy_agrees_with_the_direct_sum() {
    // A scan-like open surface: a bumpy hemisphere of 80×40 quads with 5 % of faces removed and
    // 5 % flipped; far and near queries against the direct solid-angle sum.
    let mesh = bumpy_hemisphere(80, 40, 0.05, 0.05, 11);
    let tree = with_tolerance(&mesh, 1e-8, RayAxis::PosZ);
    assert!(tree.boundary_edge_count() > 500);
    let mut rng = common::Rng(3);
    let queries: Vec<[f64; 3]> = (0..300)
        .map(|i| {
            let r = if i % 2 == 0 {
                rng.range(1.5, 6.0)
            } else {
                rng.range(0.2, 1.4)
            };
            let (th, ph) = (rng.range(0.0, std::f64::consts::PI), rng.range(0.0, 6.3));
            [
                r * th.sin() * ph.cos(),
                r * th.sin() * ph.sin(),
                r * th.cos() - 0.3,
            ]
        })
        .collect();
    let mut used = 0;
    for q in queries {
        let (w, bound) = tree.eval_with_bound(q);
        let direct = gwn::eval::direct::winding_number_direct(&mesh, q);
        assert!(
            (w - direct).abs() <= bound + 1e-11,
            "{w} vs direct {direct} (bound {bound:e}) at {q:?}"
        );
        used += usize::from(bound > 0.0);
    }
    assert!(used > 50, "only {used} queries used the hierarchy");
}

/// A ring-shaped open cap of 2,000 boundary edges (radius 40, full-precision coordinates)
/// beside a closed tetrahedron at `1e15`, which sets the extent: the 60-bit cell is `2^-8` and
/// the cap's vertices are off the lattice. With a tolerance of `1e-6`, every value must be
/// within its bound of the direct sum. Before, the loop's offsets and the hierarchy's positions
/// (moments, centres, spokes, the query) were the lattice points rounded to `f64`, up to `2^6`
/// cells off: values were up to `1e-4` from the direct sum with a reported bound of `0`.
#[test]
fn the_bound_holds_on_a_small_boundary_in_a_huge_box() {
    let mut rng = common::Rng(7);
    let (mesh, _) = common::cap_beside_far_tetrahedron(&mut rng, 2000, (40.0, 41.0), 1e15);
    let centre = common::CAP_CENTRE;
    // Around the ring (its nodes are expanded from a few node sizes away) and farther out.
    let queries: Vec<[f64; 3]> = (0..150)
        .map(|i| {
            let (r, a) = (rng.range(30.0, 55.0 + f64::from(i)), rng.range(0.0, 6.3));
            [
                centre[0] + r * a.cos(),
                centre[1] + r * a.sin(),
                centre[2] + rng.range(-20.0, 20.0),
            ]
        })
        .collect();
    for ray in [RayAxis::PosX, RayAxis::NegZ] {
        let tree = with_tolerance(&mesh, 1e-6, ray);
        assert!(
            tree.snapping().cell >= 2f64.powi(-9),
            "{:?}",
            tree.snapping()
        );
        let used: usize = queries
            .par_iter()
            .map(|&q| {
                let (w, bound) = tree.eval_with_bound(q);
                let direct = gwn::eval::direct::winding_number_direct(&mesh, q);
                assert!(
                    (w - direct).abs() <= bound + 1e-12,
                    "{ray:?}: {w} vs direct {direct} (bound {bound:e}) at {q:?}"
                );
                usize::from(bound > 0.0)
            })
            .sum();
        println!(
            "{ray:?}: {used} of {} queries used the hierarchy",
            queries.len()
        );
        assert!(
            used >= 20,
            "{ray:?}: only {used} queries used the hierarchy"
        );
    }
}

#[test]
fn the_lazy_tree_is_built_safely_from_a_parallel_batch() {
    // The hierarchy is built on first use, typically inside `eval_batch`'s rayon workers: many
    // workers reach the `OnceLock` at once (a build that itself ran in parallel could deadlock
    // there by stealing another query while waiting). Fresh evaluators, first call a big batch.
    let mesh = bumpy_hemisphere(80, 40, 0.05, 0.05, 5);
    let mut rng = common::Rng(9);
    let points: Vec<[f64; 3]> = (0..20_000)
        .map(|_| std::array::from_fn(|_| rng.range(-8.0, 8.0)))
        .collect();
    let flat = with_tolerance(&mesh, 0.0, RayAxis::PosZ).eval_batch(&points);
    for _ in 0..4 {
        let tree = with_tolerance(&mesh, 1e-6, RayAxis::PosZ);
        let w = tree.eval_batch(&points);
        for (a, b) in w.iter().zip(&flat) {
            assert!((a - b).abs() <= 1e-6 + 1e-13);
        }
    }
}

/// A bumpy open hemisphere, `nu × nv` quads, a fraction of faces removed and another flipped.
fn bumpy_hemisphere(nu: usize, nv: usize, removed: f64, flipped: f64, seed: u64) -> Mesh {
    let mut rng = common::Rng(seed);
    let mut p = Vec::new();
    for j in 0..=nv {
        for i in 0..nu {
            let (u, v) = (
                i as f64 / nu as f64 * std::f64::consts::TAU,
                j as f64 / nv as f64 * 1.5,
            );
            let r = 1.0 + 0.05 * (3.0 * u).sin() * (4.0 * v).cos();
            p.push([r * v.sin() * u.cos(), r * v.sin() * u.sin(), r * v.cos()]);
        }
    }
    let mut t = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let a = (j * nu + i) as u32;
            let b = (j * nu + (i + 1) % nu) as u32;
            let (c, d) = (a + nu as u32, b + nu as u32);
            for tri in [[a, c, d], [a, d, b]] {
                let x = rng.f64();
                if x < removed {
                    continue;
                }
                t.push(if x < removed + flipped {
                    [tri[0], tri[2], tri[1]]
                } else {
                    tri
                });
            }
        }
    }
    Mesh::from_slices(&p, &t).unwrap()
}

/// A ribbon along a random walk that may fold back on itself: `2n` triangles of width `width`,
/// one long thin boundary loop of `2n + 2` edges, with integer-friendly coordinates.
fn ribbon(steps: &[(i8, i8, i8)], width: f64) -> Mesh {
    let mut p = Vec::new();
    let mut c = [0.0f64; 3];
    for &(dx, dy, dz) in steps {
        p.push(c);
        p.push([c[0] + width, c[1] + 0.5 * width, c[2] + width]);
        // A step of zero would make a degenerate quad: keep it (degenerate triangles are inputs).
        c = [
            c[0] + f64::from(dx) * 0.25,
            c[1] + f64::from(dy) * 0.25,
            c[2] + f64::from(dz) * 0.25,
        ];
    }
    let mut t = Vec::new();
    for k in 0..steps.len().saturating_sub(1) as u32 {
        let (a, b, c2, d) = (2 * k, 2 * k + 1, 2 * k + 2, 2 * k + 3);
        t.push([a, c2, b]);
        t.push([b, c2, d]);
    }
    Mesh::from_slices(&p, &t).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Long thin loops that fold back; queries far away, next to boundary vertices and on the
    /// ray's line through them (their world coordinates across the ray equal the vertex's).
    #[test]
    fn bound_holds_on_folding_ribbons(
        steps in proptest::collection::vec((-4i8..=4, -4i8..=4, -2i8..=2), 70..200),
        width in prop_oneof![Just(1e-3), Just(0.05), Just(0.4)],
        picks in proptest::collection::vec((0usize..400, -3i32..=3, 0u8..3), 24),
        tolerance in prop_oneof![Just(1e-3), Just(1e-6), Just(1e-9)],
        ray in 0usize..6,
    ) {
        let mesh = ribbon(&steps, width);
        let ray = RayAxis::ALL[ray];
        let flat = with_tolerance(&mesh, 0.0, ray);
        let tree = with_tolerance(&mesh, tolerance, ray);
        let p = mesh.positions();
        let bbox = mesh.bounding_box().unwrap();
        let size = bbox.diagonal().max(1.0);
        let axis = ray.map()[2].0;
        let queries: Vec<[f64; 3]> = picks
            .iter()
            .map(|&(i, s, kind)| {
                let v = p[i % p.len()];
                match kind {
                    // On the ray's line through a boundary vertex, at several depths.
                    0 => {
                        let mut q = v;
                        q[axis] += f64::from(s) * 0.37 * size;
                        q
                    }
                    // Next to a boundary vertex.
                    1 => v.map(|c| c + f64::from(s) * 1e-7),
                    // Far away in a direction given by the vertex.
                    _ => std::array::from_fn(|k| bbox.min[k] + (v[k] - bbox.min[k]) * 2.0 + f64::from(s + 4) * size),
                }
            })
            .collect();
        check(&flat, &tree, &queries, &format!("ribbon of {} steps, τ={tolerance:e}, {ray:?}", steps.len()));
    }

    /// The batch at a looser tolerance than the evaluator's own
    /// (`WindingNumber::eval_batch_within`, the remesher's first pass): every value within its
    /// bound of `eval`'s, the bound within the tolerance plus the evaluator's own, columns (runs
    /// of points on one line along the ray) and single points alike, and `eval`'s own values
    /// with bound 0 at a tolerance that is not looser.
    #[test]
    fn a_looser_batch_stays_within_its_bound_of_the_values(
        seed in 0u64..1000,
        flipped in 0.05f64..0.3,
        tolerance in prop_oneof![Just(1.0 / 32.0), Just(1e-3), Just(1e-6)],
        ray in 0usize..6,
    ) {
        let mesh = bumpy_hemisphere(40, 20, 0.02, flipped, seed);
        let ray = RayAxis::ALL[ray];
        let wn = with_tolerance(&mesh, 1e-10, ray);
        let mut rng = common::Rng(seed);
        let mut queries: Vec<[f64; 3]> = (0..30)
            .map(|_| std::array::from_fn(|_| rng.range(-3.0, 3.0)))
            .collect();
        queries.extend(near_surface(&mesh, &mut rng, 30));
        // Two columns along the ray's axis through near-surface points.
        let axis = ray.map()[2].0;
        for q in near_surface(&mesh, &mut rng, 2) {
            queries.extend((0..12).map(|k| {
                let mut p = q;
                p[axis] += 0.05 * (k as f64 - 6.0);
                p
            }));
        }
        let values = wn.eval_batch(&queries);
        let looser = wn.eval_batch_within(&queries, tolerance);
        let mut expanded = 0;
        for ((q, &w), &(v, b)) in queries.iter().zip(&values).zip(&looser) {
            prop_assert!(b <= tolerance + 1e-10, "bound {b:e} at {q:?}");
            // Beyond the bound: the rounding of two long sums, as in `check`.
            prop_assert!((v - w).abs() <= b + 1e-13, "|{v} − {w}| > {b:e} at {q:?}");
            expanded += usize::from(b > 1e-10);
        }
        // The flips make long boundaries: the looser hierarchy is used.
        prop_assert!(tolerance < 1e-3 || expanded > 0, "nothing expanded at {tolerance:e}");
        let same = wn.eval_batch_within(&queries, 1e-10);
        prop_assert!(same.iter().zip(&values).all(|(&(v, b), &w)| v.to_bits() == w.to_bits() && b == 0.0));
    }

    /// Scan-like surfaces with holes and flipped faces (many small loops and weight-2 edges).
    #[test]
    fn bound_holds_on_holes_and_flips(
        seed in 0u64..1000,
        removed in 0.0f64..0.2,
        flipped in 0.0f64..0.2,
        tolerance in prop_oneof![Just(1e-2), Just(1e-5), Just(1e-10)],
        ray in 0usize..6,
    ) {
        let mesh = bumpy_hemisphere(40, 20, removed, flipped, seed);
        let ray = RayAxis::ALL[ray];
        let flat = with_tolerance(&mesh, 0.0, ray);
        let tree = with_tolerance(&mesh, tolerance, ray);
        let mut rng = common::Rng(seed);
        let mut queries: Vec<[f64; 3]> = (0..40)
            .map(|_| std::array::from_fn(|_| rng.range(-6.0, 6.0)))
            .collect();
        queries.extend(near_surface(&mesh, &mut rng, 20));
        check(&flat, &tree, &queries, &format!("hemisphere seed {seed}, τ={tolerance:e}, {ray:?}"));
    }
}

/// Slivers whose corners share lattice points with other corners (a 1e15 sheet, a corner 8.4e-4
/// off the line of two others: under the 60-bit cell), 48 of them at different `x`, so that the
/// hierarchy has nodes to expand: the expansions' open ends are merged by input position, not
/// lattice point, and every ray stays within its bound of the flat loop, which is the direct
/// sum's value (`sliver_at_1e15_magnitudes_under_a_mirrored_frame` in input_bits.rs).
#[test]
fn ends_a_cell_apart_are_not_merged() {
    let mut p = Vec::new();
    let mut t = Vec::new();
    for k in 0..48u32 {
        let x = f64::from(k) * 3.0e12;
        let z = f64::from(k % 7) * 0.37 + 8.05011069654107;
        let base = p.len() as u32;
        p.extend([
            [x, 0.0, z],
            [x, 0.0, 0.0],
            [x, 1e15, 0.0],
            [x, 1e15, z],
            [x, -0.0008442093330105354, z],
        ]);
        t.extend([[0, 3, 2], [0, 2, 1], [1, 2, 4]].map(|f: [u32; 3]| f.map(|i| base + i)));
    }
    let mesh = Mesh::from_slices(&p, &t).unwrap();
    let mut rng = common::Rng(7);
    let queries: Vec<[f64; 3]> = (0..300)
        .map(|_| {
            [
                rng.range(-1e12, 1.5e14),
                rng.range(-10.0, 20.0),
                rng.range(-5.0, 15.0),
            ]
        })
        .collect();
    for ray in RayAxis::ALL {
        let flat = with_tolerance(&mesh, 0.0, ray);
        let tree = with_tolerance(&mesh, 1e-10, ray);
        check(&flat, &tree, &queries, &format!("slivers, {ray:?}"));
        for &q in queries.iter().take(40) {
            let (w, want) = (
                flat.eval(q),
                gwn::eval::direct::winding_number_direct(&mesh, q),
            );
            assert!(
                (w - want).abs() < 1e-11,
                "{ray:?} at {q:?}: {w} against {want}"
            );
        }
    }
}
