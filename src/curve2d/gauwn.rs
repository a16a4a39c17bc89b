//! The Gaussian-smoothed winding number `W_σ(q) = ∫ w(x) G(x − q; σ²I) dx` of a polygon, and its
//! derivatives, in closed form (Sun et al. 2024, Sections 3.1–3.2 and Supplementary B–C).
//!
//! **Value** (Lemma 3.1, Eq. 3–6; Supp. Eq. 8–12). With `F_q = [g(y − q_y) Φ(x − q_x), 0]`,
//! `W = Σ_edges ∫ F_x dy`. For the directed edge `p₀ → p₁` with `Δy ≠ 0`, substituting
//! `z = (y − q_y)/σ` turns the edge integral into `∫_{z₀}^{z₁} φ(z) Φ(a + bz) dz` with `b = Δx/Δy`,
//! and Owen's 10,010.1 (Supp. Eq. 9) gives
//!
//! `c = BvN(A, z₁; ρ) − BvN(A, z₀; ρ)`, `z_i = (p_i.y − q_y)/σ`, `ρ = −sgn(Δy)·Δx/ℓ`,
//! `√(1 − ρ²) = |Δy|/ℓ`, `A = sgn(Δy)·((p₀ − q) × (p₁ − p₀))/(σℓ)` (the signed distance from `q`
//! to the edge's line over σ), `ℓ = |p₁ − p₀|`.
//!
//! This is the paper's `Δy·O''_σ` rewritten with quantities that stay finite for every edge:
//! horizontal edges (`Δy = 0`) contribute exactly 0, vertical ones (`ρ = 0`) give
//! `Φ(A)(Φ(z₁) − Φ(z₀))`, and nearly horizontal ones pass `√(1 − ρ²) = |Δy|/ℓ` to the BvN exactly
//! (no clamping of ρ).
//!
//! **Vertex gradient** (Eq. 12, Supp. Eq. 19). Moving an edge to its right (outwards for a
//! counter-clockwise loop) by `δ(x)` adds `∫ G ⟨δ, n⟩ ds`, `n = (Δy, −Δx)/ℓ`; with `δ` linear along
//! the edge and `G = g(d; σ²) g(s − μ; σ²)` (radial symmetry + separability; `d` the distance from
//! `q` to the line, `μ` the projection of `q − p₀` on the edge), with `I₀ = ∫₀^ℓ g(s − μ) ds` and
//! `I₁ = ∫₀^ℓ s g(s − μ) ds = σ²(g(−μ) − g(ℓ − μ)) + μ I₀` (Supp. Eq. 17–18):
//!
//! `∂W/∂p₁ += g(d) I₁/ℓ · n`, `∂W/∂p₀ += g(d) (ℓI₀ − I₁)/ℓ · n`.
//!
//! **Spatial gradient** (Eq. 7): `∇_q W = −Σ_i ∂W/∂v_i = −Σ_edges g(d) I₀ n`. Only `exp` and
//! `erfc` are needed for both gradients.

use super::bvn::{BvnMethod, norm_cdf, norm_cdf_diff, norm_pdf};
use super::polygon::{Point, Polygon};

/// Parameters of the smoothed winding number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GauWn {
    /// Standard deviation σ of the Gaussian kernel (> 0).
    pub sigma: f64,
    /// The bivariate normal back end used for the value.
    pub bvn: BvnMethod,
}

impl GauWn {
    /// σ with the precise BvN back end.
    pub fn new(sigma: f64) -> Self {
        assert!(sigma > 0.0 && sigma.is_finite(), "sigma must be positive");
        GauWn {
            sigma,
            bvn: BvnMethod::Precise,
        }
    }

    /// The same with another BvN back end.
    pub fn with_bvn(self, bvn: BvnMethod) -> Self {
        GauWn { bvn, ..self }
    }

    /// The contribution `∫_{p₀→p₁} ⟨F_q, n⟩ ds` of one directed edge.
    pub fn segment_value(&self, p0: Point, p1: Point, q: Point) -> f64 {
        let dy = p1[1] - p0[1];
        if dy == 0.0 {
            return 0.0;
        }
        let dx = p1[0] - p0[0];
        let sig = self.sigma;
        let z0 = (p0[1] - q[1]) / sig;
        let z1 = (p1[1] - q[1]) / sig;
        let l = dx.hypot(dy);
        let sg = dy.signum();
        let cross = (p0[0] - q[0]) * dy - (p0[1] - q[1]) * dx;
        let a = sg * cross / (sig * l);
        if dx == 0.0 {
            return norm_cdf(a) * norm_cdf_diff(z0, z1);
        }
        let rho = -sg * dx / l;
        let s = dy.abs() / l;
        self.bvn.cdf_with_s(a, z1, rho, s) - self.bvn.cdf_with_s(a, z0, rho, s)
    }

