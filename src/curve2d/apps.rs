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
//!   exact winding number. Never worse than the input: after every outer iteration the iterate is
//!   ranked by (intersecting edge pairs, test points with a wrong exact winding number,
//!   displacement) and the best one (possibly the input) is returned; the loop also stops after
//!   `patience` iterations without a new best, or after `max_outer`. The energy is evaluated in
//!   parallel (rayon, chunks summed in a fixed order, so results do not depend on the thread
//!   count). A polygon with negative total signed area is reversed first (and back at the end),
//!   so either orientation of the input works.
//! - **Robustness** (all three): parameters are validated ([`ParamError`]); the input is scaled by
//!   a power of two (exact) to unit size; every optimiser run is bounded in iterations, and a
//!   non-finite energy or gradient stops it with the best finite point kept.
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
use argmin::core::{CostFunction, Error as ArgminError, Executor, Gradient};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::quasinewton::LBFGS;
use rayon::prelude::*;
use std::fmt;
use std::sync::Mutex;

/// A parameter of [`untangle`] or [`offset`] that cannot be used.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamError {
    /// A parameter that must be a finite number `> 0` (or `≥ 0` when `zero_ok`) is not.
    NotPositive {
        /// Parameter name as on the command line.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Whether 0 is accepted.
        zero_ok: bool,
    },
    /// A parameter outside its documented range.
    OutOfRange {
        /// Parameter name as on the command line.
        name: &'static str,
        /// The value given (as text, integers and floats alike).
        value: String,
        /// The accepted range, as text.
        range: &'static str,
    },
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamError::NotPositive {
                name,
                value,
                zero_ok,
            } => write!(
                f,
                "--{name} {value}: expected a finite number {} 0",
                if *zero_ok { ">=" } else { ">" }
            ),
            ParamError::OutOfRange { name, value, range } => {
                write!(f, "--{name} {value}: expected {range}")
            }
        }
    }
}

impl std::error::Error for ParamError {}

fn positive(name: &'static str, value: f64, zero_ok: bool) -> Result<(), ParamError> {
    let ok = value.is_finite() && (value > 0.0 || (zero_ok && value == 0.0));
    if ok {
        Ok(())
    } else {
        Err(ParamError::NotPositive {
            name,
            value,
            zero_ok,
        })
    }
}

fn in_range<T: PartialOrd + fmt::Display>(
    name: &'static str,
    value: T,
    lo: T,
    hi: T,
    range: &'static str,
) -> Result<(), ParamError> {
    if value >= lo && value <= hi {
        Ok(())
    } else {
        Err(ParamError::OutOfRange {
            name,
            value: value.to_string(),
            range,
        })
    }
}

/// Largest accepted iteration counts: every loop of the applications is bounded by these.
pub const MAX_ITERATIONS: usize = 100_000;

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

/// The power of two `k` that brings the size of `poly` to `[1, 2)`, and `poly` scaled by it.
/// Scaling by a power of two is exact, so the applications run on a unit-size copy and map back
/// without rounding; this keeps every intermediate (σ², exp arguments, L-BFGS steps) in range
/// for inputs from 1e-100 to 1e100 in size.
fn normalized(poly: &Polygon) -> (f64, Polygon) {
    let size = scale_of(poly);
    let k = (2.0f64).powi(-(size.log2().floor() as i32).clamp(-1000, 1000));
    (k, scaled(poly, k))
}

fn scaled(poly: &Polygon, k: f64) -> Polygon {
    let pts = poly.points().iter().map(|p| [p[0] * k, p[1] * k]).collect();
    poly.with_points(pts).unwrap_or_else(|_| poly.clone())
}

fn flatten(p: &[Point]) -> Vec<f64> {
    p.iter().flat_map(|v| [v[0], v[1]]).collect()
}

fn unflatten(x: &[f64]) -> Vec<Point> {
    x.chunks_exact(2).map(|c| [c[0], c[1]]).collect()
}

