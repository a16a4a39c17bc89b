//! # gwn — robust generalized winding numbers
//!
//! The generalized winding number `w(q)` of a triangle mesh counts how many times the surface
//! wraps around `q`: 1 inside a closed outward-oriented surface, 0 outside, 2 where two shells
//! overlap, and a smooth fraction near holes of an open, dirty mesh.
//!
//! Evaluators:
//! - [`eval::direct`]: the Van Oosterom–Strackee solid-angle sum with compensated accumulation
//!   (ground truth, `O(F)` per query);
//! - [`eval::antipodal`]: the exact Antipodal method: `w = χ + (1/4π) Σ_boundary area`, with the
//!   crossing count χ of one axis-aligned ray and the atan2 branch decided by one symbolically
//!   perturbed integer predicate (the crate's exact kernel, private to it), `O(B + log F)` per
//!   query.
//!
//! The front door: [`spec::EvaluatorSpec`] describes an evaluator (method, ray, precision,
//! tolerance, β, order), checks it by the rules the CLI and the Python package share, and builds
//! it for any [`input::Input`] (mesh, oriented point cloud, patch set, STEP model), which
//! `input::load_input` reads from a file (feature `io`).
//!
//! ```
//! use gwn::{Mesh, eval::direct::winding_number_direct};
//! let tet = Mesh::from_slices(
//!     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
//!     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
//! )?;
//! let w = winding_number_direct(&tet, [0.1, 0.1, 0.1]);
//! assert!((w - 1.0).abs() < 1e-12);
//! # Ok::<(), gwn::error::MeshError>(())
//! ```

// `deny`, not `forbid`: the one exception is the runtime-checked AVX2 dispatch of the boundary
// loop (`kernel::boundary_sum`), justified by a benchmark and tested bit-identical to the portable loop.
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub(crate) mod base;
pub(crate) mod bvh;
#[cfg(feature = "curve2d")]
pub mod curve2d;
pub mod error;
pub mod eval;
pub mod grid;
pub mod input;
#[cfg(feature = "io")]
pub mod io;
pub(crate) mod kernel;
pub mod mesh;
mod one_shot;
#[cfg(feature = "patch")]
pub mod patch;
#[cfg(feature = "products")]
pub mod products;
pub mod spec;
#[cfg(feature = "testing-kit")]
pub mod testing;

pub use base::bounding_box::BoundingBox;
pub use kernel::frame::RayAxis;
pub use kernel::quantize::Precision;
pub use mesh::Mesh;
pub use one_shot::{Position, TriangleIndices, WindingNumberError, winding_number};

/// The README's library example, compiled and run as a doctest.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
