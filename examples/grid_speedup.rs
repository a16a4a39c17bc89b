//! Ray reuse on voxel grids: throughput of `gwn::grid::evaluate` (one ray per column) against
//! per-voxel `eval_batch` (one ray per voxel), plus signed-distance throughput.
//!
//! ```text
//! cargo run --release --features examples --example grid_speedup [-- RES... [--mesh FILE]...]
//! ```
//! Defaults: resolutions 64 and 128 on a fixed set of shared meshes (`../shared/meshes`). Grids
//! span the mesh's box grown by 5 %, longest side RES cells. Prints a Markdown table; every grid
//! is also checked against the per-voxel values (max |difference|).

use std::path::PathBuf;
use std::time::Instant;

use gwn::eval::antipodal::WindingNumber;
use gwn::grid::{GridSpec, evaluate, evaluate_per_point};
use gwn::products::sdf::SignedDistance;

const DEFAULT_MESHES: [&str; 7] = [
    "cgal-armadillo.off",
    "cgal-bunny00.off",
    "cgal-camel.off",
    "cgal-lion-head.off",
    "cgal-mech-holes-shark.off",
    "cgal-pig.stl",
    "assimp-spider.obj",
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut res = Vec::new();
    let mut meshes = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--mesh" {
            meshes.push(PathBuf::from(args.next().ok_or("--mesh needs a file")?));
        } else {
            res.push(a.parse::<usize>()?);
        }
    }
    if res.is_empty() {
        res = vec![64, 128];
    }
    if meshes.is_empty() {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes");
        meshes = DEFAULT_MESHES.iter().map(|m| dir.join(m)).collect();
    }
    println!(
        "threads: {}\n\n| mesh | faces | boundary edges | grid | per-voxel rays (voxels/s) | ray reuse (voxels/s) | speed-up | max abs diff |",
        rayon::current_num_threads()
    );
    println!("|---|---:|---:|---|---:|---:|---:|---:|");
    let mut sdf_rows = Vec::new();
    for path in &meshes {
        let name = path
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        let mesh = match gwn::io::load_mesh(path) {
            Ok(l) => l.mesh,
            Err(e) => {
                eprintln!("skipping {e}");
                continue;
            }
        };
        let Some(bbox) = mesh.bounding_box() else {
            continue;
        };
        let wn = WindingNumber::new(&mesh)?;
        for &r in &res {
            let spec = GridSpec::with_resolution(bbox.enlarged(0.05), r)?;
            let t = Instant::now();
            let per_point = evaluate_per_point(&wn, &spec);
            let t_point = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let grid = evaluate(&wn, &spec);
            let t_grid = t.elapsed().as_secs_f64();
            let diff = grid
                .iter()
                .zip(&per_point)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0_f64, f64::max);
            let n = spec.len() as f64;
            let [w, h, d] = spec.dims;
            println!(
                "| {name} | {} | {} | {w}×{h}×{d} | {:.3e} | {:.3e} | {:.1}× | {diff:.1e} |",
                wn.face_count(),
                wn.boundary_edge_count(),
                n / t_point,
                n / t_grid,
                t_point / t_grid
            );
        }
        let sdf = SignedDistance::with_evaluator(&mesh, wn);
        let spec = GridSpec::with_resolution(bbox.enlarged(0.05), 64)?;
        let t = Instant::now();
        let v = sdf.eval_grid(&spec);
        let secs = t.elapsed().as_secs_f64();
        std::hint::black_box(&v);
        let t = Instant::now();
        let u: Vec<f64> = {
            use rayon::prelude::*;
            spec.points().par_iter().map(|&q| sdf.unsigned(q)).collect()
        };
        let secs_u = t.elapsed().as_secs_f64();
        std::hint::black_box(&u);
        sdf_rows.push((name, spec.len() as f64 / secs, spec.len() as f64 / secs_u));
    }
    println!(
        "\n| mesh | signed distance on 64³ (points/s, all threads) | unsigned distance alone (points/s, all threads) |"
    );
    println!("|---|---:|---:|");
    for (name, s, u) in sdf_rows {
        println!("| {name} | {s:.3e} | {u:.3e} |");
    }
    Ok(())
}
