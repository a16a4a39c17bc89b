//! Vertex placement by bisection on `w > ½` along each output vertex's lattice edge.
//!
//! Across a sheet `w` jumps (by 1 across a closed surface, by less across an open one), so the
//! linear interpolation of `w` between the edge's corners, marching cubes' usual rule, puts the
//! vertex at a fraction that has nothing to do with where the sheet is. Bisection keeps an
//! inside end and an outside end: after `steps` steps the class changes within an interval of
//! `|edge| / 2^steps`, and the vertex is that interval's midpoint. It never reaches a corner, so
//! each triangle stays inside its tetrahedron.

use rayon::prelude::*;

use super::lattice::{Corner, Lattice};
use crate::eval::Evaluator;

/// Positions of the vertices on `edges` (inside corner, outside corner), after `steps`
/// bisection steps.
pub fn place_vertices<E: Evaluator + ?Sized>(
    evaluator: &E,
    lattice: &Lattice,
    edges: &[(Corner, Corner)],
    steps: u32,
) -> Vec<[f64; 3]> {
    // Rounds of one parallel batch each: t_in / t_out are the fractions along the edge.
    let mut bracket: Vec<(f64, f64)> = vec![(0.0, 1.0); edges.len()];
    let at = |(i, o): (Corner, Corner), t: f64| -> [f64; 3] {
        lattice
            .position([0, 1, 2].map(|a| f64::from(i[a]) + t * (f64::from(o[a]) - f64::from(i[a]))))
    };
    for _ in 0..steps {
        let mids: Vec<[f64; 3]> = edges
            .par_iter()
            .zip(&bracket)
            .map(|(&e, &(ti, to))| at(e, 0.5 * (ti + to)))
            .collect();
        let w = evaluator.eval_batch(&mids);
        for ((ti, to), w) in bracket.iter_mut().zip(w) {
            let mid = 0.5 * (*ti + *to);
            if w > 0.5 {
                *ti = mid;
            } else {
                *to = mid;
            }
        }
    }
    edges
        .par_iter()
        .zip(&bracket)
        .map(|(&e, &(ti, to))| at(e, 0.5 * (ti + to)))
        .collect()
}
