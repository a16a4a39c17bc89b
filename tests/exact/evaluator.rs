//! The `Evaluator` interface: every evaluator behind it gives the values of its own methods, grids
//! and products accept any of them, and the fast gradients are checked against finite
//! differences and against the exact gradient as β grows.

use crate::common;

use common::{Rng, open_cube, sphere_cloud};
use gwn::Mesh;
use gwn::eval::antipodal::WindingNumber;
use gwn::eval::direct::{DirectWindingNumber, winding_number_gradient_direct};
use gwn::eval::fast::{FastParams, FastWindingNumber, PointCloudWindingNumber};
use gwn::eval::{Evaluator, NoGradient};
use gwn::grid::{self, GridSpec};

fn lion_head() -> Mesh {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/lion-head.off");
    gwn::io::load_mesh(path).unwrap().mesh
}

fn queries(mesh: &Mesh, n: usize, seed: u64) -> Vec<[f64; 3]> {
    let b = mesh.bounding_box().unwrap().enlarged(0.2);
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| std::array::from_fn(|k| rng.range(b.min[k], b.max[k])))
        .collect()
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn diff(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm([a[0] - b[0], a[1] - b[1], a[2] - b[2]])
}

#[test]
fn every_evaluator_gives_its_own_values_through_the_trait() {
    let mesh = lion_head();
    let q = queries(&mesh, 64, 1);
    let exact = WindingNumber::new(&mesh).unwrap();
    let fast = FastWindingNumber::new(&mesh);
    let direct = DirectWindingNumber::new(&mesh);
    let cloud = sphere_cloud(500);
    let cloud_fast = PointCloudWindingNumber::new(&cloud);
    let cases: [(&dyn Evaluator, Vec<f64>); 4] = [
        (&exact, exact.eval_batch(&q)),
        (&fast, fast.eval_batch(&q)),
        (
            &direct,
            q.iter()
                .map(|&p| gwn::eval::direct::winding_number_direct(&mesh, p))
                .collect(),
        ),
        (&cloud_fast, cloud_fast.eval_batch(&q)),
    ];
    for (ev, want) in cases {
        let got = ev.eval_batch(&q);
        let one: Vec<f64> = q.iter().map(|&p| ev.eval(p)).collect();
        assert_eq!(
            got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            want.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            "{}",
            ev.name()
        );
        assert_eq!(
            one.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            want.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            "{}",
            ev.name()
        );
    }
    assert_eq!(exact.try_gradient(q[0]), Ok(exact.gradient(q[0])));
}

#[test]
fn columns_along_any_axis_equal_point_by_point_values() {
    let mesh = lion_head();
    let exact = WindingNumber::new(&mesh).unwrap();
    let fast = FastWindingNumber::new(&mesh);
    let b = mesh.bounding_box().unwrap();
    let ts: Vec<f64> = (0..17)
        .map(|i| b.min[0] + (b.max[0] - b.min[0]) * i as f64 / 16.0)
        .collect();
    let q = b.center();
    for ev in [&exact as &dyn Evaluator, &fast] {
        for axis in 0..3 {
            let col = ev.eval_column(q, axis, &ts);
            for (k, &t) in ts.iter().enumerate() {
                let mut p = q;
                p[axis] = t;
                assert_eq!(
                    col[k].to_bits(),
                    ev.eval(p).to_bits(),
                    "{} axis {axis}",
                    ev.name()
                );
            }
        }
    }
    assert_eq!(Evaluator::column_axis(&exact), Some(2));
    assert_eq!(Evaluator::column_axis(&fast), None);
}

#[test]
fn grids_accept_any_evaluator() {
    let mesh = open_cube();
    let spec = GridSpec::with_resolution(mesh.bounding_box().unwrap().enlarged(0.1), 9).unwrap();
    let fast = FastWindingNumber::new(&mesh);
    let direct = DirectWindingNumber::new(&mesh);
    let boxed: Box<dyn Evaluator> = Box::new(FastWindingNumber::new(&mesh));
    let by_grid = grid::evaluate(&fast, &spec);
    assert_eq!(by_grid, fast.eval_batch(&spec.points()));
    assert_eq!(grid::evaluate(&boxed, &spec), by_grid);
    assert_eq!(
        grid::evaluate(&direct, &spec),
        grid::evaluate_per_point(&direct, &spec)
    );
    // Every sample of the open cube agrees with the direct sum to the fast method's accuracy.
    for (a, b) in by_grid.iter().zip(grid::evaluate(&direct, &spec)) {
        assert!((a - b).abs() < 1e-2, "{a} vs {b}");
    }
}

