//! Times the fast (Barnes–Hut) evaluator alone, on one thread, on the 32³ grid of `gwn bench`
//! (cell centres of the bounding box enlarged by 10 % of its largest extent per side): tree
//! build and queries per second, measured in process CPU time (robust to a shared machine), and
//! a checksum of the values (bit-identical results print the same checksum).
//!
//! With `--threads 2` it also times `eval_batch` on a rayon pool of that many threads, in process
//! CPU time (summed over the threads; on a shared machine the only stable measure) and in wall
//! clock: `scaling` is the CPU time per query on one thread divided by the wall time per query on
//! the pool, `cpu efficiency` the CPU time per query on one thread divided by that on the pool
//! (1.0 = the threads do no extra work; the achievable scaling on an idle machine is the thread
//! count times it).
//!
//! `cargo run --release --features examples --example fast_speed -- [--beta B] [--order K]
//! [--rule radius|box-corner] [--reps N] [--threads T] MESH...`

use gwn::eval::fast::{Admissibility, FastParams, FastWindingNumber};

/// CPU time of this process (user + system), from /proc (10 ms ticks; runs last ≥ 0.5 s).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let tail = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = tail.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

fn main() {
    let mut beta = 2.35;
    let mut order = 2u8;
    let mut reps = 3usize;
    let mut threads = 1usize;
    let mut rule = Admissibility::Radius;
    let mut meshes = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--beta" => beta = args.next().and_then(|v| v.parse().ok()).expect("--beta B"),
            "--order" => order = args.next().and_then(|v| v.parse().ok()).expect("--order K"),
            "--reps" => reps = args.next().and_then(|v| v.parse().ok()).expect("--reps N"),
            "--threads" => {
                threads = args
                    .next()
                    .and_then(|v| v.parse().ok())
                    .expect("--threads T")
            }
            "--rule" => {
                rule = match args.next().as_deref() {
                    Some("radius") => Admissibility::Radius,
                    Some("box-corner") => Admissibility::BoxCorner,
                    r => panic!("--rule radius|box-corner, not {r:?}"),
                }
            }
            _ => meshes.push(a),
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    if threads > 1 {
        println!(
            "| mesh | faces | build ms (cpu) | queries/s (1 thread, cpu) | queries/s ({threads} threads, cpu) | queries/s ({threads} threads, wall) | scaling (wall) | cpu efficiency | checksum |"
        );
        println!("|---|---:|---:|---:|---:|---:|---:|---:|---|");
    } else {
        println!("| mesh | faces | build ms (cpu) | queries/s (1 thread, cpu) | checksum |");
        println!("|---|---:|---:|---:|---|");
    }
    for path in meshes {
        let mesh = match gwn::io::load_mesh(&path) {
            Ok(m) => m.mesh,
            Err(e) => {
                eprintln!("skipping {path}: {e}");
                continue;
            }
        };
        let Some(b) = mesh.bounding_box() else {
            continue;
        };
        let b = b.enlarged(0.1);
        let n = 32;
        let mut qs = Vec::with_capacity(n * n * n);
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let t = [k, j, i].map(|v| (v as f64 + 0.5) / n as f64);
                    qs.push([0, 1, 2].map(|a| b.min[a] + t[a] * (b.max[a] - b.min[a])));
                }
            }
        }
        let params = FastParams {
            beta,
            order,
            admissibility: rule,
        };
        let mut build = f64::INFINITY;
        let mut fast = None;
        for _ in 0..reps {
            let c = cpu_seconds();
            let f = FastWindingNumber::with_params(&mesh, params);
            build = build.min(cpu_seconds() - c);
            fast = Some(f);
        }
        let fast = fast.expect("reps ≥ 1");
        let mut best = f64::INFINITY;
        let mut values = Vec::new();

        let min_cpu = 0.5;
        for _ in 0..reps {
            let c = cpu_seconds();
            let mut rounds = 0usize;
            loop {
                values = qs.iter().map(|&q| fast.eval(q)).collect::<Vec<f64>>();
                rounds += 1;
                if cpu_seconds() - c >= min_cpu {
                    break;
                }
            }
            best = best.min((cpu_seconds() - c) / rounds as f64);
        }
        let checksum = values
            .iter()
            .fold(0u64, |h, v| h.rotate_left(5) ^ v.to_bits());
        let name = std::path::Path::new(&path)
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let one = qs.len() as f64 / best;
        if threads > 1 {
            let (mut cpu_best, mut wall_best) = (f64::INFINITY, f64::INFINITY);
            for _ in 0..reps {
                let (c, t) = (cpu_seconds(), std::time::Instant::now());
                let mut rounds = 0usize;
                loop {
                    let v = pool.install(|| fast.eval_batch(&qs));
                    assert_eq!(v, values, "{name}: threads change the values");
                    rounds += 1;
                    if t.elapsed().as_secs_f64() >= min_cpu {
                        break;
                    }
                }
                cpu_best = cpu_best.min((cpu_seconds() - c) / rounds as f64);
                wall_best = wall_best.min(t.elapsed().as_secs_f64() / rounds as f64);
            }
            let (cpu_t, wall_t) = (qs.len() as f64 / cpu_best, qs.len() as f64 / wall_best);
            println!(
                "| {name} | {} | {:.1} | {one:.3e} | {cpu_t:.3e} | {wall_t:.3e} | {:.2} | {:.2} | {checksum:016x} |",
                mesh.triangles().len(),
                build * 1e3,
                wall_t / one,
                cpu_t / one,
            );
        } else {
            println!(
                "| {name} | {} | {:.1} | {one:.3e} | {checksum:016x} |",
                mesh.triangles().len(),
                build * 1e3,
            );
        }
    }
}
