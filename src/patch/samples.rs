//! Precomputed Gauss–Kronrod samples of boundary curves: the query-independent part of the
//! boundary integral (`docs/patches.md`, "Cached boundary samples").
//!
//! A boundary curve `N(t)` (homogeneous, in the ray frame) is stored *centred*: `N_c(t) =
//! N(t) − N_w(t)·c` with `c` the centre of its control box, so that for a query `q` the curve
//! relative to `q` is `N(t) − N_w(t)·q = N_c(t) − N_w(t)·δ` with `δ = q − c`. The samples
//! `N_c`, `N_c'` at the 15 Kronrod nodes of every dyadic interval down to [`CACHE_LEVELS`]
//! are computed once; a query then pays two multiply-adds per coordinate and the integrand per
//! node, in one loop over the 15 nodes that the compiler vectorises, instead of a de Casteljau
//! evaluation per node. Deeper intervals evaluate the centred curve on the fly.
//!
//! **Rounding.** Centring keeps the magnitudes at the curve's own size: `N_c` carries the
//! de Casteljau rounding of the centred net (`|N_c| ≲ size`), and `N_w δ` is rounded relative to
//! `|δ| ≤ size + ρ`. The integrand's rounding is then relative `ε·(size + ρ)/ρ`, the same order
//! as evaluating the curve relative to `q` (the uncached path); the bound passed to the
//! quadrature (`en`, `edn` of [`super::curve::integrand_with_rounding`]) includes both parts. The
//! evaluator uses the samples only for a piece at least `1/`[`MAX_SIZE_OVER_DISTANCE`] of the
//! centred curve's size away from the query; nearer pieces take the uncached path, so the
//! near-field behaviour (issue 23's seams) is unchanged.

use super::curve::{Form, Homogeneous, eval_with_derivative, evaluation_rounding, split_half};
use super::quadrature::{gauss_kronrod_nodes, gk15_sums};

/// Dyadic levels whose interval samples are stored: level `l` has `2^l` intervals of 15
/// nodes. Most far-field integrals accept the whole curve or its two halves; level 2 covers
/// one more bisection.
pub const CACHE_LEVELS: u32 = 3;

/// The cached path is used for a piece only if the centred curve's magnitude is at most this
/// multiple of the piece's distance from the query: the integrand's relative rounding is then
/// within this factor of the uncached path's.
pub const MAX_SIZE_OVER_DISTANCE: f64 = 8.0;

/// Lanes of the sample arrays: the 15 nodes and one padding lane (a copy of the last node,
/// never summed), so that the integrand loop runs in whole vector registers.
const LANES: usize = 16;

/// Samples of one interval, structure of arrays over its 15 nodes (increasing `t`):
/// `N_c` (x, y, z), `N_w`, and the derivative (the integrand needs no `z'` in its frame).
#[derive(Clone, Debug)]
struct IntervalSamples {
    x: [f64; LANES],
    y: [f64; LANES],
    z: [f64; LANES],
    w: [f64; LANES],
    dx: [f64; LANES],
    dy: [f64; LANES],
    /// `z'`: used only by [`IntervalSamples::rotated`] (the frame's `x'`, `y'` mix all three).
    dz: [f64; LANES],
    dw: [f64; LANES],
}

impl IntervalSamples {
    /// The samples relative to the query at offset `delta`, rotated into the frame whose rows
    /// are `rotation` (the weights are unchanged; `z'` is not kept).
    fn rotated(&self, delta: [f64; 3], rotation: &[[f64; 3]; 3]) -> IntervalSamples {
        let mut out = self.clone();
        let [e1, e2, e3] = rotation;
        for i in 0..LANES {
            let w = self.w[i];
            let r = [
                self.x[i] - w * delta[0],
                self.y[i] - w * delta[1],
                self.z[i] - w * delta[2],
            ];
            let dw = self.dw[i];
            let dr = [
                self.dx[i] - dw * delta[0],
                self.dy[i] - dw * delta[1],
                self.dz[i] - dw * delta[2],
            ];
            let dot = |e: &[f64; 3], v: [f64; 3]| e[0] * v[0] + e[1] * v[1] + e[2] * v[2];
            out.x[i] = dot(e1, r);
            out.y[i] = dot(e2, r);
            out.z[i] = dot(e3, r);
            out.dx[i] = dot(e1, dr);
            out.dy[i] = dot(e2, dr);
        }
        out
    }

