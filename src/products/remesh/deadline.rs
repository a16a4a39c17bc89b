//! The remesher's time limit inside evaluations ([`super::RemeshOptions::deadline`]).
//!
//! Next to a long signed boundary (a soup of 100k loose triangles, say) one evaluation of `w`
//! costs hundreds of microseconds, and a single batch (the coarse grid, a round of placement)
//! runs for minutes: a limit checked only between phases and rounds was overrun tenfold
//! (docs/benchmarks.md, "A time limit that holds"). [`Deadlined`] hands the batches to the
//! evaluator in chunks of about [`CHUNK_SECONDS`] of work ([`MIN_CHUNK`] … [`CHUNK`] points)
//! and reads the clock between chunks; past the deadline it
//! answers NaN without evaluating. The remesher reads the clock at the end of every phase and
//! before it returns, so a value answered past the deadline never reaches a surface: a run
//! either ends in time with the surface it would have had, or returns
//! [`super::RemeshError::TimeLimit`]. NaN is the evaluator's own answer for a point it cannot
//! evaluate (a non-finite coordinate), which every caller already takes (outside, not
//! settled), so the rest of a phase runs on without a special case and ends soon.

use std::time::Instant;

use crate::eval::{Evaluator, NoGradient, SurfaceCrossing};

/// Most points per chunk: 4096 evaluations are ~5 ms at a microsecond each (the clock's read
/// is ~25 ns) and ~0.2 s at the slowest ordinary input measured (~100 µs on 2 threads); each
/// chunk is then thousands of points, enough for the evaluator's own parallel split and for
/// its rays shared along columns (a column cut by a chunk's end is two columns: the same
/// values).
pub const CHUNK: usize = 4096;

/// Fewest points per chunk, and the first chunk's size: evaluations can be far slower than
/// the ordinary ones above (a fuzzed STEP model with a radius of 1e308 took up to a second per
/// point, each ray search refused at its work cap), and 4096 of those would overrun a limit by
/// half an hour. The chunks then grow towards [`CHUNK_SECONDS`] of work each.
pub const MIN_CHUNK: usize = 8;

/// The time each chunk aims at: the next chunk's size is the last one's rate times this,
/// within [`MIN_CHUNK`] … [`CHUNK`] (so the overrun past a deadline is about this, or
/// [`MIN_CHUNK`] evaluations when each takes longer).
const CHUNK_SECONDS: f64 = 0.02;

/// An evaluator that stops evaluating at `deadline` (see the module documentation); without a
/// deadline it forwards every call unchanged.
pub struct Deadlined<'a, E: ?Sized> {
    inner: &'a E,
    deadline: Option<Instant>,
}

