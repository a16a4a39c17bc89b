//! The surfaces of B-rep faces: their parameterisation (as STEP defines it), the inversion
//! `point → (u, v)` used to map 3D trimming curves into the parameter plane, and their exact
//! rational Bézier patches over a parameter rectangle.

use super::super::curve::Homogeneous;
use super::super::model::Patch;
use super::nurbs::{euc, hom, unit_arcs};
use super::{add, scale};
use crate::base::vec3::{cross, dot, norm, sub};

use std::f64::consts::{FRAC_PI_2, TAU};

/// An orthonormal placement (`AXIS2_PLACEMENT_3D`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Origin.
    pub o: [f64; 3],
    /// First axis (ref_direction made orthogonal to `z`).
    pub x: [f64; 3],
    /// `z × x`.
    pub y: [f64; 3],
    /// Axis.
    pub z: [f64; 3],
}

impl Frame {
    fn local(&self, p: [f64; 3]) -> [f64; 3] {
        let d = sub(p, self.o);
        [dot(d, self.x), dot(d, self.y), dot(d, self.z)]
    }
    fn world(&self, a: f64, b: f64, c: f64) -> [f64; 3] {
        add(
            self.o,
            add(scale(self.x, a), add(scale(self.y, b), scale(self.z, c))),
        )
    }
}

/// How a patch parameter in `[0, 1]` maps to its surface parameter over `[a0, a1]`.
///
/// B-spline pieces map linearly. The elementary surfaces' angles do not: their patches are
/// rational quadratic arcs ([`unit_arcs`]), whose parameter `s` runs linearly in `tan` of half
/// the angle from the arc's middle, not in the angle. A hit's `(u, v)` must be the surface's own
/// parameter (the one [`Surface::invert`] gives the trimming loops): on a 90° arc the linear
/// reading is off by up to 1.2° — harmless where a face's loops run along iso-lines (arc ends
/// are exact), wrong by that much along a trimming curve that crosses the arcs obliquely
/// (`boxed_sphere.step`'s fillet cylinders ending in corner blends).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamMap {
    /// `a0 + s (a1 − a0)`.
    Linear,
    /// `mid + 2 atan(tan(half/2) (2s − 1))`, `mid`/`half` the middle/half-span of `[a0, a1]`.
    Arc,
}

impl ParamMap {
    /// The surface parameter at `s` over `[a0, a1]` and its derivative `d/ds`.
    pub fn at(self, a: [f64; 2], s: f64) -> (f64, f64) {
        match self {
            ParamMap::Linear => (a[0] + s * (a[1] - a[0]), a[1] - a[0]),
            ParamMap::Arc => {
                let mid = 0.5 * (a[0] + a[1]);
                let k = (0.25 * (a[1] - a[0])).tan();
                let x = k * (2.0 * s - 1.0);
                (mid + 2.0 * x.atan(), 4.0 * k / (1.0 + x * x))
            }
        }
    }

    /// The patch parameter of the surface parameter `x` over `[a0, a1]` (inverse of [`Self::at`]).
    pub fn inverse(self, a: [f64; 2], x: f64) -> f64 {
        match self {
            ParamMap::Linear => (x - a[0]) / (a[1] - a[0]),
            ParamMap::Arc => {
                let mid = 0.5 * (a[0] + a[1]);
                let k = (0.25 * (a[1] - a[0])).tan();
                0.5 * (1.0 + (0.5 * (x - mid)).tan() / k)
            }
        }
    }
}

/// One Bézier patch of a face with its rectangle in the surface's `(u, v)` parameters: patch
/// row parameter `s ∈ [0, 1]` ↦ `u`, column parameter `t` ↦ `v` (both increasing, through
/// [`ParamMap`]s).
#[derive(Clone, Debug)]
pub struct UvPatch {
    /// The patch (rows along `u`).
    pub patch: Patch,
    /// `[u0, u1]`.
    pub u: [f64; 2],
    /// `[v0, v1]`.
    pub v: [f64; 2],
    /// How `s` maps to `u` and `t` to `v`.
    pub map: [ParamMap; 2],
}

