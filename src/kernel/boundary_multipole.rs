//! The far-field expansion of a boundary cluster and its rigorous truncation bound
//! (docs/boundary.md, Eqs. 3–9). Everything the certified hierarchy approximates is here.
//!
//! A run of boundary edges, closed from one of its vertices `p` by the fan of triangles
//! `(p, a, b)`, bounds a surface `S` inside the convex hull of its vertices. When the ray misses
//! that hull, the Antipodal terms of the run are `Ω_S(q) − Σ_v m_v·Area(p, v)` (Eq. 2), and
//! `Ω_S` — a double-layer potential — is expanded about a centre `c` (Eq. 4):
//!
//! `Ω_S(q) = −Σ_{1≤|α|≤K} N_α·b_α(c − q) + R_K`, `N_α = ∫_S n·∇(u^α) dA`, `u = x − c`,
//!
//! with `b_α(s) = ∂^α(1/|s|)/α!` the Cartesian Taylor coefficients of `1/|s|` (computed by the
//! recurrence of Eq. 5) and the remainder bounded by Eq. 8:
//!
//! `|R_K| ≤ A·√2/r²·t^K·((K+1)/(1−t) + t/(1−t)²)`, `t = a/r < 1`,
//!
//! `A` the unsigned area of `S`, `a` the radius of a ball about `c` holding `S`, `r = |q − c|`.
//! The moments of a fan triangle are line integrals over its far edge (Eq. 6, exact by
//! Gauss–Legendre), and move between centres by the binomial shift of Eq. 7.
//!
//! Units: callers pass normalized grid coordinates (magnitudes ≤ ~2), so no power overflows.

// Multi-index arithmetic reads best with explicit indices (as in `eval/fast/moments.rs`).
#![allow(clippy::needless_range_loop)]

use std::sync::OnceLock;

/// Highest Cartesian order stored per cluster. Order `K` keeps the Legendre degrees `l ≤ K` of
/// `1/|q − x|`; its remainder falls like `t^(K+2)` (Eq. 8). Ten orders cost 286 coefficients.
pub const MAX_ORDER: usize = 10;

/// Number of multi-indices `α` with `|α| ≤ MAX_ORDER`: `C(MAX_ORDER + 3, 3)`.
pub const COEFFICIENTS: usize = (MAX_ORDER + 1) * (MAX_ORDER + 2) * (MAX_ORDER + 3) / 6;

/// Number of multi-indices with `|α| ≤ k` (the prefix of the degree-ordered tables).
pub const fn coefficients_up_to(k: usize) -> usize {
    (k + 1) * (k + 2) * (k + 3) / 6
}

/// Rounding allowance of one evaluation, relative to the magnitude of everything summed (moments
/// and coefficients in absolute values, [`Expansion::evaluate`]): a model bound, not a proof.
/// Each quantity is a sum of at most `COEFFICIENTS` products formed through a handful of shifts,
/// so its error is below `(COEFFICIENTS + 64)·2^-53 < 2^-44` of that magnitude; we allow `2^-42`.
pub const EVALUATION_ROUNDING: f64 = 1.0 / (1u64 << 42) as f64;

/// `√2`: the gradient bound `|∇(|u|^l P_l(û·ê))| ≤ √2·l·|u|^(l−1)` (radial part `l·P_l`, the
/// tangential part `√(1−x²)·P_l'(x) ≤ l` by Bernstein's inequality; Eq. 8).
const GRADIENT_CONSTANT: f64 = std::f64::consts::SQRT_2;

/// Cartesian multipole moments `N_α` of one cluster about its centre, degree-ordered.
pub type Moments = [f64; COEFFICIENTS];

