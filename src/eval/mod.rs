//! Evaluators of the winding number, all behind one interface, [`Evaluator`]:
//!
//! - [`antipodal`]: the exact Antipodal method (default), `O(B + log F)` per query;
//! - [`direct`]: the solid-angle sum over all triangles (ground truth, `O(F)`);
//! - [`fast`]: Barnes–Hut approximations for triangle soups and oriented point clouds;
//! - [`fossil`]: FOSSIL's `winding_number(point, beta)`, fast for `beta > 0`, exact otherwise.

pub mod antipodal;
pub mod direct;
mod evaluator;
pub mod fast;
pub mod fossil;
pub mod parity;

pub use evaluator::{Evaluator, NoGradient, SurfaceCrossing};

/// How many times, since the process started, an input predicate of the exact evaluator could
/// not be decided by its `f64` filter and ran in exact big-integer arithmetic (`gwn bench`
/// reports it per mesh).
pub fn exact_fallbacks() -> u64 {
    crate::kernel::input_predicates::exact_fallbacks()
}
