//! Open polylines: the generalized winding number and its Gaussian smoothing against closed
//! forms, the closed-loop formulas, and finite differences.

use gwn::curve2d::bvn::norm_cdf;
use gwn::curve2d::open::{owens_t, segment_angle, segment_smoothed, segment_smoothed_gradient};
use gwn::curve2d::tangled::Lcg;
use gwn::curve2d::{Curves, CurvesField, GauWn, Point, Polygon};
use std::f64::consts::PI;

/// Owen's T by composite Simpson on the defining integral (an independent reference).
fn owens_t_reference(h: f64, a: f64) -> f64 {
    let n = 200_000;
    let f = |x: f64| (-0.5 * h * h * (1.0 + x * x)).exp() / (1.0 + x * x);
    let dx = a / n as f64;
    let mut s = f(0.0) + f(a);
    for i in 1..n {
        s += f(i as f64 * dx) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * dx / 3.0 / (2.0 * PI)
}

#[test]
fn owens_t_matches_identities_and_quadrature() {
    for h in [0.0, 0.1, 0.7, 1.5, 3.0, 6.0, 12.0] {
        // T(h, 1) = ½Φ(h)Φ(−h); T(h, ∞) = ½Φ(−h); T(0, a) = atan(a)/2π.
        let t1 = owens_t(h, 1.0);
        assert!(
            (t1 - 0.5 * norm_cdf(h) * norm_cdf(-h)).abs() < 1e-16,
            "{h}: {t1}"
        );
        let tinf = owens_t(h, f64::INFINITY);
        assert!((tinf - 0.5 * norm_cdf(-h)).abs() < 1e-16);
        assert!((owens_t(h, 1e17) - 0.5 * norm_cdf(-h)).abs() < 1e-16);
        for a in [0.01, 0.3, 0.99, 1.01, 2.5, 40.0] {
            let t = owens_t(h, a);
            let r = owens_t_reference(h, a);
            assert!((t - r).abs() < 1e-14, "T({h}, {a}) = {t}, reference {r}");
            assert_eq!(owens_t(h, -a), -t);
        }
    }
    for a in [0.2, 1.0, 7.0] {
        assert!((owens_t(0.0, a) - a.atan() / (2.0 * PI)).abs() < 1e-16);
    }
}

fn random_polygon(rng: &mut Lcg, n: usize) -> Polygon {
    let pts = (0..n)
        .map(|_| [rng.next_f64() * 2.0 - 1.0, rng.next_f64() * 2.0 - 1.0])
        .collect();
    Polygon::new(vec![pts]).unwrap()
}

#[test]
fn segments_sum_to_the_closed_loop_value() {
    // Σ over the edges of a closed polygon of the open-segment formula (Owen's T) must equal the
    // closed-loop BvN formula: two independent derivations of the same integral.
    let mut rng = Lcg::new(7);
    let mut worst: f64 = 0.0;
    for _ in 0..20 {
        let poly = random_polygon(&mut rng, 9);
        for sigma in [0.02, 0.2, 1.0] {
            let g = GauWn::new(sigma);
            for _ in 0..20 {
                let q = [rng.next_f64() * 3.0 - 1.5, rng.next_f64() * 3.0 - 1.5];
                let p = poly.points();
                let sum: f64 = poly
                    .edges()
                    .map(|(i, j)| segment_smoothed(sigma, p[i], p[j], q))
                    .sum();
                worst = worst.max((sum - g.value(&poly, q)).abs());
            }
            // Queries on a vertex and on an edge.
            let q = poly.points()[3];
            let sum: f64 = poly
                .edges()
                .map(|(i, j)| segment_smoothed(sigma, poly.points()[i], poly.points()[j], q))
                .sum();
            worst = worst.max((sum - g.value(&poly, q)).abs());
        }
    }
    assert!(worst < 1e-13, "{worst}");
}

#[test]
fn plain_angles_sum_to_the_exact_winding_number() {
    // Σ segment angles / 2π over a closed polygon equals the exact (perturbed) crossing count,
    // also for queries exactly on vertices, on edges and on the lines of edges.
    let mut rng = Lcg::new(3);
    for _ in 0..30 {
        let poly = random_polygon(&mut rng, 8);
        let p = poly.points().to_vec();
        let mut queries: Vec<Point> = (0..20)
            .map(|_| [rng.next_f64() * 2.0 - 1.0, rng.next_f64() * 2.0 - 1.0])
            .collect();
        queries.extend(p.iter().copied());
        // Edge midpoints (often exactly on the edge) and points on an edge's line beyond it.
        for (i, j) in poly.edges() {
            queries.push([0.5 * (p[i][0] + p[j][0]), 0.5 * (p[i][1] + p[j][1])]);
            queries.push([2.0 * p[j][0] - p[i][0], 2.0 * p[j][1] - p[i][1]]);
        }
        for q in queries {
            let s: f64 = poly
                .edges()
                .map(|(i, j)| segment_angle(p[i], p[j], q))
                .sum::<f64>()
                / (2.0 * PI);
            let w = poly.winding_number(q) as f64;
            assert!((s - w).abs() < 1e-12, "{q:?}: {s} vs {w}");
        }
    }
    // Axis-aligned cases, where exact zeros are common.
    let sq = Polygon::new(vec![vec![[0., 0.], [1., 0.], [1., 1.], [0., 1.]]]).unwrap();
    for q in [
        [0., 0.],
        [1., 0.],
        [0.5, 0.],
        [0., 0.5],
        [1., 1.],
        [2., 0.],
        [0., 2.],
    ] {
        let s: f64 = sq
            .edges()
            .map(|(i, j)| segment_angle(sq.points()[i], sq.points()[j], q))
            .sum::<f64>()
            / (2.0 * PI);
        assert!((s - sq.winding_number(q) as f64).abs() < 1e-15, "{q:?}");
    }
}

#[test]
fn open_square_and_long_segment_closed_forms() {
    // The unit square without its top edge, seen from its centre: 3/4.
    let open = Curves {
        polygon: Polygon::new(vec![vec![[0., 0.], [1., 0.], [1., 1.], [0., 1.]]]).unwrap(),
        open: vec![true],
    };
    assert!((open.winding_number([0.5, 0.5]) - 0.75).abs() < 1e-15);
    // Outside, above: the sum of the three edges' angles, each arg difference wrapped.
    let q = [0.5, 2.0];
    let arg = |p: Point| (p[1] - q[1]).atan2(p[0] - q[0]);
    let verts = [[0., 0.], [1., 0.], [1., 1.], [0., 1.]];
    let expect: f64 = verts
        .windows(2)
        .map(|w| {
            let mut d = arg(w[1]) - arg(w[0]);
            if d > PI {
                d -= 2.0 * PI;
            } else if d <= -PI {
                d += 2.0 * PI;
            }
            d
        })
        .sum::<f64>()
        / (2.0 * PI);
    assert!((open.winding_number(q) - expect).abs() < 1e-15);
    // Far beyond the σ scale the smoothing changes nothing measurable.
    let field = CurvesField::new(&open);
    let g = GauWn::new(1e-3);
    assert!((field.value(&g, [0.5, 0.5]) - 0.75).abs() < 1e-14);

    // A segment of half-length 1e9 running along +x, seen from (0.3, y): w = ±1/2 (its left,
    // y > 0, is positive), and its smoothing is Φ(y/σ) − ½ (the convolution of a step), up to
    // the ends' σ/L ≈ 1e-9.
    let l = 1e9;
    for sigma in [0.1, 1.0] {
        for y in [-3.0, -0.5, -1e-9, 0.0, 1e-9, 0.2, 1.0, 4.0] {
            let s = segment_smoothed(sigma, [-l, 0.0], [l, 0.0], [0.3, y]);
            let expect = norm_cdf(y / sigma) - 0.5;
            let expect = if y == 0.0 { 0.0 } else { expect };
            assert!(
                (s - expect).abs() < 1e-8,
                "σ {sigma} y {y}: {s} vs {expect}"
            );
        }
    }
}

#[test]
fn circular_arc_closed_form() {
    // An arc of angle α and radius R centred at q: W_σ(q) = α(1 − e^{−R²/2σ²})/2π (the
    // Gauss's-law form of the module docs). A 20 000-vertex polyline is within 1e-7.
    let (r, alpha, n) = (0.7f64, 2.0f64, 20_000);
    let pts: Vec<Point> = (0..=n)
        .map(|i| {
            let t = alpha * i as f64 / n as f64;
            [r * t.cos(), r * t.sin()]
        })
        .collect();
    let curves = Curves {
        polygon: Polygon::new(vec![pts]).unwrap(),
        open: vec![true],
    };
    let field = CurvesField::new(&curves);
    for sigma in [0.2, 0.5, 1.0, 3.0] {
        let w = field.value(&GauWn::new(sigma), [0.0, 0.0]);
        let expect = alpha * (1.0 - (-r * r / (2.0 * sigma * sigma)).exp()) / (2.0 * PI);
        assert!((w - expect).abs() < 1e-7, "σ {sigma}: {w} vs {expect}");
    }
    assert!((curves.winding_number([0.0, 0.0]) - alpha / (2.0 * PI)).abs() < 1e-12);
}

#[test]
fn open_gradient_matches_central_differences() {
    let mut rng = Lcg::new(11);
    for _ in 0..10 {
        let n = 6;
        let pts: Vec<Point> = (0..n)
            .map(|_| [rng.next_f64() * 2.0 - 1.0, rng.next_f64() * 2.0 - 1.0])
            .collect();
        let curves = Curves {
            polygon: Polygon::new(vec![pts]).unwrap(),
            open: vec![true],
        };
        let field = CurvesField::new(&curves);
        for sigma in [0.1, 0.4] {
            let g = GauWn::new(sigma);
            for _ in 0..10 {
                let q = [rng.next_f64() * 2.4 - 1.2, rng.next_f64() * 2.4 - 1.2];
                let grad = field.gradient(&g, q);
                let h = 1e-6;
                let fd = [
                    (field.value(&g, [q[0] + h, q[1]]) - field.value(&g, [q[0] - h, q[1]]))
                        / (2.0 * h),
                    (field.value(&g, [q[0], q[1] + h]) - field.value(&g, [q[0], q[1] - h]))
                        / (2.0 * h),
                ];
                let scale = grad[0].abs().max(grad[1].abs()).max(1e-3);
                for c in 0..2 {
                    assert!(
                        (fd[c] - grad[c]).abs() < 1e-6 * scale,
                        "q {q:?} σ {sigma}: {fd:?} vs {grad:?}"
                    );
                }
            }
        }
    }
    // One segment alone, query on its end (the vortex term is finite there).
    let g = GauWn::new(0.3);
    let s = segment_smoothed_gradient(&g, [0.0, 0.0], [1.0, 0.0], [0.0, 0.0]);
    assert!(s.iter().all(|v| v.is_finite()));
}