impl UvPatch {
    /// The patch parameters `(s, t)` of `(u, v)`.
    pub fn local(&self, uv: [f64; 2]) -> [f64; 2] {
        [
            self.map[0].inverse(self.u, uv[0]),
            self.map[1].inverse(self.v, uv[1]),
        ]
    }
    /// `(u, v)` of patch parameters.
    pub fn global(&self, st: [f64; 2]) -> [f64; 2] {
        [
            self.map[0].at(self.u, st[0]).0,
            self.map[1].at(self.v, st[1]).0,
        ]
    }
}

/// A face's surface.
#[derive(Clone, Debug)]
pub enum Surface {
    /// `o + u x + v y`.
    Plane(Frame),
    /// `o + r (cos u x + sin u y) + v z`.
    Cylinder(Frame, f64),
    /// `o + (r + v tan α)(cos u x + sin u y) + v z` (`tan α` stored).
    Cone(Frame, f64, f64),
    /// `o + r cos v (cos u x + sin u y) + r sin v z`.
    Sphere(Frame, f64),
    /// `o + (R + r cos v)(cos u x + sin u y) + r sin v z`.
    Torus(Frame, f64, f64),
    /// `C(u) + v V` over the swept curve's Bézier pieces `(t0, t1, control points)`.
    Extrusion(Vec<(f64, f64, Vec<Homogeneous>)>, [f64; 3]),
    /// B-splines and surfaces of revolution: Bézier patches over their whole domain.
    Patches {
        /// The patches.
        patches: Vec<UvPatch>,
        /// Period in `u` if the surface closes up across its `u` domain.
        period_u: Option<f64>,
        /// Period in `v` likewise.
        period_v: Option<f64>,
        /// Sample points `(patch, (s, t), point)`: starting points of the inversion.
        samples: Vec<(usize, [f64; 2], [f64; 3])>,
    },
}

impl Surface {
    /// A patch-set surface with its inversion samples (7 × 7 per patch, without those on a
    /// collapsed edge: at a pole every `u` is the same point, and Newton's method started
    /// there on the wrong side — up to 180° away — cannot turn `u`).
    pub fn from_patches(
        patches: Vec<UvPatch>,
        period_u: Option<f64>,
        period_v: Option<f64>,
    ) -> Surface {
        let mut samples = Vec::with_capacity(patches.len() * 49);
        for (k, up) in patches.iter().enumerate() {
            for i in 0..=6 {
                for j in 0..=6 {
                    let st = [i as f64 / 6.0, j as f64 / 6.0];
                    let (x, ds, dt) = up.patch.eval_with_partials(st[0], st[1]);
                    let (a, b) = (norm(ds), norm(dt));
                    if a.min(b) > 1e-9 * a.max(b) {
                        samples.push((k, st, x));
                    }
                }
            }
        }
        Surface::Patches {
            patches,
            period_u,
            period_v,
            samples,
        }
    }

