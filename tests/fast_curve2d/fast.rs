//! The Barnes–Hut evaluator against the direct sum on shared meshes, the moment hierarchy, point
//! clouds and the FOSSIL-style API.
#![allow(clippy::needless_range_loop)] // tensor indices as in the formulas

use crate::common;

use gwn::Mesh;
use gwn::eval::direct::winding_number_direct_batch;
use gwn::eval::fast::{
    Admissibility, FastParams, FastWindingNumber, Moments, PointCloudWindingNumber, SYM_PAIRS,
    estimate_areas,
};
use gwn::mesh::PointCloud;

// ---------------------------------------------------------------- helpers

/// splitmix64: a tiny deterministic generator for test inputs.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    /// Uniform on the unit sphere.
    fn on_sphere(&mut self) -> [f64; 3] {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let s = (1.0 - z * z).sqrt();
        [s * phi.cos(), s * phi.sin(), z]
    }
}

fn shared_mesh(name: &str) -> Option<Mesh> {
    let path = common::shared_file(&format!("meshes/{name}"))?;
    Some(gwn::io::load_mesh(&path).expect("shared mesh loads").mesh)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn segment_dist2(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let c = [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]];
    let d = sub(p, c);
    dot(d, d)
}

/// Squared distance from `p` to the triangle `t` (brute force: the plane when the projection is
/// inside, else the nearest edge).
fn triangle_dist2(p: [f64; 3], t: [[f64; 3]; 3]) -> f64 {
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let nn = dot(n, n);
    if nn > 0.0 {
        let h = dot(sub(p, t[0]), n) / nn;
        let proj = [p[0] - h * n[0], p[1] - h * n[1], p[2] - h * n[2]];
        let inside = (0..3).all(|i| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            dot(cross(sub(b, a), sub(proj, a)), n) >= 0.0
        });
        if inside {
            return h * h * nn;
        }
    }
    (0..3)
        .map(|i| segment_dist2(p, t[i], t[(i + 1) % 3]))
        .fold(f64::INFINITY, f64::min)
}

fn mesh_distance(mesh: &Mesh, p: [f64; 3]) -> f64 {
    (0..mesh.triangles().len())
        .map(|f| triangle_dist2(p, mesh.triangle_positions(f)))
        .fold(f64::INFINITY, f64::min)
        .sqrt()
}

/// `n` queries uniform in the bounding box enlarged by 10 % (the paper measures its RMS error on
/// a lattice in the bounding box).
fn box_queries(mesh: &Mesh, n: usize, seed: u64) -> Vec<[f64; 3]> {
    let big = mesh.bounding_box().unwrap().enlarged(0.1);
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| [0, 1, 2].map(|k| rng.range(big.min[k], big.max[k])))
        .collect()
}

/// `n` queries near the surface: random points of random faces moved along the face normal by
/// ±{0.2 %, 1 %, 5 %} of the bounding-box diagonal.
fn near_queries(mesh: &Mesh, n: usize, seed: u64) -> Vec<[f64; 3]> {
    let diag = mesh.bounding_box().unwrap().diagonal();
    let mut rng = Rng(seed);
    let mut out = Vec::with_capacity(n);
    let faces = mesh.triangles().len();
    while out.len() < n {
        let t = mesh.triangle_positions((rng.next_u64() % faces as u64) as usize);
        let nrm = cross(sub(t[1], t[0]), sub(t[2], t[0]));
        let l = dot(nrm, nrm).sqrt();
        if l == 0.0 {
            continue;
        }
        let (mut u, mut v) = (rng.unit(), rng.unit());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let off = [0.002, 0.01, 0.05][(rng.next_u64() % 3) as usize]
            * diag
            * if rng.unit() < 0.5 { -1.0 } else { 1.0 };
        out.push([0, 1, 2].map(|k| {
            t[0][k] + u * (t[1][k] - t[0][k]) + v * (t[2][k] - t[0][k]) + off * nrm[k] / l
        }));
    }
    out
}

/// Half [`box_queries`], half [`near_queries`].
fn queries(mesh: &Mesh, n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut q = box_queries(mesh, n / 2, seed);
    q.extend(near_queries(mesh, n - n / 2, seed ^ 0x5555));
    q
}

