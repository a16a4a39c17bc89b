//! Loads STEP models and times the trimmed-model evaluator on the paper's 32³ grid over the
//! bounding box (one thread), printing ms per query and the load time.
//!
//! `cargo run --release --features examples --example step_bench -- ../shared/parametric/step/*.step`

use std::time::Instant;

use gwn::patch::step::{StepWindingNumber, load_step};

fn main() {
    let n = std::env::var("GWN_GRID")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(32usize);
    for path in std::env::args().skip(1) {
        let t = Instant::now();
        let model = match load_step(std::path::Path::new(&path)) {
            Ok(m) => m,
            Err(e) => {
                println!("{path}: {e}");
                continue;
            }
        };
        let load = t.elapsed().as_secs_f64();
        let info = model.info();
        let (lo, hi) = model.bounding_box();
        // The reference grids use the B-rep's bounding box; the patch control boxes contain it.
        let wn = StepWindingNumber::new(&model);
        let lin = |k: usize, a: f64, b: f64| a + (b - a) * k as f64 / (n - 1) as f64;
        let mut pts = Vec::with_capacity(n * n * n);
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    pts.push([
                        lin(i, lo[0], hi[0]),
                        lin(j, lo[1], hi[1]),
                        lin(k, lo[2], hi[2]),
                    ]);
                }
            }
        }
        let t = Instant::now();
        let mut uncertified = 0;
        let mut rays = 0;
        for &q in &pts {
            let e = wn.evaluate(q);
            uncertified += usize::from(e.uncertified);
            rays += e.rays;
        }
        let secs = t.elapsed().as_secs_f64();
        println!(
            "{path}: load {load:.2} s; {} faces, {} patches, {} trim segments, {} boundary edges; \
             {n}^3 grid: {:.4} ms/query (1 thread), {:.2} rays/query, {uncertified} uncertified",
            info.faces,
            info.patches,
            info.trim_segments,
            info.boundary_edges,
            1e3 * secs / pts.len() as f64,
            rays as f64 / pts.len() as f64
        );
    }
}
