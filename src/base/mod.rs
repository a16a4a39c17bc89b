//! The ground floor: vocabulary every module may use, importing nothing else from the crate —
//! axis-aligned boxes, `[f64; 3]` vector helpers, compensated summation, non-blocking file
//! reads and the seeded SplitMix64 generator. The kernel, the mesh
//! model and the 2D module all build on it without importing one another.

pub mod bounding_box;
pub mod compensated;
#[cfg(any(feature = "io", feature = "curve2d"))]
pub(crate) mod file;
#[cfg(any(feature = "testing-kit", feature = "products"))]
pub mod splitmix;
pub mod vec3;
