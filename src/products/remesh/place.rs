//! Vertex placement along each output vertex's lattice edge, on `w > ½`.
//!
//! Across a sheet `w` jumps (by 1 across a closed surface, by less across an open one), so the
//! linear interpolation of `w` between the edge's corners, marching cubes' usual rule, puts the
//! vertex at a fraction that has nothing to do with where the sheet is.
//!
//! Positions along an edge are integer *ticks* `k / T`, `T = 2^(steps+1)`: tick 0 is the inside
//! corner (`w > ½`), tick `T` the outside one. Every edge keeps a bracket `[lo, hi]` of ticks
//! whose `lo` end is known inside and `hi` end known outside, and the vertex goes to a tick of the
//! final bracket strictly between the corners (`1 ≤ k ≤ T − 1`), which keeps every triangle inside
//! its tetrahedron (the no-self-intersection argument of `docs/remesh.md` needs nothing else).
//! The final bracket is at most 2 ticks wide, so the vertex is within one tick,
//! `|edge| / 2^(steps+1)`, of a point where the class changes. Two ways to get there:
//! - **bisection**: `steps` evaluations from `[0, T]`;
//! - **guided** (when the input triangles are given): the segment's crossings with the input
//!   triangles ([`SegmentBvh`]); when they round to one tick `k`, two evaluations at `k − 1` and
//!   `k + 1` (fewer at a corner, whose class is known) *verify* it. If the verification fails,
//!   the half whose ends still differ is bisected, so a wrong proposal costs evaluations, never
//!   the guarantee. Several crossings (thin parts, double walls) or none (`w` crossing `½` away
//!   from the triangles, at a hole) fall back to bisection.
//!
//! Ticks are dyadic, so each vertex is exact in fixed point: lattice units times `T`
//! ([`Placement::fixed`]), which the exact self-intersection check of [`super::intersect`] uses.

use rayon::prelude::*;

use super::crossings::SegmentBvh;
use super::lattice::{Corner, Lattice};
use crate::eval::Evaluator;

/// Placed vertices.
#[derive(Clone, Debug, Default)]
pub struct Placement {
    /// World positions.
    pub positions: Vec<[f64; 3]>,
    /// Exact positions in lattice units times [`Placement::ticks_per_cell`].
    pub fixed: Vec<[i64; 3]>,
    /// `T = 2^(steps+1)`: ticks per lattice edge.
    pub ticks_per_cell: i64,
    /// Evaluations of `w` spent.
    pub evaluations: usize,
    /// Vertices placed by a verified crossing (no bisection).
    pub guided: usize,
}

/// Positions of the vertices on `edges` (inside corner, outside corner), within one tick
/// (`|edge| / 2^(steps+1)`) of a class change; `guide` proposes crossings (see the module
/// documentation).
pub fn place_vertices<E: Evaluator + ?Sized>(
    evaluator: &E,
    lattice: &Lattice,
    edges: &[(Corner, Corner)],
    steps: u32,
    guide: Option<&SegmentBvh>,
) -> Placement {
    let ticks: i64 = 1 << (steps + 1);
    let at = |(i, o): (Corner, Corner), k: i64| -> [f64; 3] {
        let t = k as f64 / ticks as f64;
        lattice
            .position([0, 1, 2].map(|a| f64::from(i[a]) + t * (f64::from(o[a]) - f64::from(i[a]))))
    };
    let mut evaluations = 0;
    let mut guided = 0;
    // Brackets (lo inside, hi outside) in ticks.
    let mut bracket: Vec<(i64, i64)> = vec![(0, ticks); edges.len()];
    if let Some(bvh) = guide.filter(|b| !b.is_empty()) {
        // The proposed tick per edge, when the crossings round to a single one.
        let proposal: Vec<Option<i64>> = edges
            .par_iter()
            .map_init(Vec::new, |hits, &e| {
                hits.clear();
                bvh.crossings(at(e, 0), at(e, ticks), hits);
                let mut ks = hits
                    .iter()
                    .map(|&t| ((t * ticks as f64).round() as i64).clamp(1, ticks - 1));
                let k = ks.next()?;
                ks.all(|x| x == k).then_some(k)
            })
            .collect();
        // One batch of the verification points; `None` where a corner's class is known.
        let mut points = Vec::new();
        let mut slots: Vec<(usize, bool)> = Vec::new();
        for (j, (&e, p)) in edges.iter().zip(&proposal).enumerate() {
            if let Some(k) = *p {
                if k - 1 > 0 {
                    points.push(at(e, k - 1));
                    slots.push((j, false));
                }
                if k + 1 < ticks {
                    points.push(at(e, k + 1));
                    slots.push((j, true));
                }
            }
        }
        let w = evaluator.eval_batch(&points);
        evaluations += points.len();
        // Per edge: (below proposal is inside, above proposal is outside).
        let mut verdict: Vec<(bool, bool)> = vec![(true, true); edges.len()];
        for (&(j, above), w) in slots.iter().zip(w) {
            if above {
                verdict[j].1 = w <= 0.5;
            } else {
                verdict[j].0 = w > 0.5;
            }
        }
        for ((b, p), v) in bracket.iter_mut().zip(&proposal).zip(&verdict) {
            let Some(k) = *p else { continue };
            *b = match *v {
                (true, true) => {
                    guided += 1;
                    (k - 1, k + 1)
                }
                // Tick k − 1 is outside: the class changes in [0, k − 1].
                (false, _) => (0, k - 1),
                // Tick k + 1 is inside: the class changes in [k + 1, T].
                (true, false) => (k + 1, ticks),
            };
        }
    }
    // Bisection of every bracket wider than 2 ticks, one parallel batch per round.
    loop {
        let open: Vec<usize> = (0..edges.len())
            .filter(|&j| bracket[j].1 - bracket[j].0 > 2)
            .collect();
        if open.is_empty() {
            break;
        }
        let mids: Vec<[f64; 3]> = open
            .par_iter()
            .map(|&j| {
                let (lo, hi) = bracket[j];
                at(edges[j], (lo + hi) / 2)
            })
            .collect();
        let w = evaluator.eval_batch(&mids);
        evaluations += mids.len();
        for (&j, w) in open.iter().zip(w) {
            let (lo, hi) = &mut bracket[j];
            let mid = (*lo + *hi) / 2;
            if w > 0.5 {
                *lo = mid;
            } else {
                *hi = mid;
            }
        }
    }
    // The vertex tick: the middle of a 2-tick bracket, else the end that is not a corner.
    let tick = |(lo, hi): (i64, i64)| -> i64 {
        if hi - lo == 2 {
            lo + 1
        } else if lo > 0 {
            lo
        } else {
            hi
        }
    };
    let positions = edges
        .par_iter()
        .zip(&bracket)
        .map(|(&e, &b)| at(e, tick(b)))
        .collect();
    let fixed = edges
        .par_iter()
        .zip(&bracket)
        .map(|(&(i, o), &b)| {
            let k = tick(b);
            [0, 1, 2].map(|a| i64::from(i[a]) * ticks + k * (i64::from(o[a]) - i64::from(i[a])))
        })
        .collect();
    Placement {
        positions,
        fixed,
        ticks_per_cell: ticks,
        evaluations,
        guided,
    }
}
