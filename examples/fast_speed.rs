//! Times the fast (Barnes–Hut) evaluator alone: tree build and queries per second, measured in
//! process CPU time (robust to a shared machine), with a checksum of the values (bit-identical
//! results print the same checksum). Issue 25 compares this with libigl
//! (`benches/peers/igl_fast_cpu.py`) on the very same points.
//!
//! Query points (`--points`):
//! - `grid` (default): the 32³ grid of `gwn bench` (cell centres of the bounding box enlarged by
//!   10 % of its largest extent per side);
//! - `random`: `--count N` (default 32768) uniform points in that same box, from a seeded
//!   splitmix64 (`--seed S`, default 1).
//!
//! `--dump-points FILE.npy` writes the query points (float64, N × 3) so that
//! `igl_fast_cpu.py --points FILE.npy` times libigl on the same points (one mesh only);
//! `--dump-mesh FILE.off` writes the mesh as gwn read it (coordinates round-trip exactly), for
//! meshes libigl's readers reject (pymeshlab-face000.ply).
//!
//! `--cloud N` times [`PointCloudWindingNumber`] instead, on N points sampled area-uniformly from
//! each mesh with the seeded generator (normal = the face's unit normal, area = total area / N);
//! `--dump-cloud FILE.npy` writes that cloud as N × 7 float64 (`x y z nx ny nz area`) for
//! `igl_fast_cpu.py --cloud FILE.npy`.
//!
//! Columns, all on one thread (a rayon pool of 1):
//! - `build`: the evaluator's construction, CPU and wall;
//! - `batch`: `eval_batch(&points)` (what users and the Python binding call), CPU;
//! - `per-point`: a loop of `eval(q)`, CPU.
//!
//! With `--threads T` (T > 1) it also times the build and `eval_batch` on a rayon pool of T
//! threads, in process CPU time (summed over the threads) and in wall clock: `scaling` is the
//! wall rate on the pool over the CPU rate on one thread, `cpu efficiency` the CPU rate on the
//! pool over that on one thread (1.0 = the threads do no extra work; on an idle machine the
//! achievable scaling is the thread count times it).
//!
//! `--accuracy K` adds the max |fast − direct| over K of the points (evenly strided), the direct
//! sum being `winding_number_direct` (meshes) or `winding_number_points_direct` (clouds).
//!
//! `--build-only` times only the build, on 1 and on T threads (`--threads T`, default 1).
//!
//! Checks (the run stops with a message when one fails): `eval_batch` gives the same bits in every
//! repetition, on every thread count, and as the per-point `eval`; an evaluator built on T
//! threads gives the same bits as one built on one thread.
//!
//! `cargo run --release --features examples --example fast_speed -- [--beta B] [--order K]
//! [--rule radius|box-corner|box-diagonal|radius-or-box-corner] [--reps N] [--threads T] [--points grid|random] [--count N]
//! [--seed S] [--dump-points FILE.npy] [--dump-mesh FILE.off] [--cloud N] [--dump-cloud FILE.npy] [--accuracy K] [--build-only] MESH...`

use gwn::eval::direct::winding_number_direct;
use gwn::eval::fast::{
    Admissibility, FastParams, FastWindingNumber, PointCloudWindingNumber,
    winding_number_points_direct,
};
use gwn::testing::SplitMix64;
use rayon::prelude::*;

/// CPU time of this process (user + system), from /proc (10 ms ticks; runs last ≥ 0.5 s).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let tail = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = tail.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// A measured run lasts at least this much CPU (or wall) time, repeated as needed.
const MIN_SECONDS: f64 = 0.5;

/// Writes `rows` (each of `C` float64) as a NumPy `.npy` file (format 1.0, little-endian, C order).
fn write_npy<const C: usize>(path: &str, rows: &[[f64; C]]) -> std::io::Result<()> {
    let mut header = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, {C}), }}",
        rows.len()
    );
    // Magic (6) + version (2) + header length (2) + header + '\n', padded to 64 bytes.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + rows.len() * C * 8);
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in rows.iter().flatten() {
        out.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, out)
}

/// Writes `mesh` as an OFF file; `{:?}` prints the shortest decimal that reads back to the same
/// `f64`.
fn write_off(path: &str, mesh: &gwn::Mesh) -> std::io::Result<()> {
    use std::fmt::Write as _;
    let (p, t) = (mesh.positions(), mesh.triangles());
    let mut out = format!("OFF\n{} {} 0\n", p.len(), t.len());
    for v in p {
        let _ = writeln!(out, "{:?} {:?} {:?}", v[0], v[1], v[2]);
    }
    for f in t {
        let _ = writeln!(out, "3 {} {} {}", f[0], f[1], f[2]);
    }
    std::fs::write(path, out)
}

