//! Grid evaluation by columns (one ray per column for the crossings, the boundary loop shared by
//! the column's points: `kernel::boundary_column`) against the same grid point by point, side by
//! side in one run: 1 thread, the 32³ grid of `gwn bench` (the box grown by 10 %), best of
//! `REPS` (default 5). Every sample must be bit-identical (the run fails otherwise).
//!
//! ```text
//! cargo run --release --example grid_columns -- ../shared/meshes/cgal-pig.stl ...
//! ```

use gwn::eval::antipodal::WindingNumber;
use gwn::grid::{GridSpec, evaluate, evaluate_per_point};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let reps: usize = std::env::var("REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    println!("| mesh | boundary | columns q/s | per point q/s | columns / per point |");
    println!("|---|---|---|---|---|");
    for path in std::env::args().skip(1) {
        let mesh = gwn::io::load_mesh(&path)?.mesh;
        let Some(bbox) = mesh.bounding_box() else {
            continue;
        };
        let wn = WindingNumber::new(&mesh)?;
        let spec = GridSpec::new(bbox.enlarged(0.1), [32, 32, 32])?;
        let (mut by_column, mut by_point) = (f64::INFINITY, f64::INFINITY);
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
        }
        let n = spec.len() as f64;
        let name = path.rsplit('/').next().unwrap_or(&path);
        println!(
            "| {name} | {} | {:.0} | {:.0} | {:.2}× |",
            wn.boundary_edge_count(),
            n / by_column,
            n / by_point,
            by_point / by_column
        );
    }
    Ok(())
}
