//! Issue 12, part 1: the exact evaluator's boundary matched by vertex index vs by (quantized)
//! position, on every mesh of a folder whose two boundaries differ. Prints a markdown row per
//! mesh: both edge counts, single-thread throughput of each (best of `REPS`, default 3, over the
//! 32³ grid of `gwn bench`, side by side in one run), their ratio, and the largest difference of
//! the values.
//!
//! ```text
//! cargo run --release --features examples --example boundary_welding -- ../shared/meshes
//! ```

use gwn::eval::antipodal::{BoundaryBy, Options, WindingNumber};
use gwn::grid::GridSpec;

fn throughput(w: &WindingNumber, points: &[[f64; 3]], reps: usize) -> (f64, Vec<f64>) {
    let mut best = f64::INFINITY;
    let mut values = Vec::new();
    for _ in 0..reps {
        let t = std::time::Instant::now();
        values = points.iter().map(|&p| w.eval(p)).collect();
        best = best.min(t.elapsed().as_secs_f64());
    }
    (points.len() as f64 / best, values)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let reps: usize = std::env::var("REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let dir = std::env::args().nth(1).unwrap_or("../shared/meshes".into());
    let mut files: Vec<_> = std::fs::read_dir(&dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| gwn::io::load_mesh(p).is_ok())
        .collect();
    files.sort();
    println!(
        "| mesh | F | B by index | B by position | index q/s | position q/s | speed-up | max diff |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for path in files {
        let mesh = gwn::io::load_mesh(&path)?.mesh;
        let Some(bbox) = mesh.bounding_box() else {
            continue;
        };
        let by_position = WindingNumber::new(&mesh)?;
        let by_index = WindingNumber::with_options(
            &mesh,
            Options {
                boundary: BoundaryBy::Index,
                ..Default::default()
            },
        )?;
        if by_position.boundary_edge_count() == by_index.boundary_edge_count() {
            continue;
        }
        let points = GridSpec::new(bbox.enlarged(0.1), [32; 3])?.points();
        let (qi, vi) = throughput(&by_index, &points, reps);
        let (qp, vp) = throughput(&by_position, &points, reps);
        let diff = vi
            .iter()
            .zip(&vp)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "| {} | {} | {} | {} | {:.0}k | {:.0}k | {:.1}× | {:.1e} |",
            path.file_name().unwrap().to_string_lossy(),
            mesh.triangles().len(),
            by_index.boundary_edge_count(),
            by_position.boundary_edge_count(),
            qi / 1e3,
            qp / 1e3,
            qp / qi,
            diff
        );
    }
    Ok(())
}
