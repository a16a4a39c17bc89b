//! The vertices on the lattice's face and body diagonals, removed cube by cube before the
//! quadric-ordered collapses ([`super::SimplifyOptions::lattice_diagonals`]).
//!
//! The marching-tetrahedra surface of the Freudenthal split has a vertex on every crossed edge of
//! every tetrahedron: on the bunny at res 256, 224k on the cubes' axis edges (where marching
//! cubes has its vertices), 341k on face diagonals and 146k on body diagonals. The general
//! collapses remove them one by one, each with a search of a spatial index for faces that a new
//! face could meet. Here each diagonal vertex `u` is collapsed first, with the same checks
//! (link, flip, size, distance: [`Simplifier::plan_with_ring`]) except that the intersection
//! check only looks inside the cube of each new face, which the following argument allows.
//!
//! **Invariants** (in regular lattice units — cells of the resolution, whatever sub-cell levels
//! refine below them; *cube*: a closed unit cube of the lattice; *facet*: a closed unit square
//! of a lattice plane):
//! 1. every face lies in a cube, its *owner* (the per-axis minimum of its vertices' cells), and
//!    not in a facet of it;
//! 2. the surface has no self-intersection.
//!
//! [`CubeFaces::new`] checks 1 on the input (a marching-tetrahedra triangle lies in its
//! tetrahedron, which lies in a cube, and never in a face of the tetrahedron — its vertices are
//! on three edges that no face holds — so never in a facet either: the tetrahedron is on one side
//! of the facet's plane); 2 is the simplifier's own precondition. The pass collapses the
//! vertices strictly inside a face or body diagonal of a cube (`+e_a (+e_b (+e_c))`, the
//! Freudenthal split's; with sub-cell levels, also vertices of the finer split that lie on such
//! a segment).
//!
//! **Lemma.** Let `T` and `G` be faces with owners `C ≠ E`. Then `T ∩ G ⊆ C ∩ E = S`, a facet,
//! a lattice edge or a corner, which lies in a facet `F` of both. As `T ⊂ C` and `S` is a face
//! of the convex cube, `T ∩ S` is the convex hull of `T`'s vertices in `S`, at most two of them
//! (invariant 1): a vertex or an edge of the planar graph that the surface's vertices and edges
//! in `F` form; so is `G ∩ S`. That graph has no crossing and no vertex inside an edge
//! (invariant 2): two of its elements meet in common vertices or are the same edge, which `T`
//! and `G` then share.
//! So **a face can only meet a face of another owner properly**, and a new face needs testing
//! only against the other new faces and the faces of its own owner — if the collapse keeps the
//! invariants, which these rules make sure of ([`CubeFaces::refuses`]):
//! - every new face lies in its owner and not in a facet (invariant 1);
//! - two vertices of a new face on a common facet `F` of its owner are joined by an edge of the
//!   surface already (so the graph of `F` does not change), except one: when `u` is a face
//!   diagonal's vertex, the surface in its facet `F` is the path `t₁ u t₂` (checked: no other
//!   vertex of the two cubes on `F` lies in `F`), and the collapse `u → t₁` replaces it by the
//!   edge `t₁ t₂`, whose interior lies inside `F` (checked: its ends are not on one side of the
//!   square, which another facet holds too), where no other vertex or edge is. The graph stays
//!   free of crossings.
//!
//! A body diagonal's vertex has all its faces in its own cube (the six tetrahedra around the
//! diagonal each hold one piece through it), so its collapse onto a vertex of its link only
//! changes that cube; a face diagonal's collapse onto `t₁` or `t₂` changes the two cubes of its
//! facet. Axis-edge vertices are left to the quadric-ordered collapses (their faces lie in four
//! cubes, and no vertex lies in all four), which also get the diagonal vertices that this pass
//! had to keep.

use super::super::lattice::KeyMap;
use super::{P, Plan, Simplifier, bucket_key, face_box, faces_intersect};

/// The lattice segment a vertex lies strictly inside: from the corner `base` (cells) along the
/// axes whose bits are set in `axes`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Segment {
    base: P,
    axes: u8,
}

