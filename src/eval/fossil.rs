//! The FOSSIL-style entry point `winding_number(point, beta)`: one object that answers with the
//! fast evaluator or the exact one depending on `beta`. It sits above both evaluators (neither
//! imports the other).

use std::sync::OnceLock;

use crate::eval::antipodal::WindingNumber;
use crate::eval::fast::{FastParams, FastWindingNumber};
use crate::mesh::Mesh;

/// A mesh prepared for FOSSIL-style queries: `winding_number(point, beta)` evaluates with the
/// Barnes–Hut approximation when `beta > 0` and exactly when `beta <= 0` (or NaN).
///
/// `beta` is Barill's accuracy parameter (admissibility `‖q − p̃‖ > β r`, `r` the node radius)
/// with the order-2 expansion, not FOSSIL's diagonal-based one; see the [module
/// docs](crate::eval::fast#choosing-β-fossil-vs-barill) for how the two map. For FOSSIL's own rule use
/// [`FastParams::fossil`] with [`Self::winding_number_with`].
///
/// ```
/// use gwn::{Mesh, eval::fossil::FastOrExact};
/// let tet = Mesh::from_slices(
///     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
///     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
/// )?;
/// let api = FastOrExact::new(&tet);
/// let fast = api.winding_number([0.2, 0.2, 0.2], 2.0);
/// let exact = api.winding_number([0.2, 0.2, 0.2], -1.0);
/// assert!((fast - exact).abs() < 1e-12);
/// # Ok::<(), gwn::error::MeshError>(())
/// ```
#[derive(Clone, Debug)]
pub struct FastOrExact<'m> {
    mesh: &'m Mesh,
    fast: FastWindingNumber,
    /// The exact (Antipodal) evaluator, built on the first `beta <= 0` query.
    exact: OnceLock<Option<WindingNumber>>,
}

impl<'m> FastOrExact<'m> {
    /// Prepares the fast evaluator (tree and moments) for `mesh`.
    pub fn new(mesh: &'m Mesh) -> Self {
        FastOrExact {
            mesh,
            fast: FastWindingNumber::new(mesh),
            exact: OnceLock::new(),
        }
    }

    /// FOSSIL's `surface%winding_number(point, beta)`: `beta > 0` → Barnes–Hut with that β
    /// (order 2); `beta <= 0` or NaN → exact.
    pub fn winding_number(&self, point: [f64; 3], beta: f64) -> f64 {
        if beta > 0.0 {
            self.fast.eval_with(point, FastParams::barill(beta, 2))
        } else {
            self.exact(point)
        }
    }

    /// The fast evaluation with explicit parameters (Barill's `(β, order)` or FOSSIL's rule).
    pub fn winding_number_with(&self, point: [f64; 3], params: FastParams) -> f64 {
        self.fast.eval_with(point, params)
    }

    /// [`Self::winding_number`] for many points, in parallel.
    pub fn winding_number_batch(&self, points: &[[f64; 3]], beta: f64) -> Vec<f64> {
        use rayon::prelude::*;
        if beta > 0.0 {
            self.fast
                .eval_batch_with(points, FastParams::barill(beta, 2))
        } else {
            points.par_iter().map(|&q| self.exact(q)).collect()
        }
    }

    /// The fast evaluator.
    pub fn fast(&self) -> &FastWindingNumber {
        &self.fast
    }

    /// The exact branch (`beta <= 0`).
    ///
    /// Uses the exact Antipodal evaluator, built once on first use. Only if the mesh cannot be
    /// quantized (coordinates whose extent overflows `f64`) does it fall back to the direct sum.
    fn exact(&self, point: [f64; 3]) -> f64 {
        match self
            .exact
            .get_or_init(|| WindingNumber::new(self.mesh).ok())
        {
            Some(wn) => wn.eval(point),
            None => crate::eval::direct::winding_number_direct(self.mesh, point),
        }
    }
}
