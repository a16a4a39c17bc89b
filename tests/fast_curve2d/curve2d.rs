//! Tests of the 2D GauWN module: closed forms against independent formulas, derivatives against
//! finite differences, the BVH against brute force, the applications, I/O and the CLI.

use gwn::curve2d::bvn::{norm_cdf, norm_cdf_diff};
use gwn::curve2d::{BvnMethod, CurveBvh, GauWn, Point, Polygon};
use proptest::prelude::*;
use std::f64::consts::PI;

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Polygon {
    Polygon::new(vec![vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]]).unwrap()
}

fn circle(r: f64, n: usize, c: Point) -> Polygon {
    let pts = (0..n)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / n as f64;
            [c[0] + r * t.cos(), c[1] + r * t.sin()]
        })
        .collect();
    Polygon::new(vec![pts]).unwrap()
}

/// A small deterministic generator (tests must be reproducible).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn axis_aligned_rectangle_is_product_of_1d_cdfs() {
    let (x0, y0, x1, y1) = (-0.3, 0.2, 1.1, 0.9);
    let poly = rect(x0, y0, x1, y1);
    let mut rng = Lcg(1);
    let mut worst: f64 = 0.0;
    for sigma in [0.01, 0.1, 0.5, 2.0] {
        let g = GauWn::new(sigma);
        for _ in 0..200 {
            let q = [rng.next() * 3.0 - 1.0, rng.next() * 3.0 - 1.0];
            let exact = norm_cdf_diff((x0 - q[0]) / sigma, (x1 - q[0]) / sigma)
                * norm_cdf_diff((y0 - q[1]) / sigma, (y1 - q[1]) / sigma);
            let w = g.value(&poly, q);
            worst = worst.max((w - exact).abs());
            assert!(
                (w - exact).abs() < 1e-14,
                "q {q:?} sigma {sigma}: {w} vs {exact}"
            );
        }
    }
    eprintln!("axis-aligned rectangle: worst error {worst:e}");
}

#[test]
fn rotated_rectangle_in_its_own_frame() {
    let (w, h) = (1.3, 0.6);
    let mut rng = Lcg(2);
    let mut worst: f64 = 0.0;
    let mut worst_fast: f64 = 0.0;
    for &theta in &[0.1, 0.5, 0.9, 1.3, 2.0, 2.7, 1e-9, PI / 2.0 - 1e-9] {
        let (c, s) = (f64::cos(theta), f64::sin(theta));
        let rot = |p: Point| [c * p[0] - s * p[1] + 0.2, s * p[0] + c * p[1] - 0.1];
        let poly = Polygon::new(vec![vec![
            rot([0., 0.]),
            rot([w, 0.]),
            rot([w, h]),
            rot([0., h]),
        ]])
        .unwrap();
        for sigma in [0.05, 0.3, 1.0] {
            let g = GauWn::new(sigma);
            let gf = g.with_bvn(BvnMethod::Fast);
            for _ in 0..60 {
                let q = [rng.next() * 3.0 - 1.0, rng.next() * 3.0 - 1.0];
                // q in the rectangle's frame.
                let (dx, dy) = (q[0] - 0.2, q[1] + 0.1);
                let (u, v) = (c * dx + s * dy, -s * dx + c * dy);
                let exact = norm_cdf_diff(-u / sigma, (w - u) / sigma)
                    * norm_cdf_diff(-v / sigma, (h - v) / sigma);
                let val = g.value(&poly, q);
                worst = worst.max((val - exact).abs());
                worst_fast = worst_fast.max((gf.value(&poly, q) - exact).abs());
                assert!(
                    (val - exact).abs() < 1e-13,
                    "theta {theta} sigma {sigma} q {q:?}: {val} vs {exact}"
                );
            }
        }
    }
    eprintln!("rotated rectangle: precise worst {worst:e}, fast worst {worst_fast:e}");
    assert!(worst_fast < 1e-2);
}

