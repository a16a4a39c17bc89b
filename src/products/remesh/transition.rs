//! The split of a regular cell into tetrahedra next to cells refined one level below it.
//!
//! The Freudenthal split of [`super::extract`] is conforming because every cell is cut the same
//! way; a regular cell (edge `r = 2^sub_levels` finest cells) next to a refined one (cut into
//! eight cells of edge `r / 2`, each Freudenthal-split) would leave the refined side's vertices
//! hanging on its faces and edges. Such a *transition* cell is split instead as the cone from
//! its centre over a triangulation of its boundary, face by face:
//! - **subdivided** (the cell across the face is refined): the four half-size squares, each cut
//!   along its diagonal from its minimum corner to its maximum one — the face diagonals of the
//!   refined cell's Freudenthal cubes on that side;
//! - **fanned** (not subdivided, but one of its four edges is *split*, i.e. lies along a
//!   refined cell): the fan from the face's centre over its boundary polygon, the corners and
//!   the midpoints of the split edges;
//! - **plain**: the diagonal from the minimum corner to the maximum one, as in the Freudenthal
//!   split of the cell across it.
//!
//! **Why the union of all splits is a triangulation.** A cone from an interior point of a convex
//! cell over a triangulation of its boundary triangulates the cell. Two cells meet in a face
//! (or an edge, or a corner) that both triangulate the same way: a face's kind depends on the
//! face alone (whether the cell across is refined, which of its edges is split), a subdivided
//! face is triangulated as the refined side's Freudenthal cubes do, and a plain face as a
//! Freudenthal neighbour does. An edge is split for every cell along it. Cells larger than the
//! regular ones never neighbour a refined cell (the octree balances them: see
//! [`super::octree`]), and a fanned face lies between two transition cells (the cell across
//! it holds the split edge too). So marching tetrahedra over every cell's split is closed and
//! manifold, and each triangle lies in its tetrahedron, as with the uniform split.

use super::lattice::Corner;

