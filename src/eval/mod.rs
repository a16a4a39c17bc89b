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

pub use evaluator::{Evaluator, NoGradient};