fn errors(approx: &[f64], exact: &[f64]) -> (f64, f64) {
    let mut se = 0.0;
    let mut max = 0.0_f64;
    for (a, e) in approx.iter().zip(exact) {
        let d = a - e;
        se += d * d;
        max = max.max(d.abs());
    }
    ((se / exact.len() as f64).sqrt(), max)
}

/// Closed meshes of the shared corpus, small enough for the test profile.
const CLOSED: [&str; 4] = [
    "cgal-anchor.off",
    "cgal-rotor.off",
    "cgal-hand.off",
    "cgal-triceratops.off",
];

// ---------------------------------------------------------------- accuracy vs the direct sum

#[test]
fn error_shrinks_with_beta_and_order_and_default_is_accurate() {
    for name in CLOSED {
        let Some(mesh) = shared_mesh(name) else {
            continue;
        };
        let qs = queries(&mesh, 300, 7);
        let exact = winding_number_direct_batch(&mesh, &qs);
        let fast = FastWindingNumber::new(&mesh);
        let mut rms = [[0.0; 3]; 3]; // [beta][order]
        for (bi, beta) in [1.0, 2.0, 4.0].into_iter().enumerate() {
            for order in 0..=2u8 {
                let approx = fast.eval_batch_with(&qs, FastParams::barill(beta, order));
                let (r, m) = errors(&approx, &exact);
                println!("{name}: beta {beta} order {order}: rms {r:.2e} max {m:.2e}");
                rms[bi][order as usize] = r;
            }
        }
        for order in 0..3 {
            assert!(
                rms[0][order] > rms[1][order] && rms[1][order] > rms[2][order],
                "{name}: order {order}: error does not shrink with beta: {:?}",
                [rms[0][order], rms[1][order], rms[2][order]]
            );
        }
        for (bi, row) in rms.iter().enumerate() {
            // Order 2 beats orders 0 and 1 at every beta; order 1 vs order 0 is not monotone at
            // small beta (about the area centroid the order-1 moment only carries the normal
            // variation; see docs/fast.md), so it is only required not to be much worse.
            assert!(
                row[2] < row[0] && row[2] < row[1],
                "{name}: beta index {bi}: order 2 is not the most accurate: {row:?}"
            );
            assert!(row[1] < 2.0 * row[0], "{name}: order 1 far worse: {row:?}");
        }
    }
}

#[test]
fn default_parameters_reach_the_papers_accuracy() {
    for name in CLOSED {
        let Some(mesh) = shared_mesh(name) else {
            continue;
        };
        let fast = FastWindingNumber::new(&mesh);
        assert_eq!(fast.params(), FastParams::barill(2.0, 2));
        // The paper's measure: RMS over queries filling the bounding box.
        let qs = box_queries(&mesh, 300, 21);
        let (rms, max) = errors(
            &fast.eval_batch(&qs),
            &winding_number_direct_batch(&mesh, &qs),
        );
        println!("{name}: box queries: rms {rms:.2e} max {max:.2e}");
        assert!(rms <= 1e-3, "{name}: RMS at beta 2, order 2: {rms}");
        // Near the surface the error is about the same (a regression guard, not the paper's
        // number: measured 0.3e-3 to 1.2e-3 on these meshes).
        let qs = near_queries(&mesh, 300, 22);
        let (rms, max) = errors(
            &fast.eval_batch(&qs),
            &winding_number_direct_batch(&mesh, &qs),
        );
        println!("{name}: near queries: rms {rms:.2e} max {max:.2e}");
        assert!(
            rms <= 2e-3,
            "{name}: near-surface RMS at beta 2, order 2: {rms}"
        );
    }
}