/// Wraps an energy so that a non-finite cost or gradient aborts the solver (instead of feeding
/// NaN to the line search, which then never terminates) and remembers the best finite point.
struct Guarded<P> {
    inner: P,
    best: Mutex<Option<(f64, Vec<f64>)>>,
}

impl<P> CostFunction for Guarded<P>
where
    P: CostFunction<Param = Vec<f64>, Output = f64>,
{
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, x: &Vec<f64>) -> Result<f64, ArgminError> {
        let c = self.inner.cost(x)?;
        if !c.is_finite() || x.iter().any(|v| !v.is_finite()) {
            return Err(ArgminError::msg("non-finite energy"));
        }
        if let Ok(mut b) = self.best.lock() {
            if b.as_ref().is_none_or(|(bc, _)| c < *bc) {
                *b = Some((c, x.clone()));
            }
        }
        Ok(c)
    }
}

impl<P> Gradient for Guarded<P>
where
    P: Gradient<Param = Vec<f64>, Gradient = Vec<f64>>,
{
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, x: &Vec<f64>) -> Result<Vec<f64>, ArgminError> {
        let g = self.inner.gradient(x)?;
        if g.iter().any(|v| !v.is_finite()) {
            return Err(ArgminError::msg("non-finite gradient"));
        }
        Ok(g)
    }
}

/// Runs L-BFGS for at most `iters` iterations (each line search is bounded by More–Thuente's
/// own iteration limit). Returns the point of lowest finite energy evaluated (`x0` if none was
/// lower), and whether the energy or gradient became non-finite.
fn minimize<P>(problem: P, x0: Vec<f64>, iters: u64) -> (Vec<f64>, bool)
where
    P: CostFunction<Param = Vec<f64>, Output = f64>
        + Gradient<Param = Vec<f64>, Gradient = Vec<f64>>,
{
    let guarded = Guarded {
        inner: problem,
        best: Mutex::new(None),
    };
    let Ok(c0) = guarded.cost(&x0) else {
        return (x0, true);
    };
    let solver = LBFGS::new(MoreThuenteLineSearch::new(), 7)
        .with_tolerance_grad(1e-12)
        .and_then(|s| s.with_tolerance_cost(1e-14));
    let Ok(solver) = solver else {
        return (x0, false);
    };
    let problem = &guarded;
    let run = Executor::new(GuardRef(problem), solver)
        .configure(|s| s.param(x0.clone()).max_iters(iters))
        .run();
    let non_finite = run.is_err();
    let best = guarded.best.lock().ok().and_then(|b| b.clone());
    match best {
        Some((c, x)) if c <= c0 => (x, non_finite),
        _ => (x0, non_finite),
    }
}

/// A borrowed [`Guarded`] problem (argmin takes its problem by value).
struct GuardRef<'a, P>(&'a Guarded<P>);

impl<P> CostFunction for GuardRef<'_, P>
where
    P: CostFunction<Param = Vec<f64>, Output = f64>,
{
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, x: &Vec<f64>) -> Result<f64, ArgminError> {
        self.0.cost(x)
    }
}

impl<P> Gradient for GuardRef<'_, P>
where
    P: Gradient<Param = Vec<f64>, Gradient = Vec<f64>>,
{
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, x: &Vec<f64>) -> Result<Vec<f64>, ArgminError> {
        self.0.gradient(x)
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
    /// Weight λ of the displacement regulariser (≥ 0).
    pub lambda: f64,
    /// σ factor per outer iteration (paper: 0.95), in `(0, 1]`.
    pub decay: f64,
    /// Maximum number of outer iterations (σ steps).
    pub max_outer: usize,
    /// L-BFGS iterations per outer iteration.
    pub inner_iters: u64,
    /// Stop after this many outer iterations without a new best iterate.
    pub patience: usize,
    /// Evaluate the plain winding number's limit instead of GauWN: σ stays at `1e-6·size`
    /// (ε/4000 with the defaults), where the energy's gradient vanishes at the test points. The
    /// baseline that shows what the smoothing contributes.
    pub unsmoothed: bool,
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
            patience: 8,
            unsmoothed: false,
        }
    }
}

