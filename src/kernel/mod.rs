//! The exact kernel. Nothing outside this module computes a predicate or chooses an `atan2`
//! branch.
//!
//! - [`quantize`]: the fixed-point grid (power-of-two cell size, exact power-of-two rescaling),
//!   exact snapping with residuals, and the query clamp;
//! - [`frame`]: the ray frames (the six axis directions as proper rotations);
//! - [`predicates`]: the symbolically perturbed orientation sign shared by the ray–triangle test
//!   and the atan2 branch, and the perturbed depth test (filter + exact fallback), also at
//!   queries off the lattice;
//! - [`input_predicates`]: the same predicates, same perturbation, on vertices and queries that
//!   are not on the lattice (input bits the lattice cannot hold): `f64` filters whose bounds
//!   include every rounding, then exact dyadic arithmetic (`dyadic`);
//! - [`exact_index`]: the exact query: a mesh quantized in one ray frame beside its ray BVH,
//!   answering χ and the boundary sum (per-point snap and clamp, crossings, columns);
//! - [`spherical`]: the solid-angle and spherical-triangle formulas;
//! - [`angle_sum`]: sums of many `atan2` terms as one complex product with turn counting;
//! - [`boundary_sum`]: the SIMD loop over the boundary edges of the Antipodal formula;
//! - [`boundary_column`]: the same loop for a column of queries (shared `x, y` work);
//! - [`boundary_tree`]: the certified hierarchy over the boundary chains (far nodes expanded);
//! - [`boundary_multipole`]: the far-field expansion of a boundary cluster and its error bound;
//! - [`double_double`]: the extended precision of ill-conditioned near-edge terms.

pub mod angle_sum;
pub mod boundary_column;
pub mod boundary_multipole;
pub mod boundary_sum;
pub mod boundary_tree;
pub mod double_double;
mod dyadic;
pub mod exact_index;
pub mod frame;
pub mod input_predicates;
mod lanes;
pub mod predicates;
// `Grid::in_grid_space(&self)` on a `Copy` type: clippy asks for it only now that the kernel is
// private to the crate (it leaves public API alone); quantize.rs is left to the exact-query move.
#[allow(clippy::wrong_self_convention)]
pub mod quantize;
pub mod spherical;
#[cfg(test)]
mod test_rng;
