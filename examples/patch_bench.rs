//! The patch evaluator on the Utah teapot, side by side with the exact triangle evaluator on
//! tessellations and the direct surface quadrature of the patches: single-thread ms (CPU time) per query on
//! the 32³ grid of `gwn bench` (cell centres of the control-net box enlarged by 10 %), and the
//! accuracy against a Richardson-extrapolated tessellation reference.
//!
//! ```text
//! cargo run --release --features examples --example patch_bench -- ../shared/parametric/teapot.bpt
//! ```
//! Environment: `GRID` (default 32), `REF_K` (reference tessellation k and 2k, default 128),
//! `SQ_STRIDE` (every n-th grid point for the slow surface quadrature, default 16).

use std::time::Instant;

use gwn::BoundingBox;
use gwn::eval::antipodal::WindingNumber;
use gwn::grid::GridSpec;
use gwn::patch::surface_quadrature::winding_number_surface_quadrature;
use gwn::patch::tessellate::tessellate;
use gwn::patch::{Options, PatchWindingNumber, load_patches};

fn env(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// CPU time of this thread in seconds (Linux: `/proc/thread-self/schedstat`, which other
/// processes on a shared machine disturb far less than wall-clock time), or wall-clock time
/// since `start` elsewhere.
fn cpu_seconds(start: Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map(|ns| ns * 1e-9)
        .unwrap_or_else(|| start.elapsed().as_secs_f64())
}

/// Milliseconds (CPU time of this thread) per query of `f` over `points`, and the values.
fn time_per_query(points: &[[f64; 3]], f: impl Fn([f64; 3]) -> f64) -> (f64, Vec<f64>) {
    let start = Instant::now();
    let t0 = cpu_seconds(start);
    let values: Vec<f64> = points.iter().map(|&p| f(p)).collect();
    (
        (cpu_seconds(start) - t0) * 1e3 / points.len() as f64,
        values,
    )
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "../shared/parametric/teapot.bpt".into());
    let set = load_patches(std::path::Path::new(&path))?;
    let grid = env("GRID", 32);
    let ref_k = env("REF_K", 128);
    let stride = env("SQ_STRIDE", 16).max(1);
    let (lo, hi) = set.bounding_box();
    let bbox = BoundingBox { min: lo, max: hi };
    let points = GridSpec::new(bbox.enlarged(0.1), [grid; 3])?.points();
    let wn = PatchWindingNumber::new(&set);
    let (b, s, d) = wn.edge_counts();
    println!(
        "{path}: {} patches, boundary edges {b}, shared pairs {s}, degenerate edges {d}; {} queries",
        set.patches().len(),
        points.len()
    );

    // Reference: tessellations at k and 2k, Richardson (error O(h²)); its own error estimate is
    // |R − w_2k| / 3... reported per point as |w_2k − w_k| / 3.
    let t = Instant::now();
    let coarse = WindingNumber::new(&tessellate(&set, ref_k)?)?;
    let fine = WindingNumber::new(&tessellate(&set, 2 * ref_k)?)?;
    let a = coarse.eval_batch(&points);
    let f = fine.eval_batch(&points);
    let reference: Vec<f64> = a.iter().zip(&f).map(|(a, f)| (4.0 * f - a) / 3.0).collect();
    let ref_err: Vec<f64> = a.iter().zip(&f).map(|(a, f)| (f - a).abs() / 3.0).collect();
    println!(
        "reference: tessellations k = {ref_k}, {} ({} triangles), built and evaluated in {:.1} s",
        2 * ref_k,
        set.patches().len() * 2 * (2 * ref_k).pow(2),
        t.elapsed().as_secs_f64()
    );
    // Points whose reference is trustworthy: estimate below 1e-7 (away from the surface).
    let good: Vec<usize> = (0..points.len()).filter(|&i| ref_err[i] < 1e-7).collect();
    println!(
        "{} of {} points have a reference error estimate < 1e-7",
        good.len(),
        points.len()
    );

    {
        let n = points.len() as f64;
        let (mut integrals, mut evals, mut mixed, mut uncertified) = (0.0, 0.0, 0.0, 0);
        let mut est = 0.0f64;
        for &q in &points {
            let e = wn.evaluate(q);
            integrals += e.integrals as f64;
            evals += e.evaluations as f64;
            mixed += e.mixed_patches as f64;
            uncertified += e.uncertified_pieces;
            est = est.max(e.error_estimate);
        }
        println!(
            "per query (tolerance 1e-10): {:.1} boundary integrals, {:.0} integrand evaluations, {:.2} mixed patches; {uncertified} uncertified pieces in total; max error estimate {est:.1e}",
            integrals / n,
            evals / n,
            mixed / n
        );
    }
    for tolerance in [1e-6, 1e-8, 1e-10] {
        let wn = PatchWindingNumber::with_options(
            &set,
            Options {
                tolerance,
                ..Options::default()
            },
        )
        .unwrap();
        let (ms, w) = time_per_query(&points, |q| wn.eval(q));
        let worst = good
            .iter()
            .map(|&i| (w[i] - reference[i]).abs())
            .fold(0.0, f64::max);
        let worst_any = (0..points.len())
            .map(|i| (w[i] - reference[i]).abs())
            .fold(0.0, f64::max);
        println!(
            "patch evaluator, tolerance {tolerance:e}: {ms:.4} ms/query; max |w − ref| {worst:.2e} where the reference is good, {worst_any:.2e} over all points"
        );
    }
    for k in [16, 64, 256] {
        let mesh = tessellate(&set, k)?;
        let exact = WindingNumber::new(&mesh)?;
        let (ms, w) = time_per_query(&points, |q| exact.eval(q));
        let worst = good
            .iter()
            .map(|&i| (w[i] - reference[i]).abs())
            .fold(0.0, f64::max);
        println!(
            "exact on tessellation k = {k} ({} triangles, {} boundary edges): {ms:.4} ms/query; max |w − ref| {worst:.2e}",
            mesh.triangles().len(),
            exact.boundary_edge_count()
        );
    }
    let sub: Vec<[f64; 3]> = points.iter().step_by(stride).copied().collect();
    let sub_ref: Vec<f64> = reference.iter().step_by(stride).copied().collect();
    let sub_good: Vec<bool> = ref_err.iter().step_by(stride).map(|&e| e < 1e-7).collect();
    for tol in [1e-4, 1e-5] {
        let (ms, w) = time_per_query(&sub, |q| winding_number_surface_quadrature(&set, q, tol).0);
        let worst = (0..sub.len())
            .filter(|&i| sub_good[i])
            .map(|i| (w[i] - sub_ref[i]).abs())
            .fold(0.0, f64::max);
        println!(
            "surface quadrature, tolerance {tol:e} ({} points): {ms:.4} ms/query; max |w − ref| {worst:.2e}",
            sub.len()
        );
    }
    Ok(())
}
