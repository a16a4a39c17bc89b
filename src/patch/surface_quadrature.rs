//! The direct surface integral `w(q) = (1/4π) ∫ (S − q)·(∂S/∂t × ∂S/∂s) / |S − q|³ ds dt` over
//! every patch, by adaptive tensor Gauss–Kronrod 7/15 on parameter rectangles. The baseline the
//! boundary method is compared with (the paper's "surface AQ"); it needs no boundary, no ray and
//! no classification, but `225` surface evaluations per rectangle.

use crate::kernel::spherical::FOUR_PI;

use super::model::{Patch, PatchSet};
use super::quadrature::{XG_INDEX, gauss_kronrod_nodes};
use crate::base::compensated::NeumaierSum;

/// Rectangle subdivision depth limit (a `2^-24` rectangle is far below any useful tolerance).
const MAX_DEPTH: u32 = 24;

/// `w(q)` and the summed error estimate, to absolute tolerance `tol` per patch.
pub fn winding_number_surface_quadrature(set: &PatchSet, q: [f64; 3], tol: f64) -> (f64, f64) {
    let mut sum = NeumaierSum::new();
    let mut err = 0.0;
    for p in set.patches() {
        let (v, e) = patch_integral(p, q, tol * FOUR_PI);
        sum.add(v);
        err += e;
    }
    (sum.value() / FOUR_PI, err / FOUR_PI)
}

fn density(p: &Patch, q: [f64; 3], s: f64, t: f64) -> f64 {
    let (x, ds, dt) = p.eval_with_partials(s, t);
    let r = [x[0] - q[0], x[1] - q[1], x[2] - q[2]];
    let n = [
        dt[1] * ds[2] - dt[2] * ds[1],
        dt[2] * ds[0] - dt[0] * ds[2],
        dt[0] * ds[1] - dt[1] * ds[0],
    ];
    let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    if r2 == 0.0 {
        return 0.0;
    }
    (r[0] * n[0] + r[1] * n[1] + r[2] * n[2]) / (r2 * r2.sqrt())
}

fn patch_integral(p: &Patch, q: [f64; 3], tol: f64) -> (f64, f64) {
    let (nodes, wk, wg) = gauss_kronrod_nodes();
    let mut sum = NeumaierSum::new();
    let mut err = 0.0;
    let mut stack = vec![(0.0, 1.0, 0.0, 1.0, 0u32)];
    while let Some((s0, s1, t0, t1, depth)) = stack.pop() {
        let (hs, ht) = (0.5 * (s1 - s0), 0.5 * (t1 - t0));
        let (cs, ct) = (0.5 * (s0 + s1), 0.5 * (t0 + t1));
        let mut k = 0.0;
        let mut g = 0.0;
        let mut kabs = 0.0;
        for (a, &xa) in nodes.iter().enumerate() {
            for (b, &xb) in nodes.iter().enumerate() {
                let f = density(p, q, cs + hs * xa, ct + ht * xb);
                k += wk[a] * wk[b] * f;
                kabs += wk[a] * wk[b] * f.abs();
                if let (Some(ga), Some(gb)) = (XG_INDEX[a], XG_INDEX[b]) {
                    g += wg[ga] * wg[gb] * f;
                }
            }
        }
        let (k, g) = (k * hs * ht, g * hs * ht);
        let e = (k - g).abs();
        // Below 50 ε ∫|f| the difference is rounding, which splitting cannot reduce.
        let floor = 50.0 * f64::EPSILON * kabs * hs * ht;
        if e <= (tol * (4.0 * hs * ht)).max(floor) || depth >= MAX_DEPTH || !e.is_finite() {
            sum.add(k);
            err += e;
        } else {
            let (ms, mt) = (cs, ct);
            stack.push((s0, ms, t0, mt, depth + 1));
            stack.push((ms, s1, t0, mt, depth + 1));
            stack.push((s0, ms, mt, t1, depth + 1));
            stack.push((ms, s1, mt, t1, depth + 1));
        }
    }
    (sum.value(), err)
}

/// Winding numbers at many points (parallel).
pub fn winding_number_surface_quadrature_batch(
    set: &PatchSet,
    points: &[[f64; 3]],
    tol: f64,
) -> Vec<f64> {
    use rayon::prelude::*;
    points
        .par_iter()
        .map(|&q| winding_number_surface_quadrature(set, q, tol).0)
        .collect()
}

/// The surface integral as an [`Evaluator`](crate::eval::Evaluator) (the direct method on patch
/// sets): absolute tolerance `tolerance` on `w` per patch, no gradient.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceQuadrature<'s> {
    set: &'s PatchSet,
    tolerance: f64,
}

impl<'s> SurfaceQuadrature<'s> {
    /// The surface integral over `set` to `tolerance` per patch.
    pub fn new(set: &'s PatchSet, tolerance: f64) -> Self {
        SurfaceQuadrature { set, tolerance }
    }
}

impl crate::eval::Evaluator for SurfaceQuadrature<'_> {
    fn eval(&self, q: [f64; 3]) -> f64 {
        winding_number_surface_quadrature(self.set, q, self.tolerance).0
    }
    fn name(&self) -> &'static str {
        "direct (patches)"
    }
    fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        winding_number_surface_quadrature_batch(self.set, points, self.tolerance)
    }
}
