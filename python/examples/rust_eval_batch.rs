//! The Rust side of the Python-overhead benchmark (`python/bench/bench.py`): for each mesh, the
//! best-of-`REPS` wall time of what `gwn.winding_number(V, F, Q)` does — build the exact
//! evaluator, then `eval_batch` — and of `eval_batch` alone, on the 32³ grid of `gwn bench`
//! (cell centres of the bounding box enlarged by 10 %), in a rayon pool of `THREADS` threads
//! (default: all cores). Prints one JSON object per mesh: wall-clock and process CPU seconds.
//!
//! ```text
//! cargo run --release --manifest-path python/Cargo.toml --example rust_eval_batch -- MESH...
//! ```

use gwn::eval::antipodal::WindingNumber;
use gwn::grid::GridSpec;

fn env_usize(name: &str) -> Option<usize> {
    std::env::var(name).ok().and_then(|s| s.parse().ok())
}

/// The smallest wall-clock time and the smallest process CPU time of `reps` runs of `f`.
fn best_of(reps: usize, mut f: impl FnMut()) -> (f64, f64) {
    (0..reps)
        .map(|_| {
            let cpu = cpu_time::ProcessTime::now();
            let t = std::time::Instant::now();
            f();
            (t.elapsed().as_secs_f64(), cpu.elapsed().as_secs_f64())
        })
        .fold((f64::INFINITY, f64::INFINITY), |(w, c), (w2, c2)| {
            (w.min(w2), c.min(c2))
        })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let reps = env_usize("REPS").unwrap_or(7);
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = env_usize("THREADS") {
        pool = pool.num_threads(t);
    }
    let pool = pool.build()?;
    for path in std::env::args().skip(1) {
        let mesh = gwn::io::load_mesh(&path)?.mesh;
        let Some(bbox) = mesh.bounding_box() else {
            continue;
        };
        let points = GridSpec::new(bbox.enlarged(0.1), [32; 3])?.points();
        let (build_and_eval, eval_only) = pool.install(|| {
            let one_shot = best_of(reps, || {
                let w = WindingNumber::new(&mesh).map(|wn| wn.eval_batch(&points));
                std::hint::black_box(w).ok();
            });
            let wn = WindingNumber::new(&mesh)?;
            let batch = best_of(reps, || {
                std::hint::black_box(wn.eval_batch(&points));
            });
            Ok::<_, gwn::eval::antipodal::BuildError>((one_shot, batch))
        })?;
        println!(
            "{{\"mesh\": {path:?}, \"points\": {}, \"threads\": {}, \"build_and_eval_s\": {:e}, \"eval_batch_s\": {:e}, \"build_and_eval_cpu_s\": {:e}, \"eval_batch_cpu_s\": {:e}}}",
            points.len(),
            pool.current_num_threads(),
            build_and_eval.0,
            eval_only.0,
            build_and_eval.1,
            eval_only.1,
        );
    }
    Ok(())
}
