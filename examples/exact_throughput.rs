//! Single-thread throughput of the exact evaluator, best of `REPS` (default 5) passes over the
//! 32³ grid of `gwn bench` (cell centres of the bounding box enlarged by 10 %, x varying fastest,
//! so consecutive queries take different BVH paths). Less noisy than `gwn bench` (no thread pool,
//! best of several passes): the tool for A/B comparisons of kernel changes.
//!
//! ```text
//! cargo run --release --features examples --example exact_throughput -- ../shared/meshes/cgal-lion-head.off ...
//! ```

use gwn::eval::antipodal::WindingNumber;
use gwn::grid::GridSpec;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let reps: usize = std::env::var("REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    for path in std::env::args().skip(1) {
        let mesh = gwn::io::load_mesh(&path)?.mesh;
        let Some(bbox) = mesh.bounding_box() else {
            println!("{path}: empty mesh");
            continue;
        };
        let w = WindingNumber::new(&mesh)?;
        let points = GridSpec::new(bbox.enlarged(0.1), [32; 3])?.points();
        let mut best = f64::INFINITY;
        let mut checksum = 0.0;
        for _ in 0..reps {
            let t = std::time::Instant::now();
            checksum = points.iter().map(|&p| w.eval(p)).sum::<f64>();
            best = best.min(t.elapsed().as_secs_f64());
        }
        println!(
            "{:40} F={:7} B={:5} {:8.3} M queries/s (checksum {checksum:.6})",
            path.rsplit('/').next().unwrap_or(&path),
            w.face_count(),
            w.boundary_edge_count(),
            points.len() as f64 / best / 1e6,
        );
    }
    Ok(())
}
