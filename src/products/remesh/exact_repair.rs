//! Repairs of an input that change its `w` nowhere off its surface, for [`super::keep_input`]:
//!
//! - **zero-area faces out**: a face that repeats a vertex, or whose corners are collinear
//!   (exactly, on the input's own coordinates), spans no solid angle from any point off it;
//! - **pairs of faces on the same three vertices with opposite orientations out**: their solid
//!   angles cancel from every point (a wall two touching solids share, written once for each);
//! - **faces split at the vertices on their boundary edges** (T-junctions): when a vertex `p`
//!   lies strictly inside the edge `a b` of face `a b c`, the faces `a p c` and `p b c` tile it
//!   with its orientation (`p − a` is a positive multiple of `b − a`), so every solid angle sum,
//!   hence `w`, is unchanged.
//!
//! One more repair changes `w`, by less than ½ and only where the result's own `w` is an
//! integer, so that `{w > ½}` is unchanged ([`without_repeats_in_one_plane`]): **a face written
//! twice with the same orientation loses its second copy** when all such copies lie in one plane
//! (an export that wrote one triangle of a side twice).
//!
//! What was open or degenerate only because of these (a zero-area cap over a T-junction, an
//! export that left its junctions unsplit, a needle whose two ends were welded) comes out closed;
//! no position moves, every vertex is one of the input's, and nothing else is decided here:
//! [`super::keep_input`] proves the result closed, manifold, embedded and the boundary of
//! `{w > ½}` as for any input.
//!
//! [`repair`] splits only *boundary* edges (in one face), and only at vertices of other
//! boundary edges: splitting one face of an edge that two faces share would open it, and a
//! vertex that ends no boundary edge closes no crack. [`split_at_contacts`] splits both faces
//! of an edge at once, at the vertices of faces that meet another: where solids touch, a vertex
//! of one inside an edge of the other becomes a vertex of both.

use std::collections::{HashMap, HashSet};

use super::coplanar_overlaps::CoplanarCounts;
use super::intersect::ExactPoint;

/// What [`repair`] changed: faces only, never a position.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
// Counts grow as the repairs do: built by this crate only, read by fields.
#[non_exhaustive]
pub struct RepairCounts {
    /// Zero-area faces left out.
    pub zero_area_faces: usize,
    /// Faces left out in pairs on the same three vertices with opposite orientations.
    pub cancelled_faces: usize,
    /// Faces split at vertices on their boundary edges.
    pub split_faces: usize,
    /// Second copies of faces written twice with the same orientation, all in one plane, left
    /// out ([`without_repeats_in_one_plane`]).
    pub repeated_faces: usize,
    /// Faces overlapping in one plane, replaced by their sum there
    /// ([`super::coplanar_overlaps`]).
    pub coplanar: CoplanarCounts,
}

impl RepairCounts {
    /// Whether nothing was changed.
    pub fn is_empty(&self) -> bool {
        *self == RepairCounts::default()
    }
}

impl std::fmt::Display for RepairCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = |n: usize| if n == 1 { "" } else { "s" };
        let parts = [
            (self.zero_area_faces, "zero-area face{} left out"),
            (self.cancelled_faces, "face{} cancelled in opposite pairs"),
            (self.split_faces, "face{} split at vertices on their edges"),
            (self.repeated_faces, "repeated face{} in one plane left out"),
        ];
        let mut first = true;
        if !self.coplanar.is_empty() {
            write!(f, "{}", self.coplanar)?;
            first = false;
        }
        for (n, text) in parts {
            if n > 0 {
                let sep = if first { "" } else { ", " };
                write!(f, "{sep}{n} {}", text.replace("{}", s(n)))?;
                first = false;
            }
        }
        Ok(())
    }
}

/// The result of [`repair`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Repaired {
    /// The faces: the input's in their order, zero-area and cancelled ones left out, split ones
    /// replaced by their pieces where they were.
    pub triangles: Vec<[u32; 3]>,
    /// What changed.
    pub counts: RepairCounts,
}