    /// A short name for statistics.
    pub fn kind(&self) -> &'static str {
        match self {
            Surface::Plane(_) => "plane",
            Surface::Cylinder(..) => "cylinder",
            Surface::Cone(..) => "cone",
            Surface::Sphere(..) => "sphere",
            Surface::Torus(..) => "torus",
            Surface::Extrusion(..) => "linear extrusion",
            Surface::Patches { .. } => "B-spline / revolution",
        }
    }

    /// Periods of `u` and `v`.
    pub fn periods(&self) -> (Option<f64>, Option<f64>) {
        match self {
            Surface::Plane(_) | Surface::Extrusion(..) => (None, None),
            Surface::Cylinder(..) | Surface::Cone(..) | Surface::Sphere(..) => (Some(TAU), None),
            Surface::Torus(..) => (Some(TAU), Some(TAU)),
            Surface::Patches {
                period_u, period_v, ..
            } => (*period_u, *period_v),
        }
    }

    /// `(u, v)` of the point of the surface closest to `p` (closed form for the elementary
    /// surfaces; Gauss–Newton from the nearest sample or from `hint` otherwise). A periodic
    /// parameter is returned in the period nearest `hint`.
    pub fn invert(&self, p: [f64; 3], hint: Option<[f64; 2]>) -> [f64; 2] {
        let mut uv = match self {
            Surface::Plane(f) => {
                let l = f.local(p);
                [l[0], l[1]]
            }
            Surface::Cylinder(f, _) | Surface::Cone(f, _, _) => {
                let l = f.local(p);
                let u = match hint {
                    // A cone's apex: every u is the same point.
                    Some(h) if l[0].hypot(l[1]) <= 1e-15 * norm(l) => h[0],
                    _ => angle(l[1], l[0], hint.map(|h| h[0])),
                };
                [u, l[2]]
            }
            Surface::Sphere(f, r) => {
                let l = f.local(p);
                // At a pole every u is the same point: keep the neighbour's u (the loop then
                // runs along the pole's line v = ±π/2 in the parameter plane).
                let u = match hint {
                    Some(h) if l[0].hypot(l[1]) <= 1e-12 * r => h[0],
                    _ => angle(l[1], l[0], hint.map(|h| h[0])),
                };
                [u, l[2].atan2(l[0].hypot(l[1]))]
            }
            Surface::Torus(f, big, _) => {
                let l = f.local(p);
                let rho = l[0].hypot(l[1]) - big;
                [
                    angle(l[1], l[0], hint.map(|h| h[0])),
                    angle(l[2], rho, hint.map(|h| h[1])),
                ]
            }
            Surface::Extrusion(pieces, v) => {
                let vv = dot(*v, *v);
                // Project along V: the closest point's u is the closest point of the projected
                // curve (exact for the plane ⊥ V), then v from the offset along V.
                let project = |q: [f64; 3]| sub(q, scale(*v, dot(q, *v) / vv));
                let pr: Vec<(f64, f64, Vec<Homogeneous>)> = pieces
                    .iter()
                    .map(|(a, b, c)| {
                        let cc = c
                            .iter()
                            .map(|h| {
                                let q = project([h[0], h[1], h[2]]);
                                [q[0], q[1], q[2], h[3]]
                            })
                            .collect();
                        (*a, *b, cc)
                    })
                    .collect();
                let u = invert_curve(&pr, project(p));
                let c = curve_point(pieces, u);
                [u, dot(sub(p, c), *v) / vv]
            }
            Surface::Patches {
                patches, samples, ..
            } => invert_patches(patches, samples, p, hint),
        };
        if let (Some(h), (pu, pv)) = (hint, self.periods()) {
            if let Some(pu) = pu {
                uv[0] += pu * ((h[0] - uv[0]) / pu).round();
            }
            if let Some(pv) = pv {
                uv[1] += pv * ((h[1] - uv[1]) / pv).round();
            }
        }
        uv
    }

    /// The point at `(u, v)` (`None` for an extrusion, and outside a non-periodic patch
    /// surface's domain).
    pub fn point(&self, uv: [f64; 2]) -> Option<[f64; 3]> {
        let [u, v] = uv;
        Some(match self {
            Surface::Plane(f) => f.world(u, v, 0.0),
            Surface::Cylinder(f, r) => f.world(r * u.cos(), r * u.sin(), v),
            Surface::Cone(f, r, tan) => {
                let rr = r + v * tan;
                f.world(rr * u.cos(), rr * u.sin(), v)
            }
            Surface::Sphere(f, r) => {
                f.world(r * v.cos() * u.cos(), r * v.cos() * u.sin(), r * v.sin())
            }
            Surface::Torus(f, big, r) => {
                let rr = big + r * v.cos();
                f.world(rr * u.cos(), rr * u.sin(), r * v.sin())
            }
            Surface::Extrusion(..) => return None,
            Surface::Patches {
                patches,
                period_u,
                period_v,
                ..
            } => {
                let mut dom = [
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                ];
                for p in patches {
                    dom = [
                        dom[0].min(p.u[0]),
                        dom[1].max(p.u[1]),
                        dom[2].min(p.v[0]),
                        dom[3].max(p.v[1]),
                    ];
                }
                // Periodic parameters wrap; the others are clamped to the domain (a pcurve
                // ending a rounding error outside it).
                let wrap = |x: f64, lo: f64, hi: f64, period: Option<f64>| match period {
                    Some(p) => (lo + (x - lo).rem_euclid(p)).min(hi),
                    None => x.clamp(lo, hi),
                };
                return self.patch_point([
                    wrap(u, dom[0], dom[1], *period_u),
                    wrap(v, dom[2], dom[3], *period_v),
                ]);
            }
        })
    }

    /// The point at `(u, v)` of a patch-set surface (`None` for the others, whose inversion is
    /// in closed form, and outside the domain).
    pub fn patch_point(&self, uv: [f64; 2]) -> Option<[f64; 3]> {
        let Surface::Patches { patches, .. } = self else {
            return None;
        };
        let up = patches.iter().find(|up| {
            up.u[0] <= uv[0] && uv[0] <= up.u[1] && up.v[0] <= uv[1] && uv[1] <= up.v[1]
        })?;
        let st = up.local(uv);
        Some(up.patch.eval(st[0], st[1]))
    }

    /// The surface's natural `v` bounds where it has them (the sphere's poles).
    pub fn v_bounds(&self) -> Option<[f64; 2]> {
        match self {
            Surface::Sphere(..) => Some([-FRAC_PI_2, FRAC_PI_2]),
            _ => None,
        }
    }

    /// Exact rational Bézier patches covering `[u0, u1] × [v0, v1]` (elementary surfaces and
    /// extrusions); for [`Surface::Patches`] the patches meeting that rectangle.
    pub fn patches(&self, u: [f64; 2], v: [f64; 2]) -> Result<Vec<UvPatch>, String> {
        let mut out = Vec::new();
        // Product of a u-direction list of arcs/segments and a v-direction list; `point(a, b)`
        // maps the u-factor control value and the v-factor value to a Euclidean point.
        type Factor = (ParamMap, Vec<(f64, f64, Vec<([f64; 2], f64)>)>);
        let arcs = |a0: f64, a1: f64| -> Factor {
            let n = unit_arcs(a0, a1).len();
            let pieces = unit_arcs(a0, a1)
                .into_iter()
                .enumerate()
                .map(|(k, arc)| {
                    let lo = a0 + (a1 - a0) * k as f64 / n as f64;
                    let hi = if k + 1 == n {
                        a1
                    } else {
                        a0 + (a1 - a0) * (k + 1) as f64 / n as f64
                    };
                    (lo, hi, arc.to_vec())
                })
                .collect();
            (ParamMap::Arc, pieces)
        };
        let line = |a0: f64, a1: f64| -> Factor {
            (
                ParamMap::Linear,
                vec![(a0, a1, vec![([a0, 0.0], 1.0), ([a1, 0.0], 1.0)])],
            )
        };
        let mut product =
            |fu: Factor, fv: Factor, point: &dyn Fn([f64; 2], [f64; 2]) -> [f64; 3]| {
                for (u0, u1, cu) in &fu.1 {
                    for (v0, v1, cv) in &fv.1 {
                        let mut pts = Vec::new();
                        let mut ws = Vec::new();
                        for (a, wa) in cu {
                            for (b, wb) in cv {
                                pts.push(point(*a, *b));
                                ws.push(wa * wb);
                            }
                        }
                        let patch = Patch::rational(cu.len() - 1, cv.len() - 1, pts, ws)
                            .map_err(|e| e.to_string())?;
                        out.push(UvPatch {
                            patch,
                            u: [*u0, *u1],
                            v: [*v0, *v1],
                            map: [fu.0, fv.0],
                        });
                    }
                }
                Ok::<(), String>(())
            };
        match self {
            Surface::Plane(f) => {
                let f = *f;
                product(line(u[0], u[1]), line(v[0], v[1]), &|a, b| {
                    f.world(a[0], b[0], 0.0)
                })?
            }
            Surface::Cylinder(f, r) => {
                let (f, r) = (*f, *r);
                product(arcs(u[0], u[1]), line(v[0], v[1]), &|a, b| {
                    f.world(r * a[0], r * a[1], b[0])
                })?
            }
            Surface::Cone(f, r, tan) => {
                let (f, r, tan) = (*f, *r, *tan);
                product(arcs(u[0], u[1]), line(v[0], v[1]), &|a, b| {
                    let rr = r + b[0] * tan;
                    f.world(rr * a[0], rr * a[1], b[0])
                })?
            }
            Surface::Sphere(f, r) => {
                let (f, r) = (*f, *r);
                product(arcs(u[0], u[1]), arcs(v[0], v[1]), &|a, b| {
                    f.world(r * b[0] * a[0], r * b[0] * a[1], r * b[1])
                })?
            }
            Surface::Torus(f, big, r) => {
                let (f, big, r) = (*f, *big, *r);
                product(arcs(u[0], u[1]), arcs(v[0], v[1]), &|a, b| {
                    let rr = big + r * b[0];
                    f.world(rr * a[0], rr * a[1], r * b[1])
                })?
            }
            Surface::Extrusion(pieces, dir) => {
                for (t0, t1, c) in pieces {
                    if *t1 <= u[0] || *t0 >= u[1] {
                        continue;
                    }
                    let mut pts = Vec::new();
                    let mut ws = Vec::new();
                    for h in c {
                        for vv in [v[0], v[1]] {
                            pts.push(add(euc(*h), scale(*dir, vv)));
                            ws.push(h[3]);
                        }
                    }
                    let patch =
                        Patch::rational(c.len() - 1, 1, pts, ws).map_err(|e| e.to_string())?;
                    out.push(UvPatch {
                        patch,
                        u: [*t0, *t1],
                        v,
                        // The swept curve's own parameter (pieces and inversion agree).
                        map: [ParamMap::Linear, ParamMap::Linear],
                    });
                }
            }
            Surface::Patches {
                patches,
                period_u,
                period_v,
                ..
            } => {
                // With a period, the trimming rectangle may sit in a shifted copy of the domain;
                // keep all patches then (the trimming test works modulo the period).
                for p in patches {
                    let miss_u = period_u.is_none() && (p.u[1] < u[0] || p.u[0] > u[1]);
                    let miss_v = period_v.is_none() && (p.v[1] < v[0] || p.v[0] > v[1]);
                    if !(miss_u || miss_v) {
                        out.push(p.clone());
                    }
                }
            }
        }
        Ok(out)
    }
}

