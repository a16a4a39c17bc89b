//! Applications of GauWN (Sun et al. 2024, Section 4): resolving embedding issues (untangling),
//! offsetting by the GauWN flow, and the in-out brush.
//!
//! All three minimise a smooth energy of the vertex positions with argmin's L-BFGS (More–Thuente
//! line search, memory 7). Lengths are measured relative to `scale`, the larger side of the
//! input's bounding box, so the default parameters are those of the paper's unit-size inputs.
//!
//! - **Untangling** (Eq. 13–17, Algorithm 1). Test points `x = a + t(b − a) ± ε n` at `t = ¼, ¾`
//!   of every edge `a → b` (the near halves of the edges around each vertex, Eq. 13), with target
//!   `ŵ = 1` on the left and `0` on the right. Energy
//!   `E = Σ_x (W_σ(x) − ŵ(x))² + λ Σ_i |v_i − v_i⁽⁰⁾|²/scale²`; its gradient includes the motion of
//!   the test points with the vertices (Eq. 16). Schedule: `σ₀ = 0.01·scale`, `σ ← 0.95σ` after
//!   each L-BFGS solve (Algorithm 1). Stopping rule: stop after the first outer iteration whose
//!   polygon has no self-intersection (exact test) and whose test points all have the target
//!   exact winding number, or after `max_outer` iterations. A polygon with negative total signed
//!   area is reversed first (and back at the end), so either orientation of the input works.
//! - **Offsetting** (Eq. 18). Each step fixes the current curve Γ⁽ᵏ⁻¹⁾ and minimises
//!   `Σ_i λ|v_i − v_i⁽ᵏ⁻¹⁾|²/σ² + (W_σ^{Γ⁽ᵏ⁻¹⁾}(v_i) − W_σ^{Γ⁽ᵏ⁻¹⁾}(v_i⁽ᵏ⁻¹⁾) − o_i)²`, with
//!   `o_i = −step·sgn(D)` (outward lowers W), reduced to `0.1 o_i` for vertices that moved more
//!   than 1.5× the mean (the paper's adaptive o). Stopping rule: when the mean displacement from
//!   the input reaches `|D|`, the last step is scaled back linearly so that it equals `|D|`.
//! - **In-out brush** (Section 4.3): `E = Σ_b (W_σ(x_b) − ŵ_b)² + λ Σ_i |v_i − v_i⁽⁰⁾|²/scale²`
//!   for fixed brush points `x_b` with targets `ŵ_b`; only the vertex gradient is used.

use super::bvh::CurveBvh;
use super::gauwn::GauWn;
use super::polygon::{Point, Polygon};
use argmin::core::{CostFunction, Error as ArgminError, Executor, Gradient, State};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::quasinewton::LBFGS;

fn scale_of(poly: &Polygon) -> f64 {
    scale_of_points(poly.points())
}

/// The larger side of the bounding box of `p`.
fn scale_of_points(p: &[Point]) -> f64 {
    let mut b = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
    for v in p {
        b = [
            b[0].min(v[0]),
            b[1].min(v[1]),
            b[2].max(v[0]),
            b[3].max(v[1]),
        ];
    }
    (b[2] - b[0]).max(b[3] - b[1]).max(f64::MIN_POSITIVE)
}

fn flatten(p: &[Point]) -> Vec<f64> {
    p.iter().flat_map(|v| [v[0], v[1]]).collect()
}

fn unflatten(x: &[f64]) -> Vec<Point> {
    x.chunks_exact(2).map(|c| [c[0], c[1]]).collect()
}

/// Runs L-BFGS for at most `iters` iterations; returns the best point found, or `x0` if the
/// solver fails (e.g. a line search that cannot make progress at a minimum).
fn minimize<P>(problem: P, x0: Vec<f64>, iters: u64) -> Vec<f64>
where
    P: CostFunction<Param = Vec<f64>, Output = f64>
        + Gradient<Param = Vec<f64>, Gradient = Vec<f64>>,
{
    let solver = LBFGS::new(MoreThuenteLineSearch::new(), 7)
        .with_tolerance_grad(1e-12)
        .and_then(|s| s.with_tolerance_cost(1e-14));
    let Ok(solver) = solver else {
        return x0;
    };
    let run = Executor::new(problem, solver)
        .configure(|s| s.param(x0.clone()).max_iters(iters))
        .run();
    match run {
        Ok(res) => res.state().get_best_param().cloned().unwrap_or(x0),
        Err(_) => x0,
    }
}