/// The degree-ordered multi-index tables shared by every routine of this file.
struct Table {
    /// Index of `α` at [`dense_index`]`(α)` (`ZERO` for `|α| > MAX_ORDER`).
    dense: Vec<u16>,
    /// `α` per index.
    alpha: Vec<[u8; 3]>,
    /// Index of `α − e_k` (or `ZERO` when `α_k = 0`).
    minus1: Vec<[u16; 3]>,
    /// Index of `α − 2e_k` (or `ZERO`).
    minus2: Vec<[u16; 3]>,
    /// `−(2n−1)/n` and `−(n−1)/n`, `n = |α|`: the recurrence weights of Eq. 5.
    weights: Vec<(f64, f64)>,
    /// For `|α| ≥ 1`: an axis `k` with `α_k ≥ 1` (monomials: `u^α = u^(α−e_k)·u_k`).
    axis: Vec<u8>,
}

/// The slot after the last coefficient: reads as 0 in the scratch arrays.
const ZERO: u16 = COEFFICIENTS as u16;

/// Side of the dense multi-index lookup.
const DENSE: usize = MAX_ORDER + 1;

fn dense_index(a: [u8; 3]) -> usize {
    (usize::from(a[0]) * DENSE + usize::from(a[1])) * DENSE + usize::from(a[2])
}

fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut alpha = Vec::with_capacity(COEFFICIENTS);
        for n in 0..=MAX_ORDER {
            for x in (0..=n).rev() {
                for y in (0..=n - x).rev() {
                    alpha.push([x as u8, y as u8, (n - x - y) as u8]);
                }
            }
        }
        let mut dense = vec![ZERO; DENSE * DENSE * DENSE];
        for (i, a) in alpha.iter().enumerate() {
            dense[dense_index(*a)] = i as u16;
        }
        let index = |a: [u8; 3]| dense[dense_index(a)];
        let minus = |a: [u8; 3], k: usize, d: u8| -> u16 {
            if a[k] < d {
                return ZERO;
            }
            let mut b = a;
            b[k] -= d;
            index(b)
        };
        let minus1 = alpha
            .iter()
            .map(|&a| std::array::from_fn(|k| minus(a, k, 1)))
            .collect();
        let minus2 = alpha
            .iter()
            .map(|&a| std::array::from_fn(|k| minus(a, k, 2)))
            .collect();
        let weights = alpha
            .iter()
            .map(|a| {
                let n = f64::from(a[0] + a[1] + a[2]);
                if n == 0.0 {
                    (0.0, 0.0)
                } else {
                    (-(2.0 * n - 1.0) / n, -(n - 1.0) / n)
                }
            })
            .collect();
        let axis = alpha
            .iter()
            .map(|a| (0..3).find(|&k| a[k] > 0).unwrap_or(0) as u8)
            .collect();
        Table {
            dense,
            alpha,
            minus1,
            minus2,
            weights,
            axis,
        }
    })
}

/// `b_α(s) = ∂^α(1/|s|)/α!` for `|α| ≤ order`, into `b[..coefficients_up_to(order)]`
/// (`b[COEFFICIENTS] = 0` is the padding slot). Eq. 5:
/// `n|s|²·b_α + (2n−1)·Σ_k s_k·b_{α−e_k} + (n−1)·Σ_k b_{α−2e_k} = 0`.
#[cfg(test)]
fn taylor_coefficients(s: [f64; 3], order: usize, b: &mut [f64; COEFFICIENTS + 1]) {
    let t = table();
    let r2 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
    let inv_r2 = 1.0 / r2;
    b[COEFFICIENTS] = 0.0;
    b[0] = inv_r2.sqrt();
    for i in 1..coefficients_up_to(order) {
        let [m0, m1, m2] = t.minus1[i];
        let [n0, n1, n2] = t.minus2[i];
        let (w1, w2) = t.weights[i];
        let first = s[0] * b[m0 as usize] + s[1] * b[m1 as usize] + s[2] * b[m2 as usize];
        let second = b[n0 as usize] + b[n1 as usize] + b[n2 as usize];
        b[i] = (w1 * first + w2 * second) * inv_r2;
    }
}

