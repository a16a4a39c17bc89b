//! The untangling table of docs/gauwn.md: crossings before/after and time per curve on the
//! reproducible tangled set of `gwn::curve2d::tangled::benchmark_set` (figure-eights, circles with
//! small figure-eight lobes, circles with local flips, noisy circles; 20–2000 vertices), for
//! GauWN untangling with the default parameters and for the same optimisation without smoothing
//! (`unsmoothed`: σ fixed at 1e-6 of the size, the plain winding number's limit).
//!
//! ```text
//! cargo run --release --features examples --example untangle_table            # all curves, both methods
//! cargo run --release --features examples --example untangle_table -- 500     # only curves with ≤ 500 vertices
//! cargo run --release --features examples --example untangle_table -- --count # the set's crossing counts only
//! ```

use gwn::curve2d::apps::{UntangleParams, UntangleReport, untangle};
use gwn::curve2d::tangled::benchmark_set;
use std::time::Instant;

/// CPU seconds (user + system, all threads) of this process so far, from `/proc/self/stat`
/// (Linux; 0 elsewhere). Reported next to wall time because the shared machine's load makes
/// wall time vary several-fold.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the command name (which ends with ')'): utime and stime are fields 14 and 15.
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// The report, wall seconds and CPU seconds of one run.
fn run(p: &gwn::curve2d::Polygon, unsmoothed: bool) -> (UntangleReport, f64, f64) {
    let params = UntangleParams {
        unsmoothed,
        ..UntangleParams::default()
    };
    let (t, c) = (Instant::now(), cpu_seconds());
    let rep = untangle(p, &params).expect("default parameters are valid");
    (rep, t.elapsed().as_secs_f64(), cpu_seconds() - c)
}

fn main() {
    let arg = std::env::args().nth(1);
    if arg.as_deref() == Some("--count") {
        for c in benchmark_set() {
            let k = c.polygon.self_intersections(usize::MAX).len();
            println!("{}: {} vertices, {k} crossings", c.name, c.polygon.len());
        }
        return;
    }
    let max_n: usize = arg.and_then(|s| s.parse().ok()).unwrap_or(usize::MAX);
    println!("threads: {} (rayon)\n", rayon::current_num_threads());
    println!(
        "| curve | vertices | crossings before | GauWN after | GauWN wall / CPU (s) | GauWN σ steps (best at) | stop | no smoothing after | no smoothing wall / CPU (s) |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: | --- | ---: | ---: |");
    let mut worse = 0;
    for c in benchmark_set() {
        let n = c.polygon.len();
        if n > max_n {
            continue;
        }
        let (g, tg, cg) = run(&c.polygon, false);
        let (b, tb, cb) = run(&c.polygon, true);
        if g.crossings_after > g.crossings_before || b.crossings_after > b.crossings_before {
            worse += 1;
        }
        println!(
            "| {} | {n} | {} | {} | {tg:.1} / {cg:.1} | {} ({}) | {:?} | {} | {tb:.1} / {cb:.1} |",
            c.name,
            g.crossings_before,
            g.crossings_after,
            g.outer_iterations,
            g.best_iteration,
            g.stop,
            b.crossings_after,
        );
    }
    println!("\ncurves made worse: {worse}");
}