#[test]
fn no_misclassification_away_from_the_surface_at_default_parameters() {
    for name in CLOSED {
        let Some(mesh) = shared_mesh(name) else {
            continue;
        };
        let diag = mesh.bounding_box().unwrap().diagonal();
        let qs = queries(&mesh, 300, 11);
        let exact = winding_number_direct_batch(&mesh, &qs);
        let approx = FastWindingNumber::new(&mesh).eval_batch(&qs);
        let mut checked = 0;
        for ((q, e), a) in qs.iter().zip(&exact).zip(&approx) {
            if mesh_distance(&mesh, *q) <= 1e-3 * diag {
                continue;
            }
            checked += 1;
            assert_eq!(
                *a > 0.5,
                *e > 0.5,
                "{name}: {q:?} misclassified: fast {a}, direct {e}"
            );
        }
        assert!(checked > 250, "{name}: only {checked} queries checked");
    }
}

#[test]
fn huge_beta_reproduces_the_direct_sum() {
    let Some(mesh) = shared_mesh("cgal-anchor.off") else {
        return;
    };
    let qs = queries(&mesh, 150, 3);
    let exact = winding_number_direct_batch(&mesh, &qs);
    let fast = FastWindingNumber::new(&mesh);
    for order in 0..=2 {
        let approx = fast.eval_batch_with(&qs, FastParams::barill(1e9, order));
        let (_, max) = errors(&approx, &exact);
        assert!(max <= 1e-12, "order {order}: max deviation {max:e}");
    }
}

#[test]
fn soup_of_unshared_vertices_gives_the_same_field() {
    let Some(mesh) = shared_mesh("cgal-rotor.off") else {
        return;
    };
    let positions: Vec<[f64; 3]> = (0..mesh.triangles().len())
        .flat_map(|f| mesh.triangle_positions(f))
        .collect();
    let tris = (0..mesh.triangles().len() as u32)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    let soup = Mesh::new(positions, tris).unwrap();
    let qs = queries(&mesh, 100, 5);
    let a = FastWindingNumber::new(&mesh).eval_batch(&qs);
    let b = FastWindingNumber::new(&soup).eval_batch(&qs);
    let (_, max) = errors(&a, &b);
    assert!(max < 1e-12, "{max:e}");
}

// ---------------------------------------------------------------- moments

/// The parallel-axis shift written out independently of the library.
fn shift(m: &Moments, to: [f64; 3]) -> ([[f64; 3]; 3], [[f64; 3]; 6]) {
    let d = sub(m.center, to);
    let mut m1 = m.m1;
    for i in 0..3 {
        for j in 0..3 {
            m1[i][j] += d[i] * m.n[j];
        }
    }
    let mut m2 = m.m2;
    for (s, &(i, j)) in SYM_PAIRS.iter().enumerate() {
        for k in 0..3 {
            m2[s][k] += d[i] * m.m1[j][k] + d[j] * m.m1[i][k] + d[i] * d[j] * m.n[k];
        }
    }
    (m1, m2)
}

#[test]
fn node_moments_are_the_sums_of_their_childrens_recentred_moments() {
    let Some(mesh) = shared_mesh("cgal-hand.off") else {
        return;
    };
    let fast = FastWindingNumber::new(&mesh);
    let mut inner = 0;
    for id in 0..fast.node_count() {
        let m = fast.node_moments(id);
        let scale1 = m.area * m.radius;
        let scale2 = m.area * m.radius * m.radius;
        let tol = 1e-11;
        // (a) against the children, re-centred by the test's own shift.
        if let Some([l, r]) = fast.node_children(id) {
            inner += 1;
            let (al1, al2) = shift(fast.node_moments(l), m.center);
            let (ar1, ar2) = shift(fast.node_moments(r), m.center);
            for k in 0..3 {
                let n = fast.node_moments(l).n[k] + fast.node_moments(r).n[k];
                assert!((m.n[k] - n).abs() <= tol * m.area);
            }
            for i in 0..3 {
                for j in 0..3 {
                    assert!((m.m1[i][j] - (al1[i][j] + ar1[i][j])).abs() <= tol * scale1);
                }
            }
            for s in 0..6 {
                for k in 0..3 {
                    assert!((m.m2[s][k] - (al2[s][k] + ar2[s][k])).abs() <= tol * scale2);
                }
            }
        }
        // (b) against the element-wise integrals about the node centre.
        let mut direct = Moments {
            center: m.center,
            ..Moments::default()
        };
        for &f in fast.node_triangles(id) {
            let t = mesh.triangle_positions(f as usize);
            direct.accumulate(&Moments::of_triangle(t[0], t[1], t[2], m.center));
        }
        for i in 0..3 {
            for j in 0..3 {
                assert!((m.m1[i][j] - direct.m1[i][j]).abs() <= tol * scale1);
            }
        }
        for s in 0..6 {
            for k in 0..3 {
                assert!((m.m2[s][k] - direct.m2[s][k]).abs() <= tol * scale2);
            }
        }
    }
    assert!(inner > 100);
}