impl Segment {
    /// The segment of the fixed-point `p` (`ticks` per cell), if `p` is strictly inside a
    /// segment of the Freudenthal split: its non-integer coordinates all have the same
    /// fractional part.
    fn of(p: P, ticks: i64) -> Option<Segment> {
        let mut axes = 0;
        let mut fraction = 0;
        let mut base = [0; 3];
        for a in 0..3 {
            base[a] = p[a].div_euclid(ticks);
            let r = p[a].rem_euclid(ticks);
            if r != 0 {
                if fraction != 0 && r != fraction {
                    return None;
                }
                fraction = r;
                axes |= 1 << a;
            }
        }
        (axes != 0).then_some(Segment { base, axes })
    }

    /// For a face diagonal: the axis across its facet.
    fn facet_axis(self) -> Option<usize> {
        (self.axes.count_ones() == 2).then(|| (0..3).find(|&a| self.axes & (1 << a) == 0))?
    }
}

/// The cube holding the face `t` (fixed point), if it lies in one and not in one of its facets.
fn owner(t: [P; 3], ticks: i64) -> Option<P> {
    let m: P = std::array::from_fn(|a| t.iter().map(|p| p[a].div_euclid(ticks)).min().unwrap_or(0));
    for a in 0..3 {
        let (lo, hi) = (m[a] * ticks, (m[a] + 1) * ticks);
        if t.iter().any(|p| p[a] > hi)
            || t.iter().all(|p| p[a] == lo)
            || t.iter().all(|p| p[a] == hi)
        {
            return None;
        }
    }
    Some(m)
}

/// The live faces of each cube, by owner.
pub(super) struct CubeFaces {
    /// Keyed by the owner's [`bucket_key`] (keys wrap beyond 2²¹ cells: far cubes may share a
    /// list, which costs box tests, never a miss).
    faces: KeyMap<Vec<u32>>,
}

impl CubeFaces {
    /// The faces of `s` by cube, if `s` satisfies invariant 1 of the module documentation.
    fn new(s: &Simplifier) -> Option<CubeFaces> {
        let mut faces: KeyMap<Vec<u32>> = KeyMap::default();
        for (f, t) in s.faces.iter().enumerate() {
            if s.alive[f] {
                let m = owner(t.map(|x| s.points[x as usize]), s.cube_ticks)?;
                faces.entry(bucket_key(m)).or_default().push(f as u32);
            }
        }
        Some(CubeFaces { faces })
    }

    fn of(&self, m: P) -> &[u32] {
        self.faces.get(&bucket_key(m)).map_or(&[], Vec::as_slice)
    }

    /// Whether the collapse of `u` into the faces `new` (vertex indices, and `exact` their
    /// points; replacing `old`) breaks a rule of the module documentation, or a new face meets
    /// another new face or a face of its owner. With `keeps_surface` (the collapse keeps the
    /// surface as a point set: `Simplifier::collapse_keeps_the_surface`) the rules alone: no
    /// face can meet.
    pub(super) fn refuses(
        &self,
        s: &Simplifier,
        u: u32,
        new: &[[u32; 3]],
        exact: &[[P; 3]],
        old: &[u32],
        keeps_surface: bool,
    ) -> bool {
        let ticks = s.cube_ticks;
        let pu = s.points[u as usize];
        let Some(segment) = Segment::of(pu, ticks) else {
            return true;
        };
        let mut owners = Vec::with_capacity(new.len());
        for (t, e) in new.iter().zip(exact) {
            let Some(m) = owner(*e, ticks) else {
                return true;
            };
            for a in 0..3 {
                for side in [m[a] * ticks, (m[a] + 1) * ticks] {
                    // The owner's facets never hold all three vertices: at most one pair.
                    let on = [0, 1, 2].map(|i| e[i][a] == side);
                    let (x, y) = match on {
                        [true, true, true] => return true,
                        [true, true, _] => (t[0], t[1]),
                        [true, false, true] => (t[0], t[2]),
                        [false, true, true] => (t[1], t[2]),
                        _ => continue,
                    };
                    if s.vertex_faces[x as usize]
                        .iter()
                        .any(|&f| s.faces[f as usize].contains(&y))
                    {
                        continue;
                    }
                    let own_facet = segment.facet_axis() == Some(a) && pu[a] == side;
                    if !(own_facet && self.facet_is_path(s, u, segment, a, [x, y])) {
                        return true;
                    }
                }
            }
            owners.push(m);
        }
        if keeps_surface {
            debug_assert!(
                !self.meets_in_owners(s, exact, old, &owners),
                "a collapse of {u} that keeps the surface meets another face"
            );
            return false;
        }
        self.meets_in_owners(s, exact, old, &owners)
    }

