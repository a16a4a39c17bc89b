//! Max error of the fast (Barnes–Hut) evaluator against the direct sum on the points of the
//! accuracy test (`tests/fast_curve2d/fast_vs_libigl.rs`: every `step`-th point of the 32³ grid
//! of `gwn bench`, points within 1e-6·diagonal of the surface left out), per admissibility rule
//! and β, next to libigl's max error on the same points (the test's table), and the process-CPU
//! throughput of one thread on the whole 32³ grid for the meshes named with `--time`.
//!
//! ```text
//! cargo run --release --features examples --example fast_accuracy_sweep -- \
//!     /work/shared/meshes --rule box-corner --betas 2.2,2.4,2.6 [--cache /tmp/direct] \
//!     [--time cgal-armadillo.off,npm-dragon_vrip_res2.ply]
//! ```
//!
//! The direct sums are cached in `--cache` (one little-endian `f64` file per mesh).

use gwn::Mesh;
use gwn::eval::direct::winding_number_direct_batch;
use gwn::eval::fast::{Admissibility, FastParams, FastWindingNumber};
use gwn::products::sdf::SignedDistance;

include!("../tests/fast_curve2d/libigl_max_error.rs");

const BUDGET: f64 = 1e7;

/// CPU time of this process (user + system), from /proc (10 ms ticks).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let tail = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = tail.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// The grid of `gwn bench` (x fastest), as the accuracy test builds it.
fn grid(mesh: &Mesh, n: usize) -> Vec<[f64; 3]> {
    let b = mesh.bounding_box().expect("non-empty mesh").enlarged(0.1);
    (0..n * n * n)
        .map(|i| {
            let idx = [i % n, (i / n) % n, i / (n * n)];
            std::array::from_fn(|k| {
                b.min[k] + (b.max[k] - b.min[k]) * (idx[k] as f64 + 0.5) / n as f64
            })
        })
        .collect()
}

fn main() {
    let mut dir = None;
    let mut rule = Admissibility::Radius;
    let mut betas = vec![2.8];
    let mut cache: Option<std::path::PathBuf> = None;
    let mut timed: Vec<String> = Vec::new();
    let mut only: Vec<String> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--rule" => {
                let name = args.next().unwrap_or_default();
                rule = name.parse().unwrap_or_else(|e| panic!("--rule: {e}"));
            }
            "--betas" => {
                betas = args
                    .next()
                    .expect("--betas B,B")
                    .split(',')
                    .map(|b| b.parse().expect("a number"))
                    .collect()
            }
            "--cache" => cache = args.next().map(Into::into),
            "--time" => {
                timed = args
                    .next()
                    .expect("--time A,B")
                    .split(',')
                    .map(String::from)
                    .collect()
            }
            "--only" => {
                only = args
                    .next()
                    .expect("--only A,B")
                    .split(',')
                    .map(String::from)
                    .collect()
            }
            _ => dir = Some(std::path::PathBuf::from(a)),
        }
    }
    let dir = dir.expect("the corpus folder");
    if let Some(c) = &cache {
        std::fs::create_dir_all(c).expect("cache folder");
    }
    // Per β: (worst gwn/libigl ratio, meshes above libigl, Σ log throughput ratio, timed meshes).
    let mut worst = vec![(0.0f64, String::new()); betas.len()];
    let mut above: Vec<Vec<String>> = vec![Vec::new(); betas.len()];
    for &(name, faces, igl) in LIBIGL_MAX_ERROR {
        if !only.is_empty() && !only.iter().any(|o| o == name) {
            continue;
        }
        let mesh = gwn::io::load_mesh(dir.join(name))
            .expect("corpus mesh")
            .mesh;
        assert_eq!(mesh.triangles().len(), faces, "{name}");
        let points = grid(&mesh, 32);
        let want = (BUDGET / faces as f64)
            .floor()
            .max(256.0)
            .min(points.len() as f64) as usize;
        let step = points.len().div_ceil(want).max(1);
        let probe = FastWindingNumber::new(&mesh);
        let b = mesh.bounding_box().expect("non-empty");
        let diag = (0..3)
            .map(|k| (b.max[k] - b.min[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let distance = SignedDistance::with_evaluator(&mesh, probe);
        let subset: Vec<[f64; 3]> = points
            .iter()
            .step_by(step)
            .copied()
            .filter(|&q| distance.unsigned(q) > 1e-6 * diag)
            .collect();
        let file = cache.as_ref().map(|c| c.join(format!("{name}.f64")));
        let exact: Vec<f64> = match file.as_ref().and_then(|f| std::fs::read(f).ok()) {
            Some(bytes) if bytes.len() == 8 * subset.len() => bytes
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                .collect(),
            _ => {
                let e = winding_number_direct_batch(&mesh, &subset);
                if let Some(f) = &file {
                    let bytes: Vec<u8> = e.iter().flat_map(|v| v.to_le_bytes()).collect();
                    std::fs::write(f, bytes).expect("cache write");
                }
                e
            }
        };
        let mut line = format!("{name} (igl {igl:.2e}):");
        for (i, &beta) in betas.iter().enumerate() {
            let params = FastParams {
                beta,
                order: 2,
                admissibility: rule,
            };
            let fast = FastWindingNumber::with_params(&mesh, params);
            let err = fast
                .eval_batch(&subset)
                .iter()
                .zip(&exact)
                .map(|(a, e)| (a - e).abs())
                .fold(0.0, f64::max);
            let ratio = err / igl;
            if ratio > worst[i].0 {
                worst[i] = (ratio, name.to_string());
            }
            if err > igl {
                above[i].push(format!("{name} {ratio:.2}"));
            }
            line += &format!(" β {beta}: {err:.2e} ({ratio:.2})");
            if timed.iter().any(|t| t == name) {
                let qs = grid(&mesh, 32);
                let c = cpu_seconds();
                let mut rounds = 0;
                let mut sink = 0.0;
                while rounds == 0 || cpu_seconds() - c < 1.0 {
                    sink += qs.iter().map(|&q| fast.eval(q)).sum::<f64>();
                    rounds += 1;
                }
                let qps = (rounds * qs.len()) as f64 / (cpu_seconds() - c);
                line += &format!(" [{qps:.3e} q/s cpu, sum {sink:.3}]");
            }
        }
        println!("{line}");
    }
    for (i, &beta) in betas.iter().enumerate() {
        println!(
            "β {beta}: worst ratio {:.3} ({}), above libigl on {}: {}",
            worst[i].0,
            worst[i].1,
            above[i].len(),
            above[i].join(", ")
        );
    }
}