// ---------------------------------------------------------------------------------------------
// Untangling

/// Parameters of [`untangle`]; lengths relative to the bounding-box size.
#[derive(Clone, Debug)]
pub struct UntangleParams {
    /// Initial σ relative to the size (paper: 0.01).
    pub sigma0: f64,
    /// Test-point distance ε relative to the size (paper: 0.004 or 0.02).
    pub eps: f64,
    /// Weight λ of the displacement regulariser.
    pub lambda: f64,
    /// σ factor per outer iteration (paper: 0.95).
    pub decay: f64,
    /// Maximum number of outer iterations (σ steps).
    pub max_outer: usize,
    /// L-BFGS iterations per outer iteration.
    pub inner_iters: u64,
}

impl Default for UntangleParams {
    fn default() -> Self {
        UntangleParams {
            sigma0: 0.01,
            eps: 0.004,
            lambda: 1.0,
            decay: 0.95,
            max_outer: 80,
            inner_iters: 30,
        }
    }
}

/// The outcome of [`untangle`].
#[derive(Clone, Debug)]
pub struct UntangleReport {
    /// The resulting polygon.
    pub polygon: Polygon,
    /// Outer iterations performed.
    pub outer_iterations: usize,
    /// σ used in the last iteration (absolute).
    pub final_sigma: f64,
    /// Largest vertex displacement from the input.
    pub max_displacement: f64,
    /// Whether the stopping criterion (no intersection, all test points right) was met.
    pub converged: bool,
}

struct Sample {
    a: usize,
    b: usize,
    t: f64,
    side: f64,
    target: f64,
}

fn untangle_samples(poly: &Polygon) -> Vec<Sample> {
    let mut s = Vec::new();
    for (a, b) in poly.edges() {
        for t in [0.25, 0.75] {
            s.push(Sample {
                a,
                b,
                t,
                side: 1.0,
                target: 1.0,
            });
            s.push(Sample {
                a,
                b,
                t,
                side: -1.0,
                target: 0.0,
            });
        }
    }
    s
}

/// Position of a test point, or `None` on a zero-length edge.
fn sample_point(s: &Sample, p: &[Point], eps: f64) -> Option<(Point, [f64; 2], f64)> {
    let (a, b) = (p[s.a], p[s.b]);
    let u = [b[0] - a[0], b[1] - a[1]];
    let l = u[0].hypot(u[1]);
    if l == 0.0 {
        return None;
    }
    let d = [u[0] / l, u[1] / l];
    let n = [-d[1], d[0]];
    let x = [
        a[0] + s.t * u[0] + s.side * eps * n[0],
        a[1] + s.t * u[1] + s.side * eps * n[1],
    ];
    Some((x, d, l))
}

/// The three energies below expose `eval(x, want_grad) -> (energy, gradient)`; this wires one
/// to argmin's L-BFGS (cost = the energy, gradient = the gradient).
macro_rules! impl_argmin_problem {
    ($problem:ident) => {
        impl CostFunction for $problem<'_> {
            type Param = Vec<f64>;
            type Output = f64;
            fn cost(&self, x: &Vec<f64>) -> Result<f64, ArgminError> {
                Ok(self.eval(x, false).0)
            }
        }

        impl Gradient for $problem<'_> {
            type Param = Vec<f64>;
            type Gradient = Vec<f64>;
            fn gradient(&self, x: &Vec<f64>) -> Result<Vec<f64>, ArgminError> {
                Ok(self.eval(x, true).1)
            }
        }
    };
}

struct UntangleProblem<'a> {
    base: &'a Polygon,
    rest: &'a [Point],
    samples: &'a [Sample],
    g: GauWn,
    eps: f64,
    lambda: f64,
    inv_scale2: f64,
}

