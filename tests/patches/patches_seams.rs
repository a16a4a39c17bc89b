//! Issue 23: every patch query returns with bounded work, near seams, corners, poles and
//! boundary curves of the teapot at 1e-3 … 1e-12 × diagonal, on six rays; the on-surface rule
//! on a closed sphere; extreme scales and weights; the tolerance bounds the total error.

use crate::common;
use crate::patch_points;

use std::time::{Duration, Instant};

use gwn::RayAxis;
use gwn::patch::eval::{MAX_EVALUATIONS, MAX_PIECES};
use gwn::patch::{Evaluation, Options, Patch, PatchSet, PatchWindingNumber, load_patches};

/// The teapot, below the shared corpus (`common::shared_root`).
const TEAPOT: &str = "parametric/teapot.bpt";

/// Work bound of one query: the evaluation cap plus one 15-point rule per boundary piece that
/// was pending when the cap was reached (`docs/patches.md`, "Time bound").
const EVALUATION_BOUND: usize = MAX_EVALUATIONS + 15 * 4 * MAX_PIECES;
/// Wall-clock limit per query: ~100× the worst observed in release, for slow CI machines.
const QUERY_DEADLINE: Duration = Duration::from_secs(2);

fn evaluators(set: &PatchSet, tolerance: f64) -> Vec<PatchWindingNumber> {
    RayAxis::ALL
        .iter()
        .map(|&ray| PatchWindingNumber::with_options(set, Options { ray, tolerance }).unwrap())
        .collect()
}

/// Evaluates with a deadline: the query runs in its own thread and the test fails if it has
/// not answered in time (the thread is then abandoned, the test process ends with the failure).
fn evaluate_within(wn: &PatchWindingNumber, q: [f64; 3]) -> Evaluation {
    let (tx, rx) = std::sync::mpsc::channel();
    let wn = wn.clone();
    std::thread::spawn(move || {
        let _ = tx.send(wn.evaluate(q));
    });
    let start = Instant::now();
    let ev = rx
        .recv_timeout(QUERY_DEADLINE)
        .unwrap_or_else(|_| panic!("q = {q:?}: no answer within {QUERY_DEADLINE:?}"));
    assert!(start.elapsed() <= QUERY_DEADLINE);
    assert!(
        ev.evaluations <= EVALUATION_BOUND,
        "q = {q:?}: {} evaluations",
        ev.evaluations
    );
    ev
}

#[test]
fn teapot_near_every_seam_corner_pole_and_curve_returns_and_agrees_on_six_rays() {
    // `GWN_TEAPOT` names the file directly; otherwise the shared corpus (`GWN_SHARED_DIR` or
    // `../shared`), skipping visibly when absent.
    let path = match std::env::var_os("GWN_TEAPOT") {
        Some(p) => std::path::PathBuf::from(p),
        None => {
            let Some(p) = common::shared_file(TEAPOT) else {
                return;
            };
            p
        }
    };
    if !path.exists() {
        common::report_skip(&path.display().to_string());
        return;
    }
    let set = load_patches(&path).unwrap();
    let evs = evaluators(&set, 1e-10);
    let offsets = [1e-3, 1e-6, 1e-9, 1e-12];
    let mut queries = patch_points::near_feature_queries(&set, &offsets, false);
    // Corners: every patch's, but only at the extreme offsets (the middle ones add time, not
    // cases: the same pieces are mixed).
    queries.retain(|q| q.kind != "corner" || q.offset == 1e-3 || q.offset == 1e-12);
    queries.extend(patch_points::poles(&set));
    let (mut certified, mut worst_spread) = (0, 0.0f64);
    for q in &queries {
        let results: Vec<Evaluation> = evs.iter().map(|e| evaluate_within(e, q.q)).collect();
        for r in &results {
            assert!(!r.capped, "{q:?}: {r:?}");
            // The teapot's values lie in [−1, 2.5] anywhere (open at the lid gap and tube ends,
            // the handle and spout ends inside the body: ≈ 1.75 there); an uncertified value
            // must stay in that range too.
            assert!((-1.0..=2.5).contains(&r.value), "{q:?}: {r:?}");
            if r.certified {
                assert!(r.error_estimate <= 1e-10, "{q:?}: {r:?}");
            }
        }
        if q.kind == "pole" {
            // Exactly on the surface: the principal value, flagged, the same on every ray.
            for r in &results {
                assert!(!r.certified && r.uncertified_pieces > 0, "{q:?}: {r:?}");
                assert!(
                    (r.value - results[0].value).abs() < 1e-6,
                    "{q:?}: {results:?}"
                );
            }
            continue;
        }
        if results.iter().all(|r| r.certified) {
            certified += 1;
            let hi = results.iter().map(|r| r.value).fold(f64::MIN, f64::max);
            let lo = results.iter().map(|r| r.value).fold(f64::MAX, f64::min);
            worst_spread = worst_spread.max(hi - lo);
            assert!(hi - lo < 1e-9, "{q:?}: {results:?}");
        } else {
            // Only queries that lie on the surface's extension through a boundary curve (below
            // a tube end whose edge is vertical there) may be uncertified.
            assert!(
                q.kind == "below-boundary" && q.offset <= 1e-9,
                "{q:?}: {results:?}"
            );
        }
    }
    println!(
        "{} queries × 6 rays, {certified} certified on all rays, worst spread {worst_spread:e}",
        queries.len()
    );
    assert!(
        certified + 16 >= queries.len(),
        "{certified} of {}",
        queries.len()
    );
}

