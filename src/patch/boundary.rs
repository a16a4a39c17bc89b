//! The signed boundary of a patch set: patch edges that do not cancel against a neighbour's
//! edge traversed in the opposite direction (compared exactly, control points and weights).
//!
//! Each patch's boundary loop runs counter-clockwise in the `(t, s)` parameter plane, the
//! orientation of the normal `∂S/∂t × ∂S/∂s`: edge 0 is `s = 0` (row 0, `t: 0→1`), edge 1 is
//! `t = 1` (last column, `s: 0→1`), edge 2 is `s = 1` (last row, `t: 1→0`), edge 3 is `t = 0`
//! (column 0, `s: 1→0`).

use std::collections::HashMap;

use super::model::{Patch, PatchSet};

/// What lies across one patch edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeLink {
    /// All control points coincide: the edge is one point (a collapsed side, like the teapot
    /// lid's centre) and contributes nothing.
    Degenerate,
    /// No neighbour cancels it: part of the surface boundary.
    Boundary,
    /// Cancelled by edge `edge` of patch `patch`, which has the same control points and weights
    /// in reverse order.
    Shared {
        /// The neighbouring patch.
        patch: usize,
        /// Its edge (0..4).
        edge: usize,
    },
}

/// Row-major control-point indices of edge `e` of a patch of degrees `(m, n)`, in loop order.
pub fn edge_indices(m: usize, n: usize, e: usize) -> Vec<usize> {
    let at = |i: usize, j: usize| i * (n + 1) + j;
    match e {
        0 => (0..=n).map(|j| at(0, j)).collect(),
        1 => (0..=m).map(|i| at(i, n)).collect(),
        2 => (0..=n).rev().map(|j| at(m, j)).collect(),
        _ => (0..=m).rev().map(|i| at(i, 0)).collect(),
    }
}

/// The links of every patch edge: `links[patch][edge]`.
pub fn link_edges(set: &PatchSet) -> Vec<[EdgeLink; 4]> {
    let patches = set.patches();
    let mut links = vec![[EdgeLink::Boundary; 4]; patches.len()];
    // canonical key → edges (patch, edge, traversed in the key's direction?)
    let mut groups: HashMap<Vec<u64>, Vec<(usize, usize, bool)>> = HashMap::new();
    for (pi, p) in patches.iter().enumerate() {
        for e in 0..4 {
            let fwd = edge_key(p, e, false);
            if is_degenerate(p, e) {
                links[pi][e] = EdgeLink::Degenerate;
                continue;
            }
            let rev = edge_key(p, e, true);
            let (key, forward) = if fwd <= rev {
                (fwd, true)
            } else {
                (rev, false)
            };
            groups.entry(key).or_default().push((pi, e, forward));
        }
    }
    let mut keys: Vec<_> = groups.into_iter().collect();
    // Deterministic pairing, independent of hash order.
    keys.sort_unstable();
    for (_, members) in keys {
        let (fwd, rev): (Vec<_>, Vec<_>) = members.into_iter().partition(|m| m.2);
        for (a, b) in fwd.iter().zip(&rev) {
            links[a.0][a.1] = EdgeLink::Shared {
                patch: b.0,
                edge: b.1,
            };
            links[b.0][b.1] = EdgeLink::Shared {
                patch: a.0,
                edge: a.1,
            };
        }
    }
    links
}

fn edge_key(p: &Patch, e: usize, reversed: bool) -> Vec<u64> {
    let (m, n) = p.degree();
    let mut idx = edge_indices(m, n, e);
    if reversed {
        idx.reverse();
    }
    // `+ 0.0` turns −0.0 into +0.0, so the two zeros compare equal as in f64.
    idx.iter()
        .flat_map(|&k| {
            let q = p.points()[k];
            [q[0], q[1], q[2], p.weights()[k]].map(|c| (c + 0.0).to_bits())
        })
        .collect()
}

fn is_degenerate(p: &Patch, e: usize) -> bool {
    let (m, n) = p.degree();
    let idx = edge_indices(m, n, e);
    idx.iter().all(|&k| p.points()[k] == p.points()[idx[0]])
}

/// Counts of the edge kinds: `(boundary, shared pairs, degenerate)`.
pub fn edge_counts(links: &[[EdgeLink; 4]]) -> (usize, usize, usize) {
    let mut c = (0, 0, 0);
    for l in links.iter().flatten() {
        match l {
            EdgeLink::Boundary => c.0 += 1,
            EdgeLink::Shared { .. } => c.1 += 1,
            EdgeLink::Degenerate => c.2 += 1,
        }
    }
    (c.0, c.1 / 2, c.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(p: [[f64; 3]; 4]) -> Patch {
        // corners (s,t) = (0,0), (0,1), (1,0), (1,1)
        Patch::polynomial(1, 1, p.to_vec()).unwrap()
    }

    #[test]
    fn opposite_edges_cancel_and_same_direction_edges_do_not() {
        let a = quad([[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]]);
        // Right neighbour sharing a's edge 1 ((1,0)→(1,1)) in the opposite direction: its edge 3.
        let b = quad([[1., 0., 0.], [2., 0., 0.], [1., 1., 0.], [2., 1., 0.]]);
        let links = link_edges(&PatchSet::new(vec![a.clone(), b]).unwrap());
        assert_eq!(links[0][1], EdgeLink::Shared { patch: 1, edge: 3 });
        assert_eq!(links[1][3], EdgeLink::Shared { patch: 0, edge: 1 });
        assert_eq!(edge_counts(&links), (6, 1, 0));
        // A flipped copy traverses the edge in the same direction: nothing cancels.
        let c = quad([[1., 1., 0.], [2., 1., 0.], [1., 0., 0.], [2., 0., 0.]]);
        let links = link_edges(&PatchSet::new(vec![a, c]).unwrap());
        assert_eq!(edge_counts(&links), (8, 0, 0));
    }

    #[test]
    fn collapsed_edges_are_degenerate() {
        let tri = quad([[0., 0., 1.], [0., 0., 1.], [0., 1., 0.], [1., 0., 0.]]);
        let links = link_edges(&PatchSet::new(vec![tri]).unwrap());
        assert_eq!(links[0][0], EdgeLink::Degenerate);
        assert_eq!(edge_counts(&links), (3, 0, 1));
    }
}