impl UntangleProblem<'_> {
    fn eval(&self, x: &[f64], want_grad: bool) -> (f64, Vec<f64>) {
        let pts = unflatten(x);
        let mut grad = vec![[0.0; 2]; pts.len()];
        let mut e = 0.0;
        for (i, (v, r)) in pts.iter().zip(self.rest).enumerate() {
            let (dx, dy) = (v[0] - r[0], v[1] - r[1]);
            e += self.lambda * self.inv_scale2 * (dx * dx + dy * dy);
            grad[i][0] += 2.0 * self.lambda * self.inv_scale2 * dx;
            grad[i][1] += 2.0 * self.lambda * self.inv_scale2 * dy;
        }
        let Ok(poly) = self.base.with_points(pts.clone()) else {
            return (f64::INFINITY, vec![0.0; x.len()]);
        };
        let bvh = CurveBvh::new(&poly);
        for s in self.samples {
            let Some((xq, d, l)) = sample_point(s, &pts, self.eps) else {
                continue;
            };
            let r = bvh.value(&self.g, xq) - s.target;
            e += r * r;
            if !want_grad || r == 0.0 {
                continue;
            }
            // ∂W/∂v at fixed x (Eq. 15) ...
            bvh.add_vertex_gradient(&self.g, xq, 2.0 * r, &mut grad);
            // ... plus (∂x/∂v)ᵀ ∇_x W (Eq. 16). x = a + t(b − a) + side·ε·R d̂,
            // ∂(R d̂)/∂(b − a) = R (I − d̂d̂ᵀ)/ℓ, so (∂x/∂b)ᵀ g = t g + side·ε (I − d̂d̂ᵀ) Rᵀ g / ℓ.
            let gx = bvh.gradient(&self.g, xq);
            let rtg = [gx[1], -gx[0]];
            let dot = d[0] * rtg[0] + d[1] * rtg[1];
            let proj = [
                s.side * self.eps * (rtg[0] - d[0] * dot) / l,
                s.side * self.eps * (rtg[1] - d[1] * dot) / l,
            ];
            for c in 0..2 {
                grad[s.b][c] += 2.0 * r * (s.t * gx[c] + proj[c]);
                grad[s.a][c] += 2.0 * r * ((1.0 - s.t) * gx[c] - proj[c]);
            }
        }
        (e, flatten(&grad))
    }
}

impl_argmin_problem!(UntangleProblem);

/// The untangling energy and its gradient (flattened `[x0, y0, x1, ...]`) at the vertex
/// positions of `poly`, for rest positions `rest` (which also fix `scale`; exposed for testing).
pub fn untangle_energy(
    poly: &Polygon,
    rest: &[Point],
    sigma: f64,
    eps: f64,
    lambda: f64,
) -> (f64, Vec<f64>) {
    let samples = untangle_samples(poly);
    let scale = scale_of_points(rest);
    let problem = UntangleProblem {
        base: poly,
        rest,
        samples: &samples,
        g: GauWn::new(sigma),
        eps,
        lambda,
        inv_scale2: 1.0 / (scale * scale),
    };
    problem.eval(&flatten(poly.points()), true)
}

fn untangle_done(poly: &Polygon, samples: &[Sample], eps: f64) -> bool {
    if poly.has_self_intersections() {
        return false;
    }
    samples
        .iter()
        .all(|s| match sample_point(s, poly.points(), eps) {
            Some((x, _, _)) => poly.winding_number(x) as f64 == s.target,
            None => true,
        })
}

/// Resolves the embedding issues of `poly` (Algorithm 1); see the module docs.
pub fn untangle(poly: &Polygon, params: &UntangleParams) -> UntangleReport {
    let flipped = poly.signed_area() < 0.0;
    let work = if flipped {
        poly.reversed()
    } else {
        poly.clone()
    };
    let scale = scale_of(&work);
    let eps = params.eps * scale;
    let samples = untangle_samples(&work);
    let rest = work.points().to_vec();
    let mut sigma = params.sigma0 * scale;
    let mut current = work.clone();
    let mut outer = 0;
    let mut converged = untangle_done(&current, &samples, eps);
    while !converged && outer < params.max_outer {
        let problem = UntangleProblem {
            base: &work,
            rest: &rest,
            samples: &samples,
            g: GauWn::new(sigma),
            eps,
            lambda: params.lambda,
            inv_scale2: 1.0 / (scale * scale),
        };
        let x = minimize(problem, flatten(current.points()), params.inner_iters);
        if let Ok(p) = work.with_points(unflatten(&x)) {
            current = p;
        }
        outer += 1;
        converged = untangle_done(&current, &samples, eps);
        if !converged {
            sigma *= params.decay;
        }
    }
    let max_displacement = current
        .points()
        .iter()
        .zip(&rest)
        .map(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1]))
        .fold(0.0, f64::max);
    UntangleReport {
        polygon: if flipped { current.reversed() } else { current },
        outer_iterations: outer,
        final_sigma: sigma,
        max_displacement,
        converged,
    }
}

