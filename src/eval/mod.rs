//! Evaluators of the winding number. Each offers `eval(q)` and `eval_batch(points)` (parallel).
//!
//! - [`antipodal`]: the exact Antipodal method (default);
//! - [`direct`]: the solid-angle sum over all triangles (ground truth, `O(F)`);

pub mod antipodal;
pub mod direct;
pub mod fast;
