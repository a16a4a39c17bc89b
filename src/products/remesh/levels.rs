//! The levels the remesher compares `w` with, and the evaluation that decides every comparison
//! as the field's own values would, at a fraction of the exact evaluator's cost near long signed
//! boundaries.
//!
//! The remesher reads `w` only through comparisons with fixed levels: the class ([`inside`]:
//! `½ + INSIDE_MARGIN`), the thin-part margin (`|w − ½| ≥` [`THIN_PART_MARGIN`]), the
//! integrality of the planar levels and the flatness probe (`|w − round(w)| ≤`
//! [`INTEGRAL_W_SLACK`], and `round` itself, whose steps are the half-integers) — and through
//! the interpolation of the placement's ITP steps, which chooses where to probe but never
//! decides a class (`place`). So a value `v` with a certified bound `b`, `|v − w| ≤ b`, whose
//! interval `[v − b, v + b]` holds none of these levels makes every decision `w` makes.
//!
//! [`decisive_values`] asks the evaluator for such values ([`Evaluator::eval_batch_within`] at
//! [`SCREENING_TOLERANCE`]: for the exact evaluator, its boundary hierarchy at that tolerance)
//! and evaluates the field itself only where an interval holds a level. Inputs whose signed
//! boundary is everywhere (inconsistently oriented faces, shuffled soups) pay the exact loop over
//! all of it for every near-surface point, and most of those points are far from every level.
//!
//! [`inside`]: super::inside

use super::octree::{INTEGRAL_W_SLACK, THIN_PART_MARGIN};
use crate::eval::Evaluator;
use crate::grid::GridSpec;

/// The tolerance of the first pass of [`decisive_values`]. The hierarchy's certified bound is
/// pessimistic (the values measured within `1e-5` of the exact loop at this tolerance on a
/// bunny with a tenth of its faces flipped), and only the points whose interval holds a level are
/// evaluated again: a looser tolerance expands more but sends more points to the second pass
/// (docs/benchmarks.md, "Decisive values").
pub const SCREENING_TOLERANCE: f64 = 1.0 / 32.0;

/// Widening of the interval for comparisons made on values rounded to `f32` (the octree stores
/// corner values so): rounding is monotone, so such a comparison is one with a level moved by at
/// most half an `f32` ulp, `2^-24·|level|`; this covers it with room.
const F32_ROUNDING: f64 = 1e-6;

/// Whether every comparison of the remesher gives the same answer for all of `[v − b, v + b]`
/// (see the module documentation): no level lies in the interval widened by
/// [`F32_ROUNDING`]. A bound of 0 is the value itself: it decides (NaN included, which no
/// comparison calls inside or far from ½).
pub fn decides(v: f64, b: f64) -> bool {
    if b == 0.0 {
        return true;
    }
    if !(v.is_finite() && b.is_finite()) || b > 0.125 {
        return false;
    }
    let widen = F32_ROUNDING * (1.0 + v.abs() + b);
    let (lo, hi) = (v - b - widen, v + b + widen);
    let clear = |level: f64| !(lo <= level && level <= hi);
    let half_levels = [
        super::INSIDE_LEVEL,
        0.5 - THIN_PART_MARGIN,
        0.5 + THIN_PART_MARGIN,
    ];
    if !half_levels.into_iter().all(clear) {
        return false;
    }
    // Integers and half-integers near the interval (it is less than ¼ + 2·widen wide).
    let first = lo.floor() - 1.0;
    (0..4).all(|k| {
        let n = first + f64::from(k);
        clear(n - INTEGRAL_W_SLACK) && clear(n + INTEGRAL_W_SLACK) && clear(n + 0.5)
    })
}