// ---------------------------------------------------------------- point clouds

/// Points at the centres of a latitude–longitude grid on the unit sphere, each with the exact
/// area of its cell, `(cos θ₀ − cos θ₁)(φ₁ − φ₀)`.
fn sphere_cloud(n_theta: usize, n_phi: usize) -> PointCloud {
    use std::f64::consts::{PI, TAU};
    let mut p = Vec::new();
    let mut a = Vec::new();
    for i in 0..n_theta {
        let (t0, t1) = (
            PI * i as f64 / n_theta as f64,
            PI * (i + 1) as f64 / n_theta as f64,
        );
        // The centre of the cell in cos θ, so the point sits at its cell's area centroid
        // latitude.
        let ct = 0.5 * (t0.cos() + t1.cos());
        let st = (1.0 - ct * ct).sqrt();
        for j in 0..n_phi {
            let phi = TAU * (j as f64 + 0.5) / n_phi as f64;
            p.push([st * phi.cos(), st * phi.sin(), ct]);
            a.push((t0.cos() - t1.cos()) * TAU / n_phi as f64);
        }
    }
    let total: f64 = a.iter().sum();
    assert!((total - 4.0 * PI).abs() < 1e-10);
    PointCloud::new(p.clone(), p, Some(a)).unwrap()
}

#[test]
fn sphere_cloud_with_exact_areas_is_one_inside_zero_outside() {
    let cloud = sphere_cloud(60, 120);
    let fast = PointCloudWindingNumber::new(&cloud);
    let mut rng = Rng(42);
    for _ in 0..200 {
        let dir = rng.on_sphere();
        let inside = rng.range(0.0, 0.8);
        let outside = rng.range(1.2, 4.0);
        let wi = fast.eval(dir.map(|v| v * inside));
        let wo = fast.eval(dir.map(|v| v * outside));
        assert!((wi - 1.0).abs() < 1e-2, "inside at {inside}: {wi}");
        assert!(wo.abs() < 1e-2, "outside at {outside}: {wo}");
    }
}

#[test]
fn estimated_areas_of_a_uniform_sphere_sample_add_up_to_its_area() {
    let mut rng = Rng(2024);
    let p: Vec<[f64; 3]> = (0..3000).map(|_| rng.on_sphere()).collect();
    let areas = estimate_areas(&p, &p, 20);
    let total: f64 = areas.iter().sum();
    let exact = 4.0 * std::f64::consts::PI;
    println!("estimated total area {total}, exact {exact}");
    assert!(
        (total - exact).abs() < 0.05 * exact,
        "total {total} vs {exact}"
    );
    assert!(areas.iter().all(|&a| a > 0.0));
    // And the winding number built from the estimates classifies.
    let cloud = PointCloud::new(p.clone(), p, None).unwrap();
    let fast = PointCloudWindingNumber::new(&cloud);
    for r in [0.0, 0.3, 0.6] {
        assert!((fast.eval([r, 0.1, 0.0]) - 1.0).abs() < 0.1);
    }
    for r in [1.4, 2.0, 5.0] {
        assert!(fast.eval([r, 0.1, 0.0]).abs() < 0.1);
    }
}

// ---------------------------------------------------------------- FOSSIL-style API