/// The truncated expansion at `q` straight from Eq. 4 and the recurrence: `(Ω_K(q), Σ|N_α·b_α|)`
/// for the cluster with moments `m` about `centre`. The reference for [`Expansion::evaluate`].
#[cfg(test)]
fn evaluate(m: &Moments, centre: [f64; 3], q: [f64; 3], order: usize) -> (f64, f64) {
    let mut b = [0.0; COEFFICIENTS + 1];
    let s = [centre[0] - q[0], centre[1] - q[1], centre[2] - q[2]];
    taylor_coefficients(s, order, &mut b);
    let (mut sum, mut magnitude) = (0.0, 0.0);
    for i in 1..coefficients_up_to(order) {
        let term = m[i] * b[i];
        sum -= term;
        magnitude += term.abs();
    }
    (sum, magnitude)
}

/// Eq. 8: the bound on `|Ω_S − Ω_K|` for a surface of unsigned area `area` inside the ball of
/// radius `radius` about the centre, seen from distance `distance`. Infinite unless
/// `radius < distance`.
pub fn truncation_bound(area: f64, radius: f64, distance: f64, order: usize) -> f64 {
    if radius.partial_cmp(&distance) != Some(std::cmp::Ordering::Less) {
        return f64::INFINITY;
    }
    let t = radius / distance;
    let k = order as f64;
    let one_minus = 1.0 - t;
    area * GRADIENT_CONSTANT / (distance * distance)
        * t.powi(order as i32)
        * ((k + 1.0) / one_minus + t / (one_minus * one_minus))
}

