//! Signed boundary edges by net directed multiplicity.
//!
//! Every triangle `[a, b, c]` contributes the directed edges `a→b`, `b→c`, `c→a`. An undirected
//! edge `{u, v}` used `k` times as `u→v` and `m` times as `v→u` is on the boundary with weight
//! `k − m`; interior edges of a consistently oriented surface cancel (`k = m`). This is exactly the
//! boundary that appears in the winding-number formula: the solid angle of a surface depends only
//! on its boundary curve (as a 1-chain), so flipped duplicates cancel, same-oriented duplicates
//! double, and a non-manifold fan keeps whatever net multiplicity its faces leave. Self-edges
//! (`u == v`, from degenerate triangles) project to a point and contribute nothing.

use super::Mesh;

/// A boundary edge `from → to` with positive integer weight (the net multiplicity).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BoundaryEdge {
    /// Start vertex.
    pub from: u32,
    /// End vertex.
    pub to: u32,
    /// Net number of times the edge is traversed `from → to` (always ≥ 1).
    pub weight: u32,
}

/// The signed boundary of `mesh`: edges with non-zero net multiplicity, oriented so that the
/// weight is positive, sorted by `(min(from,to), max(from,to))` (deterministic).
///
/// ```
/// use gwn::{Mesh, mesh::boundary_edges};
/// // Two triangles sharing the edge 1-2 with consistent orientation: a square with 4 boundary edges.
/// let m = Mesh::from_slices(
///     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]],
///     &[[0, 1, 2], [2, 1, 3]],
/// )?;
/// assert_eq!(boundary_edges(&m).len(), 4);
/// # Ok::<(), gwn::error::MeshError>(())
/// ```
pub fn boundary_edges(mesh: &Mesh) -> Vec<BoundaryEdge> {
    signed_boundary(mesh.triangles().iter().copied())
}

/// The signed boundary *by position*: vertices at bit-identical positions (`-0.0 = 0.0`) are one
/// vertex, so a mesh split at UV seams, or an indexed soup whose triangles each own their three
/// vertices, has the boundary of its geometry (a closed surface: none). This is the boundary
/// that the winding number sees: two directed edges with the same endpoint positions and opposite
/// directions cancel in every formula, whatever their indices. Edges name the first vertex of each
/// position.
///
/// ```
/// use gwn::{Mesh, mesh::{boundary_edges, geometric_boundary_edges}};
/// // The same square as two triangles with their own vertices (a soup).
/// let m = Mesh::from_slices(
///     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 1., 0.], [1., 0., 0.], [1., 1., 0.]],
///     &[[0, 1, 2], [3, 4, 5]],
/// )?;
/// assert_eq!(boundary_edges(&m).len(), 6);
/// assert_eq!(geometric_boundary_edges(&m).len(), 4);
/// # Ok::<(), gwn::error::MeshError>(())
/// ```
pub fn geometric_boundary_edges(mesh: &Mesh) -> Vec<BoundaryEdge> {
    let keys: Vec<[u64; 3]> = mesh
        .positions()
        .iter()
        .map(|p| p.map(|c| (c + 0.0).to_bits()))
        .collect();
    boundary_welded_by(mesh.triangles(), &keys)
}

/// The signed boundary of `triangles` after merging the vertices with equal `keys[v]` (e.g. the
/// quantized positions the exact evaluator computes with): edges name the first vertex of each key.
pub fn boundary_welded_by<K: std::hash::Hash + Eq>(
    triangles: &[[u32; 3]],
    keys: &[K],
) -> Vec<BoundaryEdge> {
    let mut first: std::collections::HashMap<&K, u32> =
        std::collections::HashMap::with_capacity(keys.len());
    let canonical: Vec<u32> = keys
        .iter()
        .enumerate()
        .map(|(v, k)| *first.entry(k).or_insert(v as u32))
        .collect();
    signed_boundary(triangles.iter().map(|t| t.map(|v| canonical[v as usize])))
}

