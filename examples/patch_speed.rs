//! The patch evaluator alone on the teapot's 32³ grid (cell centres of the control-net box
//! enlarged by 10 %, as `patch_bench`): CPU ms per query (one thread) point by point and, where
//! the evaluator has one, column by column; the work counters; and, with `SAVE=file`, the values
//! written as little-endian `f64` so that two builds can be compared bit for bit
//! (`COMPARE=file`: max difference and the count of differing values). For A/B runs and
//! `valgrind --tool=callgrind` (small `GRID`).
//!
//! ```text
//! cargo run --release --features examples --example patch_speed -- ../shared/parametric/teapot.bpt
//! ```
//! Environment: `GRID` (default 32), `TOL` (default 1e-10), `REPS` (default 1; the fastest run
//! is reported), `SAVE`, `COMPARE`.

use std::time::Instant;

use gwn::BoundingBox;
use gwn::grid::GridSpec;
use gwn::patch::{Options, PatchWindingNumber, load_patches};

/// CPU time of this thread in seconds (Linux), or wall-clock time since `start`.
fn cpu_seconds(start: Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map(|ns| ns * 1e-9)
        .unwrap_or_else(|| start.elapsed().as_secs_f64())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "../shared/parametric/teapot.bpt".into());
    let env = |name: &str| std::env::var(name).ok();
    let grid: usize = env("GRID").and_then(|s| s.parse().ok()).unwrap_or(32);
    let tolerance: f64 = env("TOL").and_then(|s| s.parse().ok()).unwrap_or(1e-10);
    let reps: usize = env("REPS").and_then(|s| s.parse().ok()).unwrap_or(1);
    let set = load_patches(std::path::Path::new(&path))?;
    let (lo, hi) = set.bounding_box();
    let points = GridSpec::new(BoundingBox { min: lo, max: hi }.enlarged(0.1), [grid; 3])?.points();
    let wn = PatchWindingNumber::with_options(
        &set,
        Options {
            tolerance,
            ..Options::default()
        },
    )?;
    let mut best = f64::INFINITY;
    let mut evals = Vec::new();
    for _ in 0..reps.max(1) {
        let start = Instant::now();
        let t0 = cpu_seconds(start);
        evals = points.iter().map(|&q| wn.evaluate(q)).collect::<Vec<_>>();
        best = best.min((cpu_seconds(start) - t0) * 1e3 / points.len() as f64);
    }
    let n = points.len() as f64;
    let integrals: usize = evals.iter().map(|e| e.integrals).sum();
    let evaluations: usize = evals.iter().map(|e| e.evaluations).sum();
    let uncertified = evals.iter().filter(|e| !e.certified).count();
    let max_est = evals.iter().map(|e| e.error_estimate).fold(0.0, f64::max);
    println!(
        "{path}: {} queries, tolerance {tolerance:e}: {best:.4} ms/query (CPU, 1 thread, best of {reps}); \
         {:.1} integrals, {:.0} integrand evaluations per query; {uncertified} not certified; \
         max error estimate {max_est:.2e}",
        points.len(),
        integrals as f64 / n,
        evaluations as f64 / n
    );
    let values: Vec<f64> = evals.iter().map(|e| e.value).collect();
    if let Some(file) = env("SAVE") {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(file, bytes)?;
    }
    if let Some(file) = env("COMPARE") {
        let bytes = std::fs::read(file)?;
        let other: Vec<f64> = bytes
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect();
        let (mut max, mut differ) = (0.0f64, 0);
        for (a, b) in values.iter().zip(&other) {
            max = max.max((a - b).abs());
            differ += usize::from(a.to_bits() != b.to_bits());
        }
        println!(
            "  against {}: max |Δ| {max:.2e}, {differ} values differ in some bit",
            values.len()
        );
    }
    Ok(())
}