fn sphere() -> PatchSet {
    PatchSet::new(common::rational_sphere_patches()).unwrap()
}

#[test]
fn closed_sphere_on_its_surface_is_one_half_on_every_ray() {
    let set = sphere();
    let evs = evaluators(&set, 1e-10);
    // Control points of the patches (exactly on the surface): an equator corner of four
    // patches and the poles (collapsed sides).
    let exact = [
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [0.0, -1.0, 0.0],
    ];
    for q in exact {
        for e in &evs {
            let r = evaluate_within(e, q);
            assert!(!r.certified && r.uncertified_pieces > 0, "q = {q:?}: {r:?}");
            assert!((r.value - 0.5).abs() < 1e-6, "q = {q:?}: {r:?}");
            assert!(
                (r.value - 0.5).abs() <= r.error_estimate,
                "q = {q:?}: {r:?}"
            );
        }
    }
    // Points on the sphere to rounding (patch interiors, a meridian seam, the equator seam):
    // within 2^-48 of the patches the principal value, flagged; otherwise resolved to the side
    // the rounding put them on, certified.
    let c = std::f64::consts::FRAC_1_SQRT_2;
    let mut points = vec![[c, c, 0.0], [0.0, 0.6, 0.8]];
    for k in 0..6 {
        let (theta, phi) = (0.3 + 0.41 * k as f64, 0.2 + 1.07 * k as f64);
        points.push([
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ]);
    }
    let mut flagged = 0;
    for q in points {
        for e in &evs {
            let r = evaluate_within(e, q);
            if r.certified {
                let side = r.value.round();
                assert!(
                    (side == 0.0 || side == 1.0) && (r.value - side).abs() < 1e-9,
                    "{r:?}"
                );
            } else {
                flagged += 1;
                assert!((r.value - 0.5).abs() < 1e-6, "q = {q:?}: {r:?}");
                assert!(
                    (r.value - 0.5).abs() <= r.error_estimate,
                    "q = {q:?}: {r:?}"
                );
            }
        }
    }
    assert!(flagged >= 24, "{flagged}");
}

/// The face `z = 0` of the unit cube, normal −z (out of the cube), as a bilinear patch with
/// weights `w`, scaled by `s`; seen from the cube's centre it is 1/6 of the sphere.
fn square(s: f64, w: f64) -> PatchSet {
    let pts = vec![[0.0, 0.0, 0.0], [s, 0.0, 0.0], [0.0, s, 0.0], [s, s, 0.0]];
    PatchSet::new(vec![Patch::rational(1, 1, pts, vec![w; 4]).unwrap()]).unwrap()
}