// ---------------------------------------------------------------------------------------------
// Offsetting

/// Parameters of [`offset`].
#[derive(Clone, Debug)]
pub struct OffsetParams {
    /// Offset distance (absolute units): positive outwards (towards lower winding number).
    pub distance: f64,
    /// σ (absolute); `None` picks `min(|D|/5, 0.02·scale)`.
    pub sigma: Option<f64>,
    /// |o|, the GauWN change requested per step (paper: 0.2 in Fig. 11).
    pub step: f64,
    /// Weight λ of the displacement term, in units of 1/σ².
    pub lambda: f64,
    /// Maximum number of flow steps.
    pub max_steps: usize,
}

impl OffsetParams {
    /// Defaults for distance `d`.
    pub fn new(distance: f64) -> Self {
        OffsetParams {
            distance,
            sigma: None,
            step: 0.1,
            lambda: 0.1,
            max_steps: 2000,
        }
    }
}

/// The outcome of [`offset`].
#[derive(Clone, Debug)]
pub struct OffsetReport {
    /// The offset polygon (same connectivity as the input).
    pub polygon: Polygon,
    /// Flow steps performed.
    pub steps: usize,
    /// Mean vertex displacement from the input.
    pub mean_displacement: f64,
    /// σ used.
    pub sigma: f64,
}

struct OffsetProblem<'a> {
    bvh: &'a CurveBvh,
    g: GauWn,
    prev: &'a [Point],
    targets: &'a [f64],
    weight: f64,
}

impl OffsetProblem<'_> {
    fn eval(&self, x: &[f64], want_grad: bool) -> (f64, Vec<f64>) {
        let mut e = 0.0;
        let mut grad = vec![0.0; x.len()];
        for (i, (p, &c)) in self.prev.iter().zip(self.targets).enumerate() {
            let v = [x[2 * i], x[2 * i + 1]];
            let (dx, dy) = (v[0] - p[0], v[1] - p[1]);
            let r = self.bvh.value(&self.g, v) - c;
            e += self.weight * (dx * dx + dy * dy) + r * r;
            if want_grad {
                let gw = self.bvh.gradient(&self.g, v);
                grad[2 * i] = 2.0 * self.weight * dx + 2.0 * r * gw[0];
                grad[2 * i + 1] = 2.0 * self.weight * dy + 2.0 * r * gw[1];
            }
        }
        (e, grad)
    }
}

impl_argmin_problem!(OffsetProblem);

fn mean_disp(a: &[Point], b: &[Point]) -> (f64, Vec<f64>) {
    let d: Vec<f64> = a
        .iter()
        .zip(b)
        .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
        .collect();
    (d.iter().sum::<f64>() / d.len().max(1) as f64, d)
}

/// Offsets `poly` by the GauWN flow (Eq. 18); see the module docs.
pub fn offset(poly: &Polygon, params: &OffsetParams) -> OffsetReport {
    let scale = scale_of(poly);
    let target = params.distance.abs();
    let sigma = params
        .sigma
        .unwrap_or_else(|| (target / 5.0).min(0.02 * scale))
        .max(1e-9 * scale);
    let g = GauWn::new(sigma);
    let input = poly.points().to_vec();
    let o = -params.step * params.distance.signum();
    let mut current = poly.clone();
    let mut steps = 0;
    let mut mean = 0.0;
    while target > 0.0 && steps < params.max_steps {
        let bvh = CurveBvh::new(&current);
        let prev = current.points().to_vec();
        let (_, disp) = mean_disp(&prev, &input);
        let targets: Vec<f64> = prev
            .iter()
            .zip(&disp)
            .map(|(v, &d)| {
                let oi = if steps > 0 && d > 1.5 * mean {
                    0.1 * o
                } else {
                    o
                };
                bvh.value(&g, *v) + oi
            })
            .collect();
        let problem = OffsetProblem {
            bvh: &bvh,
            g,
            prev: &prev,
            targets: &targets,
            weight: params.lambda / (sigma * sigma),
        };
        let x = minimize(problem, flatten(&prev), 50);
        let next = unflatten(&x);
        steps += 1;
        let (m, _) = mean_disp(&next, &input);
        if m >= target {
            // Scale the last step back so that the mean displacement is |D|.
            let f = if m > mean {
                (target - mean) / (m - mean)
            } else {
                1.0
            };
            let blended: Vec<Point> = prev
                .iter()
                .zip(&next)
                .map(|(a, b)| [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])])
                .collect();
            if let Ok(p) = current.with_points(blended) {
                current = p;
            }
            mean = mean_disp(current.points(), &input).0;
            break;
        }
        if m <= mean {
            // The flow has stalled; stop rather than loop.
            if let Ok(p) = current.with_points(next) {
                current = p;
            }
            mean = m;
            break;
        }
        mean = m;
        match current.with_points(next) {
            Ok(p) => current = p,
            Err(_) => break,
        }
    }
    OffsetReport {
        polygon: current,
        steps,
        mean_displacement: mean,
        sigma,
    }
}