impl UntangleParams {
    /// Checks every parameter (NaN, zero, negative, out of range).
    pub fn validate(&self) -> Result<(), ParamError> {
        positive("sigma0", self.sigma0, false)?;
        positive("eps", self.eps, false)?;
        positive("lambda", self.lambda, true)?;
        positive("decay", self.decay, false)?;
        in_range(
            "decay",
            self.decay,
            f64::MIN_POSITIVE,
            1.0,
            "a number in (0, 1]",
        )?;
        in_range(
            "sigma0",
            self.sigma0,
            0.0,
            10.0,
            "at most 10 (relative to the size)",
        )?;
        in_range(
            "eps",
            self.eps,
            0.0,
            1.0,
            "at most 1 (relative to the size)",
        )?;
        in_range("max-iters", self.max_outer, 1, MAX_ITERATIONS, "1..=100000")?;
        in_range(
            "inner-iters",
            self.inner_iters,
            1,
            MAX_ITERATIONS as u64,
            "1..=100000",
        )?;
        in_range("patience", self.patience, 1, MAX_ITERATIONS, "1..=100000")
    }
}

/// Why [`untangle`] stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UntangleStop {
    /// No self-intersection and every test point has its target exact winding number.
    Resolved,
    /// `patience` outer iterations in a row brought no new best iterate.
    Stalled,
    /// `max_outer` outer iterations were performed.
    MaxIterations,
    /// The energy or its gradient became non-finite; the best iterate so far is returned.
    NonFinite,
}

/// The state after one outer iteration, passed to the progress callback.
#[derive(Clone, Copy, Debug)]
pub struct UntangleProgress {
    /// Outer iterations done (1-based).
    pub outer: usize,
    /// Maximum outer iterations.
    pub max_outer: usize,
    /// σ of this iteration (absolute, input units).
    pub sigma: f64,
    /// Intersecting edge pairs of the current iterate.
    pub crossings: usize,
    /// Intersecting edge pairs of the best iterate so far.
    pub best_crossings: usize,
}