/// `atan2(y, x)` moved by whole turns next to `near`.
fn angle(y: f64, x: f64, near: Option<f64>) -> f64 {
    let a = y.atan2(x);
    match near {
        Some(h) => a + TAU * ((h - a) / TAU).round(),
        None => a,
    }
}

/// The point of a piecewise curve at parameter `u` (clamped to its range).
pub fn curve_point(pieces: &[(f64, f64, Vec<Homogeneous>)], u: f64) -> [f64; 3] {
    let k = pieces
        .iter()
        .position(|(_, b, _)| u <= *b)
        .unwrap_or(pieces.len() - 1);
    let (a, b, c) = &pieces[k];
    super::nurbs::point_at(c, ((u - a) / (b - a)).clamp(0.0, 1.0))
}

/// The parameter of the point of a piecewise Bézier curve closest to `p`: nearest of 16
/// samples per piece, then Gauss–Newton on that piece.
pub fn invert_curve(pieces: &[(f64, f64, Vec<Homogeneous>)], p: [f64; 3]) -> f64 {
    let mut best = (f64::INFINITY, 0usize, 0.0);
    for (k, (_, _, c)) in pieces.iter().enumerate() {
        for i in 0..=16 {
            let t = i as f64 / 16.0;
            let d = norm(sub(super::nurbs::point_at(c, t), p));
            if d < best.0 {
                best = (d, k, t);
            }
        }
    }
    let (_, k, mut t) = best;
    let (a, b, c) = &pieces[k];
    for _ in 0..40 {
        let (n, dn) = super::super::curve::eval_with_derivative(c, t);
        let x = euc(n);
        let d = [
            (dn[0] - x[0] * dn[3]) / n[3],
            (dn[1] - x[1] * dn[3]) / n[3],
            (dn[2] - x[2] * dn[3]) / n[3],
        ];
        let dd = dot(d, d);
        if dd == 0.0 {
            break;
        }
        let step = -dot(sub(x, p), d) / dd;
        let next = (t + step).clamp(0.0, 1.0);
        let moved = (next - t).abs();
        t = next;
        if moved < 1e-15 {
            break;
        }
    }
    a + t * (b - a)
}