/// The tetrahedra of the transition split of the regular cell with minimum corner `m` and edge
/// `size` (even), given which regular cells (by minimum corner) are refined: the cone from
/// its centre over its faces, each subdivided, fanned or plain (see the [module
/// documentation](self)).
pub fn tetrahedra(m: Corner, size: u32, refined: impl Fn(Corner) -> bool) -> Vec<[Corner; 4]> {
    debug_assert!(size >= 2 && size.is_multiple_of(2));
    let half = size / 2;
    let centre = m.map(|x| x + half);
    // A regular cell by minimum corner, if it is in the (unsigned) lattice.
    let cell =
        |c: [i64; 3]| -> Option<Corner> { c.iter().all(|&x| x >= 0).then(|| c.map(|x| x as u32)) };
    let is_refined = |c: [i64; 3]| cell(c).is_some_and(&refined);
    let step = i64::from(size);
    let mut tets = Vec::with_capacity(48);
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        for side in 0..2u32 {
            let mut base = m;
            base[a] += side * size;
            let along = |p: Corner, db: u32, dc: u32| -> Corner {
                let mut q = p;
                q[b] += db;
                q[c] += dc;
                q
            };
            let across = {
                let mut n = m.map(i64::from);
                n[a] += if side == 1 { step } else { -step };
                n
            };
            let mut triangles: Vec<[Corner; 3]> = Vec::with_capacity(8);
            if is_refined(across) {
                for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let lo = along(base, i * half, j * half);
                    let hi = along(lo, half, half);
                    triangles.push([lo, along(lo, half, 0), hi]);
                    triangles.push([lo, along(lo, 0, half), hi]);
                }
            } else {
                // The face's corners in cyclic order, and whether each edge (corner i to i + 1)
                // is split: one of the four regular cells along it is refined.
                let corners = [
                    base,
                    along(base, size, 0),
                    along(base, size, size),
                    along(base, 0, size),
                ];
                let split: [bool; 4] = std::array::from_fn(|i| {
                    let (p, q) = (corners[i], corners[(i + 1) % 4]);
                    let lo = [0, 1, 2].map(|x| i64::from(p[x].min(q[x])));
                    let axis = (0..3).find(|&x| p[x] != q[x]).unwrap_or(b);
                    let others = [(axis + 1) % 3, (axis + 2) % 3];
                    [(0, 0), (1, 0), (0, 1), (1, 1)].iter().any(|&(u, v)| {
                        let mut n = lo;
                        n[others[0]] -= u * step;
                        n[others[1]] -= v * step;
                        is_refined(n)
                    })
                });
                if split.iter().any(|&s| s) {
                    let mut polygon: Vec<Corner> = Vec::with_capacity(8);
                    for i in 0..4 {
                        polygon.push(corners[i]);
                        if split[i] {
                            let (p, q) = (corners[i], corners[(i + 1) % 4]);
                            polygon.push([0, 1, 2].map(|x| (p[x] + q[x]) / 2));
                        }
                    }
                    let middle = along(base, half, half);
                    for i in 0..polygon.len() {
                        triangles.push([middle, polygon[i], polygon[(i + 1) % polygon.len()]]);
                    }
                } else {
                    triangles.push([corners[0], corners[1], corners[2]]);
                    triangles.push([corners[0], corners[3], corners[2]]);
                }
            }
            tets.extend(triangles.into_iter().map(|[p, q, r]| [centre, p, q, r]));
        }
    }
    tets
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::products::remesh::extract::FREUDENTHAL;
    use crate::products::remesh::octree::offset;
    use std::collections::HashMap;

    fn volume6(t: [Corner; 4]) -> i64 {
        let d = |p: Corner| [0, 1, 2].map(|a| i64::from(p[a]) - i64::from(t[0][a]));
        let (u, v, w) = (d(t[1]), d(t[2]), d(t[3]));
        (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
            + u[2] * (v[0] * w[1] - v[1] * w[0]))
            .abs()
    }

    /// Every triangle of a set of tetrahedra, sorted, with its count: a triangulation of a
    /// region has each inner triangle twice and each boundary triangle once.
    fn triangle_counts(tets: &[[Corner; 4]]) -> HashMap<[Corner; 3], usize> {
        let mut counts = HashMap::new();
        for t in tets {
            for skip in 0..4 {
                let mut f: Vec<Corner> = (0..4).filter(|&i| i != skip).map(|i| t[i]).collect();
                f.sort_unstable();
                *counts.entry([f[0], f[1], f[2]]).or_insert(0) += 1;
            }
        }
        counts
    }

    /// A 4 × 4 × 4 block of regular cells (edge 2) with a random set refined: every cell is
    /// split (Freudenthal at edge 2, the refined ones as eight Freudenthal cubes of edge 1,
    /// the transition cells by [`tetrahedra`]); the block must be triangulated: volumes add up
    /// and every triangle inside the block is shared by exactly two tetrahedra.
    #[test]
    fn transition_splits_fill_space_conformingly() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..60 {
            let mut refined = std::collections::HashSet::new();
            for x in 0..4u32 {
                for y in 0..4u32 {
                    for z in 0..4u32 {
                        state ^= state << 13;
                        state ^= state >> 7;
                        state ^= state << 17;
                        if state.is_multiple_of(5) {
                            refined.insert([2 * x + 2, 2 * y + 2, 2 * z + 2]);
                        }
                    }
                }
            }
            let is_refined = |c: Corner| refined.contains(&c);
            let mut tets: Vec<[Corner; 4]> = Vec::new();
            for x in 0..4u32 {
                for y in 0..4u32 {
                    for z in 0..4u32 {
                        let m = [2 * x + 2, 2 * y + 2, 2 * z + 2];
                        if is_refined(m) {
                            for b in 0..8 {
                                let child = offset(m, b, 1);
                                tets.extend(FREUDENTHAL.map(|t| t.map(|k| offset(child, k, 1))));
                            }
                            continue;
                        }
                        // As in the remesher: the transition split next to a refined cell
                        // across a face or an edge, else Freudenthal's.
                        let transition = (0..27).any(|i: i64| {
                            let d = [i % 3 - 1, i / 3 % 3 - 1, i / 9 - 1];
                            let n = [0, 1, 2].map(|a| i64::from(m[a]) + 2 * d[a]);
                            d.iter().filter(|&&x| x != 0).count() <= 2
                                && n.iter().all(|&x| x >= 0)
                                && is_refined(n.map(|x| x as u32))
                        });
                        if transition {
                            tets.extend(tetrahedra(m, 2, is_refined));
                        } else {
                            tets.extend(FREUDENTHAL.map(|t| t.map(|k| offset(m, k, 2))));
                        }
                    }
                }
            }
            let total: i64 = tets.iter().map(|&t| volume6(t)).sum();
            assert!(tets.iter().all(|&t| volume6(t) > 0));
            assert_eq!(total, 6 * 8 * 64, "volumes add up to the block");
            let mut boundary = 0;
            for (f, n) in triangle_counts(&tets) {
                let on_boundary =
                    (0..3).any(|a| [2, 10].iter().any(|&v| f.iter().all(|p| p[a] == v)));
                if on_boundary {
                    assert_eq!(n, 1, "boundary triangle {f:?} in {n} tetrahedra");
                    boundary += 1;
                } else {
                    assert_eq!(n, 2, "triangle {f:?} in {n} tetrahedra");
                }
            }
            assert!(boundary >= 6 * 16 * 2);
        }
    }

    #[test]
    fn a_cell_without_refined_neighbours_has_plain_faces_only() {
        let tets = tetrahedra([4, 4, 4], 2, |_| false);
        assert_eq!(tets.len(), 12);
        // Every face's diagonal runs from its minimum corner to its maximum one.
        for t in tets {
            assert_eq!(t[0], [5, 5, 5]);
            assert!(t[1] <= t[3]);
        }
    }
}
