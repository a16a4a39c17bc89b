//! The direct solid-angle sum `w(q) = (1/4π) Σ_f Ω_f(q)` (Van Oosterom–Strackee per triangle,
//! Neumaier-compensated accumulation): the floating-point reference the other evaluators are
//! compared with (libigl's `winding_number`), `--method direct`.
//!
//! Accuracy: each triangle's offsets are exact (double-double), its solid angle is evaluated on
//! unit vectors (any magnitude, 1e-300 to 1e300), in double-double where `f64` is
//! ill-conditioned (query near an edge), and with the edge's exact moment within `2^-40` of its
//! length from its interior; the sign of a triple product within rounding of zero is decided on
//! the exact offsets. So the sum is accurate to ~1e-14 at any distance from the edges (it erred
//! by ≈ 2e-17·E/d before 2026-11, 0.44 at 1e-17 from an edge; and by a sign or more below
//! ~1e-30·E until 2026-12-06). Not an oracle for slivers: a triangle whose three corners are
//! within a tiny angle of one line, seen from near that line, can cancel beyond double-double
//! (docs/robustness.md; the rational oracle is `gwn::testing::exact_winding_number_rational`).
//!
//! On-surface semantics: a triangle whose plane contains the query exactly contributes 0 (the
//! principal value), so the direct sum returns the local solid-angle fraction: 1/2 on a face of
//! a closed mesh, 1/8 at the corner of a cube, 1/4 on its edges. Never NaN for finite input.

use crate::base::vec3::sub;
use rayon::prelude::*;

use crate::base::compensated::NeumaierSum;
use crate::kernel::input_predicates::exact_moment_of_points;
use crate::kernel::spherical::{segment_gradient_with_moment, triangle_solid_angle_at};
use crate::mesh::Mesh;

use crate::kernel::spherical::INV_4PI;

/// Winding number of `mesh` at `q` by the direct sum. `O(F)`.
pub fn winding_number_direct(mesh: &Mesh, q: [f64; 3]) -> f64 {
    let p = mesh.positions();
    let mut sum = NeumaierSum::new();
    for t in mesh.triangles() {
        sum.add(triangle_solid_angle_at(t.map(|i| p[i as usize]), q));
    }
    sum.value() * INV_4PI
}

/// [`winding_number_direct`] for many points, in parallel (rayon).
pub fn winding_number_direct_batch(mesh: &Mesh, points: &[[f64; 3]]) -> Vec<f64> {
    points
        .par_iter()
        .map(|&q| winding_number_direct(mesh, q))
        .collect()
}

/// Gradient `∇w(q)` by the Biot–Savart form: the field of a surface depends only on its boundary,
/// so summing the closed-form segment integral over every triangle edge (interior edges cancel)
/// gives the gradient, with the exact cross product of an edge's offsets next to its interior
/// (`kernel::spherical::segment_gradient_with_moment`). Not finite on the surface's edges.
pub fn winding_number_gradient_direct(mesh: &Mesh, q: [f64; 3]) -> [f64; 3] {
    let p = mesh.positions();
    let mut g = [NeumaierSum::new(); 3];
    for t in mesh.triangles() {
        for (i, j) in [(0, 1), (1, 2), (2, 0)] {
            if t[i] == t[j] {
                continue;
            }
            let (a, b) = (p[t[i] as usize], p[t[j] as usize]);
            // Next to the edge's interior, the exact cross product of its offsets (an interior
            // edge's two directions still cancel exactly: the moment is antisymmetric).
            let s = segment_gradient_with_moment(sub(a, q), sub(b, q), || {
                exact_moment_of_points(q, a, b)
            });
            for k in 0..3 {
                g[k].add(s[k]);
            }
        }
    }
    g.map(|s| s.value() * INV_4PI)
}

/// The direct sum as an [`Evaluator`](crate::eval::Evaluator): owns a copy of the mesh (the sum
/// visits every triangle per query anyway), so it does not borrow it.
#[derive(Clone, Debug)]
pub struct DirectWindingNumber {
    mesh: Mesh,
}

impl DirectWindingNumber {
    /// Wraps a copy of `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        DirectWindingNumber { mesh: mesh.clone() }
    }

    /// The mesh summed over.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }
}
