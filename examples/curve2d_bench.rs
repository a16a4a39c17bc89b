//! Timings of the 2D GauWN evaluators (issue 6's benchmark), single thread: queries per second of
//! `W_σ` (precise and fast BvN), `∇_q W` and `∂W/∂V` against the plain exact winding number, on a
//! 100×100 grid over the curve's bounding box, brute force and with the BVH.
//!
//! The curve is the wavy circle `r = 1 + 0.2·sin(7θ)` sampled at `n` equally spaced angles
//! (default `n` = 180, 1 800, 18 000); `σ = 0.01 ×` the larger side of its bounding box.
//! Brute-force GauWN runs on an evenly spaced sub-grid (every `s`-th row and column, `s` chosen so
//! that about 2·10⁶ edge evaluations are timed; `s = 1, 3, 10` for the defaults); rates are per
//! query, so they compare directly with the full-grid ones. Each entry is the best of `--reps`
//! runs (default 3). The gradients use only `exp`/`erfc`, so they do not depend on the BvN
//! back end.
//!
//! ```text
//! cargo run --release --features examples --example curve2d_bench                      # 180 1800 18000, 3 reps
//! cargo run --release --features examples --example curve2d_bench -- 500 5000 --reps 1
//! ```

use gwn::curve2d::{BvnMethod, CurveBvh, GauWn, Point, Polygon};
use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Instant;

/// Best-of-`reps` queries per second of `f` over `queries`.
fn rate(reps: usize, queries: &[Point], mut f: impl FnMut(Point) -> f64) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        let t = Instant::now();
        let mut acc = 0.0;
        for &q in queries {
            acc += f(black_box(q));
        }
        black_box(acc);
        best = best.min(t.elapsed().as_secs_f64());
    }
    queries.len() as f64 / best
}

fn wavy_circle(n: usize) -> Polygon {
    let pts: Vec<Point> = (0..n)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / n as f64;
            let r = 1.0 + 0.2 * (7.0 * t).sin();
            [r * t.cos(), r * t.sin()]
        })
        .collect();
    Polygon::new(vec![pts]).expect("valid polygon")
}

/// `res × res` grid over `bbox`, corners included; row-major.
fn grid(bbox: [f64; 4], res: usize) -> Vec<Point> {
    let f = |i: usize, lo: f64, hi: f64| lo + (hi - lo) * i as f64 / (res - 1) as f64;
    (0..res * res)
        .map(|k| [f(k % res, bbox[0], bbox[2]), f(k / res, bbox[1], bbox[3])])
        .collect()
}

fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

struct Row {
    name: &'static str,
    brute: f64,
    bvh: Option<f64>,
}

fn main() {
    let mut sizes = Vec::new();
    let mut reps = 3usize;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--reps" {
            reps = args.next().and_then(|r| r.parse().ok()).expect("--reps N");
        } else {
            sizes.push(a.parse::<usize>().expect("vertex count"));
        }
    }
    if sizes.is_empty() {
        sizes = vec![180, 1800, 18_000];
    }
    const RES: usize = 100;
    const BRUTE_EDGE_EVALS: f64 = 2e6;

    let mut table = String::new();
    table.push_str(
        "| vertices | evaluator | brute force (q/s) | cost vs plain WN | BVH (q/s) | cost vs plain WN | BVH speed-up |\n\
         | ---: | --- | ---: | ---: | ---: | ---: | ---: |\n",
    );
    let mut notes = Vec::new();
    for &n in &sizes {
        let poly = wavy_circle(n);
        let bb = poly.bbox();
        let sigma = 0.01 * (bb[2] - bb[0]).max(bb[3] - bb[1]);
        let full = grid(bb, RES);
        let s = ((n as f64 * (RES * RES) as f64 / BRUTE_EDGE_EVALS)
            .sqrt()
            .ceil() as usize)
            .max(1);
        let sub: Vec<Point> = full
            .iter()
            .enumerate()
            .filter(|(k, _)| (k % RES).is_multiple_of(s) && (k / RES).is_multiple_of(s))
            .map(|(_, &q)| q)
            .collect();
        let g = GauWn::new(sigma);
        let gf = g.with_bvn(BvnMethod::Fast);
        let t = Instant::now();
        let bvh = CurveBvh::new(&poly);
        let build_ms = t.elapsed().as_secs_f64() * 1e3;
        eprintln!(
            "n = {n}: sigma {sigma:.4}, brute force on {} queries (every {s}-th row and column), \
             BVH build {build_ms:.2} ms, {} nodes",
            sub.len(),
            bvh.node_count()
        );
        let mut out = vec![[0.0; 2]; n];
        let plain = rate(reps, &full, |q| poly.winding_number(q) as f64);
        let rows = [
            Row {
                name: "plain exact winding number",
                brute: plain,
                bvh: None,
            },
            Row {
                name: "W_σ, precise BvN",
                brute: rate(reps, &sub, |q| g.value(&poly, q)),
                bvh: Some(rate(reps, &full, |q| bvh.value(&g, q))),
            },
            Row {
                name: "W_σ, fast BvN",
                brute: rate(reps, &sub, |q| gf.value(&poly, q)),
                bvh: Some(rate(reps, &full, |q| bvh.value(&gf, q))),
            },
            Row {
                name: "∇_q W",
                brute: rate(reps, &sub, |q| {
                    let d = g.gradient(&poly, q);
                    d[0] + d[1]
                }),
                bvh: Some(rate(reps, &full, |q| {
                    let d = bvh.gradient(&g, q);
                    d[0] + d[1]
                })),
            },
            Row {
                name: "∂W/∂V (accumulated)",
                brute: rate(reps, &sub, |q| {
                    g.add_vertex_gradient(&poly, q, 1.0, &mut out);
                    out[0][0]
                }),
                bvh: Some(rate(reps, &full, |q| {
                    bvh.add_vertex_gradient(&g, q, 1.0, &mut out);
                    out[0][0]
                })),
            },
        ];
        for r in &rows {
            let (b, bx, sp) = match r.bvh {
                Some(v) => (
                    sci(v),
                    format!("{:.1}×", plain / v),
                    format!("{:.1}×", v / r.brute),
                ),
                None => ("–".into(), "–".into(), "–".into()),
            };
            table.push_str(&format!(
                "| {n} | {} | {} | {:.1}× | {b} | {bx} | {sp} |\n",
                r.name,
                sci(r.brute),
                plain / r.brute
            ));
        }
        // BVH value error against brute force on the sub-grid (at most ~200 queries).
        let step = (sub.len() / 200).max(1);
        let (err, bound) = sub
            .iter()
            .step_by(step)
            .map(|&q| {
                let (v, b) = bvh.value_with_bound(&g, q);
                ((v - g.value(&poly, q)).abs(), b)
            })
            .fold((0.0f64, 0.0f64), |a, x| (a.0.max(x.0), a.1.max(x.1)));
        notes.push(format!(
            "n = {n}: σ = {sigma:.4}, brute force timed on {} of the 10 000 queries (s = {s}), \
             BVH build {build_ms:.2} ms ({} nodes), BVH value max |error| {err:.1e} \
             (stated bound ≤ {bound:.1e})",
            sub.len(),
            bvh.node_count()
        ));
    }
    println!(
        "Single thread, best of {reps}; q/s = queries per second; \
         cost = (plain WN brute-force q/s) / (q/s).\n"
    );
    print!("{table}");
    println!();
    for n in notes {
        println!("- {n}");
    }
}