#[test]
fn fossil_api_dispatches_on_beta() {
    let Some(mesh) = shared_mesh("cgal-anchor.off") else {
        return;
    };
    let api = gwn::eval::fossil::FastOrExact::new(&mesh);
    let fast = FastWindingNumber::new(&mesh);
    let qs = queries(&mesh, 60, 9);
    // beta <= 0 is the exact Antipodal evaluator (bit for bit), which agrees with the direct sum.
    let direct = winding_number_direct_batch(&mesh, &qs);
    let exact = gwn::eval::antipodal::WindingNumber::new(&mesh)
        .unwrap()
        .eval_batch(&qs);
    for (e, d) in exact.iter().zip(&direct) {
        assert!((e - d).abs() < 1e-10);
    }
    for (q, e) in qs.iter().zip(&exact) {
        assert_eq!(api.winding_number(*q, -1.0), *e);
        assert_eq!(api.winding_number(*q, 0.0), *e);
        assert_eq!(api.winding_number(*q, f64::NAN), *e);
        assert_eq!(
            api.winding_number(*q, 3.0),
            fast.eval_with(*q, FastParams::barill(3.0, 2))
        );
    }
    assert_eq!(api.winding_number_batch(&qs, -1.0), exact);
}

#[test]
fn fossil_rule_with_correct_far_field_sign_tracks_the_direct_sum() {
    // FOSSIL's rule (distance > beta x box diagonal, first-order dipole): a flipped far-field
    // sign would make every far node contribute with the wrong sign (errors of order 1).
    let Some(mesh) = shared_mesh("cgal-triceratops.off") else {
        return;
    };
    let qs = queries(&mesh, 200, 13);
    let exact = winding_number_direct_batch(&mesh, &qs);
    let fast = FastWindingNumber::new(&mesh);
    let mut last = f64::INFINITY;
    for beta in [1.0, 2.0, 4.0] {
        let approx = fast.eval_batch_with(&qs, FastParams::fossil(beta));
        let (rms, max) = errors(&approx, &exact);
        println!("FOSSIL rule beta {beta}: rms {rms:.2e} max {max:.2e}");
        assert!(rms < last && max < 0.1, "beta {beta}: rms {rms}, max {max}");
        last = rms;
    }
    // FOSSIL's default beta = 2 is, node by node, Barill's test with beta = 2 D/r > 2.
    let approx = fast.eval_batch_with(&qs, FastParams::fossil(2.0));
    let (rms, _) = errors(&approx, &exact);
    assert!(rms < 5e-3, "FOSSIL default: rms {rms}");
}

#[test]
fn libigl_box_corner_rule_tracks_the_direct_sum() {
    // libigl's node size (distance from p̃ to the farthest box corner) is ≥ the radius, so at the
    // same β it opens at least the nodes the radius rule opens.
    let Some(mesh) = shared_mesh("cgal-hand.off") else {
        return;
    };
    let qs = queries(&mesh, 300, 17);
    let exact = winding_number_direct_batch(&mesh, &qs);
    let fast = FastWindingNumber::new(&mesh);
    let corner = |beta| FastParams {
        beta,
        order: 2,
        admissibility: Admissibility::BoxCorner,
    };
    let (rms_c, max_c) = errors(&fast.eval_batch_with(&qs, corner(2.0)), &exact);
    let (rms_r, _) = errors(
        &fast.eval_batch_with(&qs, FastParams::barill(2.0, 2)),
        &exact,
    );
    println!("beta 2: box corner rms {rms_c:.2e} max {max_c:.2e}, radius rms {rms_r:.2e}");
    assert!(rms_c <= rms_r && rms_c < 1e-3, "{rms_c} vs {rms_r}");
    let (_, max) = errors(&fast.eval_batch_with(&qs, corner(1e9)), &exact);
    assert!(max <= 1e-12, "{max:e}");
}

#[test]
fn radius_or_box_corner_rule_tracks_the_direct_sum() {
    // It admits a node when either Barill's test at β or libigl's at 6β/7 does, so it expands
    // nodes earlier than the radius rule; still within Barill's 1e-3 at the documented β, and
    // exact when nothing is admitted.
    let Some(mesh) = shared_mesh("cgal-hand.off") else {
        return;
    };
    let qs = queries(&mesh, 300, 17);
    let exact = winding_number_direct_batch(&mesh, &qs);
    let fast = FastWindingNumber::new(&mesh);
    let either = |beta| FastParams {
        beta,
        order: 2,
        admissibility: Admissibility::RadiusOrBoxCorner,
    };
    let (rms_e, max_e) = errors(&fast.eval_batch_with(&qs, either(2.8)), &exact);
    let (rms_r, _) = errors(
        &fast.eval_batch_with(&qs, FastParams::barill(2.8, 2)),
        &exact,
    );
    println!(
        "beta 2.8: radius or box corner rms {rms_e:.2e} max {max_e:.2e}, radius rms {rms_r:.2e}"
    );
    assert!(rms_e < 1e-3 && max_e < 1e-2, "rms {rms_e}, max {max_e}");
    let (_, max) = errors(&fast.eval_batch_with(&qs, either(1e9)), &exact);
    assert!(max <= 1e-12, "{max:e}");
}

