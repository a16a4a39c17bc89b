//! 2D curves: polygons with the exact plain winding number, and GauWN, the Gaussian-smoothed
//! winding number of Sun et al. (SIGGRAPH Asia 2024) with its closed-form derivatives, a
//! closed-curve BVH, and the curve applications (untangling, offsetting, in-out brush).
//!
//! ```
//! use gwn::curve2d::{Polygon, GauWn};
//! let square = Polygon::new(vec![vec![[0., 0.], [1., 0.], [1., 1.], [0., 1.]]])?;
//! assert_eq!(square.winding_number([0.5, 0.5]), 1);
//! let w = GauWn::new(0.05).value(&square, [0.5, 0.5]);
//! assert!((w - 1.0).abs() < 1e-12);
//! # Ok::<(), gwn::curve2d::PolygonError>(())
//! ```

pub mod apps;
pub mod bvh;
pub mod bvn;
pub mod gauwn;
pub mod io;
pub mod open;
pub mod polygon;
pub mod tangled;

pub use bvh::CurveBvh;
pub use bvn::BvnMethod;
pub use gauwn::GauWn;
pub use open::{Curves, CurvesField};
pub use polygon::{Point, Polygon, PolygonError};