/// `n` points sampled area-uniformly on the mesh: (position, unit face normal), and the area
/// each point stands for (total area / n).
fn sample_cloud(
    mesh: &gwn::Mesh,
    n: usize,
    rng: &mut SplitMix64,
) -> (Vec<[f64; 3]>, Vec<[f64; 3]>, f64) {
    let tris: Vec<[[f64; 3]; 3]> = (0..mesh.triangles().len())
        .map(|f| mesh.triangle_positions(f))
        .collect();
    let sub = |a: [f64; 3], b: [f64; 3]| [0, 1, 2].map(|k| a[k] - b[k]);
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let normals: Vec<[f64; 3]> = tris
        .iter()
        .map(|t| cross(sub(t[1], t[0]), sub(t[2], t[0])))
        .collect();
    let mut cumulative = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for n in &normals {
        total += 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        cumulative.push(total);
    }
    assert!(
        total > 0.0 && total.is_finite(),
        "the mesh has no area to sample"
    );
    let mut positions = Vec::with_capacity(n);
    let mut unit_normals = Vec::with_capacity(n);
    for _ in 0..n {
        // The first face whose cumulative area exceeds u: zero-area faces are never picked.
        let u = rng.unit() * total;
        let f = cumulative.partition_point(|&c| c <= u).min(tris.len() - 1);
        let (s, t) = (rng.unit().sqrt(), rng.unit());
        let [a, b, c] = tris[f];
        positions.push([0, 1, 2].map(|k| (1.0 - s) * a[k] + s * (1.0 - t) * b[k] + s * t * c[k]));
        let m = normals[f];
        let len = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
        unit_normals.push(m.map(|v| v / len));
    }
    (positions, unit_normals, total / n as f64)
}

/// The evaluator under test: a triangle mesh or a point cloud.
enum Fast {
    Mesh(FastWindingNumber),
    Cloud(PointCloudWindingNumber),
}

impl Fast {
    fn eval(&self, q: [f64; 3]) -> f64 {
        match self {
            Fast::Mesh(f) => f.eval(q),
            Fast::Cloud(f) => f.eval(q),
        }
    }

    fn eval_batch(&self, qs: &[[f64; 3]]) -> Vec<f64> {
        match self {
            Fast::Mesh(f) => f.eval_batch(qs),
            Fast::Cloud(f) => f.eval_batch(qs),
        }
    }
}

/// Best (CPU, wall) seconds per call of `f` over `reps` repetitions, each repeating `f` until
/// `MIN_SECONDS` of CPU time (one thread) or of wall time (a pool) have passed. `check` sees
/// every result.
fn time_best<T>(
    reps: usize,
    by_wall: bool,
    mut f: impl FnMut() -> T,
    mut check: impl FnMut(&T),
) -> (f64, f64) {
    let (mut cpu_best, mut wall_best) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..reps {
        let (c, t) = (cpu_seconds(), std::time::Instant::now());
        let mut rounds = 0usize;
        loop {
            let v = f();
            rounds += 1;
            check(&v);
            let spent = if by_wall {
                t.elapsed().as_secs_f64()
            } else {
                cpu_seconds() - c
            };
            if spent >= MIN_SECONDS {
                break;
            }
        }
        cpu_best = cpu_best.min((cpu_seconds() - c) / rounds as f64);
        wall_best = wall_best.min(t.elapsed().as_secs_f64() / rounds as f64);
    }
    (cpu_best, wall_best)
}

fn first_difference(a: &[f64], b: &[f64]) -> Option<(usize, f64, f64)> {
    a.iter()
        .zip(b)
        .enumerate()
        .find(|(_, (x, y))| x.to_bits() != y.to_bits())
        .map(|(i, (&x, &y))| (i, x, y))
}