#[test]
fn signed_distance_to_a_point_cloud_is_signed_by_its_winding_number() {
    use gwn::products::sdf::SignedDistance;
    let cloud = sphere_cloud(2000);
    let sdf = SignedDistance::with_points(cloud.positions(), PointCloudWindingNumber::new(&cloud));
    let inside = sdf.eval([0.0, 0.0, 0.1]);
    let outside = sdf.eval([0.0, 0.0, 3.0]);
    assert!(inside < 0.0 && (inside + 0.9).abs() < 0.05, "{inside}");
    assert!((outside - 2.0).abs() < 1e-3, "{outside}");
}

#[test]
fn an_evaluator_without_gradient_says_so() {
    struct Constant;
    impl Evaluator for Constant {
        fn eval(&self, _: [f64; 3]) -> f64 {
            1.0
        }
    }
    let e = Constant.try_gradient([0.0; 3]).unwrap_err();
    assert_eq!(
        e,
        NoGradient {
            evaluator: "custom"
        }
    );
    assert_eq!(e.to_string(), "the custom evaluator has no gradient");
    assert_eq!(
        Constant.eval_column([0.0; 3], 1, &[1.0, 2.0]),
        vec![1.0, 1.0]
    );
}

/// The fast soup gradient approaches the exact (and direct) gradient as β grows, and equals the
/// direct Biot–Savart sum when every triangle is summed exactly (β = ∞).
#[test]
fn fast_gradient_converges_to_the_exact_gradient_as_beta_grows() {
    let mesh = lion_head();
    let exact = WindingNumber::new(&mesh).unwrap();
    let fast = FastWindingNumber::new(&mesh);
    let q = queries(&mesh, 40, 7);
    let rms = |params: FastParams| {
        let (mut err, mut size) = (0.0, 0.0);
        for &p in &q {
            let g = exact.gradient(p);
            err += diff(fast.gradient_with(p, params), g).powi(2);
            size += norm(g).powi(2);
        }
        (err / size).sqrt()
    };
    let errors: Vec<f64> = [1.5, 2.0, 3.0, 5.0, 10.0]
        .iter()
        .map(|&b| rms(FastParams::barill(b, 2)))
        .collect();
    for w in errors.windows(2) {
        assert!(w[1] < w[0], "relative RMS error not decreasing: {errors:?}");
    }
    // Measured: 0.21, 0.046, 6.9e-3, 7.7e-4, 2.4e-5.
    assert!(errors[1] < 0.1, "{errors:?}");
    assert!(errors[4] < 1e-4, "{errors:?}");
    for &p in &q {
        let all = fast.gradient_with(p, FastParams::barill(f64::INFINITY, 2));
        let d = winding_number_gradient_direct(&mesh, p);
        assert!(diff(all, d) <= 1e-10 * norm(d), "{all:?} vs {d:?}");
    }
}

/// Each order's gradient is the derivative of its value: central differences of the fast value
/// (f32 far field, so to ~1e-4 relative) agree with it wherever the traversal does not change
/// between the two sample points.
#[test]
fn fast_gradient_matches_finite_differences_of_the_fast_value() {
    let mesh = lion_head();
    let fast = FastWindingNumber::new(&mesh);
    let diag = mesh.bounding_box().unwrap().diagonal();
    let h = 1e-4 * diag;
    let mut checked = 0;
    for order in 0..=2 {
        let params = FastParams::barill(2.0, order);
        for p in queries(&mesh, 30, 11) {
            let g = fast.gradient_with(p, params);
            let fd: [f64; 3] = std::array::from_fn(|k| {
                let (mut hi, mut lo) = (p, p);
                hi[k] += h;
                lo[k] -= h;
                (fast.eval_with(hi, params) - fast.eval_with(lo, params)) / (2.0 * h)
            });
            // A node switching between expansion and opening inside [p − h, p + h] makes the
            // value jump by up to the truncation error: such points are not a derivative test.
            if diff(fd, g) <= 2e-3 * norm(g).max(1e-3 / diag) {
                checked += 1;
            }
        }
    }
    // Measured: 78 of 90 (the others straddle an admissibility switch).
    assert!(checked >= 70, "only {checked} of 90 points matched");
}