/// The outcome of [`untangle`].
#[derive(Clone, Debug)]
pub struct UntangleReport {
    /// The best iterate (the input itself if no iterate was better): fewest intersecting edge
    /// pairs, then fewest test points with a wrong exact winding number, then least displacement.
    pub polygon: Polygon,
    /// Outer iterations performed.
    pub outer_iterations: usize,
    /// The outer iteration that produced [`UntangleReport::polygon`] (0 = the input).
    pub best_iteration: usize,
    /// σ used in the last iteration (absolute).
    pub final_sigma: f64,
    /// Largest vertex displacement of the result from the input.
    pub max_displacement: f64,
    /// Intersecting edge pairs of the input.
    pub crossings_before: usize,
    /// Intersecting edge pairs of the result (never more than `crossings_before`).
    pub crossings_after: usize,
    /// Whether the stopping criterion (no intersection, all test points right) was met.
    pub converged: bool,
    /// Why the iteration stopped.
    pub stop: UntangleStop,
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

/// Test points per parallel work item: enough to amortise one gradient buffer per item.
const SAMPLES_PER_TASK: usize = 256;

impl UntangleProblem<'_> {
    fn eval(&self, x: &[f64], want_grad: bool) -> (f64, Vec<f64>) {
        let pts = unflatten(x);
        let n = pts.len();
        let mut grad = vec![[0.0; 2]; n];
        let mut e = 0.0;
        for (i, (v, r)) in pts.iter().zip(self.rest).enumerate() {
            let (dx, dy) = (v[0] - r[0], v[1] - r[1]);
            e += self.lambda * self.inv_scale2 * (dx * dx + dy * dy);
            grad[i][0] += 2.0 * self.lambda * self.inv_scale2 * dx;
            grad[i][1] += 2.0 * self.lambda * self.inv_scale2 * dy;
        }
        if pts.iter().flatten().any(|c| !c.is_finite()) {
            return (f64::NAN, vec![f64::NAN; x.len()]);
        }
        let Ok(poly) = self.base.with_points(pts.clone()) else {
            return (f64::INFINITY, vec![0.0; x.len()]);
        };
        let bvh = CurveBvh::new(&poly);
        // Partial sums per chunk, added in chunk order: the result does not depend on the
        // thread count or on scheduling.
        let parts: Vec<(f64, Option<Vec<Point>>)> = self
            .samples
            .par_chunks(SAMPLES_PER_TASK)
            .map(|chunk| {
                let mut e = 0.0;
                let mut grad = want_grad.then(|| vec![[0.0; 2]; n]);
                for s in chunk {
                    let Some((xq, d, l)) = sample_point(s, &pts, self.eps) else {
                        continue;
                    };
                    let r = bvh.value(&self.g, xq) - s.target;
                    e += r * r;
                    let Some(grad) = grad.as_mut() else {
                        continue;
                    };
                    if r == 0.0 {
                        continue;
                    }
                    // ∂W/∂v at fixed x (Eq. 15) ...
                    bvh.add_vertex_gradient(&self.g, xq, 2.0 * r, grad);
                    // ... plus (∂x/∂v)ᵀ ∇_x W (Eq. 16). x = a + t(b − a) + side·ε·R d̂,
                    // ∂(R d̂)/∂(b − a) = R (I − d̂d̂ᵀ)/ℓ, so
                    // (∂x/∂b)ᵀ g = t g + side·ε (I − d̂d̂ᵀ) Rᵀ g / ℓ.
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
                (e, grad)
            })
            .collect();
        for (pe, pg) in parts {
            e += pe;
            if let Some(pg) = pg {
                for (g, p) in grad.iter_mut().zip(pg) {
                    g[0] += p[0];
                    g[1] += p[1];
                }
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

/// Test points whose exact winding number differs from their target.
fn wrong_test_points(poly: &Polygon, samples: &[Sample], eps: f64) -> usize {
    samples
        .par_iter()
        .filter(|s| match sample_point(s, poly.points(), eps) {
            Some((x, _, _)) => poly.winding_number(x) as f64 != s.target,
            None => false,
        })
        .count()
}

/// The ranking of an iterate: fewer intersecting edge pairs first, then fewer wrong test
/// points, then less displacement (Σ|v − v⁽⁰⁾|², the regulariser). The GauWN energy itself is
/// not used: it depends on σ, which changes between iterates.
fn rank(poly: &Polygon, samples: &[Sample], eps: f64, rest: &[Point]) -> (usize, usize, f64) {
    let crossings = poly.self_intersections(usize::MAX).len();
    let wrong = wrong_test_points(poly, samples, eps);
    let disp = poly
        .points()
        .iter()
        .zip(rest)
        .map(|(a, b)| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2))
        .sum();
    (crossings, wrong, disp)
}

/// Resolves the embedding issues of `poly` (Algorithm 1); see the module docs.
pub fn untangle(poly: &Polygon, params: &UntangleParams) -> Result<UntangleReport, ParamError> {
    untangle_with_progress(poly, params, &mut |_| {})
}

/// [`untangle`], calling `progress` after every outer iteration.
pub fn untangle_with_progress(
    poly: &Polygon,
    params: &UntangleParams,
    progress: &mut dyn FnMut(&UntangleProgress),
) -> Result<UntangleReport, ParamError> {
    params.validate()?;
    let (k, unit) = normalized(poly);
    let flipped = unit.signed_area() < 0.0;
    let work = if flipped { unit.reversed() } else { unit };
    let scale = scale_of(&work);
    let eps = params.eps * scale;
    let samples = untangle_samples(&work);
    let rest = work.points().to_vec();
    let mut sigma = if params.unsmoothed {
        1e-6 * scale
    } else {
        params.sigma0 * scale
    };
    let mut current = work.clone();
    let mut best = (current.clone(), rank(&current, &samples, eps, &rest), 0);
    let crossings_before = best.1.0;
    let mut outer = 0;
    let mut since_best = 0;
    let mut stop = if best.1.0 == 0 && best.1.1 == 0 {
        UntangleStop::Resolved
    } else {
        UntangleStop::MaxIterations
    };
    while stop != UntangleStop::Resolved && outer < params.max_outer {
        let problem = UntangleProblem {
            base: &work,
            rest: &rest,
            samples: &samples,
            g: GauWn::new(sigma),
            eps,
            lambda: params.lambda,
            inv_scale2: 1.0 / (scale * scale),
        };
        let (x, non_finite) = minimize(problem, flatten(current.points()), params.inner_iters);
        if let Ok(p) = work.with_points(unflatten(&x)) {
            current = p;
        }
        outer += 1;
        let r = rank(&current, &samples, eps, &rest);
        progress(&UntangleProgress {
            outer,
            max_outer: params.max_outer,
            sigma: sigma / k,
            crossings: r.0,
            best_crossings: best.1.0.min(r.0),
        });
        if (r.0, r.1) < (best.1.0, best.1.1)
            || ((r.0, r.1) == (best.1.0, best.1.1) && r.2 < best.1.2)
        {
            let improved = (r.0, r.1) < (best.1.0, best.1.1);
            best = (current.clone(), r, outer);
            if improved {
                since_best = 0;
            }
        } else {
            since_best += 1;
        }
        if r.0 == 0 && r.1 == 0 {
            stop = UntangleStop::Resolved;
        } else if non_finite {
            stop = UntangleStop::NonFinite;
            break;
        } else if since_best >= params.patience {
            stop = UntangleStop::Stalled;
            break;
        } else if !params.unsmoothed {
            sigma *= params.decay;
        }
    }
    let (result, r, best_iteration) = best;
    let max_displacement = result
        .points()
        .iter()
        .zip(&rest)
        .map(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1]))
        .fold(0.0, f64::max)
        / k;
    let result = scaled(&result, 1.0 / k);
    Ok(UntangleReport {
        polygon: if flipped { result.reversed() } else { result },
        outer_iterations: outer,
        best_iteration,
        final_sigma: sigma / k,
        max_displacement,
        crossings_before,
        crossings_after: r.0,
        converged: r.0 == 0 && r.1 == 0,
        stop,
    })
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

    /// Checks every parameter (NaN, zero, negative, out of range).
    pub fn validate(&self) -> Result<(), ParamError> {
        if !self.distance.is_finite() {
            return Err(ParamError::OutOfRange {
                name: "distance",
                value: self.distance.to_string(),
                range: "a finite number",
            });
        }
        if let Some(s) = self.sigma {
            positive("sigma", s, false)?;
        }
        positive("step", self.step, false)?;
        in_range("step", self.step, 0.0, 0.5, "at most 0.5")?;
        positive("lambda", self.lambda, false)?;
        in_range("max-steps", self.max_steps, 1, MAX_ITERATIONS, "1..=100000")
    }
}

/// Why [`offset`] stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffsetStop {
    /// The mean displacement reached `|D|`.
    Reached,
    /// A step did not increase the mean displacement, or the last 20 steps together increased
    /// it by less than 1% of `|D|` (e.g. an inward offset larger than the shape's inradius: the
    /// curve collapses towards a point).
    Stalled,
    /// `max_steps` steps were performed.
    MaxSteps,
    /// The energy or its gradient became non-finite; the last good curve is returned.
    NonFinite,
    /// The next step would make a curve without self-intersections intersect itself (e.g. an
    /// inward offset through the shape's centre); the last curve before it is returned.
    SelfIntersecting,
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
    /// Why the flow stopped; the target was reached only for [`OffsetStop::Reached`].
    pub stop: OffsetStop,
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
        let terms: Vec<(f64, [f64; 2])> = self
            .prev
            .par_iter()
            .zip(self.targets)
            .enumerate()
            .map(|(i, (p, &c))| {
                let v = [x[2 * i], x[2 * i + 1]];
                let (dx, dy) = (v[0] - p[0], v[1] - p[1]);
                let r = self.bvh.value(&self.g, v) - c;
                let e = self.weight * (dx * dx + dy * dy) + r * r;
                let g = if want_grad {
                    let gw = self.bvh.gradient(&self.g, v);
                    [
                        2.0 * self.weight * dx + 2.0 * r * gw[0],
                        2.0 * self.weight * dy + 2.0 * r * gw[1],
                    ]
                } else {
                    [0.0; 2]
                };
                (e, g)
            })
            .collect();
        let e = terms.iter().map(|t| t.0).sum();
        (e, terms.iter().flat_map(|t| t.1).collect())
    }
}