fn main() {
    let mut beta = 2.35;
    let mut order = 2u8;
    let mut reps = 3usize;
    let mut threads = 1usize;
    let mut rule = Admissibility::Radius;
    let mut random = false;
    let mut count = 32768usize;
    let mut seed = 1u64;
    let mut dump_points: Option<String> = None;
    let mut dump_mesh: Option<String> = None;
    let mut cloud: Option<usize> = None;
    let mut dump_cloud: Option<String> = None;
    let mut accuracy = 0usize;
    let mut build_only = false;
    let mut beta_given = false;
    let mut meshes = Vec::new();
    let mut args = std::env::args().skip(1);
    fn value<T: std::str::FromStr>(args: &mut impl Iterator<Item = String>, what: &str) -> T {
        args.next()
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("expected {what}"))
    }
    while let Some(a) = args.next() {
        match a.as_str() {
            "--beta" => {
                beta = value(&mut args, "--beta B");
                beta_given = true;
            }
            "--order" => order = value(&mut args, "--order K"),
            "--reps" => reps = value::<usize>(&mut args, "--reps N").max(1),
            "--threads" => threads = value::<usize>(&mut args, "--threads T").max(1),
            "--rule" => {
                let name = args.next().unwrap_or_default();
                rule = name.parse().unwrap_or_else(|e| panic!("--rule: {e}"));
            }
            "--points" => {
                random = match args.next().as_deref() {
                    Some("grid") => false,
                    Some("random") => true,
                    r => panic!("--points grid|random, not {r:?}"),
                }
            }
            "--count" => count = value(&mut args, "--count N"),
            "--seed" => seed = value(&mut args, "--seed S"),
            "--dump-points" => dump_points = Some(value(&mut args, "--dump-points FILE.npy")),
            "--dump-mesh" => dump_mesh = Some(value(&mut args, "--dump-mesh FILE.off")),
            "--cloud" => cloud = Some(value(&mut args, "--cloud N")),
            "--dump-cloud" => dump_cloud = Some(value(&mut args, "--dump-cloud FILE.npy")),
            "--accuracy" => accuracy = value(&mut args, "--accuracy K"),
            "--build-only" => build_only = true,
            _ => meshes.push(a),
        }
    }
    assert!(
        (dump_points.is_none() && dump_cloud.is_none() && dump_mesh.is_none()) || meshes.len() == 1,
        "--dump-points / --dump-cloud / --dump-mesh write one file: give one mesh"
    );
    assert!(
        dump_cloud.is_none() || cloud.is_some(),
        "--dump-cloud needs --cloud N"
    );
    if cloud.is_some() && !beta_given {
        // Barill's (and `PointCloudWindingNumber::new`'s) point-cloud default.
        beta = 2.3;
    }
    let pool_of = |n: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("thread pool")
    };
    let (one, many) = (pool_of(1), pool_of(threads));
    let points_label = if random {
        format!("random {count}, seed {seed}")
    } else {
        "32³ grid".to_string()
    };
    println!(
        "fast_speed: beta {beta}, order {order}, rule {rule:?}, points: {points_label}{}",
        cloud.map_or(String::new(), |n| format!(", clouds of {n} points"))
    );
    let mut head = "| input | elements | build ms (1 thread, cpu) | build ms (1 thread, wall) | batch q/s (1 thread, cpu) | per-point q/s (1 thread, cpu) |".to_string();
    let mut rule_row = "|---|---:|---:|---:|---:|---:|".to_string();
    if threads > 1 {
        head += &format!(
            " build ms ({threads} threads, cpu) | build ms ({threads} threads, wall) | batch q/s ({threads} threads, cpu) | batch q/s ({threads} threads, wall) | scaling (wall) | cpu efficiency |"
        );
        rule_row += "---:|---:|---:|---:|---:|---:|";
    }
    if accuracy > 0 {
        head += " max error |";
        rule_row += "---:|";
    }
    head += " checksum |";
    rule_row += "---|";
    if build_only {
        head = format!(
            "| input | elements | build ms (1 thread, cpu) | build ms (1 thread, wall) | build ms ({threads} threads, cpu) | build ms ({threads} threads, wall) |"
        );
        rule_row = "|---|---:|---:|---:|---:|---:|".to_string();
    }
    println!("{head}\n{rule_row}");

    for path in meshes {
        let mesh = match gwn::io::load_mesh(&path) {
            Ok(m) => m.mesh,
            Err(e) => {
                eprintln!("skipping {path}: {e}");
                continue;
            }
        };
        let Some(b) = mesh.bounding_box() else {
            eprintln!("skipping {path}: no vertices");
            continue;
        };
        let b = b.enlarged(0.1);
        let mut rng = SplitMix64(seed);
        let qs: Vec<[f64; 3]> = if random {
            (0..count)
                .map(|_| [0, 1, 2].map(|a| b.min[a] + rng.unit() * (b.max[a] - b.min[a])))
                .collect()
        } else {
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
            qs
        };
        if let Some(file) = &dump_mesh {
            write_off(file, &mesh).unwrap_or_else(|e| panic!("writing {file}: {e}"));
        }
        if let Some(file) = &dump_points {
            write_npy(file, &qs).unwrap_or_else(|e| panic!("writing {file}: {e}"));
        }
        let params = FastParams {
            beta,
            order,
            admissibility: rule,
        };
        let name = std::path::Path::new(&path)
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        // The cloud (sampled after the query points, from the same generator).
        let sampled = cloud.map(|n| sample_cloud(&mesh, n, &mut rng));
        if let (Some(file), Some((p, nrm, area))) = (&dump_cloud, &sampled) {
            let rows: Vec<[f64; 7]> = p
                .iter()
                .zip(nrm)
                .map(|(p, n)| [p[0], p[1], p[2], n[0], n[1], n[2], *area])
                .collect();
            write_npy(file, &rows).unwrap_or_else(|e| panic!("writing {file}: {e}"));
        }
        let (label, elements) = match &sampled {
            Some((p, _, _)) => (format!("{name} (cloud)"), p.len()),
            None => (name.clone(), mesh.triangles().len()),
        };
        let areas: Vec<f64> = sampled
            .as_ref()
            .map_or(Vec::new(), |(p, _, area)| vec![*area; p.len()]);
        let build = || match &sampled {
            // The areas' copy is part of the build: libigl also takes them as an input array.
            Some((p, n, _)) => Fast::Cloud(PointCloudWindingNumber::from_parts(
                p,
                n,
                areas.clone(),
                params,
            )),
            None => Fast::Mesh(FastWindingNumber::with_params(&mesh, params)),
        };

        if build_only {
            // 1 and T threads alternate, so that a change of the machine's load hits both.
            let mut best = [f64::INFINITY; 4];
            for _ in 0..reps {
                let (c1, w1) = time_best(1, false, || one.install(build), |_| {});
                let (c2, w2) = time_best(1, true, || many.install(build), |_| {});
                for (b, v) in best.iter_mut().zip([c1, w1, c2, w2]) {
                    *b = b.min(v * 1e3);
                }
            }
            let [c1, w1, c2, w2] = best;
            println!("| {label} | {elements} | {c1:.1} | {w1:.1} | {c2:.1} | {w2:.1} |");
            continue;
        }
        let (build_cpu, build_wall) = time_best(reps, false, || one.install(build), |_| {});
        let fast = one.install(build);
        let reference = one.install(|| fast.eval_batch(&qs));
        let (batch_cpu, _) = time_best(
            reps,
            false,
            || one.install(|| fast.eval_batch(&qs)),
            |v| {
                if let Some((i, x, y)) = first_difference(v, &reference) {
                    panic!(
                        "{label}: eval_batch is not deterministic: point {i} gave {x:e}, then {y:e}"
                    );
                }
            },
        );
        let (point_cpu, _) = time_best(
            reps,
            false,
            || qs.iter().map(|&q| fast.eval(q)).collect::<Vec<f64>>(),
            |v| {
                if let Some((i, x, y)) = first_difference(v, &reference) {
                    panic!(
                        "{label}: eval_batch and the per-point eval differ at point {i} ({y:e} vs {x:e}): \
                         the batch path must stay bit-identical to eval"
                    );
                }
            },
        );
        let checksum = reference
            .iter()
            .fold(0u64, |h, v| h.rotate_left(5) ^ v.to_bits());
        let rate = |seconds: f64| qs.len() as f64 / seconds;
        let mut row = format!(
            "| {label} | {elements} | {:.1} | {:.1} | {:.4e} | {:.4e} |",
            build_cpu * 1e3,
            build_wall * 1e3,
            rate(batch_cpu),
            rate(point_cpu),
        );
        if threads > 1 {
            let (many_build_cpu, many_build_wall) =
                time_best(reps, true, || many.install(build), |_| {});
            let built_on_many = many.install(build);
            if let Some((i, x, y)) =
                first_difference(&one.install(|| built_on_many.eval_batch(&qs)), &reference)
            {
                panic!(
                    "{label}: the evaluator built on {threads} threads differs from the one built on 1 at point {i} ({x:e} vs {y:e}): the build must not depend on the thread count"
                );
            }
            let (cpu, wall) = time_best(
                reps,
                true,
                || many.install(|| fast.eval_batch(&qs)),
                |v| {
                    if let Some((i, x, y)) = first_difference(v, &reference) {
                        panic!(
                            "{label}: eval_batch on {threads} threads differs from 1 thread at point {i} ({x:e} vs {y:e})"
                        );
                    }
                },
            );
            row += &format!(
                " {:.1} | {:.1} | {:.4e} | {:.4e} | {:.2} | {:.2} |",
                many_build_cpu * 1e3,
                many_build_wall * 1e3,
                rate(cpu),
                rate(wall),
                rate(wall) / rate(batch_cpu),
                rate(cpu) / rate(batch_cpu),
            );
        }
        if accuracy > 0 {
            let stride = qs.len().checked_div(accuracy).unwrap_or(1).max(1);
            let picked: Vec<usize> = (0..qs.len()).step_by(stride).take(accuracy).collect();
            let exact: Vec<f64> = picked
                .par_iter()
                .map(|&i| match &sampled {
                    Some((p, n, _)) => winding_number_points_direct(p, n, &areas, qs[i]),
                    None => winding_number_direct(&mesh, qs[i]),
                })
                .collect();
            let err = picked
                .iter()
                .zip(&exact)
                .map(|(&i, e)| (reference[i] - e).abs())
                .fold(0.0, f64::max);
            row += &format!(" {err:.3e} ({} points) |", picked.len());
        }
        row += &format!(" {checksum:016x} |");
        println!("{row}");
    }
}