/// `triangles` on the exact `points` without zero-area faces and split at the vertices that lie
/// on their boundary edges (see the [module documentation](self)). The search for those
/// vertices tests at most about `budget` candidates; beyond it no face is split. `closed` says
/// that `triangles` has no boundary edge (then, without zero-area faces, there is nothing to do).
pub fn repair<T: ExactPoint>(
    points: &[T],
    triangles: &[[u32; 3]],
    closed: bool,
    budget: u64,
) -> Repaired {
    let zero_area = |&[a, b, c]: &[u32; 3]| {
        a == b
            || b == c
            || c == a
            || T::projection_axis(points[a as usize], points[b as usize], points[c as usize])
                .is_none()
    };
    let kept: Vec<[u32; 3]> = triangles
        .iter()
        .filter(|t| !zero_area(t))
        .copied()
        .collect();
    let zero_area_faces = triangles.len() - kept.len();
    let (kept, cancelled_faces) = without_opposite_pairs(kept);
    if closed && zero_area_faces == 0 && cancelled_faces == 0 {
        return Repaired {
            triangles: kept,
            counts: RepairCounts::default(),
        };
    }
    // Undirected edges in one face only.
    let mut faces_of_edge: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &kept {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *faces_of_edge.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut boundary: Vec<(u32, u32)> = faces_of_edge
        .into_iter()
        .filter(|&(_, n)| n == 1)
        .map(|(e, _)| e)
        .collect();
    // The hash map's order is random; the budget's cut-off must not be.
    boundary.sort_unstable();
    let junctions = edge_junctions(points, &boundary, budget);
    if junctions.is_empty() {
        return Repaired {
            triangles: kept,
            counts: RepairCounts {
                zero_area_faces,
                cancelled_faces,
                split_faces: 0,
                ..RepairCounts::default()
            },
        };
    }
    let (out, split_faces) = split_at_junctions(&kept, &junctions);
    Repaired {
        triangles: out,
        counts: RepairCounts {
            zero_area_faces,
            cancelled_faces,
            split_faces,
            ..RepairCounts::default()
        },
    }
}

/// `triangles` with every face split at the vertices of `faces` (indices into `triangles`: the
/// faces found meeting another) that lie strictly inside an edge of `faces`, and how many faces
/// that split; `None` when no such vertex is found within `budget` candidates. Both faces of
/// an edge are split at the same vertices, so a closed surface stays closed, and each piece
/// keeps its face's orientation on its face's plane: `w` is unchanged off the surface, no
/// vertex moves. Where solids touch, a vertex of one lying inside an edge of another (a block
/// standing on part of another's edge) becomes a vertex of both, and the contact a shared edge
/// or vertex that [`super::separate_pinches`] can pull apart.
pub fn split_at_contacts<T: ExactPoint>(
    points: &[T],
    triangles: &[[u32; 3]],
    faces: &[u32],
    budget: u64,
) -> Option<(Vec<[u32; 3]>, usize)> {
    let edges = edges_of(triangles, faces);
    let junctions = edge_junctions(points, &edges, budget);
    if junctions.is_empty() {
        return None;
    }
    Some(split_at_junctions(triangles, &junctions))
}

/// Every face of `triangles` split at the vertices `junctions` lists inside its edges (see
/// [`split_face`]), and how many faces were split.
pub(super) fn split_at_junctions(
    triangles: &[[u32; 3]],
    junctions: &HashMap<(u32, u32), Vec<u32>>,
) -> (Vec<[u32; 3]>, usize) {
    let on_edge = |a: u32, b: u32| -> &[u32] {
        junctions
            .get(&(a.min(b), a.max(b)))
            .map_or(&[][..], Vec::as_slice)
    };
    let mut out = Vec::with_capacity(triangles.len() + 2 * junctions.len());
    let mut split_faces = 0;
    for &t in triangles {
        let before = out.len();
        split_face(t, &on_edge, &mut out);
        split_faces += usize::from(out.len() > before + 1);
    }
    (out, split_faces)
}

/// `triangles` without pairs of faces on the same three vertices with opposite orientations
/// (their solid angles cancel from every point off them), and how many faces that left out.
fn without_opposite_pairs(triangles: Vec<[u32; 3]>) -> (Vec<[u32; 3]>, usize) {
    // A face as its vertices rotated to start at the least, and whether it then runs
    // `least, lower, higher` (one orientation) or not.
    let key = |&[a, b, c]: &[u32; 3]| {
        let r = if a < b && a < c {
            [a, b, c]
        } else if b < c {
            [b, c, a]
        } else {
            [c, a, b]
        };
        ([r[0], r[1].min(r[2]), r[1].max(r[2])], r[1] < r[2])
    };
    let mut count: HashMap<[u32; 3], [usize; 2]> = HashMap::new();
    for t in &triangles {
        let (k, up) = key(t);
        count.entry(k).or_default()[usize::from(up)] += 1;
    }
    // Of each set, the first `min(up, down)` faces of each orientation go.
    let mut left: HashMap<[u32; 3], [usize; 2]> = count
        .into_iter()
        .filter(|(_, [d, u])| *d > 0 && *u > 0)
        .map(|(k, [d, u])| (k, [d.min(u); 2]))
        .collect();
    if left.is_empty() {
        return (triangles, 0);
    }
    let before = triangles.len();
    let kept: Vec<[u32; 3]> = triangles
        .into_iter()
        .filter(|t| {
            let (k, up) = key(t);
            match left.get_mut(&k) {
                Some(n) if n[usize::from(up)] > 0 => {
                    n[usize::from(up)] -= 1;
                    false
                }
                _ => true,
            }
        })
        .collect();
    let cancelled = before - kept.len();
    (kept, cancelled)
}

/// Most second copies [`without_repeats_in_one_plane`] leaves out: their interiors are tested
/// for overlap pair by pair.
pub const MAX_REPEATED_FACES: usize = 256;

/// `triangles` (on the exact `points`, bit-identical vertices merged) without the second copy
/// of each face written twice with the same orientation, and how many copies went; `None` when
/// no face repeats, or when the repeats are not all of this kind: each at most twice, the
/// copies (at most [`MAX_REPEATED_FACES`]) in one plane with pairwise disjoint interiors, and
/// the faces left with no signed boundary (every edge used as often each way).
///
/// Why `{w > ½}` stays the same, though `w` changes by `w_D`, the winding number of the copies
/// `D` left out: the faces left have no signed boundary, so their `w'`
/// is an integer off them; the copies are disjoint triangles in one plane, so from a point off
/// that plane they cover disjoint parts of the open hemisphere facing it, a solid angle below
/// `2π`, whatever their orientations, and `|w_D| < ½`, while in the plane, off them, `w_D = 0`.
/// So `w = w' + w_D > ½` exactly where `w' ≥ 1`, that is where `w' > ½`.
pub fn without_repeats_in_one_plane<T: ExactPoint>(
    points: &[T],
    triangles: &[[u32; 3]],
) -> Option<(Vec<[u32; 3]>, usize)> {
    // A face as its vertices rotated to start at the least: equal for the same orientation.
    let key = |&[a, b, c]: &[u32; 3]| {
        if a < b && a < c {
            [a, b, c]
        } else if b < c {
            [b, c, a]
        } else {
            [c, a, b]
        }
    };
    let mut copies: HashMap<[u32; 3], usize> = HashMap::new();
    for t in triangles {
        *copies.entry(key(t)).or_default() += 1;
    }
    if copies.values().all(|&n| n == 1) || copies.values().any(|&n| n > 2) {
        return None;
    }
    let mut repeated: Vec<[u32; 3]> = copies
        .iter()
        .filter(|&(_, &n)| n == 2)
        .map(|(k, _)| *k)
        .collect();
    if repeated.len() > MAX_REPEATED_FACES {
        return None;
    }
    repeated.sort_unstable();
    let corners = |t: [u32; 3]| t.map(|v| points[v as usize]);
    let [a, b, c] = corners(repeated[0]);
    let in_plane = repeated
        .iter()
        .flatten()
        .all(|&v| T::orient(a, b, c, points[v as usize]) == 0);
    if !in_plane {
        return None;
    }
    // Coplanar faces with a normal component along `axis` project without collapsing onto the
    // plane of the other two axes.
    let axis = T::projection_axis(a, b, c)?;
    let axes = ((axis + 1) % 3, (axis + 2) % 3);
    for (i, &s) in repeated.iter().enumerate() {
        for &t in &repeated[i + 1..] {
            let (s, t) = (corners(s), corners(t));
            if !(separated_by_an_edge_of(s, t, axes) || separated_by_an_edge_of(t, s, axes)) {
                return None;
            }
        }
    }
    // Of each repeated face, the first copy stays (and leaves this set), the second goes.
    let mut first_copy_ahead: HashSet<[u32; 3]> = repeated.iter().copied().collect();
    let kept: Vec<[u32; 3]> = triangles
        .iter()
        .filter(|t| {
            let k = key(t);
            copies[&k] == 1 || first_copy_ahead.remove(&k)
        })
        .copied()
        .collect();
    // No signed boundary: every directed edge as often as its reverse.
    let mut uses: HashMap<(u32, u32), i64> = HashMap::new();
    for t in &kept {
        for k in 0..3 {
            let (p, q) = (t[k], t[(k + 1) % 3]);
            *uses.entry((p.min(q), p.max(q))).or_default() += if p < q { 1 } else { -1 };
        }
    }
    if uses.values().any(|&n| n != 0) {
        return None;
    }
    Some((kept, repeated.len()))
}

/// Whether an edge line of the triangle `s` has all of `t` on its closed outer side, in the
/// projection onto `axes` (where neither collapses): for two triangles, their interiors are
/// disjoint exactly when an edge of one of them separates them so.
fn separated_by_an_edge_of<T: ExactPoint>(s: [T; 3], t: [T; 3], axes: (usize, usize)) -> bool {
    let inner = T::orient2(s[0], s[1], s[2], axes);
    (0..3).any(|e| {
        let (a, b) = (s[e], s[(e + 1) % 3]);
        t.iter().all(|&x| T::orient2(a, b, x, axes) * inner <= 0)
    })
}

/// For each of `edges` (as `(min, max)` vertex indices), the ends of `edges` strictly inside
/// it, ordered from `min` to `max`; empty when the search would exceed `budget`.
fn edge_junctions<T: ExactPoint>(
    points: &[T],
    edges: &[(u32, u32)],
    budget: u64,
) -> HashMap<(u32, u32), Vec<u32>> {
    let mut ends: Vec<u32> = edges.iter().flat_map(|&(a, b)| [a, b]).collect();
    ends.sort_unstable();
    ends.dedup();
    // The ends sorted along each axis; an edge's candidates are those whose coordinate on one
    // axis lies within the edge's range there (the axis with the fewest).
    let by_axis: [Vec<u32>; 3] = std::array::from_fn(|k| {
        let mut v = ends.clone();
        v.sort_unstable_by_key(|&i| points[i as usize].at(k));
        v
    });
    let mut junctions = HashMap::new();
    let mut tested = 0u64;
    for &(a, b) in edges {
        let (pa, pb) = (points[a as usize], points[b as usize]);
        let range = |k: usize| {
            let (lo, hi) = (pa.at(k).min(pb.at(k)), pa.at(k).max(pb.at(k)));
            let list = &by_axis[k];
            let start = list.partition_point(|&i| points[i as usize].at(k) < lo);
            let end = list.partition_point(|&i| points[i as usize].at(k) <= hi);
            &list[start..end]
        };
        let candidates = (0..3).map(range).min_by_key(|c| c.len()).unwrap_or(&[]);
        tested += candidates.len() as u64;
        if tested > budget {
            return HashMap::new();
        }
        // An axis along which the edge advances: on it, order along the edge is order of the
        // coordinate (the points are collinear with it).
        let Some(axis) = (0..3).find(|&k| pa.at(k) != pb.at(k)) else {
            continue;
        };
        let mut inside: Vec<u32> = candidates
            .iter()
            .copied()
            .filter(|&p| strictly_inside(points[p as usize], pa, pb, axis))
            .collect();
        if inside.is_empty() {
            continue;
        }
        inside.sort_unstable_by_key(|&p| points[p as usize].at(axis));
        if pa.at(axis) > pb.at(axis) {
            inside.reverse();
        }
        junctions.insert((a, b), inside);
    }
    junctions
}

/// The edges of the faces `faces` of `triangles`, each once as `(min, max)`, sorted.
pub(super) fn edges_of(triangles: &[[u32; 3]], faces: &[u32]) -> Vec<(u32, u32)> {
    let mut edges: Vec<(u32, u32)> = faces
        .iter()
        .flat_map(|&f| {
            let t = triangles[f as usize];
            (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])))
        })
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}

