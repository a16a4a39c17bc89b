//! [`Evaluator`]: the one interface every winding-number evaluator implements, so that grids and
//! products (slices, voxel grids, signed distance, tet filtering, face classification) are
//! written once and run with any method: exact, direct, fast (triangle soups) or fast (oriented
//! point clouds).
//!
//! ```
//! use gwn::Mesh;
//! use gwn::eval::{Evaluator, antipodal::WindingNumber, direct::DirectWindingNumber};
//! use gwn::eval::fast::FastWindingNumber;
//! let tet = Mesh::from_slices(
//!     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
//!     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
//! )?;
//! let methods: Vec<Box<dyn Evaluator>> = vec![
//!     Box::new(WindingNumber::new(&tet)?),
//!     Box::new(DirectWindingNumber::new(&tet)),
//!     Box::new(FastWindingNumber::new(&tet)),
//! ];
//! for m in &methods {
//!     assert!((m.eval([0.1, 0.1, 0.1]) - 1.0).abs() < 1e-12);
//!     assert!(m.try_gradient([0.1, 0.1, 0.1]).is_ok());
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use rayon::prelude::*;

use super::antipodal::WindingNumber;
use super::direct::{DirectWindingNumber, winding_number_direct, winding_number_gradient_direct};
use super::fast::{FastWindingNumber, PointCloudWindingNumber};

/// The evaluator cannot compute gradients (for any query).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NoGradient {
    /// The evaluator's [`Evaluator::name`].
    pub evaluator: &'static str,
}

impl std::fmt::Display for NoGradient {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the {} evaluator has no gradient", self.evaluator)
    }
}

impl std::error::Error for NoGradient {}

/// Where a segment crosses the evaluator's surface ([`Evaluator::segment_crossings`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceCrossing {
    /// Fraction along the segment, `0 ≤ t ≤ 1`.
    pub t: f64,
    /// The surface's unit normal there (either orientation); zero where it is not known.
    pub normal: [f64; 3],
}

/// A winding-number field `w(q)`, built once and queried from many threads.
///
/// Only [`Evaluator::eval`] is required. The provided methods are the per-point loop
/// ([`Evaluator::eval_batch`], parallel), a column of points along one axis
/// ([`Evaluator::eval_column`]; the exact evaluator specialises it with one ray per column,
/// announced by [`Evaluator::column_axis`]), and the gradient ([`Evaluator::try_gradient`],
/// `Err` for evaluators without one).
pub trait Evaluator: Send + Sync {
    /// Winding number at `q`.
    fn eval(&self, q: [f64; 3]) -> f64;

    /// A short name for messages: `"exact"`, `"direct"`, `"fast"`, `"fast point-cloud"`, ...
    fn name(&self) -> &'static str {
        "custom"
    }

    /// Winding numbers at many points, in parallel (rayon).
    fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        points.par_iter().map(|&q| self.eval(q)).collect()
    }

    /// Winding numbers at many points, each with a bound `b` on its distance from
    /// [`Evaluator::eval`]'s value there: `(v, b)`, `|v − eval(q)| ≤ b`, `b` at most about
    /// `tolerance`. For callers that only compare `w` with levels (the remesher's classes): where
    /// `[v − b, v + b]` holds no level, `v` decides like the value itself. The default is the
    /// values with bound 0; the exact evaluator expands far boundary clusters at `tolerance`
    /// ([`WindingNumber::eval_batch_within`]).
    fn eval_batch_within(&self, points: &[[f64; 3]], tolerance: f64) -> Vec<(f64, f64)> {
        let _ = tolerance;
        self.eval_batch(points)
            .into_iter()
            .map(|w| (w, 0.0))
            .collect()
    }

    /// The world axis (0, 1, 2) along which [`Evaluator::eval_column`] is cheaper than point by
    /// point, if any; grids run their columns along it.
    fn column_axis(&self) -> Option<usize> {
        None
    }

    /// Winding numbers at `q` with coordinate `axis` replaced by each `ts[k]`, in the order of
    /// `ts`. Sequential (grids parallelise over columns); equal to [`Evaluator::eval`] at every
    /// point.
    fn eval_column(&self, q: [f64; 3], axis: usize, ts: &[f64]) -> Vec<f64> {
        ts.iter()
            .map(|&t| {
                let mut p = q;
                p[axis] = t;
                self.eval(p)
            })
            .collect()
    }

    /// Where the segment `a → b` crosses the surface, in order along it, when this evaluator
    /// can find that for much less than evaluating `w` along the segment; `None` (the default)
    /// when it cannot. Proposals, not decisions: a caller that needs the class change
    /// (the remesher's vertex placement) verifies each with evaluations of `w` on either side,
    /// so a crossing missed or misplaced costs evaluations, never a wrong answer. The trimmed
    /// B-rep evaluator answers with its ray-surface hits inside the faces' loops, the Bézier
    /// patch set evaluator with the same hit search on its patches.
    fn segment_crossings(&self, a: [f64; 3], b: [f64; 3]) -> Option<Vec<SurfaceCrossing>> {
        let _ = (a, b);
        None
    }
    /// Gradient `∇w(q)`, or `Err` when this evaluator has no gradient (the answer does not
    /// depend on `q`).
    fn try_gradient(&self, q: [f64; 3]) -> Result<[f64; 3], NoGradient> {
        let _ = q;
        Err(NoGradient {
            evaluator: self.name(),
        })
    }

    /// [`Evaluator::try_gradient`] at many points, in parallel.
    fn try_gradient_batch(&self, points: &[[f64; 3]]) -> Result<Vec<[f64; 3]>, NoGradient> {
        points.par_iter().map(|&q| self.try_gradient(q)).collect()
    }
}

