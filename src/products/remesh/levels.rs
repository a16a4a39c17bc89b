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
//! and evaluates the field itself only where an interval holds a level of the caller's own
//! comparisons ([`Comparisons`]: placement reads the class alone). The octree's corners are
//! held to the class and the margin, and carry a flag for integrality, which the planar levels
//! and the lent transitions settle with the field for the few cells they test
//! ([`decisive_corner_values`]). Inputs whose signed boundary is everywhere (inconsistently
//! oriented faces, shuffled soups) pay the exact loop over all of it for every near-surface
//! point, and most of those points are far from every level they are compared with.
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

/// Which of the remesher's comparisons a caller makes with the values it asks
/// [`decisive_values`] for. A value needs to be certain only against the levels of those
/// comparisons: placement reads the class alone, and a near-surface probe is sent back to the
/// field far less often when a level it never compares with (an integer next to a consistent
/// surface, the margin next to a flipped face) does not count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Comparisons {
    /// The class alone ([`inside`]): placement's probes (whose interpolation chooses where to
    /// probe next, never a class) and the plates' runs.
    ///
    /// [`inside`]: super::inside
    Class,
    /// Whether a thin-part probe shows a hidden part (`octree::shows_hidden_part`): the other
    /// class than the cell's corners *and* at least [`THIN_PART_MARGIN`] from ½, that is
    /// `w ≤ ½ − margin` next to inside corners and `w ≥ ½ + margin` next to outside ones; the
    /// class level lies between the two and decides nothing on its own.
    ThinPart,
    /// Integrality and rounding: the flatness probe (`|w − round(w)| ≤` [`INTEGRAL_W_SLACK`] and
    /// whether `round` differs on the two sides).
    Integrality,
    /// The class and the margin: what the octree reads of a corner it classifies, the moment
    /// it classifies it (classes, and the margin of an unexplained point). Integrality, which
    /// only the planar levels and the lent transitions read, and only of some corners, is left
    /// to [`decisive_corner_values`]'s flag.
    ClassAndMargin,
}

/// Whether every comparison of `comparisons` gives the same answer for all of `[v − b, v + b]`
/// (see the module documentation): none of their levels lies in the interval widened by
/// [`F32_ROUNDING`]. A bound of 0 is the value itself: it decides (NaN included, which no
/// comparison calls inside or far from ½).
pub fn decides(v: f64, b: f64, comparisons: Comparisons) -> bool {
    if b == 0.0 {
        return true;
    }
    if !(v.is_finite() && b.is_finite()) || b > 0.125 {
        return false;
    }
    let widen = F32_ROUNDING * (1.0 + v.abs() + b);
    let (lo, hi) = (v - b - widen, v + b + widen);
    let clear = |level: f64| !(lo <= level && level <= hi);
    let class = || clear(super::INSIDE_LEVEL);
    let margins = || clear(0.5 - THIN_PART_MARGIN) && clear(0.5 + THIN_PART_MARGIN);
    // Integers and half-integers near the interval (it is less than ¼ + 2·widen wide).
    let integrality = || {
        let first = lo.floor() - 1.0;
        (0..4).all(|k| {
            let n = first + f64::from(k);
            clear(n - INTEGRAL_W_SLACK) && clear(n + INTEGRAL_W_SLACK) && clear(n + 0.5)
        })
    };
    match comparisons {
        Comparisons::Class => class(),
        Comparisons::ThinPart => margins(),
        Comparisons::Integrality => integrality(),
        Comparisons::ClassAndMargin => class() && margins(),
    }
}

