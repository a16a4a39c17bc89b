//! Face classification for winding-number booleans: each face of a mesh A gets `w_B` at its
//! centroid, computed by the exact evaluator of B. Union, intersection and difference then keep
//! the faces of A with `w_B` above or below 0.5 (and symmetrically for B).
//!
//! # Coplanar faces
//! When a face of A lies in the plane of a face of B, its centroid lies on B's surface and the
//! exact evaluator returns `w_B` at the **symbolically perturbed point**
//! `c + (ε1, ε2, ε3)` along the axes of its ray frame: with the default ray `+z`, the side
//! towards **+x, then +y, then +z**. The result does not depend on A's orientation: for a face
//! of B with outward normal `+x`, `+y` or `+z` the perturbed point is outside that face (w drops
//! by one), for `−x`, `−y`, `−z` inside (w includes the face's shell). The centroid is computed so
//! that a coordinate shared by all three corners is copied exactly (an axis-aligned face yields an
//! on-plane centroid); for faces of other orientations the rounded centroid is generally not
//! exactly on B's plane and gets the value on whichever side it rounded to.

use rayon::prelude::*;

use crate::eval::Evaluator;
use crate::mesh::Mesh;

/// Centroid of face `f` of `mesh`; a coordinate equal on all three corners is copied exactly.
pub fn face_centroid(mesh: &Mesh, f: usize) -> [f64; 3] {
    let p = mesh.triangle_positions(f);
    std::array::from_fn(|k| {
        if p[0][k] == p[1][k] && p[1][k] == p[2][k] {
            p[0][k]
        } else {
            (p[0][k] + p[1][k] + p[2][k]) / 3.0
        }
    })
}

/// `w_B` at the centroid of every face of `a` (in face order), `b_evaluator` built from B (any
/// evaluator; the coplanar-face rule above is the exact one's).
pub fn classify_faces<E: Evaluator + ?Sized>(a: &Mesh, b_evaluator: &E) -> Vec<f64> {
    (0..a.triangles().len())
        .into_par_iter()
        .map(|f| b_evaluator.eval(face_centroid(a, f)))
        .collect()
}

/// Which faces a selection keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Select {
    /// `w > threshold`.
    Inside,
    /// `w <= threshold`.
    Outside,
}

/// `keep[f]` for every face value under `select` at `threshold`.
pub fn select(values: &[f64], select: Select, threshold: f64) -> Vec<bool> {
    values
        .iter()
        .map(|&w| match select {
            Select::Inside => w > threshold,
            Select::Outside => w <= threshold,
        })
        .collect()
}

/// The faces of `mesh` with `keep[f]`, unreferenced vertices removed (order kept).
pub fn submesh(mesh: &Mesh, keep: &[bool]) -> Mesh {
    let mut map = vec![u32::MAX; mesh.positions().len()];
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for (f, t) in mesh.triangles().iter().enumerate() {
        if !keep.get(f).copied().unwrap_or(false) {
            continue;
        }
        tris.push(t.map(|i| {
            let m = &mut map[i as usize];
            if *m == u32::MAX {
                *m = pos.len() as u32;
                pos.push(mesh.positions()[i as usize]);
            }
            *m
        }));
    }
    // Indices come from a valid mesh, so this cannot fail; fall back to an empty mesh anyway.
    Mesh::new(pos, tris).unwrap_or_default()
}
