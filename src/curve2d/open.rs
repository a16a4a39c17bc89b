//! Open polylines: the generalized winding number `w(q) = (1/2π) Σ ∠(p_i − q, p_{i+1} − q)` of a
//! curve that need not close, and its Gaussian smoothing `W_σ = w ∗ G_σ`, with the same
//! exactness rules as closed loops.
//!
//! **Reduction to closed loops.** An open polyline `p₀ … p_k` equals the closed loop
//! `p₀ … p_k p₀` minus its closing edge `p_k → p₀`, i.e. plus the single segment `p₀ → p_k`. The
//! loop is stored as a loop of the [`Polygon`] (loops are implicitly closed), so
//!
//! `w_open(q) = w_loop(q) + ∠(p₀ − q, p_k − q)/2π`, `W_σ,open(q) = W_σ,loop(q) + S_σ(p₀, p_k; q)`.
//!
//! `w_loop` is the exact integer crossing count of [`Polygon::winding_number`] (perturbed query
//! `q + (ε, ε²)`), and the angle of the one segment is evaluated at the same perturbed query
//! ([`segment_angle`]), so the integer part is exact and only one `atan2` rounds. `W_σ,loop` is
//! the closed-loop value of [`super::GauWn`] / [`CurveBvh`].
//!
//! **One segment, smoothed** ([`segment_smoothed`]). Writing `w` of a segment as the line integral
//! of the 2D Poisson kernel and integrating the Gaussian first (Gauss's law: the field of a unit
//! Gaussian charge at distance `r` is `(1 − e^{−r²/2σ²})/(2πr)`) gives
//! `S_σ = (1/2π) ∫ ⟨n, p − q⟩ (1 − e^{−|p−q|²/2σ²}) / |p − q|² ds`. With `d` the signed distance
//! of `q` to the segment's line, `t₀ < t₁` the segment's ends measured from the foot of `q`,
//! `h = |d|/σ` and `a_i = t_i/|d|`:
//!
//! `S_σ = sgn(d) [U(h, a₁) − U(h, a₀)]`, `U(h, a) = atan(a)/2π − T(h, a)`,
//!
//! where `T` is Owen's T function (`T(h, a) = (1/2π) ∫₀^a e^{−h²(1+x²)/2}/(1+x²) dx`). `S_σ` is
//! continuous across the segment (the jump of the angle is cancelled by the jump of `T`), and
//! summing it over the edges of a closed polygon gives the closed-loop value (tested against the
//! BvN formula to 1e-14).
//!
//! **Gradient.** The distributional gradient of the segment's `w` is the jump across the segment
//! (the closed-loop edge term [`GauWn::segment_spatial_gradient`]) plus the smooth field of two
//! point vortices at the ends; a vortex smoothed by `G_σ` is
//! `J(p − q)(1 − e^{−|p−q|²/2σ²})/(2π|p − q|²)`, `J(x, y) = (−y, x)`.

use super::bvh::CurveBvh;
use super::bvn::{gauss_legendre_20, norm_cdf};
use super::gauwn::GauWn;
use super::polygon::{Point, Polygon, orient2d};
use std::f64::consts::PI;

/// Owen's T function `T(h, a) = (1/2π) ∫₀^a exp(−h²(1 + x²)/2)/(1 + x²) dx`.
///
/// For `|a| ≤ 1`: `T = (1/2π) ∫₀^{atan a} exp(−h²/(2cos²θ)) dθ` by composite 20-point
/// Gauss–Legendre on panels of width ≤ 1/h (the integrand's scale). For `|a| > 1`:
/// `T(h, a) = ½[Φ(h)Φ(−ah) + Φ(ah)Φ(−h)] − T(ah, 1/a)` (no cancellation). `T(h, a) < e^{−h²/2}/4`,
/// so `h > 40` returns 0.
pub fn owens_t(h: f64, a: f64) -> f64 {
    let h = h.abs();
    if a < 0.0 {
        return -owens_t(h, -a);
    }
    if a == 0.0 || h > 40.0 {
        return 0.0;
    }
    if a > 1.0 {
        if a.is_infinite() {
            return 0.5 * norm_cdf(-h);
        }
        let ah = a * h;
        let (ph, pmh) = (norm_cdf(h), norm_cdf(-h));
        let (pah, pmah) = (norm_cdf(ah), norm_cdf(-ah));
        return 0.5 * (ph * pmah + pah * pmh) - owens_t(ah, 1.0 / a);
    }
    let theta = a.atan();
    let panels = ((theta * h).ceil() as usize).clamp(1, 64);
    let width = theta / panels as f64;
    let rule = gauss_legendre_20();
    let mut sum = 0.0;
    for k in 0..panels {
        let mid = (k as f64 + 0.5) * width;
        for &(x, w) in rule {
            for t in [mid - 0.5 * width * x, mid + 0.5 * width * x] {
                let c = t.cos();
                sum += w * (-0.5 * h * h / (c * c)).exp();
            }
        }
    }
    sum * 0.5 * width / (2.0 * PI)
}