/// Values of `w` at `points` on which every comparison of `comparisons` is decided as on the
/// field's own values ([`decides`]): a first pass within [`SCREENING_TOLERANCE`], then the
/// field at the points whose interval holds one of their levels. Where the first pass's bound
/// is 0 (every evaluator but the exact one, and the exact one on an input whose boundary is too
/// short for a hierarchy), nothing is evaluated twice.
pub fn decisive_values<E: Evaluator + ?Sized>(
    evaluator: &E,
    points: &[[f64; 3]],
    comparisons: Comparisons,
) -> Vec<f64> {
    values_with_bounds(evaluator, points, comparisons)
        .into_iter()
        .map(|(v, _)| v)
        .collect()
}

/// [`decisive_values`] for corners the octree classifies ([`Comparisons::ClassAndMargin`]),
/// each with whether its value also decides [`Comparisons::Integrality`] (the field's own, or
/// a first-pass interval clear of those levels). A caller that reads the integrality of a
/// corner without the flag asks the field for it first, so every decision is still the
/// field's: on inputs with long signed boundaries most first-pass intervals next to the surface
/// hold an integer's slack (a bunny with a tenth of its faces flipped sent 222k of 479k corners
/// back to the field for it, docs/benchmarks.md), and the planar levels and lent transitions
/// read the integrality of few of them.
pub fn decisive_corner_values<E: Evaluator + ?Sized>(
    evaluator: &E,
    points: &[[f64; 3]],
) -> Vec<(f64, bool)> {
    values_with_bounds(evaluator, points, Comparisons::ClassAndMargin)
        .into_iter()
        .map(|(v, b)| (v, decides(v, b, Comparisons::Integrality)))
        .collect()
}

/// The first pass, then the field where an interval holds a level of `comparisons`: values
/// with their bounds (0 for the field's own).
fn values_with_bounds<E: Evaluator + ?Sized>(
    evaluator: &E,
    points: &[[f64; 3]],
    comparisons: Comparisons,
) -> Vec<(f64, f64)> {
    let mut values = evaluator.eval_batch_within(points, SCREENING_TOLERANCE);
    let again: Vec<usize> = (0..points.len())
        .filter(|&i| !decides(values[i].0, values[i].1, comparisons))
        .collect();
    if again.is_empty() {
        return values;
    }
    let exact = evaluator.eval_batch(&again.iter().map(|&i| points[i]).collect::<Vec<_>>());
    for (&i, w) in again.iter().zip(exact) {
        values[i] = (w, 0.0);
    }
    values
}