/// Closest point on a set of patches: Gauss–Newton in the surface's own `(u, v)` (moving from
/// patch to patch, clamped to the domain) from `hint` and from the nearest precomputed sample;
/// the nearer result wins.
fn invert_patches(
    patches: &[UvPatch],
    samples: &[(usize, [f64; 2], [f64; 3])],
    p: [f64; 3],
    hint: Option<[f64; 2]>,
) -> [f64; 2] {
    let mut dom = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    for up in patches {
        dom = [
            dom[0].min(up.u[0]),
            dom[1].max(up.u[1]),
            dom[2].min(up.v[0]),
            dom[3].max(up.v[1]),
        ];
    }
    let clamp = |uv: [f64; 2]| [uv[0].clamp(dom[0], dom[1]), uv[1].clamp(dom[2], dom[3])];
    // Point and partials in (u, v) at a domain point.
    let eval = |uv: [f64; 2]| -> ([f64; 3], [f64; 3], [f64; 3]) {
        let up = patches
            .iter()
            .find(|up| up.u[0] <= uv[0] && uv[0] <= up.u[1] && up.v[0] <= uv[1] && uv[1] <= up.v[1])
            .unwrap_or(&patches[0]);
        let st = up.local(uv);
        let st = [st[0].clamp(0.0, 1.0), st[1].clamp(0.0, 1.0)];
        let (x, ds, dt) = up.patch.eval_with_partials(st[0], st[1]);
        let (du, dv) = (up.map[0].at(up.u, st[0]).1, up.map[1].at(up.v, st[1]).1);
        (x, scale(ds, 1.0 / du), scale(dt, 1.0 / dv))
    };
    let newton = |start: [f64; 2]| -> (f64, [f64; 2]) {
        let mut uv = clamp(start);
        // On a collapsed edge (a pole: one partial vanishes) the other parameter cannot move
        // under Newton's method; start just inside the domain instead.
        let (_, su, sv) = eval(uv);
        let (nu, nv) = (norm(su) * (dom[1] - dom[0]), norm(sv) * (dom[3] - dom[2]));
        let inward = |x: f64, lo: f64, hi: f64| {
            let e = 1e-3 * (hi - lo);
            if x - lo < 0.5 * (hi - lo) {
                x.max(lo + e)
            } else {
                x.min(hi - e)
            }
        };
        if nu <= 1e-9 * nv {
            uv[1] = inward(uv[1], dom[2], dom[3]);
        } else if nv <= 1e-9 * nu {
            uv[0] = inward(uv[0], dom[0], dom[1]);
        }
        for _ in 0..60 {
            let (x, su, sv) = eval(uv);
            let r = sub(x, p);
            let (a, b, c) = (dot(su, su), dot(su, sv), dot(sv, sv));
            let (g0, g1) = (dot(su, r), dot(sv, r));
            let det = a * c - b * b;
            let (d0, d1) = if det > 1e-14 * a * c && det > 0.0 {
                ((-c * g0 + b * g1) / det, (b * g0 - a * g1) / det)
            } else if a + c > 0.0 {
                (-g0 / (a + c), -g1 / (a + c))
            } else {
                break;
            };
            // Limit a step to a quarter of the domain (Gauss–Newton can overshoot far from
            // the solution), then clamp.
            let lim = |d: f64, w: f64| d.clamp(-0.25 * w, 0.25 * w);
            let next = clamp([
                uv[0] + lim(d0, dom[1] - dom[0]),
                uv[1] + lim(d1, dom[3] - dom[2]),
            ]);
            let moved = (next[0] - uv[0]).abs() / (dom[1] - dom[0])
                + (next[1] - uv[1]).abs() / (dom[3] - dom[2]);
            uv = next;
            if moved < 1e-15 {
                break;
            }
        }
        (norm(sub(eval(uv).0, p)), uv)
    };
    let mut nearest = (f64::INFINITY, [0.0, 0.0]);
    for (k, st, x) in samples {
        let d = norm(sub(*x, p));
        if d < nearest.0 {
            nearest = (d, patches[*k].global(*st));
        }
    }
    let mut best = newton(nearest.1);
    if let Some(h) = hint {
        let r = newton(h);
        if r.0 <= best.0 {
            best = r;
        }
    }
    best.1
}