/// Values of `w` at `points` on which every comparison of the remesher is decided as on the
/// field's own values ([`decides`]): a first pass within [`SCREENING_TOLERANCE`], then the field
/// at the points whose interval holds a level. Where the first pass's bound is 0 (every
/// evaluator but the exact one, and the exact one on an input whose boundary is too short for a
/// hierarchy), nothing is evaluated twice.
pub fn decisive_values<E: Evaluator + ?Sized>(evaluator: &E, points: &[[f64; 3]]) -> Vec<f64> {
    let first = evaluator.eval_batch_within(points, SCREENING_TOLERANCE);
    let again: Vec<usize> = (0..points.len())
        .filter(|&i| !decides(first[i].0, first[i].1))
        .collect();
    let mut values: Vec<f64> = first.into_iter().map(|(v, _)| v).collect();
    if again.is_empty() {
        return values;
    }
    let exact = evaluator.eval_batch(&again.iter().map(|&i| points[i]).collect::<Vec<_>>());
    for (&i, w) in again.iter().zip(exact) {
        values[i] = w;
    }
    values
}

/// [`decisive_values`] at the sample points of `spec`, in its storage order. The points go to
/// the evaluator column by column along its [`crate::grid::column_axis`], so the exact evaluator
/// still shares one ray per column ([`crate::eval::antipodal::WindingNumber::eval_batch`]).
pub fn decisive_grid_values<E: Evaluator + ?Sized>(evaluator: &E, spec: &GridSpec) -> Vec<f64> {
    let axis = crate::grid::column_axis(evaluator);
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut order = Vec::with_capacity(spec.len());
    for a in 0..spec.dims[u] {
        for b in 0..spec.dims[v] {
            for c in 0..spec.dims[axis] {
                let mut ijk = [0; 3];
                (ijk[u], ijk[v], ijk[axis]) = (a, b, c);
                order.push(ijk);
            }
        }
    }
    let points: Vec<[f64; 3]> = order.iter().map(|&[i, j, k]| spec.point(i, j, k)).collect();
    let values = decisive_values(evaluator, &points);
    let mut out = vec![f64::NAN; spec.len()];
    for (&[i, j, k], w) in order.iter().zip(values) {
        out[spec.index(i, j, k)] = w;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_interval_decides_only_away_from_every_level() {
        assert!(decides(0.9, 0.01) && decides(0.1, 0.01) && decides(0.35, 0.05));
        assert!(decides(f64::NAN, 0.0) && decides(0.5, 0.0));
        // The class, the thin-part margin, integrality and rounding.
        assert!(!decides(0.5, 0.01) && !decides(0.52, 0.03));
        assert!(!decides(0.76, 0.02) && !decides(0.24, 0.02));
        assert!(!decides(1.0, 0.01) && !decides(0.998, 0.001) && !decides(-2.0, 0.01));
        assert!(!decides(1.49, 0.02) && !decides(-0.51, 0.02));
        // An f32 level's worth of room.
        assert!(!decides(0.5 + 1e-9 + 0.01 + 1e-7, 0.01));
        assert!(!decides(f64::NAN, 0.01) && !decides(0.9, f64::INFINITY) && !decides(0.9, 0.2));
    }

    /// Every comparison the remesher makes, on a value and on every point of the interval.
    #[test]
    fn a_deciding_interval_makes_every_comparison_of_its_points() {
        let comparisons = |w: f64| {
            let f = f64::from(w as f32);
            [
                super::super::inside(w),
                (w - 0.5).abs() >= THIN_PART_MARGIN,
                (f - 0.5).abs() >= THIN_PART_MARGIN,
                (f - f.round()).abs() <= INTEGRAL_W_SLACK,
                (w - w.round()).abs() <= INTEGRAL_W_SLACK,
                w.round() as i64 == 0,
                w.round() as i64 == 1,
            ]
        };
        let mut rng = crate::base::splitmix::SplitMix64(7);
        let mut next = || rng.unit();
        let mut decided = 0;
        for _ in 0..200_000 {
            let v = -2.0 + 5.0 * next();
            let b = 0.05 * next() * next();
            if !decides(v, b) {
                continue;
            }
            decided += 1;
            let at = comparisons(v);
            for t in [-1.0, -0.5, 0.0, 0.5, 1.0] {
                assert_eq!(comparisons(v + t * b), at, "v {v} b {b} t {t}");
            }
        }
        assert!(decided > 100_000, "{decided}");
    }
}