/// [`decisive_corner_values`] at the sample points of `spec`, in its storage order. The points
/// go to the evaluator column by column along its [`crate::grid::column_axis`], so the exact
/// evaluator still shares one ray per column ([`crate::eval::antipodal::WindingNumber::eval_batch`]).
pub fn decisive_grid_values<E: Evaluator + ?Sized>(
    evaluator: &E,
    spec: &GridSpec,
) -> Vec<(f64, bool)> {
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
    let values = decisive_corner_values(evaluator, &points);
    let mut out = vec![(f64::NAN, true); spec.len()];
    for (&[i, j, k], w) in order.iter().zip(values) {
        out[spec.index(i, j, k)] = w;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use Comparisons::{Class, ClassAndMargin, Integrality, ThinPart};

    /// Every level at once: the class, margins and integrality.
    fn decides_all(v: f64, b: f64) -> bool {
        decides(v, b, ClassAndMargin) && decides(v, b, Integrality)
    }

    #[test]
    fn an_interval_decides_only_away_from_every_level() {
        assert!(decides_all(0.9, 0.01) && decides_all(0.1, 0.01) && decides_all(0.35, 0.05));
        assert!(decides_all(f64::NAN, 0.0) && decides_all(0.5, 0.0));
        // The class, the thin-part margin, integrality and rounding.
        assert!(!decides_all(0.5, 0.01) && !decides_all(0.52, 0.03));
        assert!(!decides_all(0.76, 0.02) && !decides_all(0.24, 0.02));
        assert!(!decides_all(1.0, 0.01) && !decides_all(0.998, 0.001));
        assert!(!decides_all(-2.0, 0.01));
        assert!(!decides_all(1.49, 0.02) && !decides_all(-0.51, 0.02));
        // An f32 level's worth of room.
        assert!(!decides(0.5 + 1e-9 + 0.01 + 1e-7, 0.01, Class));
        for c in [Class, ThinPart, Integrality, ClassAndMargin] {
            assert!(!decides(f64::NAN, 0.01, c) && !decides(0.9, f64::INFINITY, c));
            assert!(!decides(0.9, 0.2, c));
        }
    }

    #[test]
    fn each_caller_is_held_only_to_its_own_levels() {
        // Next to a consistent surface: an integer decides the class and the margin.
        assert!(decides(1.0, 0.01, Class) && decides(1.0, 0.01, ThinPart));
        assert!(decides(1.0, 0.01, ClassAndMargin) && !decides(1.0, 0.01, Integrality));
        // Next to a flipped face: ½ decides the margin and integrality, not the class.
        assert!(!decides(0.5, 0.01, Class) && decides(0.5, 0.01, ThinPart));
        assert!(!decides(0.5, 0.01, ClassAndMargin));
        // Rounding's step is a level of integrality; the class alone is not.
        assert!(!decides(0.5, 0.01, Integrality) && decides(0.4, 0.01, Integrality));
        // The margin.
        assert!(decides(0.75, 0.01, Class) && !decides(0.75, 0.01, ThinPart));
        assert!(decides(0.25, 0.01, Integrality) && !decides(0.25, 0.01, ClassAndMargin));
    }

    /// Every comparison each caller makes, on a value and on every point of the interval: an
    /// interval that decides for a caller must make all of that caller's comparisons as each
    /// of its points would.
    #[test]
    fn a_deciding_interval_makes_its_callers_comparisons_of_its_points() {
        use super::super::octree::shows_hidden_part;
        fn class(w: f64) -> Vec<bool> {
            vec![super::super::inside(w)]
        }
        fn thin_part(w: f64) -> Vec<bool> {
            vec![
                shows_hidden_part(w, true, THIN_PART_MARGIN),
                shows_hidden_part(w, false, THIN_PART_MARGIN),
            ]
        }
        fn integrality(w: f64) -> Vec<bool> {
            let n = w.round();
            vec![
                (w - n).abs() <= INTEGRAL_W_SLACK,
                n == 0.0,
                n == 1.0,
                n == -1.0,
            ]
        }
        // The octree stores corner values as `f32` and reads the class and margin of those.
        fn class_and_margin(w: f64) -> Vec<bool> {
            let f = f64::from(w as f32);
            let margin = |w: f64| (w - 0.5).abs() >= THIN_PART_MARGIN;
            [class(w), class(f), thin_part(w), thin_part(f)]
                .concat()
                .into_iter()
                .chain([margin(w), margin(f)])
                .collect()
        }
        type Reads = fn(f64) -> Vec<bool>;
        let callers: [(Comparisons, Reads); 4] = [
            (Class, class),
            (ThinPart, thin_part),
            (Integrality, |w| {
                // The flatness probe reads its `f64` values; the corners' flag their `f32` ones.
                [integrality(w), integrality(f64::from(w as f32))].concat()
            }),
            (ClassAndMargin, class_and_margin),
        ];
        for (comparisons, reads) in callers {
            let mut rng = crate::base::splitmix::SplitMix64(7);
            let mut next = || rng.unit();
            let mut decided = 0;
            for _ in 0..200_000 {
                let v = -2.0 + 5.0 * next();
                let b = 0.05 * next() * next();
                if !decides(v, b, comparisons) {
                    continue;
                }
                decided += 1;
                let at = reads(v);
                for t in [-1.0, -0.5, 0.0, 0.5, 1.0] {
                    assert_eq!(reads(v + t * b), at, "{comparisons:?}: v {v} b {b} t {t}");
                }
            }
            assert!(decided > 100_000, "{comparisons:?}: {decided}");
        }
    }
}