/// Adds the moments of the fan triangle `(p, a, b)` about `p` (coordinates relative to `p`:
/// `ra = a − p`, `rb = b − p`) to `m`. Eq. 6: with `m⃗ = ra × rb` (twice the vector area),
/// `∫_T n_k u^β dA = m⃗_k/(|β|+2)·∫_0^1 v(μ)^β dμ`, `v(μ) = (1−μ)·ra + μ·rb`, a polynomial of
/// degree `≤ MAX_ORDER − 1` in `μ`, integrated exactly by five Gauss–Legendre points. `sign`
/// (±1) orients the triangle. Returns the triangle's area.
pub fn add_fan_triangle(m: &mut Moments, ra: [f64; 3], rb: [f64; 3], sign: f64) -> f64 {
    // Gauss–Legendre on [0, 1], exact to degree 9 = MAX_ORDER − 1.
    const NODES: [f64; 5] = [
        0.046_910_077_030_668_004,
        0.230_765_344_947_158_45,
        0.5,
        0.769_234_655_052_841_6,
        0.953_089_922_969_332,
    ];
    const WEIGHTS: [f64; 5] = [
        0.118_463_442_528_094_54,
        0.239_314_335_249_683_23,
        0.284_444_444_444_444_45,
        0.239_314_335_249_683_23,
        0.118_463_442_528_094_54,
    ];
    const _: () = assert!(2 * NODES.len() > MAX_ORDER - 1);
    let t = table();
    let normal = [
        ra[1] * rb[2] - ra[2] * rb[1],
        ra[2] * rb[0] - ra[0] * rb[2],
        ra[0] * rb[1] - ra[1] * rb[0],
    ];
    let below = coefficients_up_to(MAX_ORDER - 1);
    // The monomials v(μ)^β at the five nodes side by side (one table lookup serves five products;
    // node-by-node, the lookups dominated the tree's build), then the weighted sums over nodes.
    let v: [[f64; 5]; 3] = std::array::from_fn(|k| {
        std::array::from_fn(|j| (1.0 - NODES[j]) * ra[k] + NODES[j] * rb[k])
    });
    let mut power = [[0.0; 5]; COEFFICIENTS + 1];
    power[0] = [1.0; 5];
    let mut line = [0.0; COEFFICIENTS + 1];
    line[0] = WEIGHTS.iter().sum();
    for i in 1..below {
        let k = t.axis[i] as usize;
        let from = power[t.minus1[i][k] as usize];
        let p: [f64; 5] = std::array::from_fn(|j| from[j] * v[k][j]);
        power[i] = p;
        line[i] = (0..5).map(|j| WEIGHTS[j] * p[j]).sum();
    }
    // N_α = Σ_k α_k ∫ n_k u^(α−e_k) dA, and |α − e_k| + 2 = |α| + 1. `minus1` is the zero slot
    // (`line[ZERO] = 0`) where α_k = 0, so the sum needs no branch.
    let scale: [f64; MAX_ORDER + 1] = std::array::from_fn(|n| sign / (n as f64 + 1.0));
    for i in 1..COEFFICIENTS {
        let a = t.alpha[i];
        let [m0, m1, m2] = t.minus1[i];
        let sum = f64::from(a[0]) * normal[0] * line[m0 as usize]
            + f64::from(a[1]) * normal[1] * line[m1 as usize]
            + f64::from(a[2]) * normal[2] * line[m2 as usize];
        m[i] += scale[usize::from(a[0] + a[1] + a[2])] * sum;
    }
    0.5 * (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt()
}

/// Eq. 7: moments about `c` → moments about `c'`, with `delta = c − c'` (old centre minus new): `N'_γ = Σ_{β≤γ} C(γ, β)·δ^(γ−β)·N_β`, one axis at a time.
pub fn shifted(m: &Moments, delta: [f64; 3]) -> Moments {
    let t = table();
    let mut cur = *m;
    for k in 0..3 {
        if delta[k] == 0.0 {
            continue;
        }
        let mut next = [0.0; COEFFICIENTS];
        let mut powers = [1.0; MAX_ORDER + 1];
        for j in 1..=MAX_ORDER {
            powers[j] = powers[j - 1] * delta[k];
        }
        for i in 0..COEFFICIENTS {
            // Walk β = γ − j·e_k, j = 0..=γ_k, with the binomial C(γ_k, j).
            let g = t.alpha[i][k] as usize;
            let mut idx = i;
            let mut binomial = 1.0;
            let mut sum = 0.0;
            for j in 0..=g {
                sum += binomial * powers[j] * cur[idx];
                if j < g {
                    idx = t.minus1[idx][k] as usize;
                    binomial = binomial * (g - j) as f64 / (j + 1) as f64;
                }
            }
            next[i] = sum;
        }
        cur = next;
    }
    cur
}

/// The expansion of one cluster ready to evaluate: Eq. 4 regrouped by degree (Eq. 5b). Each
/// `b_α(s)·|s|^(2n+1)` is a homogeneous polynomial of degree `n = |α|` in `s`, so
/// `Ω_K(q) = (1/r)·Σ_{1≤|β|≤K} P_β·σ^β`, `σ = s/r²`, `s = c − q`, with
/// `P_β = −Σ_{|α|=|β|} N_α·[σ^β](b_α·r^(2n+1))` computed once per cluster: a query costs one
/// multiply-add per coefficient instead of the recurrence.
#[derive(Clone, Debug)]
pub struct Expansion {
    coefficients: Moments,
    /// Per degree `n`, a bound on `Σ_{|β|=n} Σ_α |N_α·[σ^β](B_α)|` and on the same sums over the
    /// moments' summands: the scale of the rounding errors of the coefficients and of the sum.
    magnitude_by_degree: [f64; MAX_ORDER + 1],
}

/// The polynomials `B_α(s) = b_α(s)·|s|^(2n+1)`: `B_α` has its coefficients over the degree-`n`
/// monomials at `offsets[n]..` in the degree-ordered table. From Eq. 5 multiplied by
/// `|s|^(2n−1)`: `n·B_α = −(2n−1)·Σ_k s_k·B_{α−e_k} − (n−1)·|s|²·Σ_k B_{α−2e_k}`.
fn polynomials() -> &'static Vec<Vec<f64>> {
    static POLY: OnceLock<Vec<Vec<f64>>> = OnceLock::new();
    POLY.get_or_init(|| {
        let t = table();
        let index = |a: [u8; 3]| usize::from(t.dense[dense_index(a)]);
        // Polynomials as dense vectors over all multi-indices (only one degree is non-zero).
        let mut poly: Vec<Vec<f64>> = Vec::with_capacity(COEFFICIENTS);
        for i in 0..COEFFICIENTS {
            let a = t.alpha[i];
            let mut p = vec![0.0; COEFFICIENTS];
            if a == [0; 3] {
                p[0] = 1.0;
                poly.push(p);
                continue;
            }
            let (w1, w2) = t.weights[i];
            for k in 0..3 {
                let j = t.minus1[i][k];
                if j != ZERO {
                    // −(2n−1)/n · s_k · B_{α−e_k}
                    for (m, &c) in poly[j as usize].iter().enumerate() {
                        if c != 0.0 {
                            let mut e = t.alpha[m];
                            e[k] += 1;
                            p[index(e)] += w1 * c;
                        }
                    }
                }
                let j = t.minus2[i][k];
                if j != ZERO {
                    // −(n−1)/n · (s_x² + s_y² + s_z²) · B_{α−2e_k}
                    for (m, &c) in poly[j as usize].iter().enumerate() {
                        if c != 0.0 {
                            for l in 0..3 {
                                let mut e = t.alpha[m];
                                e[l] += 2;
                                p[index(e)] += w2 * c;
                            }
                        }
                    }
                }
            }
            poly.push(p);
        }
        poly
    })
}