    /// The centred curve at the 15 nodes of the interval with centre `c` and half-length `h`.
    fn at_nodes(centred: &[Homogeneous], c: f64, h: f64) -> IntervalSamples {
        let (nodes, _, _) = gauss_kronrod_nodes();
        let mut s = IntervalSamples {
            x: [0.0; LANES],
            y: [0.0; LANES],
            z: [0.0; LANES],
            w: [0.0; LANES],
            dx: [0.0; LANES],
            dy: [0.0; LANES],
            dz: [0.0; LANES],
            dw: [0.0; LANES],
        };
        for i in 0..LANES {
            let (p, dp) = eval_with_derivative(centred, c + h * nodes[i.min(14)]);
            (s.x[i], s.y[i], s.z[i], s.w[i]) = (p[0], p[1], p[2], p[3]);
            (s.dx[i], s.dy[i], s.dz[i], s.dw[i]) = (dp[0], dp[1], dp[2], dp[3]);
        }
        s
    }
}

/// One boundary curve with its centred samples.
#[derive(Clone, Debug)]
pub struct CurveSamples {
    /// The curve's homogeneous control points in the ray frame, not centred (the uncached
    /// path subtracts the query from these, as before the cache existed).
    pub frame_ctrl: Vec<Homogeneous>,
    /// Centred control points.
    centred: Vec<Homogeneous>,
    /// The centre `c` (frame coordinates).
    centre: [f64; 3],
    /// De Casteljau rounding bounds of the centred curve (`N_c`, `N_c'`), including the
    /// centring's own rounding.
    en0: f64,
    edn0: f64,
    /// Largest centred coordinate magnitude.
    size: f64,
    /// Largest weight and largest `|N_w'|` over the curve (bounds from the control points).
    w_max: f64,
    dw_max: f64,
    /// The curve's degree.
    degree: f64,
    /// Control boxes (centred) of the dyadic pieces at levels `0..=CACHE_LEVELS`, at index
    /// `2^l − 1 + k`.
    boxes: Vec<([f64; 3], [f64; 3])>,
    /// Samples of the dyadic intervals, same indexing.
    samples: Vec<IntervalSamples>,
}

impl CurveSamples {
    /// Samples of the curve with homogeneous frame control points `ctrl`.
    pub fn new(ctrl: Vec<Homogeneous>) -> CurveSamples {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for h in &ctrl {
            for a in 0..3 {
                let x = h[a] / h[3];
                lo[a] = lo[a].min(x);
                hi[a] = hi[a].max(x);
            }
        }
        let centre: [f64; 3] = std::array::from_fn(|a| 0.5 * lo[a] + 0.5 * hi[a]);
        let centred: Vec<Homogeneous> = ctrl
            .iter()
            .map(|h| {
                let w = h[3];
                [
                    h[0] - w * centre[0],
                    h[1] - w * centre[1],
                    h[2] - w * centre[2],
                    w,
                ]
            })
            .collect();
        let size = centred.iter().fold(0.0f64, |a, h| {
            a.max(h[0].abs()).max(h[1].abs()).max(h[2].abs())
        });
        let (en, edn) = evaluation_rounding(&centred);
        // Centring `h − w·c` rounds twice per coordinate, relative to `|h| + |w c|`; the
        // derivative differences these errors (`2d` of them at most).
        let raw = ctrl.iter().fold(0.0f64, |a, h| {
            a.max(h[0].abs()).max(h[1].abs()).max(h[2].abs())
        });
        let w_max = ctrl.iter().fold(0.0f64, |a, h| a.max(h[3]));
        let cmax = centre.iter().fold(0.0f64, |a, c| a.max(c.abs()));
        let centring = 2.0 * f64::EPSILON * (raw + w_max * cmax);
        let d = (ctrl.len() - 1) as f64;
        let en0 = en + centring;
        let edn0 = edn + 2.0 * d.max(1.0) * centring;
        let dw_max = d * ctrl
            .windows(2)
            .fold(0.0f64, |a, p| a.max((p[1][3] - p[0][3]).abs()));
        let count = (1usize << (CACHE_LEVELS + 1)) - 1;
        let mut boxes = Vec::with_capacity(count);
        let mut samples = Vec::with_capacity(count);
        // Pieces level by level (each level's pieces are the halves of the previous level's).
        let mut pieces = vec![centred.clone()];
        for l in 0..=CACHE_LEVELS {
            let n = 1u64 << l;
            for (k, piece) in pieces.iter().enumerate() {
                boxes.push(super::curve::control_box(piece));
                let (a, b) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
                samples.push(IntervalSamples::at_nodes(
                    &centred,
                    0.5 * (a + b),
                    0.5 * (b - a),
                ));
            }
            pieces = pieces
                .iter()
                .flat_map(|p| {
                    let (a, b) = split_half(p);
                    [a, b]
                })
                .collect();
        }
        CurveSamples {
            frame_ctrl: ctrl,
            centred,
            centre,
            en0,
            edn0,
            size,
            w_max,
            dw_max,
            degree: d,
            boxes,
            samples,
        }
    }