/// P(|q + σZ| ≤ R) = 1 − Q₁(|q|/σ, R/σ), by Gauss–Legendre integration of the Rice density
/// `x exp(−(x² + a²)/2) I₀(ax)` over [0, b], with `I₀` scaled and computed by the periodic
/// trapezoidal rule of its integral representation.
fn one_minus_marcum_q1(a: f64, b: f64) -> f64 {
    let i0e = |t: f64| {
        // e^{−t} I₀(t) = (1/π) ∫₀^π e^{t(cos θ − 1)} dθ
        let m = 400;
        let mut s = 0.0;
        for j in 0..m {
            let th = PI * (j as f64 + 0.5) / m as f64;
            s += (t * (th.cos() - 1.0)).exp();
        }
        s / m as f64
    };
    // Composite 5-point Gauss–Legendre on [0, b].
    let nodes = [
        (0.0, 0.568_888_888_888_888_9),
        (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (0.906_179_845_938_664, 0.236_926_885_056_189_1),
        (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    ];
    let panels = 2000;
    let h = b / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let c = (p as f64 + 0.5) * h;
        for &(x, wt) in &nodes {
            let r = c + 0.5 * h * x;
            sum += 0.5 * h * wt * r * (-(r - a) * (r - a) / 2.0).exp() * i0e(a * r);
        }
    }
    sum
}

#[test]
fn disc_matches_marcum_q() {
    let big_r = 1.0;
    let n = 4000;
    let poly = circle(big_r, n, [0.0, 0.0]);
    for sigma in [0.1, 0.3] {
        let g = GauWn::new(sigma);
        // Inscribed polygon: the missing area between polygon and disc bounds the error.
        let missing =
            PI * big_r * big_r - 0.5 * n as f64 * big_r * big_r * (2.0 * PI / n as f64).sin();
        let bound = missing / (2.0 * PI * sigma * sigma);
        for &r in &[0.0, 0.3, 0.9, 1.0, 1.1, 1.6] {
            let q = [r * 0.6, r * 0.8];
            let exact = one_minus_marcum_q1(r / sigma, big_r / sigma);
            let w = g.value(&poly, q);
            assert!(
                (w - exact).abs() <= bound + 1e-12,
                "sigma {sigma} r {r}: {w} vs {exact} (bound {bound:e})"
            );
            // The polygon lies inside the disc: W cannot exceed the disc's value.
            assert!(w <= exact + 1e-12);
        }
    }
}

fn random_polygon(rng: &mut Lcg, n: usize) -> Polygon {
    // A star-shaped-ish random loop, possibly self-intersecting, plus a second small loop.
    let mut pts = Vec::new();
    for i in 0..n {
        let t = 2.0 * PI * (i as f64 + 0.8 * rng.next()) / n as f64;
        let r = 0.4 + 0.6 * rng.next();
        pts.push([r * t.cos(), r * t.sin()]);
    }
    let c = [rng.next() - 0.5, rng.next() - 0.5];
    let small = vec![
        [c[0], c[1]],
        [c[0] - 0.2, c[1] + 0.1 * rng.next()],
        [c[0] - 0.1, c[1] - 0.3],
    ];
    Polygon::new(vec![pts, small]).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn gradients_match_central_differences(seed in 0u64..1_000_000, sigma in 0.05f64..0.5) {
        let mut rng = Lcg(seed);
        let poly = random_polygon(&mut rng, 7);
        let g = GauWn::new(sigma);
        let q = [rng.next() * 2.0 - 1.0, rng.next() * 2.0 - 1.0];
        let h = 1e-6;
        // Spatial gradient.
        let grad = g.gradient(&poly, q);
        let fd = [
            (g.value(&poly, [q[0] + h, q[1]]) - g.value(&poly, [q[0] - h, q[1]])) / (2.0 * h),
            (g.value(&poly, [q[0], q[1] + h]) - g.value(&poly, [q[0], q[1] - h])) / (2.0 * h),
        ];
        let scale = grad[0].hypot(grad[1]).max(1e-3);
        for c in 0..2 {
            prop_assert!((grad[c] - fd[c]).abs() <= 1e-6 * scale, "spatial {grad:?} vs {fd:?}");
        }
        // Vertex gradient; and the translation identity ∇_q W = −Σ ∂W/∂v_i.
        let vg = g.vertex_gradient(&poly, q);
        let sum = vg.iter().fold([0.0; 2], |s, v| [s[0] + v[0], s[1] + v[1]]);
        prop_assert!((sum[0] + grad[0]).abs() < 1e-12 * scale.max(1.0));
        prop_assert!((sum[1] + grad[1]).abs() < 1e-12 * scale.max(1.0));
        let vscale = vg.iter().map(|v| v[0].hypot(v[1])).fold(1e-3, f64::max);
        for i in 0..poly.len() {
            for c in 0..2 {
                let mut plus = poly.points().to_vec();
                let mut minus = plus.clone();
                plus[i][c] += h;
                minus[i][c] -= h;
                let wp = g.value(&poly.with_points(plus).unwrap(), q);
                let wm = g.value(&poly.with_points(minus).unwrap(), q);
                let fd = (wp - wm) / (2.0 * h);
                prop_assert!(
                    (vg[i][c] - fd).abs() <= 1e-6 * vscale,
                    "vertex {i} axis {c}: {} vs {fd}", vg[i][c]
                );
            }
        }
    }
}

#[test]
fn small_sigma_recovers_winding_number_and_stays_in_range() {
    let mut rng = Lcg(7);
    for _ in 0..5 {
        let poly = random_polygon(&mut rng, 12);
        let g = GauWn::new(1e-4);
        let pts = poly.points();
        // Every face of the arrangement borders an edge: sample both sides along every edge.
        let mut wmin_wmax = (0i64, 0i64);
        for (i, j) in poly.edges() {
            let (a, b) = (pts[i], pts[j]);
            let l = (b[0] - a[0]).hypot(b[1] - a[1]);
            for k in 0..200 {
                let t = (k as f64 + 0.5) / 200.0;
                for side in [-1e-9, 1e-9] {
                    let x = [
                        a[0] + t * (b[0] - a[0]) - side * (b[1] - a[1]) / l,
                        a[1] + t * (b[1] - a[1]) + side * (b[0] - a[0]) / l,
                    ];
                    let w = poly.winding_number(x);
                    wmin_wmax = (wmin_wmax.0.min(w), wmin_wmax.1.max(w));
                }
            }
        }
        for _ in 0..200 {
            let q = [rng.next() * 3.0 - 1.5, rng.next() * 3.0 - 1.5];
            // Distance to the curve.
            let d = poly
                .edges()
                .map(|(i, j)| seg_dist(pts[i], pts[j], q))
                .fold(f64::INFINITY, f64::min);
            let w = g.value(&poly, q);
            if d > 1e-2 {
                let exact = poly.winding_number(q) as f64;
                assert!((w - exact).abs() < 1e-12, "q {q:?}: {w} vs {exact}");
            }
            // Convex combination of the winding numbers (0 is always attained far away).
            let gb = GauWn::new(0.2).value(&poly, q);
            assert!(
                gb >= wmin_wmax.0 as f64 - 1e-12 && gb <= wmin_wmax.1 as f64 + 1e-12,
                "{gb} {wmin_wmax:?}"
            );
        }
    }
}

fn seg_dist(a: Point, b: Point, q: Point) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a[0] + t * dx - q[0]).hypot(a[1] + t * dy - q[1])
}

