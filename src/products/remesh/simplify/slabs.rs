//! The collapses planned and made in parallel slabs of space, each by its own simplifier, before
//! the global, cost-ordered ones ([`super::SimplifyOptions::slab_cells`]).
//!
//! The surface is cut by lattice planes across its longest axis into slabs holding about equal
//! numbers of faces. Each slab gets a simplifier of its own ([`Simplifier::slab`]) holding every
//! face whose box meets the closed slab `lo ≤ x_a ≤ hi`, and may collapse a vertex only if its
//! ring's box lies inside the **open** slab `lo < x_a < hi` ([`Slab::holds`]). Then the slabs
//! cannot see each other's changes, so they run at once and the result is the same for every
//! thread count:
//! - every face a collapse in slab `A` kills or creates lies inside the open slab `A` (its
//!   vertices are in the ring), and every face of a vertex inside it meets it: the faces, lists
//!   and quadrics a collapse reads (its own, its target's, their neighbours') are all in `A`'s
//!   simplifier, and no other slab writes them (the open slabs are disjoint);
//! - a face that meets a new face of `A` has a point inside the open slab `A`, so it is in `A`'s
//!   simplifier, and is either `A`'s own or a face no slab can change (one reaching outside
//!   `A`, whose vertices outside no slab's ring may hold while it lies inside `A`).
//!
//! So every check of [`super`] — link, flip, size, distance and the exact intersection test —
//! holds against the whole surface, as in the global collapses. The pass over the lattice
//! diagonals ([`super::lattice_diagonals`]) runs inside each slab as well: slab planes are
//! lattice planes, so a cube that meets the open slab lies in the closed one and all its faces
//! are in the slab's simplifier; new faces never touch a slab plane, so the planar graphs the
//! surface draws on the facets in those planes (the other slab's side of the argument) do not
//! change; and every slab keeps the pass's invariants by the same rules.
//! The slabs collapse, cheapest first, to their share of the target with [`SLAB_SLACK`] to
//! spare, then make the flat collapses with faces of the general size (the first stage of
//! [`Simplifier::run_flat`], same checks); the global collapses ([`Simplifier::run`], then the
//! flat ones with large flat faces) finish in global cost order, which also takes the vertices
//! within a ring of the planes.

use super::{P, Simplifier, SimplifyStats};
use rayon::prelude::*;

/// Most slabs. Not the thread count: the result must not depend on it. Eight slabs keep two
/// threads busy to the end (the slabs' collapse counts differ) and leave 7 seams.
const MAX_SLABS: usize = 8;

/// How far above its share of the target face count a slab stops: the global collapses make
/// the rest, in one cost order over the whole surface, and reach the vertices along the seams
/// that no slab could collapse.
const SLAB_SLACK: f64 = 1.1;

/// The open slab `lo < x[axis] < hi` (fixed point).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Slab {
    axis: usize,
    lo: i64,
    hi: i64,
}

impl Slab {
    /// Whether the box `lo..=hi` lies inside the open slab.
    pub(super) fn holds(&self, (lo, hi): (P, P)) -> bool {
        self.lo < lo[self.axis] && hi[self.axis] < self.hi
    }

    /// Whether the span `lo..=hi` along the slab's axis meets the closed slab.
    fn meets(&self, (lo, hi): (i64, i64)) -> bool {
        lo <= self.hi && self.lo <= hi
    }
}

/// A slab's simplifier and what it needs to give its work back.
struct SlabWork {
    s: Simplifier,
    /// Global index of each local vertex.
    global: Vec<u32>,
    /// Per local face present at the start: whether this slab gives it back (the slab of the
    /// face's lowest coordinate along the axis; faces no slab may change are given back by
    /// that one too, unchanged).
    owned: Vec<bool>,
}