impl<'a, E: Evaluator + ?Sized> Deadlined<'a, E> {
    /// `inner`, stopped at `deadline`.
    pub fn new(inner: &'a E, deadline: Option<Instant>) -> Deadlined<'a, E> {
        Deadlined { inner, deadline }
    }

    fn past(&self) -> bool {
        self.deadline.is_some_and(|at| Instant::now() > at)
    }

    /// `batch` over `points` chunk by chunk, `missing` for the points left past the deadline.
    fn chunked<T: Clone>(
        &self,
        points: &[[f64; 3]],
        missing: T,
        batch: impl Fn(&[[f64; 3]]) -> Vec<T>,
    ) -> Vec<T> {
        if self.deadline.is_none() {
            return batch(points);
        }
        let mut out = Vec::with_capacity(points.len());
        let mut size = MIN_CHUNK;
        while out.len() < points.len() {
            if self.past() {
                out.resize(points.len(), missing);
                break;
            }
            let chunk = &points[out.len()..(out.len() + size).min(points.len())];
            let start = Instant::now();
            out.extend(batch(chunk));
            let seconds = start.elapsed().as_secs_f64();
            let rate = chunk.len() as f64 / seconds.max(1e-9);
            size = (rate * CHUNK_SECONDS).clamp(MIN_CHUNK as f64, CHUNK as f64) as usize;
        }
        out
    }
}

impl<E: Evaluator + ?Sized> Evaluator for Deadlined<'_, E> {
    fn eval(&self, q: [f64; 3]) -> f64 {
        if self.past() {
            f64::NAN
        } else {
            self.inner.eval(q)
        }
    }
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        self.chunked(points, f64::NAN, |c| self.inner.eval_batch(c))
    }
    fn eval_batch_within(&self, points: &[[f64; 3]], tolerance: f64) -> Vec<(f64, f64)> {
        self.chunked(points, (f64::NAN, 0.0), |c| {
            self.inner.eval_batch_within(c, tolerance)
        })
    }
    fn column_axis(&self) -> Option<usize> {
        self.inner.column_axis()
    }
    fn eval_column(&self, q: [f64; 3], axis: usize, ts: &[f64]) -> Vec<f64> {
        if self.past() {
            vec![f64::NAN; ts.len()]
        } else {
            self.inner.eval_column(q, axis, ts)
        }
    }
    fn segment_crossings(&self, a: [f64; 3], b: [f64; 3]) -> Option<Vec<SurfaceCrossing>> {
        if self.past() {
            None
        } else {
            self.inner.segment_crossings(a, b)
        }
    }
    fn try_gradient(&self, q: [f64; 3]) -> Result<[f64; 3], NoGradient> {
        self.inner.try_gradient(q)
    }
    fn try_gradient_batch(&self, points: &[[f64; 3]]) -> Result<Vec<[f64; 3]>, NoGradient> {
        self.inner.try_gradient_batch(points)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::time::Duration;

    /// Counts its evaluations and takes a while over each.
    struct Slow(AtomicUsize);

    impl Evaluator for Slow {
        fn eval(&self, q: [f64; 3]) -> f64 {
            self.0.fetch_add(1, Ordering::Relaxed);
            std::thread::sleep(Duration::from_micros(50));
            q[0]
        }
    }

    #[test]
    fn a_batch_stops_at_the_deadline_and_answers_nan_for_the_rest() {
        let slow = Slow(AtomicUsize::new(0));
        let points: Vec<[f64; 3]> = (0..40 * CHUNK).map(|i| [i as f64, 0.0, 0.0]).collect();
        let start = Instant::now();
        let stopped = Deadlined::new(&slow, Some(start + Duration::from_millis(100)));
        let w = stopped.eval_batch(&points);
        // 40 chunks take ~4 s on 2 threads; the deadline stops them within a chunk of it.
        assert!(
            start.elapsed() < Duration::from_secs(2),
            "{:?}",
            start.elapsed()
        );
        let evaluated = slow.0.load(Ordering::Relaxed);
        assert!(
            evaluated >= MIN_CHUNK && evaluated < points.len(),
            "{evaluated}"
        );
        let first_nan = w.iter().position(|x| x.is_nan()).unwrap();
        assert_eq!(first_nan, evaluated);
        assert_eq!(w.len(), points.len());
        // The values before the deadline are the evaluator's, every later one NaN.
        assert!(w[..first_nan].iter().zip(&points).all(|(x, p)| *x == p[0]));
        assert!(w[first_nan..].iter().all(|x| x.is_nan()));
        assert!(stopped.eval([1.0, 0.0, 0.0]).is_nan());
        assert!(
            stopped
                .eval_column([0.0; 3], 0, &[1.0, 2.0])
                .iter()
                .all(|x| x.is_nan())
        );
    }

    #[test]
    fn without_a_deadline_or_before_it_every_value_is_the_evaluators() {
        let slow = Slow(AtomicUsize::new(0));
        let points: Vec<[f64; 3]> = (0..2 * CHUNK + 5).map(|i| [i as f64, 1.0, 0.0]).collect();
        let far = Some(Instant::now() + Duration::from_secs(3600));
        for deadline in [None, far] {
            let w = Deadlined::new(&slow, deadline).eval_batch_within(&points, 0.1);
            assert!(w.iter().zip(&points).all(|(x, p)| *x == (p[0], 0.0)));
        }
    }

    /// Evaluations of a second each (a hostile curved input at its work caps): the first chunk
    /// is [`MIN_CHUNK`] points, so a limit of 0.1 s is overrun by one chunk of them, not by
    /// [`CHUNK`] seconds.
    #[test]
    fn very_slow_evaluations_overrun_by_a_small_chunk() {
        struct VerySlow(AtomicUsize);
        impl Evaluator for VerySlow {
            fn eval(&self, q: [f64; 3]) -> f64 {
                self.0.fetch_add(1, Ordering::Relaxed);
                std::thread::sleep(Duration::from_millis(200));
                q[0]
            }
        }
        let slow = VerySlow(AtomicUsize::new(0));
        let points: Vec<[f64; 3]> = (0..CHUNK).map(|i| [i as f64, 0.0, 0.0]).collect();
        let start = Instant::now();
        let w = Deadlined::new(&slow, Some(start + Duration::from_millis(100))).eval_batch(&points);
        let evaluated = slow.0.load(Ordering::Relaxed);
        assert_eq!(evaluated, MIN_CHUNK);
        assert!(w[MIN_CHUNK..].iter().all(|x| x.is_nan()));
        // 8 points of 0.2 s on at least one thread: 1.6 s at most (before: 4096 of them).
        assert!(
            start.elapsed() < Duration::from_secs(3),
            "{:?}",
            start.elapsed()
        );
    }
}