    /// The query relative to the centre, `δ = q − c` (frame coordinates, one rounding each).
    #[inline]
    pub fn offset(&self, q: [f64; 3]) -> [f64; 3] {
        [
            q[0] - self.centre[0],
            q[1] - self.centre[1],
            q[2] - self.centre[2],
        ]
    }

    /// `(distance, size)` of the dyadic piece `(level, index)` (`level ≤ CACHE_LEVELS`) from the
    /// query at offset `delta`, as `eval::distance_and_size` measures a piece relative to the
    /// query: distance to its control box and the box's diagonal.
    #[inline]
    pub fn piece_distance_and_size(&self, level: u32, index: u64, delta: [f64; 3]) -> (f64, f64) {
        let (lo, hi) = self.boxes[(1usize << level) - 1 + index as usize];
        let mut d2 = 0.0;
        let mut s2 = 0.0;
        for a in 0..3 {
            let (l, h) = (lo[a] - delta[a], hi[a] - delta[a]);
            let gap = l.max(-h).max(0.0);
            d2 += gap * gap;
            s2 += (h - l) * (h - l);
        }
        (d2.sqrt(), s2.sqrt())
    }

    /// Whether the samples are accurate enough for a piece at `distance` from the query (see
    /// [`MAX_SIZE_OVER_DISTANCE`]).
    #[inline]
    pub fn usable_at(&self, distance: f64) -> bool {
        self.size <= MAX_SIZE_OVER_DISTANCE * distance
    }

    /// Rounding bounds `(en, edn)` of `N_c − N_w δ` and its derivative `N_c' − N_w' δ` for the
    /// offset `delta`, per component: the centred curve's own bounds (`en0`, `edn0`), the
    /// de Casteljau rounding of `N_w` and `N_w'` (as [`evaluation_rounding`] bounds `N` and
    /// `N'`, with the weights in place of the coordinates) times `|δ|`, and one rounding each
    /// for `δ` itself, the product and the difference.
    #[inline]
    pub fn rounding(&self, delta: [f64; 3]) -> (f64, f64) {
        let eps = f64::EPSILON;
        let d = self.degree;
        let dmax = delta[0].abs().max(delta[1].abs()).max(delta[2].abs());
        let ew = 3.0 * (d + 1.0) * eps * self.w_max;
        let edw = 2.0 * d.max(1.0) * ew + 3.0 * eps * d * self.w_max;
        let en = self.en0 + dmax * (ew + 1.5 * eps * self.w_max) + 0.5 * eps * self.size;
        let edn = self.edn0 + dmax * (edw + 1.5 * eps * self.dw_max) + eps * d.max(1.0) * self.size;
        (en, edn)
    }

    /// [`rounding`](Self::rounding) after the rotation into an orthonormal ray frame (as
    /// [`rule_rotated`](Self::rule_rotated) applies it): each frame component is a dot product
    /// of three, `√3` times a component's bound plus three roundings of `|r|`.
    #[inline]
    pub fn rounding_rotated(&self, delta: [f64; 3]) -> (f64, f64) {
        let (en, edn) = self.rounding(delta);
        let eps = f64::EPSILON;
        let dmax = delta[0].abs().max(delta[1].abs()).max(delta[2].abs());
        let r = 1.8 * (self.size + self.w_max * dmax);
        let dr = 1.8 * (2.0 * self.degree.max(1.0) * self.size + self.dw_max * dmax);
        (1.8 * en + 4.0 * eps * r, 1.8 * edn + 4.0 * eps * dr)
    }

