//! Grid evaluation by columns (one ray per column for the crossings, the boundary loop shared by
//! the column's points: `kernel::boundary_column`) against the same grid point by point, side by
//! side in one run: 1 thread, the 32³ grid of `gwn bench` (the box grown by 10 %), best of
//! `REPS` (default 5). A third column times `eval_batch` on the same points listed with z (the
//! ray's axis) varying fastest, as a numpy grid `np.mgrid[...].reshape(3, -1).T` lists them
//! (`eval_batch` finds the runs and evaluates them as columns). Every sample must be
//! bit-identical (the run fails otherwise).
//!
//! ```text
//! cargo run --release --features examples --example grid_columns -- ../shared/meshes/cgal-pig.stl ...
//! ```

use gwn::eval::antipodal::WindingNumber;
use gwn::grid::{GridSpec, evaluate, evaluate_per_point};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let reps: usize = std::env::var("REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    println!(
        "| mesh | boundary | columns q/s | per point q/s | columns / per point | eval_batch, z fastest q/s |"
    );
    println!("|---|---|---|---|---|---|");
    for path in std::env::args().skip(1) {
        let mesh = gwn::io::load_mesh(&path)?.mesh;
        let Some(bbox) = mesh.bounding_box() else {
            continue;
        };
        let wn = WindingNumber::new(&mesh)?;
        let spec = GridSpec::new(bbox.enlarged(0.1), [32, 32, 32])?;
        let (mut by_column, mut by_point, mut by_batch) =
            (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        // The grid's points with z varying fastest.
        let [nx, ny, nz] = spec.dims;
        let grid_points = spec.points();
        let z_fastest: Vec<[f64; 3]> = (0..nx * ny * nz)
            .map(|i| {
                let (k, j, x) = (i % nz, (i / nz) % ny, i / (nz * ny));
                grid_points[(k * ny + j) * nx + x]
            })
            .collect();
        for _ in 0..reps {
            let t = std::time::Instant::now();
            let columns = pool.install(|| evaluate(&wn, &spec));
            by_column = by_column.min(t.elapsed().as_secs_f64());
            let t = std::time::Instant::now();
            let points = pool.install(|| evaluate_per_point(&wn, &spec));
            by_point = by_point.min(t.elapsed().as_secs_f64());
            let same = columns
                .iter()
                .zip(&points)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "{path}: columns differ from per-point values");
            let t = std::time::Instant::now();
            let batch = pool.install(|| wn.eval_batch(&z_fastest));
            by_batch = by_batch.min(t.elapsed().as_secs_f64());
            let same = z_fastest
                .iter()
                .zip(&batch)
                .all(|(q, w)| w.to_bits() == wn.eval(*q).to_bits());
            assert!(same, "{path}: eval_batch differs from per-point values");
        }
        let n = spec.len() as f64;
        let name = path.rsplit('/').next().unwrap_or(&path);
        println!(
            "| {name} | {} | {:.0} | {:.0} | {:.2}× | {:.0} |",
            wn.boundary_edge_count(),
            n / by_column,
            n / by_point,
            by_point / by_column,
            n / by_batch
        );
    }
    Ok(())
}