#[test]
fn bvh_matches_brute_force() {
    let mut rng = Lcg(11);
    // A wiggly curve of 3000 vertices plus an overlapping second loop and a loop through a
    // vertex of the first (a geometrically non-manifold point).
    let n = 3000;
    let mut a = Vec::new();
    for i in 0..n {
        let t = 2.0 * PI * i as f64 / n as f64;
        let r = 1.0 + 0.2 * (13.0 * t).sin() + 0.01 * rng.next();
        a.push([r * t.cos(), r * t.sin()]);
    }
    let b = circle(0.7, 500, [0.5, 0.2]).points().to_vec();
    let c = vec![
        a[0],
        [a[0][0] + 0.3, a[0][1] + 0.2],
        [a[0][0] + 0.3, a[0][1] - 0.2],
    ];
    let poly = Polygon::new(vec![a, b, c]).unwrap();
    let bvh = CurveBvh::new(&poly);
    for sigma in [0.005, 0.02, 0.1] {
        let g = GauWn::new(sigma);
        for _ in 0..100 {
            let q = [rng.next() * 3.0 - 1.5, rng.next() * 3.0 - 1.5];
            let exact = g.value(&poly, q);
            let (v, bound) = bvh.value_with_bound(&g, q);
            assert!(
                (v - exact).abs() <= bound + 1e-12,
                "value {v} vs {exact}, bound {bound:e}"
            );
            assert!(bound < 1e-10);
            let gr = g.gradient(&poly, q);
            let gb = bvh.gradient(&g, q);
            assert!((gr[0] - gb[0]).abs() < 1e-12 && (gr[1] - gb[1]).abs() < 1e-12);
            let vg = g.vertex_gradient(&poly, q);
            let vb = bvh.vertex_gradient(&g, q);
            for (x, y) in vg.iter().zip(&vb) {
                assert!((x[0] - y[0]).abs() < 1e-12 && (x[1] - y[1]).abs() < 1e-12);
            }
        }
    }
}