    /// [`rule`](Self::rule) for samples stored in world coordinates and a ray frame given by
    /// the rows of `rotation` (orthonormal: `e1`, `e2`, ray direction), with rounding bounds
    /// from [`rounding_rotated`](Self::rounding_rotated) as `(en, edn)`.
    pub fn rule_rotated(
        &self,
        form: Form,
        level: u32,
        index: u64,
        delta: [f64; 3],
        rotation: &[[f64; 3]; 3],
        (en, edn): (f64, f64),
    ) -> (f64, f64, f64, f64) {
        let h = 0.5f64.powi(level as i32 + 1);
        if level <= CACHE_LEVELS {
            let s = &self.samples[(1usize << level) - 1 + index as usize];
            return interval_sums(&s.rotated(delta, rotation), form, [0.0; 3], en, edn, h);
        }
        let c = (2 * index + 1) as f64 * h;
        let s = IntervalSamples::at_nodes(&self.centred, c, h);
        interval_sums(&s.rotated(delta, rotation), form, [0.0; 3], en, edn, h)
    }

    /// The rule sums ([`gk15_sums`]) of `α_form` on the dyadic interval `(level, index)` of
    /// `[0, 1]` for the query at offset `delta`, with rounding bounds `(en, edn)` from
    /// [`rounding`](Self::rounding).
    pub fn rule(
        &self,
        form: Form,
        level: u32,
        index: u64,
        delta: [f64; 3],
        en: f64,
        edn: f64,
    ) -> (f64, f64, f64, f64) {
        let h = 0.5f64.powi(level as i32 + 1);
        if level <= CACHE_LEVELS {
            let s = &self.samples[(1usize << level) - 1 + index as usize];
            return interval_sums(s, form, delta, en, edn, h);
        }
        // Deeper than the cache: the centred curve at this interval's nodes.
        let c = (2 * index + 1) as f64 * h;
        let s = IntervalSamples::at_nodes(&self.centred, c, h);
        interval_sums(&s, form, delta, en, edn, h)
    }
}

