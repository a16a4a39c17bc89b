//! `gwn remesh` phases on shared meshes: time of classification (coarse grid + octree band),
//! extraction and bisection, face count, topology, at several resolutions.
//!
//! ```text
//! cargo run --release --features examples --example remesh_bench [-- RES... [--mesh FILE]...]
//! ```
//! `--bisect-only` places every vertex by bisection (the input triangles are not used as a
//! guide); `--no-simplify` skips the edge collapses (`simplify s` 0, output = marching
//! tetrahedra). "MT faces" are the marching-tetrahedra triangles before simplification, "MC
//! faces" a dense marching cubes' count on the same corner classes (counted, not built). Defaults: resolutions 64, 128, 256 on two shared meshes (`../shared/meshes`, or
//! `$GWN_SHARED_DIR/meshes`); the thread count is rayon's (set `RAYON_NUM_THREADS`). Prints a
//! Markdown table.

use std::path::PathBuf;
use std::time::Instant;

use gwn::eval::antipodal::WindingNumber;
use gwn::products::remesh::lattice::Lattice;
use gwn::products::remesh::report::TopologyReport;
use gwn::products::remesh::{DEFAULT_BISECTION_STEPS, crossings, extract, octree, place, simplify};

const DEFAULT_MESHES: [&str; 2] = ["cgal-bunny00.off", "assimp-Spider_binary.stl"];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut res = Vec::new();
    let mut meshes = Vec::new();
    let mut guided = true;
    let mut simplified = true;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--bisect-only" {
            guided = false;
        } else if a == "--no-simplify" {
            simplified = false;
        } else if a == "--mesh" {
            meshes.push(PathBuf::from(args.next().ok_or("--mesh needs a file")?));
        } else {
            res.push(a.parse::<usize>()?);
        }
    }
    if res.is_empty() {
        res = vec![64, 128, 256];
    }
    if meshes.is_empty() {
        let shared = std::env::var("GWN_SHARED_DIR")
            .map(PathBuf::from)
            .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared"));
        meshes = DEFAULT_MESHES
            .iter()
            .map(|m| shared.join("meshes").join(m))
            .collect();
    }
    println!(
        "| mesh | input faces | res | classify s | extract s | place s | simplify s | evaluations | guided | \
         total s | points classified | band cells | MT faces | MC faces | output faces | output / MC | \
         closed+manifold+oriented | Euler | components |"
    );
    println!(
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|"
    );
    for path in &meshes {
        let mesh = gwn::io::load_mesh(path)?.mesh;
        let wn = WindingNumber::new(&mesh)?;
        let bounds = mesh.bounding_box().ok_or("empty mesh")?;
        for &r in &res {
            let lattice = Lattice::new(bounds, r).ok_or("bad bounds")?;
            // As in `remesh_guided`: the guide also refines the cells its triangles meet (its
            // build is timed with classification).
            let t0 = Instant::now();
            let guide = crossings::SegmentBvh::of_mesh(&mesh);
            let classified = octree::classify(
                &wn,
                &lattice,
                if guided { Some(&guide) } else { None },
                usize::MAX,
                None,
            )
            .map_err(|_| "too large")?;
            let t1 = Instant::now();
            let band = extract::extract(&lattice, &classified, None).expect("no deadline");
            let t2 = Instant::now();
            let placed = place::place_vertices(
                &wn,
                &lattice,
                &band.edges,
                &classified.edge_values(&band.edges),
                DEFAULT_BISECTION_STEPS,
                if guided {
                    place::CrossingSource::Triangles(&guide)
                } else {
                    place::CrossingSource::None
                },
                None,
            )
            .expect("no deadline");
            let t3 = Instant::now();
            let (positions, triangles) = if simplified {
                let planes = placed.planes_in_lattice_units(&lattice);
                let s = simplify::simplify_with_planes(
                    placed.fixed.clone(),
                    band.triangles.clone(),
                    placed.ticks_per_cell,
                    &simplify::SimplifyOptions::default(),
                    (simplify::DEFAULT_TARGET_FRACTION * band.marching_cubes_triangles as f64)
                        as usize,
                    Some(planes),
                );
                let positions: Vec<[f64; 3]> = s
                    .vertices
                    .iter()
                    .map(|&v| placed.positions[v as usize])
                    .collect();
                (positions, s.triangles)
            } else {
                (placed.positions, band.triangles.clone())
            };
            let t4 = Instant::now();
            let rep = TopologyReport::of(&positions, &triangles);
            let ok = rep.closed && rep.edge_manifold && rep.vertex_manifold && rep.oriented;
            println!(
                "| {} | {} | {r} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {} | {:.2} | {} | {} | {} | {} | {} | {:.3} | {} | {} | {} |",
                path.file_name().and_then(|n| n.to_str()).unwrap_or("?"),
                mesh.triangles().len(),
                (t1 - t0).as_secs_f64(),
                (t2 - t1).as_secs_f64(),
                (t3 - t2).as_secs_f64(),
                (t4 - t3).as_secs_f64(),
                placed.evaluations,
                placed.guided,
                (t4 - t0).as_secs_f64(),
                classified.labels.len(),
                classified.band.len(),
                band.triangles.len(),
                band.marching_cubes_triangles,
                rep.faces,
                rep.faces as f64 / band.marching_cubes_triangles.max(1) as f64,
                if ok { "yes" } else { "NO" },
                rep.euler_characteristic,
                rep.components
            );
        }
    }
    Ok(())
}
