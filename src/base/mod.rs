//! The ground floor: vocabulary every module may use, importing nothing else from the crate —
//! axis-aligned boxes, `[f64; 3]` vector helpers, compensated summation and non-blocking file
//! reads. The kernel, the mesh
//! model and the 2D module all build on it without importing one another.

pub mod bounding_box;
pub mod compensated;
#[cfg(any(feature = "io", feature = "curve2d"))]
pub(crate) mod file;
pub mod vec3;
