//! Measures the fast (Barnes–Hut) winding number against the direct sum: the error table of
//! `docs/fast.md` (orders 0–2, β 1/2/4, FOSSIL's rule) and queries per second on a 32³ grid.
//!
//! `cargo run --release --features examples --example fast_table [MESH_DIR]` (default `../shared/meshes`).

use std::path::PathBuf;
use std::time::Instant;

use gwn::Mesh;
use gwn::eval::direct::winding_number_direct_batch;
use gwn::eval::fast::{FastParams, FastWindingNumber};

fn grid(mesh: &Mesh, n: usize) -> Vec<[f64; 3]> {
    let b = mesh.bounding_box().expect("non-empty mesh").enlarged(0.1);
    let mut out = Vec::with_capacity(n * n * n);
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let t = [i, j, k].map(|v| (v as f64 + 0.5) / n as f64);
                out.push([0, 1, 2].map(|a| b.min[a] + t[a] * (b.max[a] - b.min[a])));
            }
        }
    }
    out
}

fn errors(approx: &[f64], exact: &[f64]) -> (f64, f64, usize) {
    let mut se = 0.0;
    let mut max = 0.0_f64;
    let mut wrong = 0;
    for (a, e) in approx.iter().zip(exact) {
        let d = a - e;
        se += d * d;
        max = max.max(d.abs());
        wrong += usize::from((*a > 0.5) != (*e > 0.5));
    }
    ((se / exact.len() as f64).sqrt(), max, wrong)
}

fn load(dir: &std::path::Path, name: &str) -> Option<Mesh> {
    match gwn::io::load_mesh(dir.join(name)) {
        Ok(m) => Some(m.mesh),
        Err(e) => {
            eprintln!("skipping {name}: {e}");
            None
        }
    }
}

fn main() {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes"));
    let threads = rayon::current_num_threads();

    println!("## Error vs the direct sum (16³ grid over the bounding box enlarged by 10 %)\n");
    println!("| mesh | faces | rule | β | order | RMS | max | misclassified at 0.5 |");
    println!("|---|---:|---|---:|---:|---:|---:|---:|");
    for name in [
        "cgal-anchor.off",
        "cgal-rotor.off",
        "cgal-hand.off",
        "cgal-triceratops.off",
    ] {
        let Some(mesh) = load(&dir, name) else {
            continue;
        };
        let qs = grid(&mesh, 16);
        let exact = winding_number_direct_batch(&mesh, &qs);
        let fast = FastWindingNumber::new(&mesh);
        let faces = mesh.triangles().len();
        for beta in [1.0, 2.0, 4.0] {
            for order in 0..=2 {
                let a = fast.eval_batch_with(&qs, FastParams::barill(beta, order));
                let (rms, max, wrong) = errors(&a, &exact);
                println!(
                    "| {name} | {faces} | Barill | {beta} | {order} | {rms:.1e} | {max:.1e} | {wrong} |"
                );
            }
        }
        for beta in [1.0, 2.0, 4.0] {
            let a = fast.eval_batch_with(&qs, FastParams::fossil(beta));
            let (rms, max, wrong) = errors(&a, &exact);
            println!(
                "| {name} | {faces} | FOSSIL | {beta} | 0 | {rms:.1e} | {max:.1e} | {wrong} |"
            );
        }
        let mut ratios: Vec<f64> = (0..fast.node_count())
            .filter(|&i| fast.node_moments(i).radius > 0.0)
            .map(|i| fast.node_box(i).diagonal() / fast.node_moments(i).radius)
            .collect();
        ratios.sort_by(f64::total_cmp);
        eprintln!(
            "{name}: node diagonal / radius: min {:.2}, median {:.2}, max {:.2}",
            ratios[0],
            ratios[ratios.len() / 2],
            ratios[ratios.len() - 1]
        );
    }

    println!("\n## Speed (32³ grid over the bounding box enlarged by 10 %, {threads} threads)\n");
    println!("| mesh | faces | method | build | queries/s | RMS vs direct |");
    println!("|---|---:|---|---:|---:|---:|");
    for name in ["cgal-armadillo.off", "cgal-diplodocus.off"] {
        let Some(mesh) = load(&dir, name) else {
            continue;
        };
        let faces = mesh.triangles().len();
        let qs = grid(&mesh, 32);
        // The direct sum on every 8th grid point (it is O(F) per query).
        let sub: Vec<[f64; 3]> = qs.iter().step_by(8).copied().collect();
        let t = Instant::now();
        let exact = winding_number_direct_batch(&mesh, &sub);
        let direct_qps = sub.len() as f64 / t.elapsed().as_secs_f64();
        println!(
            "| {name} | {faces} | direct | – | {direct_qps:.3e} | 0 (reference, {} queries) |",
            sub.len()
        );
        let t = Instant::now();
        let fast = FastWindingNumber::new(&mesh);
        let build = t.elapsed().as_secs_f64();
        let runs = [
            ("fast β=2 order 2", FastParams::barill(2.0, 2)),
            ("fast β=2 order 1", FastParams::barill(2.0, 1)),
            ("fast β=2 order 0", FastParams::barill(2.0, 0)),
            ("fast β=4 order 2", FastParams::barill(4.0, 2)),
            ("fast β=1 order 2", FastParams::barill(1.0, 2)),
            ("fast, FOSSIL rule β_F=2", FastParams::fossil(2.0)),
        ];
        for (label, params) in runs {
            let _ = fast.eval_batch_with(&qs[..1024], params); // warm-up
            let t = Instant::now();
            let all = fast.eval_batch_with(&qs, params);
            let qps = qs.len() as f64 / t.elapsed().as_secs_f64();
            let on_sub: Vec<f64> = all.iter().step_by(8).copied().collect();
            let (rms, _, _) = errors(&on_sub, &exact);
            println!(
                "| {name} | {faces} | {label} | {:.0} ms | {qps:.3e} | {rms:.1e} |",
                build * 1e3
            );
        }
    }
}