impl Expansion {
    /// From moments about the centre of a surface of unsigned area `area` within `radius` of it.
    ///
    /// Magnitudes: `|∇u^α| ≤ n·|u|^(n−1)` (`|u^β| ≤ |u|^|β|`), so every moment, and every summand
    /// that formed it (moments about other centres of the same ball, `|u| ≤ 2·radius`), is at
    /// most `area·n·(2·radius)^(n−1)`.
    pub fn new(moments: &Moments, area: f64, radius: f64) -> Self {
        let t = table();
        let poly = polynomials();
        let mut coefficients = [0.0; COEFFICIENTS];
        let mut magnitude_by_degree = [0.0; MAX_ORDER + 1];
        for i in 1..COEFFICIENTS {
            let a = t.alpha[i];
            let n = usize::from(a[0] + a[1] + a[2]);
            let (lo, hi) = (coefficients_up_to(n - 1), coefficients_up_to(n));
            let bound = area * n as f64 * (2.0 * radius).powi(n as i32 - 1);
            for j in lo..hi {
                let c = poly[i][j];
                coefficients[j] -= moments[i] * c;
                magnitude_by_degree[n] += bound.max(moments[i].abs()) * c.abs();
            }
        }
        Expansion {
            coefficients,
            magnitude_by_degree,
        }
    }

    /// `(Ω_K(q), rounding allowance)` about the expansion's centre (Eq. 5b), from `s = centre −
    /// q` (the caller computes it without cancellation). The allowance is
    /// [`EVALUATION_ROUNDING`] times the sum's magnitude bound `(1/r)·Σ_n M_n·r^−n` (`|σ^β| ≤ r^−n`).
    #[inline]
    pub fn evaluate(&self, s: [f64; 3], order: usize) -> (f64, f64) {
        let r2 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
        let inv_r2 = 1.0 / r2;
        let inv_r = inv_r2.sqrt();
        let sigma = s.map(|c| c * inv_r2);
        let mut px = [1.0; MAX_ORDER + 1];
        let mut py = [1.0; MAX_ORDER + 1];
        let mut pz = [1.0; MAX_ORDER + 1];
        for j in 1..=order {
            px[j] = px[j - 1] * sigma[0];
            py[j] = py[j - 1] * sigma[1];
            pz[j] = pz[j - 1] * sigma[2];
        }
        // The monomials σ^β in the table's order (degree, then x descending, then y descending),
        // then one long dot product with four accumulators.
        let count = coefficients_up_to(order);
        let mut monomials = [0.0; COEFFICIENTS];
        let mut i = 0;
        for n in 0..=order {
            for a in (0..=n).rev() {
                let x = px[a];
                for b in (0..=n - a).rev() {
                    monomials[i] = x * (py[b] * pz[n - a - b]);
                    i += 1;
                }
            }
        }
        let mut acc = [0.0; 4];
        let (c, m) = (&self.coefficients[1..count], &monomials[1..count]);
        for (cc, mm) in c.chunks_exact(4).zip(m.chunks_exact(4)) {
            for l in 0..4 {
                acc[l] += cc[l] * mm[l];
            }
        }
        for l in (c.len() / 4 * 4)..c.len() {
            acc[0] += c[l] * m[l];
        }
        let sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
        let (mut scale, mut inv_rn) = (0.0, 1.0);
        for n in 1..=order {
            inv_rn *= inv_r;
            scale += self.magnitude_by_degree[n] * inv_rn;
        }
        (sum * inv_r, EVALUATION_ROUNDING * scale * inv_r)
    }
}

