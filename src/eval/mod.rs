//! Evaluators of the winding number. Each offers `eval(q)` and `eval_batch(points)` (parallel).
//!
//! - [`direct`]: the solid-angle sum over all triangles (ground truth, `O(F)`);

pub mod direct;