#[test]
fn cloud_gradient_matches_the_dipole_sum_gradient() {
    let cloud = sphere_cloud(3000);
    let fast = PointCloudWindingNumber::new(&cloud);
    let (p, n) = (cloud.positions(), cloud.normals());
    let a = cloud.areas().unwrap();
    let direct = |q: [f64; 3]| gwn::eval::fast::winding_number_points_direct(p, n, a, q);
    let h = 1e-5;
    for q in [
        [0.1, 0.2, 0.3],
        [1.5, -0.3, 0.2],
        [0.0, 2.0, -1.0],
        [0.5, 0.5, 0.5],
    ] {
        let exact = fast.gradient_with(q, FastParams::barill(f64::INFINITY, 2));
        let fd: [f64; 3] = std::array::from_fn(|k| {
            let (mut hi, mut lo) = (q, q);
            hi[k] += h;
            lo[k] -= h;
            (direct(hi) - direct(lo)) / (2.0 * h)
        });
        assert!(
            diff(exact, fd) <= 1e-6 * norm(fd).max(1e-3),
            "{exact:?} vs {fd:?}"
        );
        // The approximation's error falls as β grows (outside the sphere the true gradient is
        // almost 0, so the error is measured against the field's scale, 1/(4π d²)).
        let scale = 1.0 / (4.0 * std::f64::consts::PI * norm(q).powi(2)).max(1.0);
        let errors: Vec<f64> = [2.3, 4.0, 8.0, 16.0]
            .iter()
            .map(|&b| diff(fast.gradient_with(q, FastParams::barill(b, 2)), exact) / scale)
            .collect();
        // Measured at (0.5, 0.5, 0.5): 0.35, 4.6e-2, 3.8e-3, 1.8e-4.
        assert!(errors.windows(2).all(|w| w[1] < w[0]), "{q:?}: {errors:?}");
        assert!(errors[0] < 0.5 && errors[3] < 1e-3, "{q:?}: {errors:?}");
    }
}

/// `eval_batch` evaluates runs of points on one line parallel to the ray as columns (numpy grids
/// with the ray's axis last): every value must be the point's own, bit for bit, for every ray,
/// with non-finite and signed-zero coordinates inside runs, runs longer than one column batch,
/// and points in random order (no runs).
#[test]
fn batches_with_grid_runs_equal_point_by_point_values() {
    use gwn::RayAxis;
    use gwn::eval::antipodal::Options;
    let mesh = lion_head();
    let b = mesh.bounding_box().unwrap().enlarged(0.1);
    let mut rng = Rng(77);
    for ray in RayAxis::ALL {
        let wn = WindingNumber::with_options(
            &mesh,
            Options {
                ray,
                ..Options::default()
            },
        )
        .unwrap();
        let axis = ray.map()[2].0;
        let mut points = Vec::new();
        for line in 0..40 {
            let mut q: [f64; 3] = std::array::from_fn(|k| rng.range(b.min[k], b.max[k]));
            if line % 5 == 0 {
                // A run that starts (and goes on) with a non-finite or signed-zero coordinate.
                let mut odd = q;
                odd[axis] = [f64::NAN, -0.0, f64::INFINITY][line % 3];
                points.push(odd);
            }
            let n = [1, 2, 7, 300][line % 4];
            for i in 0..n {
                q[axis] = b.min[axis] + (b.max[axis] - b.min[axis]) * (i as f64 + 0.5) / n as f64;
                points.push(q);
            }
            if line % 5 == 0 {
                let mut odd = q;
                odd[axis] = f64::NAN;
                points.push(odd);
            }
        }
        let batch = wn.eval_batch(&points);
        let mut by_point = 0;
        for (q, w) in points.iter().zip(&batch) {
            let want = wn.eval(*q);
            assert_eq!(
                w.to_bits(),
                want.to_bits(),
                "{ray:?} at {q:?}: {w} vs {want}"
            );
            by_point += 1;
        }
        assert!(by_point > 3000);
    }
}