/// The signed boundary of a list of triangles (vertex indices).
pub fn signed_boundary(triangles: impl Iterator<Item = [u32; 3]>) -> Vec<BoundaryEdge> {
    let (lower, _) = triangles.size_hint();
    // (lo, hi, +1 if traversed lo→hi else −1); sorting groups each undirected edge.
    let mut directed: Vec<(u32, u32, i8)> = Vec::with_capacity(lower * 3);
    for t in triangles {
        for (u, v) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            if u == v {
                continue;
            }
            if u < v {
                directed.push((u, v, 1));
            } else {
                directed.push((v, u, -1));
            }
        }
    }
    directed.sort_unstable();
    let mut out = Vec::new();
    let mut i = 0;
    while i < directed.len() {
        let (lo, hi, _) = directed[i];
        let mut net: i64 = 0;
        while i < directed.len() && directed[i].0 == lo && directed[i].1 == hi {
            net += i64::from(directed[i].2);
            i += 1;
        }
        if net > 0 {
            out.push(BoundaryEdge {
                from: lo,
                to: hi,
                weight: net as u32,
            });
        } else if net < 0 {
            out.push(BoundaryEdge {
                from: hi,
                to: lo,
                weight: (-net) as u32,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Vec<[f64; 3]> {
        vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [0., 1., 0.],
            [1., 1., 0.],
            [0., 0., 1.],
        ]
    }

    #[test]
    fn isolated_triangle_has_three_unit_edges() {
        let m = Mesh::from_slices(&quad(), &[[0, 1, 2]]).unwrap();
        let b = boundary_edges(&m);
        assert_eq!(
            b,
            vec![
                BoundaryEdge {
                    from: 0,
                    to: 1,
                    weight: 1
                },
                BoundaryEdge {
                    from: 2,
                    to: 0,
                    weight: 1
                },
                BoundaryEdge {
                    from: 1,
                    to: 2,
                    weight: 1
                },
            ]
        );
    }

    #[test]
    fn flipped_duplicate_cancels_completely() {
        let m = Mesh::from_slices(&quad(), &[[0, 1, 2], [0, 2, 1]]).unwrap();
        assert!(boundary_edges(&m).is_empty());
    }

    #[test]
    fn same_oriented_duplicate_doubles_weights() {
        let m = Mesh::from_slices(&quad(), &[[0, 1, 2], [1, 2, 0]]).unwrap();
        let b = boundary_edges(&m);
        assert_eq!(b.len(), 3);
        assert!(b.iter().all(|e| e.weight == 2));
    }

    #[test]
    fn three_face_fan_leaves_net_multiplicity() {
        // Edge 0-1 used by three triangles: 0→1 twice, 1→0 once: net weight 1 along 0→1.
        let m = Mesh::from_slices(&quad(), &[[0, 1, 2], [0, 1, 4], [1, 0, 3]]).unwrap();
        let b = boundary_edges(&m);
        let e01: Vec<_> = b
            .iter()
            .filter(|e| (e.from.min(e.to), e.from.max(e.to)) == (0, 1))
            .collect();
        assert_eq!(
            e01,
            vec![&BoundaryEdge {
                from: 0,
                to: 1,
                weight: 1
            }]
        );
        // All other edges appear once each: 1-2, 2-0, 1-4, 4-0, 0-3, 3-1.
        assert_eq!(b.len(), 7);
        // Four faces on one edge, all the same way round: weight 4.
        let m = Mesh::from_slices(&quad(), &[[0, 1, 2], [0, 1, 4], [0, 1, 3], [3, 0, 1]]).unwrap();
        let e = boundary_edges(&m)
            .into_iter()
            .find(|e| (e.from.min(e.to), e.from.max(e.to)) == (0, 1))
            .unwrap();
        assert_eq!(
            e,
            BoundaryEdge {
                from: 0,
                to: 1,
                weight: 4
            }
        );
    }

    #[test]
    fn self_edges_of_degenerate_triangles_are_dropped() {
        let m = Mesh::from_slices(&quad(), &[[0, 0, 1]]).unwrap();
        let b = boundary_edges(&m);
        // 0→0 dropped; 0→1 and 1→0 cancel.
        assert!(b.is_empty());
        let m = Mesh::from_slices(&quad(), &[[0, 0, 0]]).unwrap();
        assert!(boundary_edges(&m).is_empty());
    }

    #[test]
    fn closed_tetrahedron_has_no_boundary_and_order_is_deterministic() {
        let tet =
            Mesh::from_slices(&quad(), &[[0, 2, 1], [0, 1, 4], [1, 2, 4], [2, 0, 4]]).unwrap();
        assert!(boundary_edges(&tet).is_empty());
        let open = Mesh::from_slices(&quad(), &[[0, 1, 4], [1, 2, 4], [2, 0, 4]]).unwrap();
        let a = boundary_edges(&open);
        let b = boundary_edges(&open);
        assert_eq!(a, b);
        assert_eq!(a.len(), 3);
    }
}