/// [`super::curve::integrand_with_rounding`] at the 15 nodes of `s` shifted by `−N_w δ`, in one
/// branch-free loop, then the rule sums.
#[inline]
fn interval_sums(
    s: &IntervalSamples,
    form: Form,
    delta: [f64; 3],
    en: f64,
    edn: f64,
    h: f64,
) -> (f64, f64, f64, f64) {
    // `z` of `integrand_with_rounding`: the frame height, negated for `α↑`.
    let (num_sign, z_sign) = match form {
        Form::Down => (-1.0, 1.0),
        Form::Up => (1.0, -1.0),
    };
    let mut f = [0.0f64; LANES];
    let mut noise = [0.0f64; LANES];
    // Branch-free (both sides of the `ρ − z` choice are computed, reciprocals shared), so that
    // the loop runs two or four lanes at a time.
    for i in 0..LANES {
        let w = s.w[i];
        let x = s.x[i] - w * delta[0];
        let y = s.y[i] - w * delta[1];
        let zr = s.z[i] - w * delta[2];
        let dw = s.dw[i];
        let dx = s.dx[i] - dw * delta[0];
        let dy = s.dy[i] - dw * delta[1];
        let cross_z = x * dy - y * dx;
        let xy2 = x * x + y * y;
        let rho = (xy2 + zr * zr).sqrt();
        let z = z_sign * zr;
        // ρ − z without cancellation (as the scalar integrand): ρ² − z² = x² + y² for z > 0.
        let far_side = rho - z;
        let near_side = xy2 / (rho + z);
        let rho_minus_z = if z <= 0.0 { far_side } else { near_side };
        let den = rho * rho_minus_z;
        let inv_den = 1.0 / den;
        let inv_rho = 1.0 / rho;
        // 1/(ρ − z) = ρ/den.
        let inv_rho_minus_z = rho * inv_den;
        let valid = den != 0.0 && den.is_finite();
        let value = num_sign * cross_z * inv_den;
        let dn_abs = dx.abs().max(dy.abs());
        let n_abs = x.abs().max(y.abs());
        let num_err = 2.0 * (en * dn_abs + n_abs * edn);
        // The reciprocals carry one more rounding each: 8ε → 12ε on the relative part.
        let bound = num_err * inv_den
            + value.abs() * (1.8 * en * inv_rho + 3.5 * en * inv_rho_minus_z + 12.0 * f64::EPSILON);
        f[i] = if valid { value } else { 0.0 };
        noise[i] = if valid { bound } else { 0.0 };
    }
    let f: &[f64; 15] = f[..15].try_into().expect("15 lanes");
    let noise: &[f64; 15] = noise[..15].try_into().expect("15 lanes");
    gk15_sums(f, noise, h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patch::curve::integrand_with_rounding;
    use crate::patch::quadrature::gk15;

    /// A rational cubic in general position.
    fn curve() -> Vec<Homogeneous> {
        let pts = [
            ([0.3, -0.2, 0.1], 1.0),
            ([0.5, 0.4, -0.3], 0.7),
            ([-0.1, 0.6, 0.2], 1.3),
            ([-0.4, 0.1, 0.5], 0.9),
        ];
        pts.iter()
            .map(|&(p, w)| [w * p[0], w * p[1], w * p[2], w])
            .collect()
    }

    #[test]
    fn rotated_rule_matches_the_direct_rule_in_the_rotated_frame() {
        let ctrl = curve();
        let samples = CurveSamples::new(ctrl.clone());
        // An orthonormal frame (rows), as `step::eval::RayFrame` builds them.
        let (c, s) = (0.6f64, 0.8f64);
        let rotation = [[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]];
        let q = [1.5, -0.7, 2.0];
        let rel: Vec<Homogeneous> = ctrl
            .iter()
            .map(|h| {
                let r = [h[0] - h[3] * q[0], h[1] - h[3] * q[1], h[2] - h[3] * q[2]];
                let f = rotation.map(|e| e[0] * r[0] + e[1] * r[1] + e[2] * r[2]);
                [f[0], f[1], f[2], h[3]]
            })
            .collect();
        let delta = samples.offset(q);
        let (en, edn) = samples.rounding_rotated(delta);
        let (en_direct, edn_direct) = evaluation_rounding(&rel);
        for (level, index) in [(0u32, 0u64), (2, 3), (4, 9)] {
            let n = (1u64 << level) as f64;
            let direct = gk15(
                &mut |t| {
                    let (p, dp) = eval_with_derivative(&rel, t);
                    integrand_with_rounding(Form::Down, p, dp, en_direct, edn_direct)
                },
                index as f64 / n,
                (index + 1) as f64 / n,
            );
            let cached =
                samples.rule_rotated(Form::Down, level, index, delta, &rotation, (en, edn));
            assert!(
                (cached.0 - direct.0).abs() <= 1e-13 * direct.2,
                "{cached:?} {direct:?}"
            );
            assert!(
                (cached.1 - direct.1).abs() <= 1e-13 * direct.2,
                "{cached:?} {direct:?}"
            );
            assert!((cached.0 - direct.0).abs() <= cached.3 + direct.3);
            assert!(cached.3 <= 16.0 * direct.3, "{cached:?} {direct:?}");
        }
    }

    #[test]
    fn cached_rule_matches_the_direct_rule() {
        let ctrl = curve();
        let samples = CurveSamples::new(ctrl.clone());
        for q in [[2.0, 1.0, -0.5], [-1.5, 0.3, 2.5], [0.1, -3.0, 0.2]] {
            let rel: Vec<Homogeneous> = ctrl
                .iter()
                .map(|h| {
                    [
                        h[0] - h[3] * q[0],
                        h[1] - h[3] * q[1],
                        h[2] - h[3] * q[2],
                        h[3],
                    ]
                })
                .collect();
            let delta = samples.offset(q);
            let (en, edn) = samples.rounding(delta);
            let (en_direct, edn_direct) = evaluation_rounding(&rel);
            for form in [Form::Down, Form::Up] {
                // Levels inside and beyond the cache.
                for (level, index) in [(0u32, 0u64), (1, 1), (3, 5), (5, 17)] {
                    let n = (1u64 << level) as f64;
                    let (a, b) = (index as f64 / n, (index + 1) as f64 / n);
                    let direct = gk15(
                        &mut |t| {
                            let (p, dp) = eval_with_derivative(&rel, t);
                            integrand_with_rounding(form, p, dp, en_direct, edn_direct)
                        },
                        a,
                        b,
                    );
                    let cached = samples.rule(form, level, index, delta, en, edn);
                    let scale = direct.2.max(1e-300);
                    assert!(
                        (cached.0 - direct.0).abs() <= 1e-13 * scale,
                        "{cached:?} {direct:?}"
                    );
                    assert!(
                        (cached.1 - direct.1).abs() <= 1e-13 * scale,
                        "{cached:?} {direct:?}"
                    );
                    assert!((cached.2 - direct.2).abs() <= 1e-13 * scale);
                    // The rounding bound covers the difference and stays at the rounding level
                    // of the uncached path (both are worst-case bounds).
                    assert!((cached.0 - direct.0).abs() <= cached.3 + direct.3);
                    assert!(cached.3 <= 16.0 * direct.3, "{cached:?} {direct:?}");
                }
            }
        }
    }
}