/// What a slab gives back ([`SlabWork::result`]), in global indices: the rest of its simplifier
/// is dropped as soon as it is done (at most one per thread is alive).
struct SlabResult {
    /// Its live faces, owned or new, and the removed vertices each answers for.
    faces: Vec<([u32; 3], Vec<u32>)>,
    /// The vertices it removed.
    removed: Vec<u32>,
    /// The kept vertices whose quadrics it changed (collapse targets), with the new quadrics.
    /// Only changes travel: all of a slab's vertices with their quadrics took 200 bytes each,
    /// and every slab's were alive until the merge (314 MB of the README cube's 790 MB peak at
    /// res 256).
    merged: Vec<(u32, SlabQuadrics)>,
    stats: SimplifyStats,
}

/// A kept vertex's quadrics after a slab's collapses.
struct SlabQuadrics {
    quadric: [f64; 11],
    relocation_quadric: Option<[f64; 11]>,
}

impl SlabWork {
    /// The slab's changes against `before`, the simplifier it was cut from. Only vertices inside
    /// the open slab can change (a collapse's ring, its target included, lies inside it).
    fn result(self, before: &Simplifier) -> SlabResult {
        let SlabWork { s, global, owned } = self;
        let slab = s.slab;
        let inside = |x: usize| slab.is_some_and(|slab| slab.holds((s.points[x], s.points[x])));
        let removed = (0..global.len())
            .filter(|&x| s.removed[x] && !before.removed[global[x] as usize] && inside(x))
            .map(|x| global[x])
            .collect();
        let merged = (0..global.len())
            .filter(|&x| {
                let g = global[x] as usize;
                !s.removed[x]
                    && (s.quadric[x] != before.quadric[g]
                        || s.relocation_quadric.get(x) != before.relocation_quadric.get(g))
                    && inside(x)
            })
            .map(|x| {
                let quadrics = SlabQuadrics {
                    quadric: s.quadric[x],
                    relocation_quadric: s.relocation_quadric.get(x).copied(),
                };
                (global[x], quadrics)
            })
            .collect();
        let faces = (0..s.faces.len())
            .filter(|&f| s.alive[f] && owned.get(f).is_none_or(|&o| o))
            .map(|f| {
                (
                    s.faces[f].map(|x| global[x as usize]),
                    s.support[f].iter().map(|&x| global[x as usize]).collect(),
                )
            })
            .collect();
        SlabResult {
            faces,
            removed,
            merged,
            stats: s.stats,
        }
    }
}

impl Simplifier {
    /// Whether the collapses of `u` may be made here: always, except in a slab's simplifier,
    /// where `u`'s ring must lie inside the open slab.
    pub(super) fn may_collapse(&self, u: u32) -> bool {
        self.slab.is_none_or(|slab| slab.holds(self.ring_box(u)))
    }

    /// Runs `work` on every slab's simplifier, all at once, and takes their changes back.
    /// `work` gets the slab's share of the live faces (those it gives back, over all) and the
    /// number of faces in its simplifier that are not its own.
    pub(super) fn in_slabs(
        &mut self,
        slabs: &[Slab],
        work: impl Fn(&mut Simplifier, f64, usize) + Sync,
    ) {
        if slabs.is_empty() {
            return;
        }
        let live = self.alive.iter().filter(|&&a| a).count().max(1);
        let results: Vec<SlabResult> = slabs
            .par_iter()
            .map(|slab| {
                let mut w = self.slab(*slab);
                let owned = w.owned.iter().filter(|&&o| o).count();
                work(&mut w.s, owned as f64 / live as f64, w.owned.len() - owned);
                w.result(self)
            })
            .collect();
        self.merge(results);
        self.stats.slabs = slabs.len();
    }

    /// A slab's target: its `share` of `target_faces` with [`SLAB_SLACK`] to spare, plus the
    /// `foreign` faces it holds and cannot change (0: no target).
    pub(super) fn slab_target(target_faces: usize, share: f64, foreign: usize) -> usize {
        if target_faces == 0 {
            0
        } else {
            ((target_faces as f64 * share * SLAB_SLACK).ceil() as usize).saturating_add(foreign)
        }
    }