/// Whether a patch set closes up across its `u` (or `v`) domain: the first and last
/// iso-curves agree within `tol` at several points.
pub fn detect_periods(patches: &[UvPatch], tol: f64) -> (Option<f64>, Option<f64>) {
    let (mut u0, mut u1, mut v0, mut v1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in patches {
        u0 = u0.min(p.u[0]);
        u1 = u1.max(p.u[1]);
        v0 = v0.min(p.v[0]);
        v1 = v1.max(p.v[1]);
    }
    let at = |u: f64, v: f64| -> Option<[f64; 3]> {
        let p = patches
            .iter()
            .find(|p| p.u[0] <= u && u <= p.u[1] && p.v[0] <= v && v <= p.v[1])?;
        let st = p.local([u, v]);
        Some(p.patch.eval(st[0], st[1]))
    };
    let closes = |a: &dyn Fn(f64) -> (f64, f64), b: &dyn Fn(f64) -> (f64, f64)| {
        (0..=8).all(|k| {
            let s = k as f64 / 8.0;
            let (pa, pb) = (a(s), b(s));
            match (at(pa.0, pa.1), at(pb.0, pb.1)) {
                (Some(x), Some(y)) => norm(sub(x, y)) <= tol,
                _ => false,
            }
        })
    };
    let pu = closes(&|s| (u0, v0 + s * (v1 - v0)), &|s| (u1, v0 + s * (v1 - v0)));
    let pv = closes(&|s| (u0 + s * (u1 - u0), v0), &|s| (u0 + s * (u1 - u0), v1));
    (pu.then_some(u1 - u0), pv.then_some(v1 - v0))
}

/// A circle or ellipse `o + a cos θ x + b sin θ y`: its angle at a point.
pub fn conic_angle(f: &Frame, a: f64, b: f64, p: [f64; 3]) -> f64 {
    let l = f.local(p);
    (l[1] / b).atan2(l[0] / a)
}

/// Rational quadratic pieces of a circle/ellipse from angle `t0` to `t1`, with their angle
/// ranges.
pub fn conic_pieces(
    f: &Frame,
    a: f64,
    b: f64,
    t0: f64,
    t1: f64,
) -> Vec<(f64, f64, Vec<Homogeneous>)> {
    let arcs = unit_arcs(t0, t1);
    let n = arcs.len();
    arcs.into_iter()
        .enumerate()
        .map(|(k, arc)| {
            let lo = t0 + (t1 - t0) * k as f64 / n as f64;
            let hi = if k + 1 == n {
                t1
            } else {
                t0 + (t1 - t0) * (k + 1) as f64 / n as f64
            };
            let c = arc
                .iter()
                .map(|(q, w)| hom(f.world(a * q[0], b * q[1], 0.0), *w))
                .collect();
            (lo, hi, c)
        })
        .collect()
}

/// The full turn of angles starting at `t0` when `t1` is not after it.
pub fn next_turn(t0: f64, t1: f64) -> f64 {
    let mut t = t1;
    while t <= t0 {
        t += TAU;
    }
    while t > t0 + TAU {
        t -= TAU;
    }
    t
}

/// Frame from a location, an optional axis and an optional reference direction (ISO 10303-42
/// `build_axes`: axis defaults to `+z`, the reference direction to `+x`, or `+y` when `+x` is
/// parallel to the axis).
pub fn frame(o: [f64; 3], axis: Option<[f64; 3]>, refd: Option<[f64; 3]>) -> Result<Frame, String> {
    let z = unit(axis.unwrap_or([0.0, 0.0, 1.0])).ok_or("zero axis direction")?;
    let r = match refd {
        Some(r) => r,
        None if dot(z, [1.0, 0.0, 0.0]).abs() < 1.0 - 1e-9 => [1.0, 0.0, 0.0],
        None => [0.0, 1.0, 0.0],
    };
    let x = unit(sub(r, scale(z, dot(r, z)))).ok_or("reference direction parallel to the axis")?;
    Ok(Frame {
        o,
        x,
        y: cross(z, x),
        z,
    })
}

/// `v / |v|`, `None` for a zero or non-finite vector.
pub fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let n = norm(v);
    (n > 0.0 && n.is_finite()).then(|| scale(v, 1.0 / n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patch_parameters_map_to_the_surface_angles() {
        // Every point of a torus's rational patches (arcs in u and v, spans of 1° … 90°) is at
        // the angles `global` gives its patch parameters, as `invert` reads them; `local`
        // inverts `global`; the derivative is the angle's.
        let f = frame([0.1, -0.2, 0.3], Some([0.0, 0.6, 0.8]), None).unwrap();
        let torus = Surface::Torus(f, 2.0, 0.5);
        for (u, v) in [
            ([0.3, 2.9], [-1.0, 0.2]),
            ([-0.01, 0.01], [3.0, 3.1]),
            ([0.0, TAU], [0.0, TAU]),
        ] {
            for up in torus.patches(u, v).unwrap() {
                assert_eq!(up.map, [ParamMap::Arc, ParamMap::Arc]);
                for k in 0..=8 {
                    let st = [k as f64 / 8.0, (8 - k) as f64 / 8.0];
                    let x = up.patch.eval(st[0], st[1]);
                    let uv = up.global(st);
                    let inv = torus.invert(x, Some(uv));
                    assert!((inv[0] - uv[0]).abs() < 1e-12, "{st:?} {uv:?} {inv:?}");
                    assert!((inv[1] - uv[1]).abs() < 1e-12, "{st:?} {uv:?} {inv:?}");
                    let back = up.local(uv);
                    assert!((back[0] - st[0]).abs() < 1e-12 && (back[1] - st[1]).abs() < 1e-12);
                    let h = 1e-6;
                    let (a, da) = up.map[0].at(up.u, st[0]);
                    let (b, _) = up.map[0].at(up.u, st[0] + h);
                    assert!(((b - a) / h - da).abs() < 1e-5 * da.abs().max(1.0));
                }
            }
        }
    }

    #[test]
    fn inversion_near_a_pole_of_a_patch_surface() {
        // A quarter of a sphere's upper half as rational patches; points on the meridian at
        // the far end of the u range, approaching the pole.
        let f = frame([0.0; 3], None, None).unwrap();
        let sphere = Surface::Sphere(f, 0.5);
        let patches = sphere.patches([0.0, FRAC_PI_2], [0.0, FRAC_PI_2]).unwrap();
        let s = Surface::from_patches(patches, None, None);
        for lat in [1e-9, 1e-6, 1e-3, 0.05, 0.3] {
            let v = FRAC_PI_2 - lat;
            let p = [0.0, 0.5 * v.cos(), 0.5 * v.sin()]; // u = π/2
            for hint in [None, Some([0.0, FRAC_PI_2])] {
                // The patch parameters are not angles (rational arcs): check the point.
                let uv = s.invert(p, hint);
                let Surface::Patches { patches, .. } = &s else {
                    unreachable!()
                };
                let up = patches
                    .iter()
                    .find(|up| {
                        up.u[0] <= uv[0] && uv[0] <= up.u[1] && up.v[0] <= uv[1] && uv[1] <= up.v[1]
                    })
                    .unwrap();
                let st = up.local(uv);
                let x = up.patch.eval(st[0], st[1]);
                assert!(norm(sub(x, p)) < 1e-12, "{lat} {hint:?} {uv:?} {x:?} {p:?}");
                if lat >= 1e-6 {
                    assert_eq!(uv[0], FRAC_PI_2, "{lat} {hint:?} {uv:?}");
                }
            }
        }
    }
}