    /// Whether a face of `exact` (replacing `old`) meets another or a face of its owner cube.
    fn meets_in_owners(&self, s: &Simplifier, exact: &[[P; 3]], old: &[u32], owners: &[P]) -> bool {
        let boxes: Vec<(P, P)> = exact.iter().map(|t| face_box(*t)).collect();
        for i in 0..exact.len() {
            for j in i + 1..exact.len() {
                if super::boxes_overlap(boxes[i], boxes[j]) && faces_intersect(exact[i], exact[j]) {
                    return true;
                }
            }
        }
        let p = |x: u32| s.points[x as usize];
        for ((t, b), m) in exact.iter().zip(&boxes).zip(owners) {
            for &g in self.of(*m) {
                if old.contains(&g) {
                    continue;
                }
                let tg = s.faces[g as usize].map(p);
                if super::boxes_overlap(*b, face_box(tg)) && faces_intersect(*t, tg) {
                    return true;
                }
            }
        }
        false
    }

    /// Whether `ends` lie in the facet of the face diagonal `segment` (of `u`, across axis
    /// `a`), and the only vertices in that facet among the faces of its two cubes are `u` and
    /// `ends`.
    fn facet_is_path(
        &self,
        s: &Simplifier,
        u: u32,
        segment: Segment,
        a: usize,
        ends: [u32; 2],
    ) -> bool {
        let side = s.points[u as usize][a];
        let in_facet = |q: P| {
            q[a] == side
                && (0..3).all(|b| {
                    b == a
                        || (segment.base[b] * s.cube_ticks..=(segment.base[b] + 1) * s.cube_ticks)
                            .contains(&q[b])
                })
        };
        let [p, q] = ends.map(|x| s.points[x as usize]);
        if !in_facet(p) || !in_facet(q) {
            return false;
        }
        // Both ends on one side of the square: the new edge would lie in that side, which a
        // facet of other cubes holds too. (Never so on the uniform Freudenthal split, where the
        // ends are on two sides; possible on the finer splits of sub-cell levels.)
        let one_side = (0..3).any(|b| {
            b != a
                && [segment.base[b], segment.base[b] + 1]
                    .iter()
                    .any(|&k| p[b] == k * s.cube_ticks && q[b] == k * s.cube_ticks)
        });
        if one_side {
            return false;
        }
        let mut below = segment.base;
        below[a] -= 1;
        [segment.base, below].iter().all(|&m| {
            self.of(m).iter().all(|&f| {
                s.faces[f as usize]
                    .iter()
                    .all(|&x| x == u || ends.contains(&x) || !in_facet(s.points[x as usize]))
            })
        })
    }

    fn remove(&mut self, m: P, f: u32) {
        if let Some(list) = self.faces.get_mut(&bucket_key(m))
            && let Some(i) = list.iter().position(|&g| g == f)
        {
            list.swap_remove(i);
        }
    }
}

impl Simplifier {
    /// Collapses the vertices on body diagonals, then those on face diagonals, each into the
    /// cheapest neighbour (quadric error, at most `max_error` cells) that passes the checks,
    /// with the cube-local
    /// intersection check of the module documentation. Does nothing when the surface is not a
    /// marching-tetrahedra surface of the lattice (invariant 1).
    ///
    /// One at a time, in index order (the extraction's: by `z`, then `y`, then `x`, so
    /// neighbours follow each other in memory). Tried and slower: planning the collapses of
    /// cubes a cube apart in parallel (classes of equal coordinate parities) visits memory in a
    /// scattered order, 4.5 s on two threads against 2.4 s for this on one (bunny at res 256);
    /// planning the next vertex of the lower and of the upper half of the order together
    /// (`rayon::join` per pair) gained nothing on two threads (2.9–3.0 s).
    pub(super) fn collapse_lattice_diagonals(&mut self, max_error: f64) {
        let Some(mut cubes) = CubeFaces::new(self) else {
            return;
        };
        let ticks = self.cube_ticks;
        for axes in [3, 2] {
            for u in 0..self.points.len() as u32 {
                let p = self.points[u as usize];
                // In a slab's simplifier, the slab's own vertices (those of a slab plane are
                // left to the global collapses, uncounted).
                if !self.removed[u as usize]
                    && !self.vertex_faces[u as usize].is_empty()
                    && Segment::of(p, ticks).is_some_and(|s| s.axes.count_ones() == axes)
                    && self.slab.is_none_or(|slab| slab.holds((p, p)))
                {
                    let plan = self.plan_diagonal(u, &cubes, max_error);
                    self.make_diagonal_collapse(u, plan, &mut cubes);
                }
            }
        }
    }