    /// The slabs for [`Simplifier::in_slabs`] (none if fewer than two): across the axis along which the live
    /// vertices spread most, cut at lattice planes at quantiles of the faces' lowest cells.
    pub(super) fn slabs(&self, slab_cells: u32) -> Vec<Slab> {
        if slab_cells == 0 {
            return Vec::new();
        }
        let mut lo = [i64::MAX; 3];
        let mut hi = [i64::MIN; 3];
        for (x, p) in self.points.iter().enumerate() {
            if !self.removed[x] && !self.vertex_faces[x].is_empty() {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
        }
        let Some(axis) = (0..3)
            .filter(|&a| lo[a] <= hi[a])
            .max_by_key(|&a| hi[a] - lo[a])
        else {
            return Vec::new();
        };
        let cells = (hi[axis] - lo[axis]) / self.ticks;
        // An even count: two threads (or four) end together when the slabs cost about the same
        // (7 slabs on 2 threads take 4 slabs' time, 8 take 4 as well).
        let fit = (cells / i64::from(slab_cells)).max(0) as usize;
        if fit < 2 {
            return Vec::new();
        }
        let count = (fit + fit % 2).min(MAX_SLABS);
        let mut lowest: Vec<i64> = self
            .faces
            .iter()
            .zip(&self.alive)
            .filter(|(_, a)| **a)
            .map(|(t, _)| {
                t.iter()
                    .map(|&x| self.points[x as usize][axis].div_euclid(self.ticks))
                    .min()
                    .unwrap_or(0)
            })
            .collect();
        lowest.sort_unstable();
        // Planes at lattice coordinates (ticks), strictly increasing, inside the surface's span.
        let mut planes: Vec<i64> = (1..count)
            .map(|k| lowest[k * lowest.len() / count] * self.ticks)
            .filter(|&c| lo[axis] < c && c < hi[axis])
            .collect();
        planes.dedup();
        let mut slabs = Vec::with_capacity(planes.len() + 1);
        let mut below = i64::MIN;
        for &c in planes.iter().chain(std::iter::once(&i64::MAX)) {
            slabs.push(Slab {
                axis,
                lo: below,
                hi: c,
            });
            below = c;
        }
        slabs
    }

    /// The simplifier of `slab`: the live faces whose spans along the axis meet the closed
    /// slab (a face in a slab plane is in both slabs' and no slab may change it), their vertices
    /// and the removed vertices they answer for, renumbered in the global order (the
    /// extraction's, which keeps neighbours near each other in memory).
    fn slab(&self, slab: Slab) -> SlabWork {
        // Computed per slab, not stored per face (16 bytes × 3M faces at res 256).
        let span = |f: u32| {
            let c = self.faces[f as usize].map(|x| self.points[x as usize][slab.axis]);
            (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]))
        };
        let mine: Vec<u32> = (0..self.faces.len() as u32)
            .filter(|&f| self.alive[f as usize] && slab.meets(span(f)))
            .collect();
        let mut local = vec![u32::MAX; self.points.len()];
        for &f in &mine {
            let f = f as usize;
            for &x in self.faces[f].iter().chain(&self.support[f]) {
                local[x as usize] = 0;
            }
        }
        let mut global: Vec<u32> = Vec::new();
        for (x, l) in local.iter_mut().enumerate() {
            if *l == 0 {
                *l = global.len() as u32;
                global.push(x as u32);
            }
        }
        let faces: Vec<[u32; 3]> = mine
            .iter()
            .map(|&f| self.faces[f as usize].map(|x| local[x as usize]))
            .collect();
        let support: Vec<Vec<u32>> = mine
            .iter()
            .map(|&f| {
                self.support[f as usize]
                    .iter()
                    .map(|&x| local[x as usize])
                    .collect()
            })
            .collect();
        let owned: Vec<bool> = mine
            .iter()
            .map(|&f| {
                let lowest = span(f).0;
                slab.lo <= lowest && lowest < slab.hi
            })
            .collect();
        let mut vertex_faces = vec![Vec::new(); global.len()];
        for (f, t) in faces.iter().enumerate() {
            for &x in t {
                vertex_faces[x as usize].push(f as u32);
            }
        }
        let s = Simplifier {
            points: global.iter().map(|&x| self.points[x as usize]).collect(),
            at: global.iter().map(|&x| self.at[x as usize]).collect(),
            alive: vec![true; faces.len()],
            removed: global.iter().map(|&x| self.removed[x as usize]).collect(),
            quadric: global.iter().map(|&x| self.quadric[x as usize]).collect(),
            relocation_quadric: if self.relocation_quadric.is_empty() {
                Vec::new()
            } else {
                global
                    .iter()
                    .map(|&x| self.relocation_quadric[x as usize])
                    .collect()
            },
            vertex_faces,
            support,
            grids: Vec::new(),
            indexed: false,
            shift: self.shift,
            ticks: self.ticks,
            cube_ticks: self.cube_ticks,
            max_extent: self.max_extent,
            max_flat_extent: self.max_flat_extent,
            large_flat_faces: false,
            max_distance2: self.max_distance2,
            flat_limit: None,
            slab: Some(slab),
            deadline: self.deadline,
            stats: SimplifyStats {
                faces_before: faces.len(),
                ..SimplifyStats::default()
            },
            faces,
        };
        SlabWork { s, global, owned }
    }

    /// Takes back the slabs' work: their removed vertices and merged quadrics, the faces each
    /// gives back, the counters; the face lists are rebuilt (the spatial index is built on
    /// first need).
    fn merge(&mut self, work: Vec<SlabResult>) {
        let mut faces = Vec::new();
        let mut support = Vec::new();
        for w in work {
            for g in w.removed {
                self.removed[g as usize] = true;
            }
            for (g, q) in w.merged {
                let g = g as usize;
                self.quadric[g] = q.quadric;
                if let Some(r) = q.relocation_quadric {
                    self.relocation_quadric[g] = r;
                }
            }
            for (t, s) in w.faces {
                faces.push(t);
                support.push(s);
            }
            let st = w.stats;
            self.stats.collapses += st.collapses;
            self.stats.slab_collapses += st.collapses;
            self.stats.rounds += st.rounds;
            self.stats.diagonal_collapses += st.diagonal_collapses;
            self.stats.diagonals_left += st.diagonals_left;
            self.stats.flat_star_collapses += st.flat_star_collapses;
            for (a, b) in self.stats.refused.iter_mut().zip(st.refused) {
                *a += b;
            }
        }
        for list in &mut self.vertex_faces {
            list.clear();
        }
        for (f, t) in faces.iter().enumerate() {
            for &x in t {
                self.vertex_faces[x as usize].push(f as u32);
            }
        }
        self.alive = vec![true; faces.len()];
        self.faces = faces;
        self.support = support;
        self.grids = Vec::new();
        self.indexed = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collapses_stay_inside_the_open_slab_and_faces_of_its_planes_belong_to_both() {
        let slab = Slab {
            axis: 1,
            lo: 16,
            hi: 32,
        };
        let at = |y: i64| [0, y, 0];
        // Rings strictly inside may collapse; a ring touching a plane may not.
        assert!(slab.holds((at(17), at(31))));
        assert!(!slab.holds((at(16), at(20))));
        assert!(!slab.holds((at(20), at(32))));
        // Faces meeting the closed slab are in its simplifier, those in a plane included.
        assert!(slab.meets((32, 32)) && slab.meets((8, 16)) && slab.meets((0, 40)));
        assert!(!slab.meets((33, 40)) && !slab.meets((0, 15)));
    }

    /// Collapses merge quadrics, so the sum of the kept vertices' quadrics is the sum over all
    /// vertices before; the same for the relocation quadrics. After the slabs' collapses are
    /// taken back, both sums must hold and every collapse must have removed one vertex: a slab
    /// that gave back too little (a target's quadric, a removed vertex) breaks them.
    #[test]
    fn slabs_give_back_every_removed_vertex_and_merged_quadric() {
        use crate::eval::antipodal::WindingNumber;
        use crate::products::remesh::{crossings::SegmentBvh, extract, lattice, octree, place};
        // A cube turned off the axes (generic planes), at res 40 in 8-cell slabs.
        let (c, s) = (0.8f64, 0.6f64);
        let turn = |p: [f64; 3]| [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
        let corners: Vec<[f64; 3]> = (0..8)
            .map(|i| turn([(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]))
            .collect();
        let faces = [
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        let mesh = crate::Mesh::from_slices(&corners, &faces).unwrap();
        let wn = WindingNumber::new(&mesh).unwrap();
        let guide = SegmentBvh::of_mesh(&mesh);
        let lattice = lattice::Lattice::new(mesh.bounding_box().unwrap(), 40).unwrap();
        let classified = octree::classify(&wn, &lattice, Some(&guide), usize::MAX, None).unwrap();
        let band = extract::extract(&lattice, &classified, None).unwrap();
        let placed = place::place_vertices(
            &wn,
            &lattice,
            &band.edges,
            &classified.edge_values(&band.edges),
            8,
            place::CrossingSource::Triangles(&guide),
            None,
        )
        .unwrap();
        let planes = placed.planes_in_lattice_units(&lattice);
        assert!(planes.iter().filter(|p| p.is_some()).count() * 2 > planes.len());
        let options = super::super::SimplifyOptions::default();
        let Ok(mut simplifier) = Simplifier::new_unindexed(
            placed.fixed.clone(),
            band.triangles.clone(),
            placed.ticks_per_cell,
            &options,
            Some(planes),
        ) else {
            panic!("the marching-tetrahedra surface is simplifiable");
        };
        let sum = |s: &Simplifier, q: &[[f64; 11]]| {
            let mut total = [0.0; 11];
            for (x, q) in q.iter().enumerate() {
                if !s.removed[x] {
                    for (t, v) in total.iter_mut().zip(q) {
                        *t += v;
                    }
                }
            }
            total
        };
        let before = (
            sum(&simplifier, &simplifier.quadric),
            sum(&simplifier, &simplifier.relocation_quadric),
        );
        let slabs = simplifier.slabs(8);
        assert!(slabs.len() >= 4, "{slabs:?}");
        simplifier.in_slabs(&slabs, |slab, _, _| {
            slab.collapse_lattice_diagonals(options.lattice_diagonal_error);
            slab.run(0);
        });
        let stats = simplifier.stats;
        assert!(stats.slab_collapses > 1000, "{stats:?}");
        let removed = simplifier.removed.iter().filter(|&&r| r).count();
        assert_eq!(removed, stats.slab_collapses);
        let after = (
            sum(&simplifier, &simplifier.quadric),
            sum(&simplifier, &simplifier.relocation_quadric),
        );
        for (b, a) in [(before.0, after.0), (before.1, after.1)] {
            let scale: f64 = b.iter().map(|x| x.abs()).sum();
            for k in 0..11 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-9 * scale,
                    "{k}: {} vs {}",
                    a[k],
                    b[k]
                );
            }
        }
    }

    #[test]
    fn a_slab_target_is_its_share_with_slack_plus_what_it_cannot_change() {
        assert_eq!(Simplifier::slab_target(0, 0.5, 7), 0);
        assert_eq!(Simplifier::slab_target(1000, 0.25, 7), 275 + 7);
        // No target (`usize::MAX`) stays out of reach, without overflow.
        assert_eq!(Simplifier::slab_target(usize::MAX, 1.0, 7), usize::MAX);
        assert!(Simplifier::slab_target(usize::MAX, 0.5, 7) > usize::MAX / 2);
    }
}
