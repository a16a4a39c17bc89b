//! Tetrahedral meshes: keep the tets inside a surface (the front-end of a tet mesher such as
//! TetGen or fTetWild, which fill the bounding box and leave inside/outside to the caller).
//!
//! [`filter_tets`] works on plain slices: tet `t` is kept when `w` at its centroid is above the
//! threshold (default [`DEFAULT_THRESHOLD`] = 0.5). The TetGen `.node`/`.ele` and MEDIT `.mesh`
//! readers and writers live in `io::tets` and are re-exported here.
//!
//! Formats accepted (see `io::tets`):
//! - **TetGen**: `.node` header `<#points> 3 <#attributes> <0|1 markers>`, then
//!   `<index> x y z [attributes] [marker]`; `.ele` header `<#tets> <4|10> <#attributes>`, then
//!   `<index> n1 n2 n3 n4 [n5..n10] [attributes]`. `#` starts a comment. Indices start at 0 or 1
//!   (the first point's index decides, as in TetGen). For 10-node tets only the four corners are
//!   kept; attributes and markers are dropped. Written files are 1-based without attributes.
//! - **MEDIT** (`.mesh`, ascii): free-format keywords `MeshVersionFormatted`, `Dimension 3`,
//!   `Vertices`, `Tetrahedra` (1-based, with a reference that is kept), and `Triangles`, `Edges`,
//!   `Quadrilaterals`, `Hexahedra`, `Corners`, `Ridges`, `Required*`, `Normals`, `Tangents`,
//!   `NormalAtVertices` which are skipped; `End` stops reading. Other keywords are errors.

use rayon::prelude::*;

use crate::eval::Evaluator;

/// The default inside threshold on `w`.
pub const DEFAULT_THRESHOLD: f64 = 0.5;

/// Marks each tet by `w` at its centroid: `true` when `w > threshold`. A tet with a corner index
/// outside `tet_vertices` is never kept.
pub fn filter_tets<E: Evaluator + ?Sized>(
    tet_vertices: &[[f64; 3]],
    tets: &[[u32; 4]],
    evaluator: &E,
    threshold: f64,
) -> Vec<bool> {
    tets.par_iter()
        .map(|t| match centroid(tet_vertices, t) {
            Some(c) => evaluator.eval(c) > threshold,
            None => false,
        })
        .collect()
}

/// Centroid of a tet, `None` for an index out of range.
pub fn centroid(points: &[[f64; 3]], t: &[u32; 4]) -> Option<[f64; 3]> {
    let mut c = [0.0; 3];
    for &i in t {
        let p = points.get(i as usize)?;
        for k in 0..3 {
            c[k] += p[k];
        }
    }
    Some(c.map(|v| v * 0.25))
}
