//! `gwn remesh` over every mesh of a folder (the shared corpus by default): per mesh, whether the
//! output is closed, manifold and oriented, its exact self-intersection count, the occupancy
//! agreement with the input (uniform samples in the box), the sampled Hausdorff distance in
//! cells, the output faces and the time. Prints a Markdown table and a summary line.
//!
//! ```text
//! cargo run --release --features examples --example remesh_corpus [-- --res 64 --samples 100000 DIR]
//! ```
//! Files that do not load as a triangle mesh (point clouds, tets, unreadable) are listed as
//! skipped. The thread count is rayon's (set `RAYON_NUM_THREADS`).

use std::path::PathBuf;
use std::time::Instant;

use gwn::eval::antipodal::WindingNumber;
use gwn::products::remesh::crossings::SegmentBvh;
use gwn::products::remesh::intersect::self_intersections;
use gwn::products::remesh::report::{TopologyReport, hausdorff_distance, occupancy_agreement};
use gwn::products::remesh::{RemeshOptions, remesh_guided};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut res = 64;
    let mut samples = 100_000;
    let mut dir = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--res" => res = args.next().ok_or("--res needs a value")?.parse()?,
            "--samples" => samples = args.next().ok_or("--samples needs a value")?.parse()?,
            _ => dir = Some(PathBuf::from(a)),
        }
    }
    let dir = dir.unwrap_or_else(|| {
        std::env::var("GWN_SHARED_DIR")
            .map(PathBuf::from)
            .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared"))
            .join("meshes")
    });
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    println!(
        "| mesh | input faces | output faces | closed+manifold+oriented | self-intersections | \
         agreement | Hausdorff (cells) | guided % | s |"
    );
    println!("|---|---:|---:|---|---:|---:|---:|---:|---:|");
    let (mut done, mut good, mut clean, mut agree_999, mut empty) = (0, 0, 0, 0, 0);
    let mut skipped = Vec::new();
    for path in &files {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("?");
        let mesh = match gwn::io::load_mesh(path) {
            Ok(m) if !m.mesh.is_empty() => m.mesh,
            _ => {
                skipped.push(name.to_string());
                continue;
            }
        };
        let Some(bounds) = mesh.bounding_box() else {
            skipped.push(name.to_string());
            continue;
        };
        let Ok(wn) = WindingNumber::new(&mesh) else {
            skipped.push(name.to_string());
            continue;
        };
        let start = Instant::now();
        let guide = SegmentBvh::of_mesh(&mesh);
        let out = match remesh_guided(
            &wn,
            Some(&guide),
            bounds,
            &RemeshOptions::with_resolution(res),
            &|_| {},
        ) {
            Ok(out) => out,
            Err(e) => {
                println!(
                    "| {name} | {} | error: {e} | | | | | | |",
                    mesh.triangles().len()
                );
                continue;
            }
        };
        let secs = start.elapsed().as_secs_f64();
        done += 1;
        let rep = TopologyReport::of(&out.positions, &out.triangles);
        let ok = rep.closed && rep.edge_manifold && rep.vertex_manifold && rep.oriented;
        good += usize::from(ok);
        let si = self_intersections(&out.fixed, &out.triangles, u64::MAX)
            .map(|s| s.pairs.to_string())
            .unwrap_or_else(|e| e.to_string());
        clean += usize::from(si == "0");
        let cell = out.cell_size;
        // Of the marching-tetrahedra vertices, which the guide places (the output's are fewer).
        let guided =
            100.0 * out.stats.guided_vertices as f64 / out.stats.extracted_vertices.max(1) as f64;
        let out_mesh = gwn::Mesh::new(out.positions, out.triangles)?;
        if out_mesh.is_empty() {
            empty += 1;
        }
        let (agreement, hausdorff) = if out_mesh.is_empty() {
            (None, None)
        } else {
            let output = WindingNumber::new(&out_mesh)?;
            (
                occupancy_agreement(&wn, &output, bounds, samples, 0x9e57),
                hausdorff_distance(&mesh, &out_mesh, 10_000, 0x4a5d),
            )
        };
        agree_999 += usize::from(agreement.is_some_and(|a| a >= 0.999));
        println!(
            "| {name} | {} | {} | {} | {si} | {} | {} | {guided:.1} | {secs:.2} |",
            mesh.triangles().len(),
            rep.faces,
            if ok { "yes" } else { "NO" },
            agreement.map_or("-".into(), |a| format!("{:.3} %", 100.0 * a)),
            hausdorff.map_or("-".into(), |d| format!("{:.2}", d / cell)),
        );
    }
    println!(
        "\nres {res}: {done} meshes remeshed; closed+manifold+oriented {good}/{done}; \
         0 self-intersections {clean}/{done}; agreement >= 99.9 % {agree_999}/{done} \
         ({samples} samples); empty outputs {empty}; skipped {} ({})",
        skipped.len(),
        skipped.join(", ")
    );
    Ok(())
}
