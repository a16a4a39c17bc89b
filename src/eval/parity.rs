//! Inside by ray parity: for a mesh that is closed but not consistently oriented (flipped
//! faces, shuffled soups, non-orientable or non-manifold closed surfaces), the solid it encloses
//! is the set of points from which a ray crosses the surface an odd number of times.
//!
//! Why it is well defined: a mesh in which every edge has an even number of faces is a cycle
//! mod 2, hence the boundary of a 3-chain mod 2, and a ray from `q` to infinity meets the
//! surface an odd number of times exactly when `q` lies in that chain — whatever the ray and
//! whatever the faces' orientations. The count is the exact evaluator's χ (each crossing
//! counts ±1, and `±1 ≡ 1 mod 2`), decided by the kernel's perturbed predicates at the
//! symbolically perturbed query, so a query on the surface, a ray through an edge or a vertex,
//! and degenerate triangles get one consistent answer. The signed boundary is not summed:
//! each query costs the ray's `O(log F)`, where `w` of a mesh with flipped faces pays for a
//! boundary along every flipped face (and is not the enclosed solid there: `w` of a closed
//! mesh with one face flipped is fractional near it).
//!
//! On a closed, consistently oriented mesh with no nested or overlapping shells the parity is
//! `w` itself; where shells nest (`w = 2`) parity says 0, as the even-odd rule does.
//!
//! ```
//! use gwn::Mesh;
//! use gwn::eval::{Evaluator, parity::CrossingParity};
//! // A tetrahedron with one face flipped: closed, not oriented.
//! let tet = Mesh::from_slices(
//!     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
//!     &[[0, 1, 2], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
//! )?;
//! let inside = CrossingParity::new(&tet)?;
//! assert_eq!(inside.eval([0.1, 0.1, 0.1]), 1.0);
//! assert_eq!(inside.eval([1.0, 1.0, 1.0]), 0.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::Evaluator;
use super::antipodal::{BoundaryBy, BuildError, Options, WindingNumber};
use crate::mesh::{Mesh, boundary_edges, geometric_boundary_edges};

/// The crossing parity of a closed mesh: 1 inside, 0 outside, NaN for a non-finite query.
#[derive(Clone, Debug)]
pub struct CrossingParity {
    crossings: WindingNumber,
}

impl CrossingParity {
    /// Builds it with the exact evaluator's default [`Options`] (60-bit grid, ray `+z`).
    pub fn new(mesh: &Mesh) -> Result<Self, BuildError> {
        Self::with_options(mesh, Options::default())
    }

    /// Builds it with `options`' precision, ray and edge matching ([`Options::tolerance`] has no
    /// use here). [`BuildError::NotClosed`] unless every edge has an even number of faces
    /// (edges matched by position by default, as the exact evaluator matches its boundary).
    pub fn with_options(mesh: &Mesh, options: Options) -> Result<Self, BuildError> {
        let census = EdgeCensus::of(mesh, options.boundary);
        if census.odd_edges > 0 {
            return Err(BuildError::NotClosed {
                odd_edges: census.odd_edges,
            });
        }
        Ok(CrossingParity {
            crossings: WindingNumber::crossings_only(mesh, options)?,
        })
    }

    /// 1 if a ray from `q` crosses the surface an odd number of times, else 0; NaN if `q` is
    /// not finite.
    pub fn eval(&self, q: [f64; 3]) -> f64 {
        parity(self.crossings.eval(q))
    }

    /// [`CrossingParity::eval`] at many points, in parallel (columns along the ray share one
    /// traversal, as the exact evaluator's do).
    pub fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        let mut values = self.crossings.eval_batch(points);
        values.iter_mut().for_each(|v| *v = parity(*v));
        values
    }

    /// The evaluator's options.
    pub fn options(&self) -> Options {
        self.crossings.options()
    }
}

/// What the edges of a mesh say about the parity method: it needs `odd_edges == 0` (closed mod
/// 2); with `signed_boundary_edges > 0` as well the mesh is closed but not consistently
/// oriented, and its `w` is not the solid it encloses (fractional near flipped faces) — the
/// case the parity method is for. Both 0: closed and oriented, `w` is the parity's integer
/// wherever shells do not nest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeCensus {
    /// Edges with an odd number of faces (matched as the evaluators match their boundary).
    pub odd_edges: usize,
    /// Edges of the signed boundary (nonzero net orientation).
    pub signed_boundary_edges: usize,
}

impl EdgeCensus {
    /// The census of `mesh`, edges matched by position ([`BoundaryBy::Position`], the exact
    /// evaluator's default) or by index.
    pub fn of(mesh: &Mesh, by: BoundaryBy) -> EdgeCensus {
        let boundary = match by {
            BoundaryBy::Position => geometric_boundary_edges(mesh),
            BoundaryBy::Index => boundary_edges(mesh),
        };
        EdgeCensus {
            // An edge's signed weight, (forward − backward) faces, has the parity of their sum.
            odd_edges: boundary.iter().filter(|e| e.weight % 2 != 0).count(),
            signed_boundary_edges: boundary.len(),
        }
    }

    /// Closed mod 2 but not oriented: the parity method's case.
    pub fn closed_but_not_oriented(&self) -> bool {
        self.odd_edges == 0 && self.signed_boundary_edges > 0
    }
}

/// The crossing count `chi` (an exact integer as `f64`, or NaN) mod 2.
fn parity(chi: f64) -> f64 {
    chi.rem_euclid(2.0)
}

impl Evaluator for CrossingParity {
    fn eval(&self, q: [f64; 3]) -> f64 {
        CrossingParity::eval(self, q)
    }
    fn name(&self) -> &'static str {
        "parity"
    }
    fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        CrossingParity::eval_batch(self, points)
    }
    fn column_axis(&self) -> Option<usize> {
        Evaluator::column_axis(&self.crossings)
    }
    fn eval_column(&self, q: [f64; 3], axis: usize, ts: &[f64]) -> Vec<f64> {
        let mut values = Evaluator::eval_column(&self.crossings, q, axis, ts);
        values.iter_mut().for_each(|v| *v = parity(*v));
        values
    }
}