/// The signed angle (radians, in `[−π, π]`) under which the directed segment `a → b` is seen from
/// the perturbed query `q + (ε, ε²)`: positive when `a → b` runs counter-clockwise around it.
/// Zero-length segments give 0. Queries on the segment or its line get the value of the
/// perturbed point, consistently with [`Polygon::winding_number`].
pub fn segment_angle(a: Point, b: Point, q: Point) -> f64 {
    if a == b {
        return 0.0;
    }
    let u = [a[0] - q[0], a[1] - q[1]];
    let v = [b[0] - q[0], b[1] - q[1]];
    let d = [b[0] - a[0], b[1] - a[1]];
    // With e = (ε, ε²): cross(u − e, v − e) = cross(u, v) − ε·d_y + ε²·d_x.
    let mut sign = orient2d(q, a, b);
    if sign == 0 {
        sign = if d[1] != 0.0 {
            if d[1] > 0.0 { -1 } else { 1 }
        } else if d[0] > 0.0 {
            1
        } else {
            -1
        };
        // Magnitude at the perturbed point: q on the line of a → b.
        let magnitude = if u == [0.0, 0.0] {
            // At a: the angle between (−1, 0) and d.
            d[1].abs().atan2(-d[0])
        } else if v == [0.0, 0.0] {
            // At b: the angle between −d and (−1, 0).
            d[1].abs().atan2(d[0])
        } else if u[0] * v[0] + u[1] * v[1] < 0.0 {
            PI // strictly inside the segment
        } else {
            0.0 // on the line, outside the segment
        };
        return f64::from(sign) * magnitude;
    }
    let cross = u[0] * v[1] - u[1] * v[0];
    let dot = u[0] * v[0] + u[1] * v[1];
    f64::from(sign) * cross.abs().atan2(dot)
}

/// `S_σ(a → b; q)`: the Gaussian-smoothed generalized winding number of the single directed
/// segment `a → b` (see the module docs).
pub fn segment_smoothed(sigma: f64, a: Point, b: Point, q: Point) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l = dx.hypot(dy);
    if l == 0.0 {
        return 0.0;
    }
    let (tx, ty) = (dx / l, dy / l);
    let (rx, ry) = (q[0] - a[0], q[1] - a[1]);
    let mu = rx * tx + ry * ty;
    // Signed distance, positive when q is left of a → b (the angle is then positive).
    let d = tx * ry - ty * rx;
    if d == 0.0 {
        return 0.0; // the limit from both sides
    }
    let (t0, t1) = (-mu, l - mu);
    let ad = d.abs();
    let h = ad / sigma;
    let u = |t: f64| {
        let x = t / ad;
        x.atan() / (2.0 * PI) - owens_t(h, x)
    };
    d.signum() * (u(t1) - u(t0))
}

/// `∇_q S_σ(a → b; q)`: the segment's jump term plus the two smoothed end vortices.
pub fn segment_smoothed_gradient(g: &GauWn, a: Point, b: Point, q: Point) -> Point {
    if a == b {
        return [0.0; 2];
    }
    let jump = g.segment_spatial_gradient(a, b, q);
    let s2 = 2.0 * g.sigma * g.sigma;
    // (1 − e^{−r²/2σ²})/r², finite at r = 0.
    let vortex = |p: Point| -> Point {
        let (x, y) = (p[0] - q[0], p[1] - q[1]);
        let r2 = x * x + y * y;
        let m = if r2 == 0.0 {
            1.0 / s2
        } else {
            -(-r2 / s2).exp_m1() / r2
        };
        [-y * m / (2.0 * PI), x * m / (2.0 * PI)]
    };
    let (va, vb) = (vortex(a), vortex(b));
    [jump[0] + va[0] - vb[0], jump[1] + va[1] - vb[1]]
}

/// Loops of a [`Polygon`] of which some are open polylines.
#[derive(Clone, Debug, PartialEq)]
pub struct Curves {
    /// All loops (an open one is stored with its implicit closing edge, see the module docs).
    pub polygon: Polygon,
    /// `open[k]`: loop `k` is an open polyline from its first to its last vertex.
    pub open: Vec<bool>,
}

impl Curves {
    /// All loops closed.
    pub fn closed(polygon: Polygon) -> Self {
        let open = vec![false; polygon.num_loops()];
        Curves { polygon, open }
    }

    /// Whether any loop is open.
    pub fn has_open(&self) -> bool {
        self.open.iter().any(|&o| o)
    }

    /// The directed segments `first → last` of the open loops (the corrections of the module
    /// docs).
    pub fn open_chords(&self) -> Vec<(Point, Point)> {
        (0..self.polygon.num_loops())
            .filter(|&k| self.open[k])
            .map(|k| {
                let l = self.polygon.loop_points(k);
                (l[0], l[l.len() - 1])
            })
            .collect()
    }

    /// The generalized winding number at the perturbed query `q + (ε, ε²)`: an exact integer for
    /// closed loops, plus one segment angle per open loop.
    pub fn winding_number(&self, q: Point) -> f64 {
        let closed = self.polygon.winding_number(q) as f64;
        let open: f64 = self
            .open_chords()
            .iter()
            .map(|&(a, b)| segment_angle(a, b, q))
            .sum();
        closed + open / (2.0 * PI)
    }
}

/// The smoothed winding number of [`Curves`] with a BVH over all edges.
#[derive(Clone, Debug)]
pub struct CurvesField {
    bvh: CurveBvh,
    chords: Vec<(Point, Point)>,
}

impl CurvesField {
    /// Builds the BVH of the loops.
    pub fn new(curves: &Curves) -> Self {
        CurvesField {
            bvh: CurveBvh::new(&curves.polygon),
            chords: curves.open_chords(),
        }
    }

    /// `W_σ(q)`.
    pub fn value(&self, g: &GauWn, q: Point) -> f64 {
        let closed = self.bvh.value(g, q);
        closed
            + self
                .chords
                .iter()
                .map(|&(a, b)| segment_smoothed(g.sigma, a, b, q))
                .sum::<f64>()
    }

    /// `∇_q W_σ(q)`.
    pub fn gradient(&self, g: &GauWn, q: Point) -> Point {
        let mut grad = self.bvh.gradient(g, q);
        for &(a, b) in &self.chords {
            let s = segment_smoothed_gradient(g, a, b, q);
            grad[0] += s[0];
            grad[1] += s[1];
        }
        grad
    }
}