// ---------------------------------------------------------------------------------------------
// In-out brush

/// Parameters of [`apply_brush`].
#[derive(Clone, Debug)]
pub struct BrushParams {
    /// σ (absolute).
    pub sigma: f64,
    /// Weight λ of the displacement term (relative to the size², as in untangling).
    pub lambda: f64,
    /// L-BFGS iterations.
    pub iters: u64,
}

struct BrushProblem<'a> {
    base: &'a Polygon,
    rest: &'a [Point],
    brush: &'a [(Point, f64)],
    g: GauWn,
    lambda: f64,
    inv_scale2: f64,
}

impl BrushProblem<'_> {
    fn eval(&self, x: &[f64], want_grad: bool) -> (f64, Vec<f64>) {
        let pts = unflatten(x);
        let mut grad = vec![[0.0; 2]; pts.len()];
        let mut e = 0.0;
        for (i, (v, r)) in pts.iter().zip(self.rest).enumerate() {
            let (dx, dy) = (v[0] - r[0], v[1] - r[1]);
            e += self.lambda * self.inv_scale2 * (dx * dx + dy * dy);
            grad[i][0] += 2.0 * self.lambda * self.inv_scale2 * dx;
            grad[i][1] += 2.0 * self.lambda * self.inv_scale2 * dy;
        }
        let Ok(poly) = self.base.with_points(pts) else {
            return (f64::INFINITY, vec![0.0; x.len()]);
        };
        let bvh = CurveBvh::new(&poly);
        for &(xb, target) in self.brush {
            let r = bvh.value(&self.g, xb) - target;
            e += r * r;
            if want_grad && r != 0.0 {
                bvh.add_vertex_gradient(&self.g, xb, 2.0 * r, &mut grad);
            }
        }
        (e, flatten(&grad))
    }
}

impl_argmin_problem!(BrushProblem);

/// The in-out brush energy and its flattened gradient at the vertices of `poly`, for rest
/// positions `rest` and brush points with target winding numbers.
pub fn brush_energy(
    poly: &Polygon,
    rest: &[Point],
    brush: &[(Point, f64)],
    params: &BrushParams,
) -> (f64, Vec<f64>) {
    let scale = scale_of_points(rest);
    BrushProblem {
        base: poly,
        rest,
        brush,
        g: GauWn::new(params.sigma),
        lambda: params.lambda,
        inv_scale2: 1.0 / (scale * scale),
    }
    .eval(&flatten(poly.points()), true)
}

/// Deforms `poly` so that the brush points get their target winding numbers (Section 4.3).
pub fn apply_brush(poly: &Polygon, brush: &[(Point, f64)], params: &BrushParams) -> Polygon {
    let scale = scale_of(poly);
    let rest = poly.points().to_vec();
    let problem = BrushProblem {
        base: poly,
        rest: &rest,
        brush,
        g: GauWn::new(params.sigma),
        lambda: params.lambda,
        inv_scale2: 1.0 / (scale * scale),
    };
    let x = minimize(problem, flatten(&rest), params.iters);
    poly.with_points(unflatten(&x))
        .unwrap_or_else(|_| poly.clone())
}
