// Shared by the fuzz target and by `tests/inputs/fuzz_corpus_loaders.rs` (via `include!`), so the
// stable test replays the corpus through exactly the code the fuzzer runs.

/// Feeds `data` to a loader: the first byte selects the format (OBJ, STL, OFF, PLY, detect by
/// content, query points, or glTF), the rest is the file. Must never panic; a successful load must
/// give a valid, non-empty mesh whose statistics compute, and which the remesher's exact test of
/// "already the surface" either keeps as a closed, manifold, oriented surface or refuses (and
/// then the components it would keep are closed, manifold and oriented).
pub fn check_load_mesh(data: &[u8]) {
    use gwn::io::{Format, LoadOptions, load_mesh_from_bytes_with, load_points_from_bytes};
    let Some((&selector, body)) = data.split_first() else {
        return;
    };
    let hint = match selector % 7 {
        0 => Some(Format::Obj),
        1 => Some(Format::Stl),
        2 => Some(Format::Off),
        3 => Some(Format::Ply),
        4 => None,
        6 => Some(Format::Gltf),
        _ => {
            if let Ok(p) = load_points_from_bytes(body, "fuzz.txt") {
                assert!(!p.is_empty());
                assert!(p.iter().flatten().all(|c| c.is_finite()));
            }
            return;
        }
    };
    let weld = Some(selector & 0x80 != 0);
    match load_mesh_from_bytes_with(body, "fuzz", hint, &LoadOptions { weld }) {
        Ok(l) => {
            assert!(!l.mesh.triangles().is_empty());
            let s = gwn::mesh::stats::MeshStats::compute(&l.mesh);
            assert_eq!(s.faces, l.mesh.triangles().len());
            if let Some(bounds) = l.mesh.bounding_box() {
                let options = gwn::products::remesh::RemeshOptions::with_resolution(16);
                use gwn::products::remesh::report::TopologyReport;
                let valid = |p: &[[f64; 3]], t: &[[u32; 3]]| {
                    let t = TopologyReport::of(p, t);
                    t.closed && t.edge_manifold && t.vertex_manifold && t.oriented
                };
                match gwn::products::remesh::keep_input::keep_input(&l.mesh, bounds, &options) {
                    Ok(kept) => assert!(valid(&kept.positions, &kept.triangles)),
                    // The clean components of what is not kept whole, and the rest.
                    Err(_) => {
                        use gwn::products::remesh::keep_parts::kept_parts;
                        if let Some(parts) = kept_parts(&l.mesh, bounds, &options) {
                            assert!(valid(&parts.kept_positions, &parts.kept_triangles));
                            assert!(!parts.rest.triangles().is_empty());
                        }
                    }
                }
                // The parity method's keep: faces turned, every guarantee proved again.
                use gwn::products::remesh::reorient::keep_reoriented;
                if let Ok(kept) = keep_reoriented(&l.mesh, bounds, &options) {
                    assert!(kept.triangles.is_empty() || valid(&kept.positions, &kept.triangles));
                }
            }
        }
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.starts_with("fuzz"));
            assert!(!msg.contains('\n'), "not one line: {msg}");
        }
    }
}
