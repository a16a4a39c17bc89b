//! Winding numbers of curved surfaces: sets of tensor-product polynomial and rational Bézier
//! patches (antipodal paper, Section 4.4 and Alg. 2), see `docs/patches.md`. Compiled with the
//! `patch` feature; the file readers (`io`, `step`) also need `io`.
//!
//! - [`model`]: patches and patch sets;
//! - `io` (feature `io`): the `.bpt` reader (Utah teapot format) and the rational `.rbpt` format;
//! - [`boundary`]: the signed boundary (patch edges that no neighbour cancels exactly);
//! - [`curve`]: rational Bézier curves and the two potentials of the solid-angle form;
//! - [`quadrature`]: adaptive Gauss–Kronrod 7/15;
//! - [`samples`]: precomputed quadrature samples of the surface-boundary curves;
//! - [`eval`]: the evaluator [`PatchWindingNumber`];
//! - [`tessellate`]: triangle meshes of patch sets (reference values, products);
//! - [`surface_quadrature`]: the direct surface integral (the benchmark's baseline);
//! - `step` (feature `io`): trimmed B-rep models from STEP files and their evaluator.

// Homogeneous points are `[f64; 4]` updated component by component in de Casteljau loops;
// index loops over `0..4` read more plainly than zipped iterators there.
#![allow(clippy::needless_range_loop)]

pub mod boundary;
pub mod curve;
pub mod eval;
#[cfg(feature = "io")]
pub mod io;
pub mod model;
pub mod quadrature;
mod ray_hits;
pub mod samples;
#[cfg(feature = "io")]
pub mod step;
pub mod surface_quadrature;
pub mod tessellate;

pub use eval::{Evaluation, Options, PatchWindingNumber};

/// A tolerance the patch and STEP evaluators refuse: not a finite positive number (their
/// quadratures cannot meet a tolerance of 0, and NaN or a negative value is a mistake). Before,
/// they silently replaced it by the default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToleranceError(pub f64);

impl std::fmt::Display for ToleranceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "tolerance must be a finite positive number for curved surfaces, got {}",
            self.0
        )
    }
}

impl std::error::Error for ToleranceError {}

impl ToleranceError {
    /// `Ok` for a finite positive tolerance.
    pub fn check(tolerance: f64) -> Result<(), ToleranceError> {
        if tolerance.is_finite() && tolerance > 0.0 {
            Ok(())
        } else {
            Err(ToleranceError(tolerance))
        }
    }
}
#[cfg(feature = "io")]
pub use io::{is_patch_path, load_patches};
pub use model::{Patch, PatchError, PatchSet};