#[test]
fn extreme_scales_and_weights_give_the_unscaled_value() {
    let reference = PatchWindingNumber::new(&square(1.0, 1.0)).eval([0.5, 0.5, 0.5]);
    assert!((reference.abs() - 1.0 / 6.0).abs() < 1e-12, "{reference}");
    for s in [
        2f64.powi(600),
        1e300,
        1e150,
        1e-160,
        2f64.powi(-600),
        1e-300,
    ] {
        for ray in RayAxis::ALL {
            let wn = PatchWindingNumber::with_options(
                &square(s, 1.0),
                Options {
                    ray,
                    tolerance: 1e-12,
                },
            )
            .unwrap();
            let r = wn.evaluate([0.5 * s, 0.5 * s, 0.5 * s]);
            assert!(
                (r.value - reference).abs() < 1e-12 && r.certified,
                "s = {s:e}, {ray:?}: {r:?}"
            );
        }
    }
    for w in [1e300, 1e-300, f64::MAX, f64::MIN_POSITIVE, 5e-324] {
        let r = PatchWindingNumber::new(&square(1.0, w)).evaluate([0.5, 0.5, 0.5]);
        assert!(
            (r.value - reference).abs() < 1e-12 && r.certified,
            "w = {w:e}: {r:?}"
        );
    }
    // Far queries of a tiny set (overflow after rescaling): 0, certified.
    let tiny = PatchWindingNumber::new(&square(1e-300, 1.0));
    let r = tiny.evaluate([1e300, 0.0, 1e300]);
    assert!(r.value == 0.0 && r.certified, "{r:?}");
    // Within 1e-30 (relative 1e-30 of a set of size 1e-20) of the surface: in range.
    let small = PatchWindingNumber::new(&square(1e-20, 1.0));
    for dz in [1e-50, -1e-50, 0.0] {
        let r = small.evaluate([0.5e-20, 0.3e-20, dz]);
        assert!((-0.5..=0.5).contains(&r.value), "dz = {dz:e}: {r:?}");
    }
}

#[test]
fn tolerance_bounds_the_total_error_estimate() {
    // The open hemisphere on its axis (closed form, tests/patches.rs) at loose tolerances:
    // the summed estimate stays below the tolerance and bounds the true error.
    let set = PatchSet::new(sphere().patches()[4..].to_vec()).unwrap();
    for tolerance in [1e-4, 1e-6, 1e-8] {
        for h in [-0.5, 0.25, 0.999, 2.0] {
            for ray in RayAxis::ALL {
                let r = PatchWindingNumber::with_options(&set, Options { ray, tolerance })
                    .unwrap()
                    .evaluate([0.01, -0.02, h]);
                assert!(r.certified, "{r:?}");
                assert!(
                    r.error_estimate <= tolerance,
                    "{tolerance:e}, h = {h}: {r:?}"
                );
            }
        }
    }
    // Against the closed form exactly on the axis.
    for tolerance in [1e-4, 1e-6, 1e-8] {
        for h in [-0.5, 0.25, 0.999, 2.0] {
            let disk = 0.5 * (1.0 - f64::abs(h) / (1.0 + h * h).sqrt());
            let expected = if h > 0.0 && h < 1.0 { 1.0 } else { 0.0 } - f64::signum(h) * disk;
            for ray in RayAxis::ALL {
                let r = PatchWindingNumber::with_options(&set, Options { ray, tolerance })
                    .unwrap()
                    .evaluate([0.0, 0.0, h]);
                assert!(
                    r.error_estimate <= tolerance,
                    "{tolerance:e}, h = {h}: {r:?}"
                );
                assert!(
                    (r.value - expected).abs() <= tolerance,
                    "{tolerance:e}, h = {h}, {ray:?}: {r:?} vs {expected}"
                );
            }
        }
    }
}