    /// `W_σ(q)` by summing every edge (brute force, `O(n)`).
    pub fn value(&self, poly: &Polygon, q: Point) -> f64 {
        let p = poly.points();
        let mut sum = Neumaier::default();
        for (i, j) in poly.edges() {
            sum.add(self.segment_value(p[i], p[j], q));
        }
        sum.value()
    }

    /// `(∂c/∂p₀, ∂c/∂p₁)` for the edge `p₀ → p₁` (zero for a zero-length edge).
    pub fn segment_vertex_gradients(&self, p0: Point, p1: Point, q: Point) -> (Point, Point) {
        let (dx, dy) = (p1[0] - p0[0], p1[1] - p0[1]);
        let l = dx.hypot(dy);
        if l == 0.0 {
            return ([0.0; 2], [0.0; 2]);
        }
        let sig = self.sigma;
        let (tx, ty) = (dx / l, dy / l);
        let (rx, ry) = (q[0] - p0[0], q[1] - p0[1]);
        let mu = rx * tx + ry * ty;
        let d = tx * ry - ty * rx;
        let gd = norm_pdf(d / sig) / sig;
        if gd == 0.0 {
            return ([0.0; 2], [0.0; 2]);
        }
        let i0 = norm_cdf_diff(-mu / sig, (l - mu) / sig);
        // σ² g(x; σ²) = σ φ(x/σ).
        let e0 = sig * norm_pdf(mu / sig);
        let e1 = sig * norm_pdf((l - mu) / sig);
        let i1 = e0 - e1 + mu * i0; // ∫₀^ℓ s g(s − μ) ds
        let j1 = e1 - e0 + (l - mu) * i0; // ∫₀^ℓ (ℓ − s) g(s − μ) ds
        let n = [ty, -tx];
        let w0 = gd * j1 / l;
        let w1 = gd * i1 / l;
        ([w0 * n[0], w0 * n[1]], [w1 * n[0], w1 * n[1]])
    }

    /// `−∂c/∂q` contribution of one edge, i.e. its share of `∇_q W` is the negation of the sum of
    /// its two vertex gradients: `−g(d) I₀ n`.
    pub fn segment_spatial_gradient(&self, p0: Point, p1: Point, q: Point) -> Point {
        let (dx, dy) = (p1[0] - p0[0], p1[1] - p0[1]);
        let l = dx.hypot(dy);
        if l == 0.0 {
            return [0.0; 2];
        }
        let sig = self.sigma;
        let (tx, ty) = (dx / l, dy / l);
        let (rx, ry) = (q[0] - p0[0], q[1] - p0[1]);
        let mu = rx * tx + ry * ty;
        let d = tx * ry - ty * rx;
        let gd = norm_pdf(d / sig) / sig;
        let i0 = norm_cdf_diff(-mu / sig, (l - mu) / sig);
        let w = -gd * i0;
        [w * ty, -w * tx]
    }

    /// `∇_q W_σ(q)` (brute force).
    pub fn gradient(&self, poly: &Polygon, q: Point) -> Point {
        let p = poly.points();
        let mut g = [0.0; 2];
        for (i, j) in poly.edges() {
            let s = self.segment_spatial_gradient(p[i], p[j], q);
            g[0] += s[0];
            g[1] += s[1];
        }
        g
    }

    /// `∂W_σ(q)/∂v_i` for every vertex (brute force).
    pub fn vertex_gradient(&self, poly: &Polygon, q: Point) -> Vec<Point> {
        let mut out = vec![[0.0; 2]; poly.len()];
        self.add_vertex_gradient(poly, q, 1.0, &mut out);
        out
    }

    /// `out[i] += scale · ∂W_σ(q)/∂v_i` for every vertex (brute force).
    pub fn add_vertex_gradient(&self, poly: &Polygon, q: Point, scale: f64, out: &mut [Point]) {
        let p = poly.points();
        for (i, j) in poly.edges() {
            let (g0, g1) = self.segment_vertex_gradients(p[i], p[j], q);
            out[i][0] += scale * g0[0];
            out[i][1] += scale * g0[1];
            out[j][0] += scale * g1[0];
            out[j][1] += scale * g1[1];
        }
    }
}

/// Neumaier's compensated summation: the crate's one implementation (`crate::base`).
pub(crate) use crate::base::compensated::NeumaierSum as Neumaier;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn horizontal_edges_contribute_zero_and_square_matches_product() {
        let g = GauWn::new(0.3);
        assert_eq!(g.segment_value([0., 1.], [5., 1.], [0.2, 0.7]), 0.0);
        let sq = Polygon::new(vec![vec![[0., 0.], [1., 0.], [1., 1.], [0., 1.]]]).unwrap();
        let q = [0.3, 0.6];
        let exact = norm_cdf_diff(-q[0] / 0.3, (1. - q[0]) / 0.3)
            * norm_cdf_diff(-q[1] / 0.3, (1. - q[1]) / 0.3);
        assert!((g.value(&sq, q) - exact).abs() < 1e-15);
    }
}