#[test]
fn exact_winding_number_is_consistent_on_degenerate_queries() {
    let mut rng = Lcg(5);
    // Integer-grid polygon so that vertices and edges are hit exactly.
    for _ in 0..20 {
        let pts: Vec<Point> = (0..9)
            .map(|_| [(rng.next() * 8.0).floor(), (rng.next() * 8.0).floor()])
            .collect();
        let Ok(poly) = Polygon::new(vec![pts.clone()]) else {
            continue;
        };
        let t = 1e-7;
        let mut queries: Vec<Point> = pts.clone();
        for (i, j) in poly.edges() {
            let (a, b) = (pts[i], pts[j]);
            queries.push([(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0]);
        }
        for x in 0..8 {
            for y in 0..8 {
                queries.push([x as f64, y as f64]);
            }
        }
        for q in queries {
            let w = poly.winding_number(q);
            let w_pert = poly.winding_number([q[0] + t, q[1] + t * t]);
            assert_eq!(w, w_pert, "q {q:?}");
        }
    }
}

#[test]
fn bvn_limits_and_symmetries() {
    for m in [BvnMethod::Precise, BvnMethod::Fast] {
        let tol = if m == BvnMethod::Precise { 1e-15 } else { 2e-3 };
        for &(h, k) in &[(0.3, -0.7), (1.5, 2.0), (-2.0, -1.0), (0.0, 0.0)] {
            // ρ = 0: product.
            assert!((m.cdf(h, k, 0.0) - norm_cdf(h) * norm_cdf(k)).abs() < 1e-16);
            // ρ = ±1 limits.
            assert!((m.cdf(h, k, 1.0) - norm_cdf(h.min(k))).abs() < 1e-16);
            assert!((m.cdf(h, k, -1.0) - (norm_cdf(h) + norm_cdf(k) - 1.0).max(0.0)).abs() < 4e-16);
            for &r in &[-0.95, -0.6, -0.2, 0.4, 0.8, 0.97, 0.999_999_9] {
                // Symmetry in (h, k).
                assert!((m.cdf(h, k, r) - m.cdf(k, h, r)).abs() < tol);
                // P(X ≤ h, Y ≤ k) + P(X ≤ h, Y > k) = Φ(h), and P(X ≤ h, −Y < −k) has corr −ρ.
                let s = m.cdf(h, k, r) + m.cdf(h, -k, -r);
                assert!((s - norm_cdf(h)).abs() < 2.0 * tol, "{m:?} {h} {k} {r}");
            }
        }
        // Approaching ρ → 1 continuously (no clamping jump).
        let a = m.cdf(0.3, 0.5, 1.0 - 1e-12);
        assert!((a - norm_cdf(0.3)).abs() < 1e-5);
    }
    // A reference value: BvN(1, 1; 0.5) = 0.74520358684674973 (30-digit quadrature).
    let v = BvnMethod::Precise.cdf(1.0, 1.0, 0.5);
    assert!((v - 0.745_203_586_846_749_7).abs() < 1e-15, "{v}");
}

mod apps {
    use super::*;
    use gwn::curve2d::apps::{
        BrushParams, OffsetParams, UntangleParams, apply_brush, brush_energy, offset, untangle,
        untangle_energy,
    };
    use gwn::curve2d::polygon::segments_intersect;

    /// Exact check, independent of `Polygon::has_self_intersections`: any two non-adjacent
    /// edges sharing a point.
    fn count_crossings(p: &Polygon) -> usize {
        let pts = p.points();
        let e: Vec<(usize, usize)> = p.edges().collect();
        let mut n = 0;
        for i in 0..e.len() {
            for j in i + 1..e.len() {
                let adjacent = e[i].1 == e[j].0 || e[j].1 == e[i].0;
                if !adjacent
                    && segments_intersect(pts[e[i].0], pts[e[i].1], pts[e[j].0], pts[e[j].1])
                {
                    n += 1;
                }
            }
        }
        n
    }

    /// A unit square (40 vertices) whose bottom edge has a small twisted lobe: the curve runs
    /// right, loops back over itself and continues, like a figure eight in miniature.
    fn twisted_square() -> Polygon {
        let mut pts = Vec::new();
        for i in 0..10 {
            pts.push([i as f64 / 10.0, 0.0]);
        }
        // Twist between x = 0.4 and 0.6 replaced: a small figure-eight lobe.
        pts.retain(|p| !(p[0] > 0.35 && p[0] < 0.65));
        let lobe = [
            [0.45, 0.0],
            [0.58, 0.05],
            [0.58, -0.03],
            [0.5, 0.04],
            [0.62, 0.0],
        ];
        let at = pts.iter().position(|p| p[0] > 0.65).unwrap();
        for (k, l) in lobe.iter().enumerate() {
            pts.insert(at + k, *l);
        }
        for i in 0..10 {
            pts.push([1.0, i as f64 / 10.0]);
        }
        for i in 0..10 {
            pts.push([1.0 - i as f64 / 10.0, 1.0]);
        }
        for i in 0..10 {
            pts.push([0.0, 1.0 - i as f64 / 10.0]);
        }
        Polygon::new(vec![pts]).unwrap()
    }

    #[test]
    fn untangling_removes_self_intersections() {
        let poly = twisted_square();
        assert!(
            count_crossings(&poly) > 0,
            "test polygon must start tangled"
        );
        let rep = untangle(&poly, &UntangleParams::default()).unwrap();
        eprintln!(
            "untangle: {} outer iterations, final sigma {:e}, max displacement {:.4}, converged {}",
            rep.outer_iterations, rep.final_sigma, rep.max_displacement, rep.converged
        );
        assert!(rep.converged);
        assert_eq!(count_crossings(&rep.polygon), 0);
        assert!(!rep.polygon.has_self_intersections());
        // Every vertex stays within 0.15 (the extent of the twisted lobe) of its input position,
        // and vertices away from the lobe hardly move.
        assert!(rep.max_displacement < 0.15, "{}", rep.max_displacement);
        for (a, b) in poly.points().iter().zip(rep.polygon.points()) {
            let d = (a[0] - b[0]).hypot(a[1] - b[1]);
            let near_lobe = a[1] < 0.1 && a[0] > 0.3 && a[0] < 0.75;
            if !near_lobe {
                assert!(d < 0.02, "{a:?} moved by {d}");
            }
        }
        // Same result (mirrored) for the reversed input.
        let rev = untangle(&poly.reversed(), &UntangleParams::default()).unwrap();
        assert_eq!(count_crossings(&rev.polygon), 0);
    }

    #[test]
    fn untangle_energy_gradient_matches_finite_differences() {
        let poly = twisted_square();
        let rest: Vec<Point> = poly
            .points()
            .iter()
            .map(|p| [p[0] + 0.01, p[1] - 0.005])
            .collect();
        let (sigma, eps, lambda) = (0.02, 0.01, 1.0);
        let (_, grad) = untangle_energy(&poly, &rest, sigma, eps, lambda);
        let gmax = grad.iter().fold(0.0f64, |m, g| m.max(g.abs()));
        let h = 1e-6;
        for i in [0usize, 4, 5, 6, 7, 20, 41] {
            for c in 0..2 {
                let mut p = poly.points().to_vec();
                p[i][c] += h;
                let ep = untangle_energy(
                    &poly.with_points(p.clone()).unwrap(),
                    &rest,
                    sigma,
                    eps,
                    lambda,
                )
                .0;
                p[i][c] -= 2.0 * h;
                let em =
                    untangle_energy(&poly.with_points(p).unwrap(), &rest, sigma, eps, lambda).0;
                let fd = (ep - em) / (2.0 * h);
                assert!(
                    (fd - grad[2 * i + c]).abs() < 1e-5 * gmax,
                    "{i} {c}: {fd} vs {}",
                    grad[2 * i + c]
                );
            }
        }
    }

    #[test]
    fn offsetting_a_circle_grows_its_radius() {
        // The paper's step (|o| = 0.2, Fig. 11): half the flow steps of the default 0.1.
        for (d, n) in [(0.1, 100), (-0.1, 100)] {
            let poly = circle(1.0, n, [0.0, 0.0]);
            let params = OffsetParams {
                step: 0.2,
                ..OffsetParams::new(d)
            };
            let rep = offset(&poly, &params).unwrap();
            let radii: Vec<f64> = rep
                .polygon
                .points()
                .iter()
                .map(|p| p[0].hypot(p[1]))
                .collect();
            let mean = radii.iter().sum::<f64>() / radii.len() as f64;
            let spread = radii.iter().fold(0.0f64, |m, r| m.max((r - mean).abs()));
            eprintln!(
                "offset {d}: {} steps, sigma {}, mean radius {mean:.5}, spread {spread:e}",
                rep.steps, rep.sigma
            );
            assert!((mean - (1.0 + d)).abs() < 0.01 * d.abs() + 1e-3, "{mean}");
            assert!(spread < 1e-3);
            assert_eq!(count_crossings(&rep.polygon), 0);
        }
    }

    #[test]
    fn brush_pulls_the_curve_over_a_point() {
        let poly = circle(1.0, 100, [0.0, 0.0]);
        let target_pt = [1.03, 0.0];
        assert_eq!(poly.winding_number(target_pt), 0);
        let params = BrushParams {
            sigma: 0.03,
            lambda: 0.01,
            iters: 100,
        };
        // Gradient check of the brush energy.
        let brush = vec![(target_pt, 1.0), ([0.9, 0.1], 1.0), ([1.2, 0.0], 0.0)];
        let rest = poly.points().to_vec();
        let moved = poly
            .with_points(rest.iter().map(|p| [p[0] * 1.01, p[1]]).collect())
            .unwrap();
        let (_, grad) = brush_energy(&moved, &rest, &brush, &params);
        let h = 1e-6;
        let gmax = grad.iter().fold(0.0f64, |m, g| m.max(g.abs()));
        for i in [0usize, 1, 99, 50] {
            for c in 0..2 {
                let mut p = moved.points().to_vec();
                p[i][c] += h;
                let ep = brush_energy(
                    &moved.with_points(p.clone()).unwrap(),
                    &rest,
                    &brush,
                    &params,
                )
                .0;
                p[i][c] -= 2.0 * h;
                let em = brush_energy(&moved.with_points(p).unwrap(), &rest, &brush, &params).0;
                assert!(((ep - em) / (2.0 * h) - grad[2 * i + c]).abs() < 1e-5 * gmax.max(1e-3));
            }
        }
        let out = apply_brush(&poly, &brush, &params);
        assert_eq!(out.winding_number(target_pt), 1);
        assert_eq!(out.winding_number([1.2, 0.0]), 0);
    }
}

mod text_io {
    use super::*;

    fn write_text(p: &Polygon) -> String {
        let mut s = String::from("# test polygon\n");
        for k in 0..p.num_loops() {
            for v in p.loop_points(k) {
                s.push_str(&format!("{} {}\n", v[0], v[1]));
            }
            s.push('\n');
        }
        s
    }

    #[test]
    fn text_round_trip() {
        let p = Polygon::new(vec![
            circle(1.0, 17, [0.0, 0.0]).points().to_vec(),
            vec![[3.0, 3.0], [4.0, 3.0], [3.5, 4.0]],
        ])
        .unwrap();
        let q = gwn::curve2d::io::parse_text(&write_text(&p), "mem").unwrap();
        assert_eq!(p, q);
    }
}