#[test]
fn near_field_keeps_the_scalar_semantics_on_degenerate_and_remote_triangles() {
    // Leaves mixing zero-area triangles (collinear, repeated corners), tiny and huge ones, far
    // from the origin: the four-lane near field must agree with the scalar direct sum, including
    // queries in the plane of, on the line of, and at a corner of a triangle.
    let mut rng = Rng(99);
    let mut tris: Vec<[[f64; 3]; 3]> = Vec::new();
    for i in 0..60 {
        let o = [1e6, -2e6, 3e5].map(|v| v + rng.range(-1.0, 1.0));
        let p = |rng: &mut Rng| o.map(|v| v + rng.range(-0.5, 0.5));
        let (a, b) = (p(&mut rng), p(&mut rng));
        let t = match i % 5 {
            0 => [a, b, [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]))], // collinear
            1 => [a, a, b],                                      // repeated corner
            2 => [a, b, [0, 1, 2].map(|k| a[k] + 1e-9 * (b[k] - a[k]) + 1e-12)], // sliver
            _ => [a, b, p(&mut rng)],
        };
        tris.push(t);
    }
    let positions: Vec<[f64; 3]> = tris.iter().flatten().copied().collect();
    let triangles = (0..tris.len() as u32)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    let soup = Mesh::new(positions, triangles).unwrap();
    let mut qs: Vec<[f64; 3]> = (0..100)
        .map(|_| [1e6, -2e6, 3e5].map(|v| v + rng.range(-1.5, 1.5)))
        .collect();
    for t in &tris[..10] {
        qs.push(t[0]);
        qs.push([0, 1, 2].map(|k| 2.0 * t[1][k] - t[0][k]));
    }
    let exact = winding_number_direct_batch(&soup, &qs);
    let fast = FastWindingNumber::new(&soup);
    let approx = fast.eval_batch_with(&qs, FastParams::barill(f64::INFINITY, 2));
    let (_, max) = errors(&approx, &exact);
    assert!(max <= 1e-12, "{max:e}");
}

#[test]
fn near_field_is_accurate_next_to_an_interior_edge() {
    // Issue 22: 1e-17 off the diagonal edge shared by the two triangles of the open box's x = 0
    // face, the two triangles' solid angles are each ≈ ±2π and cancel; the f64 formula errs by
    // ≈ 2e-17/d there (0.44 at d = 1e-17). The near field must use the direct sum's
    // accurate (double-double) term for such ill-conditioned triangles.
    let p = [
        [0., 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 0., 1.],
        [1., 1., 1.],
        [0., 1., 1.],
    ];
    let t = [
        [0, 2, 1],
        [0, 3, 2],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ];
    let open_box = Mesh::from_slices(&p, &t).unwrap();
    let fast = FastWindingNumber::new(&open_box);
    let mut qs = Vec::new();
    for d in [1e-17, 1e-15, 1e-12, 1e-9, 1e-6] {
        for s in [-1.0, 1.0] {
            qs.push([s * d, 0.5, 0.5]);
            qs.push([s * d, 0.25, 0.75]);
            qs.push([0.5 + s * d, 0.5 - s * d, 0.0]); // the bottom face's diagonal
        }
    }
    let exact = winding_number_direct_batch(&open_box, &qs);
    let approx = fast.eval_batch(&qs);
    for ((q, a), e) in qs.iter().zip(&approx).zip(&exact) {
        assert!((a - e).abs() <= 1e-13, "{q:?}: fast {a} direct {e}");
    }
}
