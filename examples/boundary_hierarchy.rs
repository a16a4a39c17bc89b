//! Issue 12, part 2: the certified boundary hierarchy against the flat exact loop. For every mesh
//! of a folder (or the files given) with at least `MIN_B` (default 300) boundary edges, over the
//! 32³ grid of `gwn bench` (the box grown by 10 %, "+0.1") and over a far grid (the box grown by
//! 3× its extent on every side, "+3"): throughput flat (tolerance 0) and at each tolerance, side by side in one run
//! (best of `REPS`, default 3; 1 thread, and 2 threads at the default tolerance); the largest
//! difference from the flat loop and the largest certified bound (the difference must not exceed
//! it: the run fails otherwise); the share of queries that expanded a node; the build time flat
//! and with the hierarchy (built on first use, forced here).
//!
//! ```text
//! cargo run --release --features examples --example boundary_hierarchy -- ../shared/meshes
//! TOLS=1e-10 GROW=0.1,0.5,1,2,3 cargo run --release --features examples --example boundary_hierarchy -- MESH
//! ```
//!
//! `TOLS` and `GROW` (comma-separated) choose the tolerances and the grids (the box grown by that
//! fraction of its largest extent on every side; default `0.1,3`).

use gwn::eval::antipodal::{Options, WindingNumber};
use gwn::grid::GridSpec;

fn run(w: &WindingNumber, points: &[[f64; 3]], reps: usize) -> (f64, Vec<(f64, f64)>) {
    let mut best = f64::INFINITY;
    let mut values = Vec::new();
    for _ in 0..reps {
        let t = std::time::Instant::now();
        values = points.iter().map(|&p| w.eval_with_bound(p)).collect();
        best = best.min(t.elapsed().as_secs_f64());
    }
    (points.len() as f64 / best, values)
}

/// Throughput with two threads (rayon pool of 2), best of `reps`.
fn run2(w: &WindingNumber, points: &[[f64; 3]], reps: usize) -> f64 {
    use rayon::prelude::*;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        let t = std::time::Instant::now();
        let v: Vec<f64> = pool.install(|| points.par_iter().map(|&p| w.eval(p)).collect());
        std::hint::black_box(v);
        best = best.min(t.elapsed().as_secs_f64());
    }
    points.len() as f64 / best
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let env = |k: &str, d: usize| {
        std::env::var(k)
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(d)
    };
    let (reps, min_b) = (env("REPS", 3), env("MIN_B", 300));
    let list = |k: &str, d: &str| -> Vec<f64> {
        std::env::var(k)
            .unwrap_or_else(|_| d.into())
            .split(',')
            .filter_map(|v| v.trim().parse().ok())
            .collect()
    };
    let tolerances = list("TOLS", "1e-10,1e-6,1e-3");
    let grows = list("GROW", "0.1,3");
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut files: Vec<std::path::PathBuf> = Vec::new();
    for a in if args.is_empty() {
        vec!["../shared/meshes".to_string()]
    } else {
        args
    } {
        let p = std::path::PathBuf::from(a);
        if p.is_dir() {
            files.extend(std::fs::read_dir(&p)?.filter_map(|e| e.ok().map(|e| e.path())));
        } else {
            files.push(p);
        }
    }
    files.sort();
    println!(
        "| mesh | B | grid | flat q/s | τ | q/s | speed-up | 2 threads: flat, τ, speed-up | max diff | max bound | expanded | build: flat, with hierarchy |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut violations = 0;
    for path in files {
        let Ok(loaded) = gwn::io::load_mesh(&path) else {
            continue;
        };
        let mesh = loaded.mesh;
        let Some(bbox) = mesh.bounding_box() else {
            continue;
        };
        let flat = WindingNumber::with_options(
            &mesh,
            Options {
                tolerance: 0.0,
                ..Default::default()
            },
        )?;
        let b = flat.boundary_edge_count();
        if b < min_b {
            continue;
        }
        let name = path
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        for &grow in &grows {
            let label = format!("+{grow}");
            let points = GridSpec::new(bbox.enlarged(grow), [32; 3])?.points();
            let (q0, v0) = run(&flat, &points, reps);
            let q0_2 = run2(&flat, &points, reps);
            for &tol in &tolerances {
                let t = std::time::Instant::now();
                let w = WindingNumber::with_options(
                    &mesh,
                    Options {
                        tolerance: tol,
                        ..Default::default()
                    },
                )?;
                // The hierarchy is built on first use: a far query forces it.
                w.eval(bbox.max.map(|c| c * 4.0 + 1e3));
                let build = t.elapsed().as_secs_f64();
                let (q, v) = run(&w, &points, reps);
                let two = if tol == tolerances[0] {
                    let q2 = run2(&w, &points, reps);
                    format!("{q0_2:.0}, {q2:.0}, {:.2}×", q2 / q0_2)
                } else {
                    String::new()
                };
                let mut diff: f64 = 0.0;
                let mut bound: f64 = 0.0;
                let mut expanded = 0;
                for (a, b) in v0.iter().zip(&v) {
                    let d = (a.0 - b.0).abs();
                    diff = diff.max(d);
                    bound = bound.max(b.1);
                    if b.1 > 0.0 {
                        expanded += 1;
                    }
                    if d > b.1 + 1e-13 {
                        violations += 1;
                    }
                }
                println!(
                    "| {name} | {b} | {label} | {q0:.0} | {tol:e} | {q:.0} | {:.2}× | {two} | {diff:.1e} | {bound:.1e} | {:.0} % | {:.0} ms, {:.0} ms |",
                    q / q0,
                    100.0 * expanded as f64 / points.len() as f64,
                    flat.precompute_time().as_secs_f64() * 1e3,
                    build * 1e3,
                );
            }
        }
    }
    println!("\nqueries whose difference exceeded the bound: {violations}");
    if violations > 0 {
        std::process::exit(1);
    }
    Ok(())
}
