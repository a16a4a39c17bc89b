//! Triangle meshes of patch sets: every patch sampled on a uniform `k × k` parameter grid.
//!
//! Used for reference values (the exact triangle evaluator on tessellations at `k` and `2k`,
//! Richardson-extrapolated: the tessellation error of `w` off the surface is `O(h²)`) and by the
//! CLI products. Vertices on shared patch edges are welded (positions rounded to `2^-36` of the
//! bounding-box diagonal), so a watertight patch set gives a watertight mesh; a vertex pair that
//! straddles a rounding cell stays unwelded, which leaves a crack of width ~1e-11 — harmless for
//! the winding number away from it.

use std::collections::HashMap;

use super::model::PatchSet;
use crate::error::MeshError;
use crate::mesh::Mesh;

/// The tessellation of `set` with `k × k` quads (two triangles each) per patch, oriented like the
/// patches (normal `∂S/∂t × ∂S/∂s`).
pub fn tessellate(set: &PatchSet, k: usize) -> Result<Mesh, MeshError> {
    let k = k.max(1);
    let (lo, hi) = set.bounding_box();
    let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2))
        .sqrt()
        .max(f64::MIN_POSITIVE);
    let cell = diag * 2f64.powi(-36);
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for patch in set.patches() {
        let mut ids = Vec::with_capacity((k + 1) * (k + 1));
        for i in 0..=k {
            for j in 0..=k {
                let p = patch.eval(i as f64 / k as f64, j as f64 / k as f64);
                let key = p.map(|c| ((c - 0.0) / cell).round() as i64);
                let id = *index.entry(key).or_insert_with(|| {
                    positions.push(p);
                    (positions.len() - 1) as u32
                });
                ids.push(id);
            }
        }
        let at = |i: usize, j: usize| ids[i * (k + 1) + j];
        for i in 0..k {
            for j in 0..k {
                let (c00, c01, c11, c10) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
                triangles.push([c00, c01, c11]);
                triangles.push([c00, c11, c10]);
            }
        }
    }
    Mesh::new(positions, triangles)
}