impl_argmin_problem!(OffsetProblem);

/// Offset steps over which the mean displacement must grow by 1% of |D| (else: stalled).
const STALL_WINDOW: usize = 20;

fn mean_disp(a: &[Point], b: &[Point]) -> (f64, Vec<f64>) {
    let d: Vec<f64> = a
        .iter()
        .zip(b)
        .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
        .collect();
    (d.iter().sum::<f64>() / d.len().max(1) as f64, d)
}

/// Offsets `poly` by the GauWN flow (Eq. 18); see the module docs.
pub fn offset(poly: &Polygon, params: &OffsetParams) -> Result<OffsetReport, ParamError> {
    params.validate()?;
    let (k, unit) = normalized(poly);
    let scale = scale_of(&unit);
    let target = params.distance.abs() * k;
    let sigma = params
        .sigma
        .map(|s| s * k)
        .unwrap_or_else(|| (target / 5.0).min(0.02 * scale))
        .max(1e-9 * scale);
    let g = GauWn::new(sigma);
    let input = unit.points().to_vec();
    let o = -params.step * params.distance.signum();
    let mut current = unit.clone();
    let simple = !unit.has_self_intersections();
    let mut steps = 0;
    let mut mean = 0.0;
    let mut history: Vec<f64> = Vec::new();
    let mut stop = if target > 0.0 {
        OffsetStop::MaxSteps
    } else {
        OffsetStop::Reached
    };
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
        let (x, non_finite) = minimize(problem, flatten(&prev), 50);
        steps += 1;
        if non_finite {
            stop = OffsetStop::NonFinite;
            break;
        }
        let next = unflatten(&x);
        if simple
            && current
                .with_points(next.clone())
                .map_or(true, |p| p.has_self_intersections())
        {
            stop = OffsetStop::SelfIntersecting;
            break;
        }
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
            stop = OffsetStop::Reached;
            break;
        }
        history.push(m);
        let window = STALL_WINDOW.min(history.len() - 1);
        let slow =
            history.len() > STALL_WINDOW && m - history[history.len() - 1 - window] < 0.01 * target;
        if m <= mean || slow {
            // The flow has stalled (e.g. the curve collapses to a point); stop rather than loop.
            if let Ok(p) = current.with_points(next) {
                current = p;
            }
            mean = m;
            stop = OffsetStop::Stalled;
            break;
        }
        mean = m;
        match current.with_points(next) {
            Ok(p) => current = p,
            Err(_) => {
                stop = OffsetStop::NonFinite;
                break;
            }
        }
    }
    Ok(OffsetReport {
        polygon: scaled(&current, 1.0 / k),
        steps,
        mean_displacement: mean / k,
        sigma: sigma / k,
        stop,
    })
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
    let (x, _) = minimize(problem, flatten(&rest), params.iters);
    poly.with_points(unflatten(&x))
        .unwrap_or_else(|_| poly.clone())
}