/// The smallest order whose [`truncation_bound`] is at most `budget`, if any is `≤ MAX_ORDER`
/// (the tests' statement of the bound; the tree picks orders as it builds).
#[cfg(test)]
pub fn order_for(area: f64, radius: f64, distance: f64, budget: f64) -> Option<(usize, f64)> {
    if radius.partial_cmp(&distance) != Some(std::cmp::Ordering::Less) {
        return None;
    }
    (1..=MAX_ORDER)
        .map(|k| (k, truncation_bound(area, radius, distance, k)))
        .find(|&(_, b)| b <= budget)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::spherical::triangle_solid_angle;

    fn lcg(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    fn legendre(l: usize, x: f64) -> f64 {
        let (mut p0, mut p1) = (1.0, x);
        if l == 0 {
            return 1.0;
        }
        for n in 1..l {
            let p2 = ((2 * n + 1) as f64 * x * p1 - n as f64 * p0) / (n + 1) as f64;
            (p0, p1) = (p1, p2);
        }
        p1
    }

    #[test]
    fn taylor_coefficients_sum_to_legendre_terms() {
        // Σ_{|α|=l} b_α(s)·u^α is the degree-l term of 1/|s + u|: |u|^l·P_l(−û·ŝ)/|s|^(l+1).
        let t = table();
        let mut state = 7;
        for _ in 0..50 {
            let s: [f64; 3] = std::array::from_fn(|_| lcg(&mut state) * 4.0);
            let u: [f64; 3] = std::array::from_fn(|_| lcg(&mut state));
            let mut b = [0.0; COEFFICIENTS + 1];
            taylor_coefficients(s, MAX_ORDER, &mut b);
            let (rs, ru) = (
                s.iter().map(|v| v * v).sum::<f64>().sqrt(),
                u.iter().map(|v| v * v).sum::<f64>().sqrt(),
            );
            let cos = -(s[0] * u[0] + s[1] * u[1] + s[2] * u[2]) / (rs * ru);
            for l in 0..=MAX_ORDER {
                let mut sum = 0.0;
                let mut scale = 0.0;
                for i in 0..COEFFICIENTS {
                    let a = t.alpha[i];
                    if (a[0] + a[1] + a[2]) as usize != l {
                        continue;
                    }
                    let term = b[i]
                        * u[0].powi(a[0].into())
                        * u[1].powi(a[1].into())
                        * u[2].powi(a[2].into());
                    sum += term;
                    scale += term.abs();
                }
                let want = ru.powi(l as i32) * legendre(l, cos) / rs.powi(l as i32 + 1);
                assert!(
                    (sum - want).abs() <= 1e-12 * scale.max(want.abs()),
                    "l = {l}: {sum} vs {want}"
                );
            }
        }
    }

    #[test]
    fn legendre_gradient_constant_holds() {
        // l²·P_l(x)² + (1 − x²)·P_l'(x)² ≤ 2l² on [−1, 1] (the constant of Eq. 8).
        for l in 1..=40 {
            for i in 0..=2000 {
                let x = -1.0 + i as f64 / 1000.0;
                let p = legendre(l, x);
                // (1 − x²) P_l' = l (P_{l−1} − x P_l).
                let dp_times = l as f64 * (legendre(l - 1, x) - x * p);
                let g2 = (l * l) as f64 * p * p + dp_times * dp_times / (1.0 - x * x).max(1e-300);
                let g2 = if (1.0 - x * x) < 1e-300 {
                    (l * l) as f64 * p * p
                } else {
                    g2
                };
                assert!(
                    g2 <= 2.0 * (l * l) as f64 * (1.0 + 1e-12),
                    "l = {l}, x = {x}"
                );
            }
        }
    }

    /// A random fan: apex and a chain of vertices, all inside the unit ball about `centre`.
    fn fan(state: &mut u64, n: usize) -> Vec<[f64; 3]> {
        (0..=n)
            .map(|_| std::array::from_fn(|_| lcg(state) * 1.1))
            .collect()
    }

    #[test]
    fn expansion_matches_solid_angle_within_bound() {
        let mut state = 99;
        for trial in 0..40 {
            let pts = fan(&mut state, 6);
            let p = pts[0];
            let mut m = [0.0; COEFFICIENTS];
            let mut area = 0.0;
            for w in pts[1..].windows(2) {
                let ra = std::array::from_fn(|k| w[0][k] - p[k]);
                let rb = std::array::from_fn(|k| w[1][k] - p[k]);
                area += add_fan_triangle(&mut m, ra, rb, 1.0);
            }
            // Move the moments from the apex to the origin: δ = p − 0.
            let m = shifted(&m, p);
            let radius = pts
                .iter()
                .map(|v| v.iter().map(|c| c * c).sum::<f64>().sqrt())
                .fold(0.0, f64::max);
            let expansion = Expansion::new(&m, area, radius);
            let dir: [f64; 3] = std::array::from_fn(|_| lcg(&mut state));
            let norm = dir.iter().map(|c| c * c).sum::<f64>().sqrt();
            for dist in [1.3, 2.0, 4.0, 10.0, 100.0] {
                let d = dist * radius;
                let q: [f64; 3] = std::array::from_fn(|k| dir[k] / norm * d);
                let rel = |v: [f64; 3]| -> [f64; 3] { std::array::from_fn(|k| v[k] - q[k]) };
                let exact: f64 = pts[1..]
                    .windows(2)
                    .map(|w| triangle_solid_angle(rel(p), rel(w[0]), rel(w[1])))
                    .sum();
                for order in 1..=MAX_ORDER {
                    let (value, rounding) = expansion.evaluate(q.map(|c| -c), order);
                    let (reference, _) = evaluate(&m, [0.0; 3], q, order);
                    assert!(
                        (value - reference).abs() <= 1e-13 * (1.0 + reference.abs()),
                        "K = {order}: {value} vs recurrence {reference}"
                    );
                    let bound = truncation_bound(area, radius, d, order) + rounding + 1e-15;
                    let err = (value - exact).abs();
                    assert!(
                        err <= bound,
                        "trial {trial}, r/a = {dist}, K = {order}: err {err:e} > bound {bound:e}"
                    );
                    if dist >= 100.0 && order >= 4 {
                        // The expansion converges: relative error ~t^(K+2).
                        assert!(err < 1e-12 + 1e-9 * exact.abs(), "{err:e} vs {exact:e}");
                    }
                }
            }
        }
    }

    #[test]
    fn shifts_compose() {
        let mut state = 5;
        let pts = fan(&mut state, 4);
        let mut m = [0.0; COEFFICIENTS];
        for w in pts[1..].windows(2) {
            add_fan_triangle(
                &mut m,
                std::array::from_fn(|k| w[0][k] - pts[0][k]),
                std::array::from_fn(|k| w[1][k] - pts[0][k]),
                1.0,
            );
        }
        let once = shifted(&m, [0.3, -0.2, 0.5]);
        let twice = shifted(&shifted(&m, [0.1, -0.25, 0.2]), [0.2, 0.05, 0.3]);
        for i in 0..COEFFICIENTS {
            assert!((once[i] - twice[i]).abs() <= 1e-12 * (1.0 + once[i].abs()));
        }
    }

    #[test]
    fn orders_are_chosen_by_the_bound() {
        assert_eq!(order_for(1.0, 1.0, 1.0, 1.0), None);
        let (k, b) = order_for(1.0, 0.1, 1.0, 1e-8).unwrap();
        assert!(b <= 1e-8 && truncation_bound(1.0, 0.1, 1.0, k - 1) > 1e-8);
        assert_eq!(order_for(1.0, 0.9, 1.0, 1e-12), None);
    }
}