/// References and boxes of an evaluator are evaluators (every method forwarded, so overrides such
/// as the exact evaluator's ray-reuse column are kept).
macro_rules! forward_evaluator {
    ($($ty:ty),*) => {$(
        impl<E: Evaluator + ?Sized> Evaluator for $ty {
            fn eval(&self, q: [f64; 3]) -> f64 {
                (**self).eval(q)
            }
            fn name(&self) -> &'static str {
                (**self).name()
            }
            fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
                (**self).eval_batch(points)
            }
            fn eval_batch_within(&self, points: &[[f64; 3]], tolerance: f64) -> Vec<(f64, f64)> {
                (**self).eval_batch_within(points, tolerance)
            }
            fn column_axis(&self) -> Option<usize> {
                (**self).column_axis()
            }
            fn eval_column(&self, q: [f64; 3], axis: usize, ts: &[f64]) -> Vec<f64> {
                (**self).eval_column(q, axis, ts)
            }
            fn segment_crossings(
                &self,
                a: [f64; 3],
                b: [f64; 3],
            ) -> Option<Vec<SurfaceCrossing>> {
                (**self).segment_crossings(a, b)
            }
            fn try_gradient(&self, q: [f64; 3]) -> Result<[f64; 3], NoGradient> {
                (**self).try_gradient(q)
            }
            fn try_gradient_batch(&self, points: &[[f64; 3]]) -> Result<Vec<[f64; 3]>, NoGradient> {
                (**self).try_gradient_batch(points)
            }
        }
    )*};
}

forward_evaluator!(&E, Box<E>);

impl Evaluator for WindingNumber {
    fn eval(&self, q: [f64; 3]) -> f64 {
        WindingNumber::eval(self, q)
    }
    fn name(&self) -> &'static str {
        "exact"
    }
    fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        WindingNumber::eval_batch(self, points)
    }
    fn eval_batch_within(&self, points: &[[f64; 3]], tolerance: f64) -> Vec<(f64, f64)> {
        WindingNumber::eval_batch_within(self, points, tolerance)
    }
    /// The ray's axis: one BVH traversal serves a whole column ([`WindingNumber::eval_column`]).
    fn column_axis(&self) -> Option<usize> {
        Some(self.options().ray.map()[2].0)
    }
    fn eval_column(&self, q: [f64; 3], axis: usize, ts: &[f64]) -> Vec<f64> {
        if Some(axis) == Evaluator::column_axis(self) {
            WindingNumber::eval_column(self, q, ts)
        } else {
            ts.iter()
                .map(|&t| {
                    let mut p = q;
                    p[axis] = t;
                    WindingNumber::eval(self, p)
                })
                .collect()
        }
    }
    fn try_gradient(&self, q: [f64; 3]) -> Result<[f64; 3], NoGradient> {
        Ok(self.gradient(q))
    }
    fn try_gradient_batch(&self, points: &[[f64; 3]]) -> Result<Vec<[f64; 3]>, NoGradient> {
        Ok(self.gradient_batch(points))
    }
}

impl Evaluator for DirectWindingNumber {
    fn eval(&self, q: [f64; 3]) -> f64 {
        winding_number_direct(self.mesh(), q)
    }
    fn name(&self) -> &'static str {
        "direct"
    }
    fn try_gradient(&self, q: [f64; 3]) -> Result<[f64; 3], NoGradient> {
        Ok(winding_number_gradient_direct(self.mesh(), q))
    }
}

impl Evaluator for FastWindingNumber {
    fn eval(&self, q: [f64; 3]) -> f64 {
        FastWindingNumber::eval(self, q)
    }
    fn name(&self) -> &'static str {
        "fast"
    }
    fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        FastWindingNumber::eval_batch(self, points)
    }
    fn try_gradient(&self, q: [f64; 3]) -> Result<[f64; 3], NoGradient> {
        Ok(self.gradient(q))
    }
}

impl Evaluator for PointCloudWindingNumber {
    fn eval(&self, q: [f64; 3]) -> f64 {
        PointCloudWindingNumber::eval(self, q)
    }
    fn name(&self) -> &'static str {
        "fast point-cloud"
    }
    fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        PointCloudWindingNumber::eval_batch(self, points)
    }
    fn try_gradient(&self, q: [f64; 3]) -> Result<[f64; 3], NoGradient> {
        Ok(self.gradient(q))
    }
}
