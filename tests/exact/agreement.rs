//! Agreement of the exact evaluator with the compensated direct sum, and its independence of the
//! ray direction, on every mesh of the shared corpus (skipped with a reason when it is absent).

use crate::common;

use gwn::RayAxis;
use gwn::eval::antipodal::{BoundaryBy, Options, WindingNumber};
use gwn::eval::direct::winding_number_direct;
use gwn::products::sdf::SignedDistance;
use rayon::prelude::*;

/// Triangle visits of the direct sum per mesh: a mesh of F faces is checked against the direct
/// sum at `BUDGET / F` of its queries (at least [`MIN_DIRECT`], at most all of them). The large
/// scans would otherwise be most of this binary's run; the ray and boundary comparisons below
/// still cover every mesh's first 300 queries.
const BUDGET: f64 = 5e6;
const MIN_DIRECT: usize = 100;

#[test]
fn exact_agrees_with_direct_and_with_other_rays_on_the_shared_corpus() {
    let Some((dir, files)) = common::shared_mesh_files() else {
        return;
    };
    assert!(files.len() > 90, "manifest has {} rows", files.len());
    let mut worst = (0.0f64, String::new());
    let mut worst_dir = (0.0f64, String::new());
    let mut total_queries = 0usize;
    let mut direct_total = 0usize;
    let mut welded = Vec::new();
    for (fi, file) in files.iter().enumerate() {
        let mesh = gwn::io::load_mesh(dir.join(file))
            .unwrap_or_else(|e| panic!("{e}"))
            .mesh;
        let Some(bbox) = mesh.bounding_box() else {
            continue;
        };
        let diag = bbox.diagonal();
        let eps = 1e-6 * diag;
        let big = bbox.enlarged(0.1);
        let mut rng = common::Rng(1000 + fi as u64);
        let candidates: Vec<[f64; 3]> = (0..1100)
            .map(|_| std::array::from_fn(|k| rng.range(big.min[k], big.max[k])))
            .collect();
        // The unsigned distance's BVH query (the brute-force distance to every triangle was as
        // costly as the direct sum itself).
        let distance = SignedDistance::new(&mesh).unwrap();
        let queries: Vec<[f64; 3]> = candidates
            .into_par_iter()
            .filter(|&q| distance.unsigned(q) > eps)
            .collect();
        let queries = &queries[..queries.len().min(1000)];
        assert!(
            queries.len() >= 1000,
            "{file}: only {} queries off the surface",
            queries.len()
        );
        total_queries += queries.len();
        let exact = WindingNumber::new(&mesh).unwrap();
        let w: Vec<f64> = exact.eval_batch(queries);
        let direct_count = ((BUDGET / mesh.triangles().len().max(1) as f64) as usize)
            .clamp(MIN_DIRECT, queries.len());
        direct_total += direct_count;
        let d: Vec<f64> = queries[..direct_count]
            .par_iter()
            .map(|&q| winding_number_direct(&mesh, q))
            .collect();
        for i in 0..direct_count {
            let e = (w[i] - d[i]).abs();
            if e > worst.0 {
                worst = (
                    e,
                    format!("{file} at {:?}: exact {} direct {}", queries[i], w[i], d[i]),
                );
            }
        }
        // Boundary matched by vertex index (the mesh's topology) instead of position: the same
        // values, whatever edges the welding cancelled (issue 12, part 1).
        let by_index = WindingNumber::with_options(
            &mesh,
            Options {
                boundary: BoundaryBy::Index,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(exact.boundary_edge_count() <= by_index.boundary_edge_count());
        if exact.boundary_edge_count() < by_index.boundary_edge_count() {
            welded.push(format!(
                "{file}: B {} -> {}",
                by_index.boundary_edge_count(),
                exact.boundary_edge_count()
            ));
        }
        for (i, &q) in queries.iter().enumerate().take(300) {
            let v = by_index.eval(q);
            assert!(
                (v - w[i]).abs() <= 1e-12,
                "{file} at {q:?}: by position {} vs by index {v}",
                w[i]
            );
        }
        // Direction independence: other rays resolve every degeneracy differently.
        for ray in [RayAxis::NegZ, RayAxis::PosX] {
            let other = WindingNumber::with_options(
                &mesh,
                Options {
                    ray,
                    ..Default::default()
                },
            )
            .unwrap();
            for (i, &q) in queries.iter().enumerate().take(300) {
                let (chi0, _) = exact.parts(q);
                let v = other.eval(q);
                let e = (v - w[i]).abs();
                if e > worst_dir.0 {
                    worst_dir = (e, format!("{file} {ray:?} at {q:?}: {v} vs {}", w[i]));
                }
                if exact.boundary_edge_count() == 0 {
                    assert_eq!(
                        other.parts(q).0,
                        chi0,
                        "{file} {ray:?} at {q:?}: integer parts differ"
                    );
                }
            }
        }
    }
    eprintln!(
        "{} meshes, {total_queries} queries ({direct_total} against the direct sum): \
         max |exact − direct| = {:.3e} ({})",
        files.len(),
        worst.0,
        worst.1
    );
    eprintln!(
        "max direction dependence = {:.3e} ({})",
        worst_dir.0, worst_dir.1
    );
    eprintln!("boundary by position vs by index: {}", welded.join("; "));
    assert!(worst.0 <= 1e-10, "exact vs direct: {}", worst.1);
    assert!(
        worst_dir.0 <= 1e-10,
        "direction dependence: {}",
        worst_dir.1
    );
}
