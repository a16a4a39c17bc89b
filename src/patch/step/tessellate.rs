//! Triangle meshes of trimmed B-rep models, for measuring distances to them (the remesher's
//! Hausdorff distance): every Bézier patch of every face sampled on a uniform parameter grid
//! with segments no longer than asked, and a grid triangle kept where its centre's `(u, v)` is
//! inside the face's loops ([`super::trim::Trim::indicator`]).
//!
//! Not a watertight tessellation: along a trimming curve the kept triangles end in a staircase
//! up to one segment inside or outside the curve, and faces are not stitched. What it is good
//! for is distance: every point of a kept triangle is within its chord error of the face's
//! surface (and within a segment of the trimmed face), and every point of the trimmed face is
//! within a segment of a kept triangle.

use std::collections::HashMap;

use rayon::prelude::*;

use super::model::StepModel;
use crate::base::vec3::{norm, sub};
use crate::error::MeshError;
use crate::mesh::Mesh;

/// One face's grid points and its kept triangles (indices into those points).
type FaceGrid = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Grid steps along each side of a patch with the box `lo..hi`: its diagonal over `segment`,
/// rounded up.
fn steps(lo: [f64; 3], hi: [f64; 3], segment: f64) -> f64 {
    (norm(sub(hi, lo)) / segment).ceil().max(1.0)
}

/// How many grid triangles [`trimmed_triangles`] looks at with `segment` (it keeps those inside
/// the loops): `2k²` per patch.
pub fn grid_triangles(model: &StepModel, segment: f64) -> f64 {
    model
        .faces
        .iter()
        .flat_map(|f| &f.patches)
        .map(|fp| 2.0 * steps(fp.lo, fp.hi, segment).powi(2))
        .sum()
}

/// The triangles of `model`'s faces, each patch on a `k × k` grid with `k` the patch's box
/// diagonal over `segment` (rounded up), oriented by the face's normal (`sense · S_u × S_v`), so
/// that the mesh's winding number is the model's away from the staircases. `None` for a
/// non-positive or non-finite `segment`, and where the grids would hold more than
/// `max_triangles` triangles ([`grid_triangles`]).
pub fn trimmed_triangles(
    model: &StepModel,
    segment: f64,
    max_triangles: usize,
) -> Option<Result<Mesh, MeshError>> {
    if !(segment.is_finite() && segment > 0.0) {
        return None;
    }
    if grid_triangles(model, segment) > max_triangles as f64 {
        return None;
    }
    let steps = |lo: [f64; 3], hi: [f64; 3]| steps(lo, hi, segment);
    // Each face's grids in parallel (the loops' indicator is most of the work), then one
    // pass that welds the points the faces' patches share (positions rounded to `2^-36` of the
    // diagonal, as `crate::patch::tessellate::tessellate` does): unwelded, every patch border
    // is a boundary edge of the mesh, and a winding number of it pays for each near them
    // (boxed_sphere at res 64 with exact side tests: 16.5 s for the whole run unwelded, 14.7 s
    // welded).
    let faces: Vec<FaceGrid> = model
        .faces
        .par_iter()
        .map(|face| {
            let (mut positions, mut triangles) = (Vec::new(), Vec::new());
            for fp in &face.patches {
                let k = steps(fp.lo, fp.hi) as usize;
                let base = positions.len() as u32;
                let at = |i: usize, j: usize| base + (i * (k + 1) + j) as u32;
                for i in 0..=k {
                    for j in 0..=k {
                        positions.push(fp.patch.eval(i as f64 / k as f64, j as f64 / k as f64));
                    }
                }
                // `S_s × S_t` has the sign of `S_u × S_v` times `du/ds · dv/dt`.
                let (_, [du, dv]) = fp.uv_at([0.5, 0.5]);
                let flip = face.sense * du * dv < 0.0;
                let inside = |s: f64, t: f64| face.trim.indicator(fp.uv_at([s, t]).0) == 1;
                let h = 1.0 / k as f64;
                for i in 0..k {
                    for j in 0..k {
                        let (s, t) = (i as f64 * h, j as f64 * h);
                        let (c00, c10, c11, c01) =
                            (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                        // Centres of the two triangles: a third of the way across the quad.
                        for (tri, centre) in [
                            ([c00, c10, c11], (s + 2.0 * h / 3.0, t + h / 3.0)),
                            ([c00, c11, c01], (s + h / 3.0, t + 2.0 * h / 3.0)),
                        ] {
                            if inside(centre.0, centre.1) {
                                triangles.push(if flip { [tri[0], tri[2], tri[1]] } else { tri });
                            }
                        }
                    }
                }
            }
            (positions, triangles)
        })
        .collect();
    let weld = model.diagonal().max(f64::MIN_POSITIVE) * 2f64.powi(-36);
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for (points, local) in faces {
        let ids: Vec<u32> = points
            .into_iter()
            .map(|p| {
                *index
                    .entry(p.map(|c| (c / weld).round() as i64))
                    .or_insert_with(|| {
                        positions.push(p);
                        (positions.len() - 1) as u32
                    })
            })
            .collect();
        triangles.extend(local.iter().map(|t| t.map(|x| ids[x as usize])));
    }
    Some(Mesh::new(positions, triangles))
}
