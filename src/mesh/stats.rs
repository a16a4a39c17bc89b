//! Topology and quality statistics of a mesh (what `gwn info` prints).
//!
//! All counts use vertex indices as stored (no welding) and are computed by sorting, in
//! `O(F log F)`. Definitions follow the test-corpus manifest:
//! - an undirected edge `{u, v}` (`u ≠ v`) is counted once per triangle side that uses it;
//!   a *boundary* edge is used exactly once, a *non-manifold* edge more than twice;
//! - the *signed boundary* ([`boundary_edges`]) keeps edges whose directed uses do not cancel;
//!   when it is empty the winding number is an integer everywhere off the surface;
//! - *components* are vertex-connected components of the triangles (unreferenced vertices are
//!   not components);
//! - a *degenerate* face has a repeated index or an exactly zero `f64` cross product;
//! - *duplicate* faces are the extra copies of a vertex triple, in either orientation.

use super::{Mesh, boundary_edges};
use crate::base::bounding_box::BoundingBox;

/// Statistics of a mesh; see the module documentation for the definitions.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshStats {
    /// Number of triangles.
    pub faces: usize,
    /// Number of vertices as stored.
    pub vertices: usize,
    /// Vertices that no triangle references.
    pub unreferenced_vertices: usize,
    /// Undirected edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Edges of the signed boundary (net directed multiplicity ≠ 0).
    pub signed_boundary_edges: usize,
    /// Signed boundary edges whose net multiplicity is greater than 1.
    pub signed_boundary_heavy_edges: usize,
    /// Edges of the signed boundary by position ([`super::geometric_boundary_edges`]): the
    /// boundary of the geometry, which the exact evaluator's cost depends on.
    pub geometric_boundary_edges: usize,
    /// Undirected edges used by more than two triangles.
    pub nonmanifold_edges: usize,
    /// Vertex-connected components of the triangles.
    pub components: usize,
    /// Triangles with a repeated index or an exactly zero cross product.
    pub degenerate_faces: usize,
    /// Extra copies of a vertex triple (either orientation).
    pub duplicate_faces: usize,
    /// Has triangles and no boundary edge (edges used once).
    pub closed: bool,
    /// Has triangles and an empty signed boundary: every edge is traversed equally often in both
    /// directions, so the winding number is an integer off the surface.
    pub oriented_closed: bool,
    /// Bounding box of the referenced vertices.
    pub bounding_box: Option<BoundingBox>,
    /// Diagonal of the bounding box (0 without triangles).
    pub diagonal: f64,
}

impl MeshStats {
    /// Computes all statistics.
    ///
    /// ```
    /// use gwn::{Mesh, mesh::stats::MeshStats};
    /// let tet = Mesh::from_slices(
    ///     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
    ///     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
    /// )?;
    /// let s = MeshStats::compute(&tet);
    /// assert!(s.closed && s.oriented_closed);
    /// assert_eq!((s.boundary_edges, s.components), (0, 1));
    /// # Ok::<(), gwn::error::MeshError>(())
    /// ```
    pub fn compute(mesh: &Mesh) -> MeshStats {
        let tris = mesh.triangles();
        let pos = mesh.positions();

        // Undirected edge uses.
        let mut edges: Vec<(u32, u32)> = Vec::with_capacity(tris.len() * 3);
        for t in tris {
            for (u, v) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                if u != v {
                    edges.push((u.min(v), u.max(v)));
                }
            }
        }
        edges.sort_unstable();
        let (mut boundary, mut nonmanifold) = (0, 0);
        for run in edges.chunk_by(|a, b| a == b) {
            match run.len() {
                1 => boundary += 1,
                2 => {}
                _ => nonmanifold += 1,
            }
        }

        let signed = boundary_edges(mesh);
        let heavy = signed.iter().filter(|e| e.weight > 1).count();

        // Components by union-find over the triangles' vertices.
        let mut parent: Vec<u32> = (0..pos.len() as u32).collect();
        let mut referenced = vec![false; pos.len()];
        for t in tris {
            for &i in t {
                referenced[i as usize] = true;
            }
            let a = find(&mut parent, t[0]);
            for &i in &t[1..] {
                let b = find(&mut parent, i);
                if a != b {
                    parent[b as usize] = a;
                }
            }
        }
        let mut components = 0;
        for (v, &r) in referenced.iter().enumerate() {
            if r && find(&mut parent, v as u32) == v as u32 {
                components += 1;
            }
        }
        let unreferenced = referenced.iter().filter(|&&r| !r).count();

        let degenerate = tris
            .iter()
            .filter(|t| {
                if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                    return true;
                }
                let [a, b, c] = t.map(|i| pos[i as usize]);
                let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                u[1] * v[2] - u[2] * v[1] == 0.0
                    && u[2] * v[0] - u[0] * v[2] == 0.0
                    && u[0] * v[1] - u[1] * v[0] == 0.0
            })
            .count();

        let mut sorted: Vec<[u32; 3]> = tris
            .iter()
            .map(|t| {
                let mut s = *t;
                s.sort_unstable();
                s
            })
            .collect();
        sorted.sort_unstable();
        let distinct = sorted.chunk_by(|a, b| a == b).count();
        let duplicates = sorted.len() - distinct;

        let bounding_box = mesh.bounding_box();
        MeshStats {
            faces: tris.len(),
            vertices: pos.len(),
            unreferenced_vertices: unreferenced,
            boundary_edges: boundary,
            signed_boundary_edges: signed.len(),
            signed_boundary_heavy_edges: heavy,
            geometric_boundary_edges: super::geometric_boundary_edges(mesh).len(),
            nonmanifold_edges: nonmanifold,
            components,
            degenerate_faces: degenerate,
            duplicate_faces: duplicates,
            closed: !tris.is_empty() && boundary == 0,
            oriented_closed: !tris.is_empty() && signed.is_empty(),
            bounding_box,
            diagonal: bounding_box.map_or(0.0, |b| b.diagonal()),
        }
    }
}

/// Root of `x` with path halving.
fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let p = parent[x as usize];
        parent[x as usize] = parent[p as usize];
        x = p;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dirty_mesh_counts() {
        // Two triangles sharing an edge, one duplicated flipped, one degenerate, a far vertex.
        let m = Mesh::from_slices(
            &[
                [0., 0., 0.],
                [1., 0., 0.],
                [0., 1., 0.],
                [1., 1., 0.],
                [2., 2., 0.],
                [9., 9., 9.],
            ],
            &[[0, 1, 2], [2, 1, 3], [0, 2, 1], [0, 3, 4]],
        )
        .unwrap();
        let s = MeshStats::compute(&m);
        assert_eq!(s.faces, 4);
        assert_eq!(s.unreferenced_vertices, 1);
        assert_eq!(s.duplicate_faces, 1);
        assert_eq!(s.degenerate_faces, 1);
        assert_eq!(s.components, 1);
        // Edge 0-1 and 0-2 and 1-2 are used 2, 2, 3 times.
        assert_eq!(s.nonmanifold_edges, 1);
        assert!(!s.closed);
    }

    #[test]
    fn empty() {
        let s = MeshStats::compute(&Mesh::default());
        assert_eq!(s.components, 0);
        assert!(!s.closed && !s.oriented_closed);
    }
}