    /// Makes the planned collapse of the diagonal vertex `u`, if any, and counts it.
    fn make_diagonal_collapse(
        &mut self,
        u: u32,
        (plan, refused): (Option<Plan>, [usize; 5]),
        cubes: &mut CubeFaces,
    ) {
        for (a, b) in self.stats.refused.iter_mut().zip(refused) {
            *a += b;
        }
        let Some(plan) = plan else {
            self.stats.diagonals_left += 1;
            return;
        };
        let ticks = self.cube_ticks;
        let p = |s: &Simplifier, f: u32| s.faces[f as usize].map(|x| s.points[x as usize]);
        for &f in &plan.old {
            if let Some(m) = owner(p(self, f), ticks) {
                cubes.remove(m, f);
            }
        }
        let first = self.faces.len() as u32;
        self.apply(u, plan);
        for f in first..self.faces.len() as u32 {
            // Every new face passed `refuses`, so it has an owner.
            if let Some(m) = owner(p(self, f), ticks) {
                cubes.faces.entry(bucket_key(m)).or_default().push(f);
            }
        }
        self.stats.diagonal_collapses += 1;
    }

    /// The collapse of the diagonal vertex `u` into its cheapest neighbour, among those within
    /// `max_error` cells (quadric error), that passes the checks, and the refusals on the way
    /// (link, face size, flip, distance, intersection).
    fn plan_diagonal(
        &self,
        u: u32,
        cubes: &CubeFaces,
        max_error: f64,
    ) -> (Option<Plan>, [usize; 5]) {
        let facet = Segment::of(self.points[u as usize], self.cube_ticks)
            .and_then(|s| s.facet_axis())
            .map(|a| (a, self.points[u as usize][a]));
        // A face diagonal's faces lie in the two cubes of its facet: only a target in the facet
        // keeps each of them in its cube.
        self.plan_cheapest(
            u,
            |v| {
                facet.is_none_or(|(a, side)| self.points[v as usize][a] == side)
                    && self.quadric_error(u, v) <= max_error * max_error
            },
            Some(cubes),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: i64 = 8;

    #[test]
    fn segments_are_freudenthal_edges_only() {
        // An axis edge, a face diagonal and the body diagonal of the cube at (1, 2, 3).
        assert_eq!(
            Segment::of([8 + 3, 16, 24], T),
            Some(Segment {
                base: [1, 2, 3],
                axes: 1
            })
        );
        let face = Segment::of([8 + 5, 16, 24 + 5], T).unwrap();
        assert_eq!((face.axes, face.facet_axis()), (0b101, Some(1)));
        let body = Segment::of([8 + 2, 16 + 2, 24 + 2], T).unwrap();
        assert_eq!((body.axes, body.facet_axis()), (7, None));
        // Negative coordinates floor to the cell below.
        assert_eq!(Segment::of([-3, 0, 0], T).unwrap().base, [-1, 0, 0]);
        // A lattice corner, and a point of a square off its `+e_a + e_b` diagonal.
        assert_eq!(Segment::of([8, 16, 24], T), None);
        assert_eq!(Segment::of([8 + 5, 16 + 3, 24], T), None);
    }

    #[test]
    fn owners_hold_their_faces_outside_their_facets() {
        // In the cube at the origin, touching its facets x = 0 and x = 1 at one vertex each.
        let inside = [[0, 3, 3], [8, 3, 5], [4, 4, 4]];
        assert_eq!(owner(inside, T), Some([0, 0, 0]));
        // The same face's owner does not depend on where the vertices start.
        assert_eq!(owner([inside[2], inside[0], inside[1]], T), Some([0, 0, 0]));
        // In the facet x = 8 of the cube at the origin (and of the one beyond): no owner.
        assert_eq!(owner([[8, 1, 1], [8, 5, 1], [8, 1, 5]], T), None);
        // Across two cubes: no owner.
        assert_eq!(owner([[1, 1, 1], [12, 1, 1], [4, 5, 1]], T), None);
    }
}