/// Whether `p` lies strictly between `a` and `b` on their segment (`a ≠ b`, differing on
/// `axis`): collinear, exactly, and strictly between them on `axis`.
pub(super) fn strictly_inside<T: ExactPoint>(p: T, a: T, b: T, axis: usize) -> bool {
    let (lo, hi) = (a.at(axis).min(b.at(axis)), a.at(axis).max(b.at(axis)));
    lo < p.at(axis) && p.at(axis) < hi && T::projection_axis(a, b, p).is_none()
}

/// Face `t` tiled by faces whose edges pass through none of the vertices `on_edge` lists
/// (ordered from the edge's lower index to its higher one): a fan from the corner opposite the
/// first edge that has any, then the same for the fan's two outer faces, which keep the other two
/// edges. Every piece has two corners on one of `t`'s edges and the third off its line, so none
/// is degenerate, and each has `t`'s orientation.
fn split_face<'a>(t: [u32; 3], on_edge: &impl Fn(u32, u32) -> &'a [u32], out: &mut Vec<[u32; 3]>) {
    // Work items: a face and, for each of its edges, whether it is a piece of one of `t`'s
    // edges (only those can carry junctions; the fan's inner edges cross `t`).
    let mut stack = vec![(t, [true; 3])];
    while let Some((f, original)) = stack.pop() {
        let split = (0..3).find_map(|k| {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            if !original[k] {
                return None;
            }
            // Flagged edges are whole edges of `t` (the pieces' edges along one carry none).
            let mut inside = on_edge(a, b).to_vec();
            if inside.is_empty() {
                return None;
            }
            if a > b {
                inside.reverse();
            }
            Some((k, inside))
        });
        let Some((k, inside)) = split else {
            out.push(f);
            continue;
        };
        let (a, b, c) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
        // Edge flags of `f` in the order (a b), (b c), (c a).
        let (bc, ca) = (original[(k + 1) % 3], original[(k + 2) % 3]);
        let chain: Vec<u32> = std::iter::once(a)
            .chain(inside.iter().copied())
            .chain(std::iter::once(b))
            .collect();
        let last = chain.len() - 2;
        for (i, w) in chain.windows(2).enumerate() {
            // The piece `w0 w1 c`: its edge `w0 w1` lies on `a b` (no junction left inside it),
            // `w1 c` is `b c` for the last piece, `c w0` is `c a` for the first.
            let piece = [w[0], w[1], c];
            let flags = [false, i == last && bc, i == 0 && ca];
            if flags[1] || flags[2] {
                stack.push((piece, flags));
            } else {
                out.push(piece);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type P = [i64; 3];

    /// A cube of edge 2 (outward) whose bottom face `0 2 1` is split at `8`, the midpoint of its
    /// front edge `1 0`, while the front face `0 1 5` across that edge is not: a T-junction.
    fn capped_cube() -> (Vec<P>, Vec<[u32; 3]>) {
        let (mut p, mut t) = cube();
        p.push([1, 0, 0]);
        assert_eq!(t[0], [0, 2, 1]);
        t.splice(0..1, [[0, 2, 8], [8, 2, 1]]);
        (p, t)
    }

    /// The unit cube's corners times 2, and its 12 outward faces (`testing::unit_cube`).
    fn cube() -> (Vec<P>, Vec<[u32; 3]>) {
        let unit = crate::testing::unit_cube(false);
        let p = unit
            .positions()
            .iter()
            .map(|v| v.map(|c| 2 * c as i64))
            .collect();
        (p, unit.triangles().to_vec())
    }

    #[test]
    fn second_copies_in_one_plane_go_and_every_other_repeat_stays() {
        let (p, t) = cube();
        assert_eq!(
            without_repeats_in_one_plane(&p, &t),
            None,
            "nothing repeats"
        );
        // One side's two faces written twice, the copies rotated: both second copies go, the
        // first copies stay where they were.
        let mut twice = t.clone();
        twice.push([t[4][1], t[4][2], t[4][0]]);
        twice.push(t[5]);
        assert_eq!(
            without_repeats_in_one_plane(&p, &twice),
            Some((t.clone(), 2))
        );
        // Copies in two planes, or a face three times: left as they are.
        let mut two_planes = t.clone();
        two_planes.extend([t[4], t[0]]);
        assert_eq!(without_repeats_in_one_plane(&p, &two_planes), None);
        let mut thrice = t.clone();
        thrice.extend([t[4], t[4]]);
        assert_eq!(without_repeats_in_one_plane(&p, &thrice), None);
        // A wall written twice in a box that does not close without it: the copy would leave a
        // signed boundary behind.
        let mut open = t[1..].to_vec();
        open.push(t[4]);
        assert_eq!(without_repeats_in_one_plane(&p, &open), None);
    }

    #[test]
    fn overlapping_copies_in_one_plane_stay() {
        // Two triangles in z = 0 over each other's corner, each written twice, and once the
        // other way (so that the faces left have no signed boundary): the copies overlap, and
        // `|w_D|` may exceed ½ over both.
        let p: Vec<P> = vec![
            [0, 0, 0],
            [4, 0, 0],
            [0, 4, 0],
            [1, 1, 0],
            [5, 1, 0],
            [1, 5, 0],
        ];
        let (a, b) = ([0, 1, 2], [3, 4, 5]);
        let rev = |t: [u32; 3]| [t[0], t[2], t[1]];
        assert_eq!(
            without_repeats_in_one_plane(&p, &[a, a, b, b, rev(a), rev(b)]),
            None
        );
        // Moved apart, the same copies go.
        let far: Vec<P> = p[..3]
            .iter()
            .chain(
                &p[3..]
                    .iter()
                    .map(|v| [v[0] + 8, v[1], 0])
                    .collect::<Vec<_>>(),
            )
            .copied()
            .collect();
        assert_eq!(
            without_repeats_in_one_plane(&far, &[a, a, b, b, rev(a), rev(b)]),
            Some((vec![a, b, rev(a), rev(b)], 2))
        );
        // Separated triangles, and triangles sharing an edge, have disjoint interiors.
        let axes = (0, 1);
        let c = |t: [u32; 3]| t.map(|v| p[v as usize]);
        assert!(
            !separated_by_an_edge_of(c(a), c(b), axes)
                && !separated_by_an_edge_of(c(b), c(a), axes)
        );
        let q: Vec<P> = vec![
            [0, 0, 0],
            [4, 0, 0],
            [0, 4, 0],
            [4, 4, 0],
            [9, 0, 0],
            [9, 4, 0],
        ];
        let d = |t: [u32; 3]| t.map(|v| q[v as usize]);
        assert!(separated_by_an_edge_of(d([0, 1, 2]), d([1, 3, 2]), axes));
        assert!(separated_by_an_edge_of(d([0, 1, 2]), d([4, 5, 3]), axes));
    }

    #[test]
    fn a_t_junction_is_split_and_zero_area_faces_go() {
        let (p, mut t) = capped_cube();
        let plain = repair(&p, &t, false, 1000);
        // Without the cap the front face's edge 0 1 meets 0 8 and 8 1: split there.
        assert_eq!(plain.counts.zero_area_faces, 0);
        assert_eq!(plain.counts.split_faces, 1);
        assert_eq!(plain.triangles.len(), t.len() + 1);
        assert!(plain.triangles.contains(&[0, 8, 5]) && plain.triangles.contains(&[8, 1, 5]));
        // With a cap `0 8 1` closing it instead, the cap goes and the same split is made; a
        // needle repeating a vertex goes too.
        t.push([0, 8, 1]);
        t.push([3, 3, 7]);
        let capped = repair(&p, &t, false, 1000);
        assert_eq!(capped.counts.zero_area_faces, 2);
        assert_eq!(capped.triangles, plain.triangles);
        // Over budget: nothing is split.
        assert_eq!(repair(&p, &t, false, 0).counts.split_faces, 0);
    }

    #[test]
    fn several_junctions_on_several_edges_give_nondegenerate_pieces_with_the_faces_area() {
        // A triangle (doubled area 2·64·64 along z) whose three edges carry 3, 1 and 2 junctions,
        // against a fan of slivers on the other side that ends each boundary run there.
        let p: Vec<P> = vec![
            [0, 0, 0],
            [64, 0, 0],
            [0, 64, 0],
            [16, 0, 0],
            [32, 0, 0],
            [48, 0, 0],
            [32, 32, 0],
            [0, 48, 0],
            [0, 16, 0],
        ];
        let face = [0, 1, 2];
        // The other side's edges: 0 3 4 5 1 along the bottom, 1 6 2 along the diagonal, 2 7 8 0.
        let chain = [0u32, 3, 4, 5, 1, 6, 2, 7, 8, 0];
        let mut t = vec![face];
        for w in chain.windows(2) {
            t.push([w[1], w[0], 9]);
        }
        let mut p = p;
        p.push([20, 20, -10]);
        let r = repair(&p, &t, false, 1000);
        assert_eq!(r.counts.split_faces, 1);
        let pieces: Vec<[u32; 3]> = r
            .triangles
            .iter()
            .filter(|f| !f.contains(&9))
            .copied()
            .collect();
        assert_eq!(pieces.len(), 1 + 6);
        let doubled_area = |&[a, b, c]: &[u32; 3]| {
            let (a, b, c) = (p[a as usize], p[b as usize], p[c as usize]);
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        };
        assert!(pieces.iter().all(|f| doubled_area(f) > 0));
        assert_eq!(pieces.iter().map(doubled_area).sum::<i64>(), 64 * 64);
        // Every piece's edges are matched by the other side's or by another piece: closed.
        let mut count: HashMap<(u32, u32), i32> = HashMap::new();
        for f in &r.triangles {
            for k in 0..3 {
                *count.entry((f[k], f[(k + 1) % 3])).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &count {
            assert_eq!(count.get(&(b, a)), Some(&n), "edge {a} {b}");
        }
    }
}
