//! An exact inside/outside oracle that shares no predicate with the kernel.
//!
//! [`exact_winding_number_rational`] returns a certified interval `[lo, hi]` for the winding
//! number at the perturbed query `q_ε = q + R·(t, t², t³)`, `t → 0⁺` (`R` the ray frame of
//! [`RayAxis`], default `+z`: `ε1` along `+x`, `ε2` along `+y`, `ε3` along `+z`), i.e. the value
//! `gwn`'s exact evaluator defines everywhere (see `docs/robustness.md`). Off the surface this is
//! the winding number at `q` itself.
//!
//! How, and why it is a second opinion:
//! - Every `f64` is a dyadic rational `m·2^e`, so the mesh and the query are scaled by one power of
//!   two to big integers **without error** (there is no grid and no snapping).
//! - The crossing count χ of the ray from `q_ε` is computed with `BigInt` *polynomials in `t`*:
//!   each predicate (2D orientation of `q_t` against a projected edge, side of `q_t` of a
//!   triangle's plane) is expanded symbolically and its sign is the sign of the lowest-order
//!   non-zero coefficient. Nothing is hand-expanded and the exact kernel's predicates are not called.
//! - The boundary term `Σ k·Area(A, B, −d)` is the limit `t → 0⁺` of each edge's spherical-triangle
//!   area, evaluated in outward-rounded interval arithmetic ([`super::interval`]). Its sign is the
//!   exact sign of the `t`-polynomial of its numerator; its magnitude is `2·atan2(|N|, D)` of the
//!   limit configuration, with the three degenerate limits (`a` directly above `q` on the ray, `b`
//!   above, `q_ε` inside the segment) derived independently as lune areas.
//!
//! Guarantees:
//! - The returned interval contains the exact value at `q_ε` (the only non-IEEE assumption is the
//!   accuracy of `libm::atan2`, enclosed with a 4-ulp margin, see [`super::interval::atan2_hull`]).
//! - If the mesh's signed boundary (by exact position, so coincident vertices are merged) is
//!   empty — closed and consistently oriented, even if self-intersecting or non-manifold — the
//!   interval is the point `χ` (an exact integer).
//! - [`Certified::decide`] is never wrong when it answers.
//!
//! Cost: `O(F + B)` big-integer work per query (no acceleration structure); see the rates in
//! `docs/testing-kit.md`. For bulk evaluation use [`super::WindingNumber`] (exact integer part,
//! fractional part accurate to ~1e-12).

use std::collections::{BTreeMap, HashMap};

use num_bigint::{BigInt, Sign};

use super::interval::{Iv, atan2_hull, big, pi};
use crate::kernel::frame::RayAxis;
use crate::mesh::Mesh;

/// A certified enclosure of the winding number at the perturbed query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Certified {
    /// Lower bound of `w(q_ε)`.
    pub lo: f64,
    /// Upper bound of `w(q_ε)`.
    pub hi: f64,
    /// The exact signed crossing count χ of the ray from `q_ε`.
    pub crossings: i64,
    /// Number of edges of the signed boundary (by exact position) that contributed a non-zero
    /// area. Zero means `lo == hi == χ`.
    pub boundary_terms: usize,
    /// Those edges' multiplicities summed (an edge of `k` coincident boundary edges counts
    /// `k`): what the interval's width grows with.
    pub boundary_weight: u64,
}

/// The width of `w` that one boundary term may add to a [`Certified`] interval: each half-area
/// is enclosed to `2^-60` before its `atan2`, whose corners are widened by 4 ulp of `π`
/// (`2.8e-15`) on each side, which is `≈ 9e-16` of `w` per term after `2/4π`; `1e-14` leaves
/// a margin of ten.
pub const NARROW_PER_TERM: f64 = 1e-14;

/// The answer of [`Certified::decide`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Decision {
    /// `w(q_ε) > threshold`, certainly.
    Inside,
    /// `w(q_ε) < threshold`, certainly.
    Outside,
    /// The interval contains the threshold.
    Undecided,
}

impl Certified {
    /// `Inside` if `lo > threshold`, `Outside` if `hi < threshold`, else `Undecided`. Certain
    /// whenever it answers (a NaN bound gives `Undecided`).
    pub fn decide(&self, threshold: f64) -> Decision {
        if self.lo > threshold {
            Decision::Inside
        } else if self.hi < threshold {
            Decision::Outside
        } else {
            Decision::Undecided
        }
    }

    /// True when the value is known exactly (`lo == hi`).
    pub fn is_exact(&self) -> bool {
        self.lo == self.hi
    }

    /// True when `w` lies in `[lo − tol, hi + tol]`.
    pub fn contains(&self, w: f64, tol: f64) -> bool {
        self.lo - tol <= w && w <= self.hi + tol
    }

    /// `hi − lo`: 0 when the value is exact.
    pub fn width(&self) -> f64 {
        self.hi - self.lo
    }

    /// Whether the interval is as narrow as the oracle promises: at most [`NARROW_PER_TERM`]
    /// per boundary term and unit of its multiplicity. A test should assert it next to [`Certified::contains`], which a wide
    /// interval passes for any value (before the oracle's denominators were evaluated in big
    /// fixed point, about 7 % of the intervals at queries one ulp from a vertex were wider
    /// than `1e-9`, some `[0, π]` per edge).
    pub fn is_narrow(&self) -> bool {
        self.width() <= NARROW_PER_TERM * (self.boundary_weight as f64 + 1.0)
    }

    /// The midpoint of the interval.
    pub fn mid(&self) -> f64 {
        0.5 * (self.lo + self.hi)
    }
}

/// The winding number of `mesh` at the perturbed query `q_ε` for the ray `ray`, certified.
/// Exact for every finite input (all `f64` are dyadic rationals); the mesh is converted on every
/// call, so for many queries build an [`Oracle`] once.
///
/// ```
/// use gwn::Mesh;
/// use gwn::RayAxis;
/// use gwn::testing::{exact_winding_number_rational, Decision};
/// let tet = Mesh::from_slices(
///     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
///     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
/// )?;
/// // On the face x = 0: the default ray +z perturbs towards +x, into the tetrahedron.
/// let c = exact_winding_number_rational(&tet, [0.0, 0.25, 0.25], RayAxis::PosZ);
/// assert_eq!((c.lo, c.hi), (1.0, 1.0));
/// assert_eq!(c.decide(0.5), Decision::Inside);
/// # Ok::<(), gwn::error::MeshError>(())
/// ```
pub fn exact_winding_number_rational(mesh: &Mesh, q: [f64; 3], ray: RayAxis) -> Certified {
    Oracle::new(mesh, ray).eval(q)
}

/// [`exact_winding_number_rational`] for integer coordinates of any size. Rational inputs:
/// multiply every coordinate (mesh and query) by a common denominator first — the winding number
/// is invariant under scaling by a positive factor.
pub fn exact_winding_number_integer(
    positions: &[[BigInt; 3]],
    triangles: &[[u32; 3]],
    q: &[BigInt; 3],
    ray: RayAxis,
) -> Certified {
    let frame: Vec<[BigInt; 3]> = positions.iter().map(|p| to_frame_big(ray, p)).collect();
    let o = Oracle::from_frame(ray, 0, &frame, triangles);
    o.eval_frame(&to_frame_big(ray, q))
}

/// The exact oracle for one mesh and one ray direction: the mesh converted to big integers once.
#[derive(Clone, Debug)]
pub struct Oracle {
    ray: RayAxis,
    /// Frame coordinates are `world · 2^scale`.
    scale: i64,
    verts: Vec<[BigInt; 3]>,
    tris: Vec<[usize; 3]>,
    /// Per triangle: frame-coordinate bounding box.
    bbox: Vec<([BigInt; 3], [BigInt; 3])>,
    /// Signed boundary by exact position: `(from, to, weight > 0)`.
    boundary: Vec<(usize, usize, i64)>,
}

impl Oracle {
    /// Converts `mesh` (exactly) for queries with ray `ray`.
    pub fn new(mesh: &Mesh, ray: RayAxis) -> Oracle {
        let scale = mesh
            .positions()
            .iter()
            .flatten()
            .map(|&c| needed_scale(c))
            .max()
            .unwrap_or(0);
        let frame: Vec<[BigInt; 3]> = mesh
            .positions()
            .iter()
            .map(|&p| ray.to_frame(p).map(|c| to_big(c, scale)))
            .collect();
        Oracle::from_frame(ray, scale, &frame, mesh.triangles())
    }

    fn from_frame(
        ray: RayAxis,
        scale: i64,
        positions: &[[BigInt; 3]],
        triangles: &[[u32; 3]],
    ) -> Oracle {
        // Merge coincident positions: the boundary is a property of the geometry.
        let mut ids: HashMap<&[BigInt; 3], usize> = HashMap::new();
        let mut verts: Vec<[BigInt; 3]> = Vec::new();
        let remap: Vec<usize> = positions
            .iter()
            .map(|p| {
                *ids.entry(p).or_insert_with(|| {
                    verts.push(p.clone());
                    verts.len() - 1
                })
            })
            .collect();
        let tris: Vec<[usize; 3]> = triangles
            .iter()
            .map(|t| t.map(|i| remap[i as usize]))
            .collect();
        let bbox = tris
            .iter()
            .map(|t| {
                let lo = std::array::from_fn(|k| {
                    t.iter()
                        .map(|&i| &verts[i][k])
                        .min()
                        .cloned()
                        .unwrap_or_default()
                });
                let hi = std::array::from_fn(|k| {
                    t.iter()
                        .map(|&i| &verts[i][k])
                        .max()
                        .cloned()
                        .unwrap_or_default()
                });
                (lo, hi)
            })
            .collect();
        let mut net: BTreeMap<(usize, usize), i64> = BTreeMap::new();
        for t in &tris {
            for (u, v) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                if u < v {
                    *net.entry((u, v)).or_default() += 1;
                } else if v < u {
                    *net.entry((v, u)).or_default() -= 1;
                }
            }
        }
        let boundary = net
            .into_iter()
            .filter(|&(_, k)| k != 0)
            .map(|((u, v), k)| if k > 0 { (u, v, k) } else { (v, u, -k) })
            .collect();
        Oracle {
            ray,
            scale,
            verts,
            tris,
            bbox,
            boundary,
        }
    }

    /// The ray direction.
    pub fn ray(&self) -> RayAxis {
        self.ray
    }

    /// Number of edges of the signed boundary (by exact position).
    pub fn boundary_edge_count(&self) -> usize {
        self.boundary.len()
    }

    /// The certified value at `q_ε`. NaN bounds for a non-finite query.
    pub fn eval(&self, q: [f64; 3]) -> Certified {
        if q.iter().any(|c| !c.is_finite()) {
            return Certified {
                lo: f64::NAN,
                hi: f64::NAN,
                crossings: 0,
                boundary_terms: 0,
                boundary_weight: 0,
            };
        }
        let qs = q.iter().map(|&c| needed_scale(c)).max().unwrap_or(0);
        if qs > self.scale {
            // The query has finer bits than the mesh: refine the mesh's scale (rare).
            return self.rescaled(qs).eval(q);
        }
        let qf = self.ray.to_frame(q).map(|c| to_big(c, self.scale));
        self.eval_frame(&qf)
    }

    fn rescaled(&self, scale: i64) -> Oracle {
        let d = (scale - self.scale) as usize;
        let sh = |p: &[BigInt; 3]| -> [BigInt; 3] { std::array::from_fn(|k| &p[k] << d) };
        Oracle {
            ray: self.ray,
            scale,
            verts: self.verts.iter().map(sh).collect(),
            tris: self.tris.clone(),
            bbox: self.bbox.iter().map(|(a, b)| (sh(a), sh(b))).collect(),
            boundary: self.boundary.clone(),
        }
    }

    /// The certified value for a query given in (scaled) frame coordinates.
    fn eval_frame(&self, q: &[BigInt; 3]) -> Certified {
        let qt = perturbed(q);
        let mut chi = 0i64;
        for (t, (lo, hi)) in self.tris.iter().zip(&self.bbox) {
            // The ray from q_t (t → 0⁺) can only meet the closed box's column above q.
            if q[0] < lo[0] || q[0] > hi[0] || q[1] < lo[1] || q[1] > hi[1] || q[2] > hi[2] {
                continue;
            }
            chi += i64::from(crossing(&qt, t.map(|i| &self.verts[i])));
        }
        let mut sum = Iv::point(0.0);
        let mut terms = 0;
        let mut weight = 0u64;
        for &(a, b, k) in &self.boundary {
            let (a, b) = (&self.verts[a], &self.verts[b]);
            // Sign of the numerator x1·(A×B) = −(A×B)_z at q_t.
            let s = -orient2d(&qt, a, b);
            if s == 0 {
                continue;
            }
            let ra = sub(a, q);
            let rb = sub(b, q);
            let area = edge_area_magnitude(&ra, &rb);
            if area == Iv::point(0.0) {
                continue;
            }
            let signed = area * Iv::point(f64::from(2 * s) * k as f64);
            sum = sum + signed;
            terms += 1;
            weight += k.unsigned_abs();
        }
        if terms == 0 {
            return Certified {
                lo: chi as f64,
                hi: chi as f64,
                crossings: chi,
                boundary_terms: 0,
                boundary_weight: 0,
            };
        }
        let inv_4pi = Iv::point(1.0) / (pi() * Iv::point(4.0));
        let w = Iv::point(chi as f64) + sum * inv_4pi;
        Certified {
            lo: w.lo,
            hi: w.hi,
            crossings: chi,
            boundary_terms: terms,
            boundary_weight: weight,
        }
    }
}

/// Exactly: does `q` lie on a (closed, possibly degenerate) triangle of `mesh`? Any finite
/// coordinates (dyadic, converted without error).
pub fn on_surface(mesh: &Mesh, q: [f64; 3]) -> bool {
    let scale = mesh
        .positions()
        .iter()
        .flatten()
        .chain(q.iter())
        .map(|&c| needed_scale(c))
        .max()
        .unwrap_or(0);
    let qi = q.map(|c| to_big(c, scale));
    mesh.triangles().iter().any(|t| {
        let p = t.map(|i| mesh.positions()[i as usize].map(|c| to_big(c, scale)));
        if (0..3).any(|k| p.iter().all(|v| v[k] < qi[k]) || p.iter().all(|v| v[k] > qi[k])) {
            return false;
        }
        point_on_triangle(&qi, &p)
    })
}

/// The queries off the surface of `mesh` ([`on_surface`] decides exactly) at which the exact
/// evaluator's six ray directions spread by more than `tolerance`, with their values in
/// [`RayAxis::ALL`] order: off the surface `w` does not depend on the ray, so any entry is a
/// kernel error (the check of the `kernel_tiny_offsets` fuzz target and its stable replay).
pub fn ray_disagreements(
    mesh: &Mesh,
    queries: &[[f64; 3]],
    tolerance: f64,
) -> Vec<([f64; 3], [f64; 6])> {
    let rays = six_rays(mesh);
    queries
        .iter()
        .filter(|&&q| !on_surface(mesh, q))
        .filter_map(|&q| {
            let w: [f64; 6] = std::array::from_fn(|k| rays[k].eval(q));
            let (lo, hi) = w
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                    (lo.min(x), hi.max(x))
                });
            // A non-finite value is a disagreement too (min and max would skip a NaN).
            let agree = w.iter().all(|x| x.is_finite()) && hi - lo <= tolerance;
            (!agree).then_some((q, w))
        })
        .collect()
}

/// The queries at which the exact evaluator on some ray of [`RayAxis::ALL`] leaves the
/// oracle's interval for that ray (widened by `tolerance`), or that interval is not
/// [narrow](Certified::is_narrow), with the six values: on the surface too, where each ray
/// defines its own perturbed point (the check of the `kernel_grazing` and
/// `kernel_tiny_offsets` fuzz targets).
pub fn oracle_disagreements(
    mesh: &Mesh,
    queries: &[[f64; 3]],
    tolerance: f64,
) -> Vec<([f64; 3], [f64; 6])> {
    let rays = six_rays(mesh);
    let oracles: Vec<Oracle> = RayAxis::ALL
        .iter()
        .map(|&ray| Oracle::new(mesh, ray))
        .collect();
    queries
        .iter()
        .filter_map(|&q| {
            let w: [f64; 6] = std::array::from_fn(|k| rays[k].eval(q));
            let agree = (0..6).all(|k| {
                let c = oracles[k].eval(q);
                c.is_narrow() && c.contains(w[k], tolerance)
            });
            (!agree).then_some((q, w))
        })
        .collect()
}

/// The exact evaluator of `mesh` on each ray of [`RayAxis::ALL`], in that order.
fn six_rays(mesh: &Mesh) -> Vec<crate::eval::antipodal::WindingNumber> {
    RayAxis::ALL
        .iter()
        .map(|&ray| {
            let options = crate::eval::antipodal::Options {
                ray,
                ..Default::default()
            };
            crate::eval::antipodal::WindingNumber::with_options(mesh, options)
                .expect("a valid mesh builds on every ray")
        })
        .collect()
}

fn point_on_triangle(q: &[BigInt; 3], p: &[[BigInt; 3]; 3]) -> bool {
    let n = cross(&sub(&p[1], &p[0]), &sub(&p[2], &p[0]));
    if is_zero(&n) {
        return (0..3).any(|i| on_segment(q, &p[i], &p[(i + 1) % 3]));
    }
    if dot(&sub(q, &p[0]), &n).sign() != Sign::NoSign {
        return false;
    }
    (0..3).all(|i| {
        let e = sub(&p[(i + 1) % 3], &p[i]);
        dot(&cross(&e, &sub(q, &p[i])), &n).sign() != Sign::Minus
    })
}

fn on_segment(q: &[BigInt; 3], a: &[BigInt; 3], b: &[BigInt; 3]) -> bool {
    let ab = sub(b, a);
    let aq = sub(q, a);
    if is_zero(&ab) {
        return is_zero(&aq);
    }
    if !is_zero(&cross(&ab, &aq)) {
        return false;
    }
    let d = dot(&aq, &ab);
    d.sign() != Sign::Minus && d <= dot(&ab, &ab)
}

/// The magnitude `|Area(A, B, x1)| / 2 ∈ [0, π]` of one boundary edge's term in the limit
/// `t → 0⁺` (the caller supplies the sign), for `ra = a − q`, `rb = b − q` (frame, exact).
fn edge_area_magnitude(ra: &[BigInt; 3], rb: &[BigInt; 3]) -> Iv {
    // A point coinciding with q is seen from q_t in the direction −(t, t², t³) → −x.
    let minus_x = || [BigInt::from(-1), BigInt::from(0), BigInt::from(0)];
    let ra = if is_zero(ra) { minus_x() } else { ra.clone() };
    let rb = if is_zero(rb) { minus_x() } else { rb.clone() };
    let up = |r: &[BigInt; 3]| {
        r[0].sign() == Sign::NoSign && r[1].sign() == Sign::NoSign && r[2].sign() == Sign::Plus
    };
    let (a_up, b_up) = (up(&ra), up(&rb));
    if a_up && b_up {
        return Iv::point(0.0);
    }
    if a_up || b_up {
        // One end directly above q on the ray: its direction tends to +z, approached from the
        // meridian of −(t, t²) → −x. The spherical triangle becomes the lune between that
        // meridian and the other end's meridian: half-area = angle between (r_x, r_y) and −x.
        let r = if a_up { &rb } else { &ra };
        let s = shift(r);
        return atan2_hull(big(&r[1], s).abs(), big(&-&r[0], s));
    }
    let c = cross(&ra, &rb);
    if is_zero(&c) && dot(&ra, &rb).sign() == Sign::Minus {
        // q_ε inside the segment: A → −u, B → u; the arc A→B passes through −p, p the dominant
        // part of (t, t², t³) perpendicular to u. Lune between the half great circles −u…−p…u
        // and −u…x1…u: half-area = dihedral angle = atan2(|x1·(u×p)|, −x1·p), x1 = −z.
        let v = sub(&rb, &ra);
        let zero = BigInt::from(0);
        let p = if v[1] == zero && v[2] == zero {
            [zero.clone(), BigInt::from(1), zero]
        } else {
            // |v|²·x − v_x·v
            [
                &v[1] * &v[1] + &v[2] * &v[2],
                -(&v[0] * &v[1]),
                -(&v[0] * &v[2]),
            ]
        };
        // Scaled by |v|·|P|: N = −(v×P)_z, D = P_z·|v|, each of degree one in v and in P, so
        // each factor takes its own shift (P = e2 has none: scaling it like |v|² underflowed
        // N to 0 and gave [0, π] for an edge 2^1124 long).
        let n = -(&v[0] * &p[1] - &v[1] * &p[0]);
        let (sv, sp) = (shift(&v), shift(&p));
        let len = big(&dot(&v, &v), 2 * sv).sqrt();
        let d = big(&p[2], sp) * len;
        return atan2_hull(big(&n, sv + sp).abs(), d);
    }
    // Generic: N·|ra||rb| = −(ra×rb)_z, D·|ra||rb| = (|ra| − ra_z)(|rb| − rb_z) + ra_x rb_x + ra_y rb_y.
    generic_half_area(&c[2], &ra, &rb)
}

/// Fractional bits beyond the operands' own at which [`generic_half_area`] starts: with
/// `N ≥ 1` (an integer) the first pass already meets [`HALF_AREA_RELATIVE_WIDTH_BITS`].
const HALF_AREA_EXTRA_BITS: u64 = 64;

/// The widest the enclosure of `D` may be, relative to `max(N, |D|)`, before it goes to `f64`:
/// `2^-60`, below the `f64` rounding that follows.
const HALF_AREA_RELATIVE_WIDTH_BITS: u64 = 60;

/// Past this many fractional bits the enclosure is returned as it is (still an enclosure). Not
/// reached: `D ≠ 0` whenever `N = 0` outside the lune and segment limits (`N = 0` puts both ends
/// in one vertical half-plane pair; `D = 0` there needs them antiparallel or one straight up).
const HALF_AREA_MAX_BITS: u64 = 1 << 16;

/// `atan2(|N|, D)` for the generic edge, `N = (ra×rb)_z`, enclosed to a few ulp of `π`.
///
/// `D` cancels (a sum of two terms of opposite sign and up to `|ra||rb|` each) exactly where the
/// ray passes close to the edge, the configurations the oracle exists to check, so `D` is
/// evaluated in big fixed point with `p` fractional bits — `|r|·2^p` by an integer square root,
/// bracketed — and `p` doubles until `D`'s bracket is `2^-60` of `max(|N|, |D|)`. Only then
/// are `N` and `D` scaled by one power of two (`atan2` is homogeneous of degree 0) and rounded
/// to `f64`. A plain `f64` evaluation of `D` gave `[0, π]` for whole terms at queries one ulp
/// from a vertex.
fn generic_half_area(cz: &BigInt, ra: &[BigInt; 3], rb: &[BigInt; 3]) -> Iv {
    let n = BigInt::from(cz.magnitude().clone());
    let planar_dot = &ra[0] * &rb[0] + &ra[1] * &rb[1];
    let operand_bits = ra.iter().chain(rb).map(BigInt::bits).max().unwrap_or(0);
    let mut p = operand_bits + HALF_AREA_EXTRA_BITS;
    loop {
        let (a_lo, a_hi) = len_minus_z_fixed(ra, p);
        let (b_lo, b_hi) = len_minus_z_fixed(rb, p);
        let planar = &planar_dot << (2 * p);
        // Both factors are ≥ 0, so their product's bracket is the products of the ends.
        let d_lo = &a_lo * &b_lo + &planar;
        let d_hi = &a_hi * &b_hi + &planar;
        let n_p = &n << (2 * p);
        let size = n_p.bits().max(d_lo.bits()).max(d_hi.bits());
        let width = (&d_hi - &d_lo).bits();
        if width + HALF_AREA_RELATIVE_WIDTH_BITS <= size || p >= HALF_AREA_MAX_BITS {
            let s = size as i64 - 60;
            let d = Iv {
                lo: big(&d_lo, s).lo,
                hi: big(&d_hi, s).hi,
            };
            return atan2_hull(big(&n_p, s), d);
        }
        p *= 2;
    }
}

/// Integers `[lo, hi]` enclosing `(|r| − r_z)·2^p`, without cancellation when `r_z > 0`
/// (there `|r| − r_z = (r_x² + r_y²) / (|r| + r_z)`).
fn len_minus_z_fixed(r: &[BigInt; 3], p: u64) -> (BigInt, BigInt) {
    let planar = &r[0] * &r[0] + &r[1] * &r[1];
    let len_sq = &planar + &r[2] * &r[2];
    // len ≤ |r|·2^p < len + 1.
    let len = (len_sq << (2 * p)).sqrt();
    let z = &r[2] << p;
    if r[2].sign() == Sign::Plus {
        let num = planar << (2 * p);
        let lo = &num / (&len + 1u32 + &z);
        let den = &len + &z;
        let hi = (&num + &den - 1u32) / den;
        (lo, hi)
    } else {
        (&len - &z, &len + 1u32 - &z)
    }
}

/// A shift bringing the largest component of `r` to about 60 bits.
fn shift(r: &[BigInt; 3]) -> i64 {
    let bits = r.iter().map(|c| c.bits()).max().unwrap_or(0) as i64;
    (bits - 60).max(0)
}

/// Polynomial in `t` with big-integer coefficients (`c[i]` multiplies `t^i`).
#[derive(Clone, Debug)]
struct Poly(Vec<BigInt>);

impl Poly {
    fn add(&self, o: &Poly) -> Poly {
        let n = self.0.len().max(o.0.len());
        Poly(
            (0..n)
                .map(|i| {
                    let a = self.0.get(i).cloned().unwrap_or_default();
                    match o.0.get(i) {
                        Some(b) => a + b,
                        None => a,
                    }
                })
                .collect(),
        )
    }

    fn sub(&self, o: &Poly) -> Poly {
        let n = self.0.len().max(o.0.len());
        Poly(
            (0..n)
                .map(|i| {
                    let a = self.0.get(i).cloned().unwrap_or_default();
                    match o.0.get(i) {
                        Some(b) => a - b,
                        None => a,
                    }
                })
                .collect(),
        )
    }

    fn mul(&self, o: &Poly) -> Poly {
        let mut c = vec![BigInt::default(); (self.0.len() + o.0.len()).saturating_sub(1)];
        for (i, a) in self.0.iter().enumerate() {
            if a.sign() == Sign::NoSign {
                continue;
            }
            for (j, b) in o.0.iter().enumerate() {
                c[i + j] += a * b;
            }
        }
        Poly(c)
    }

    /// Sign for `t → 0⁺`: the sign of the lowest-order non-zero coefficient.
    fn sign(&self) -> i32 {
        for c in &self.0 {
            match c.sign() {
                Sign::Plus => return 1,
                Sign::Minus => return -1,
                Sign::NoSign => {}
            }
        }
        0
    }

    fn constant(c: &BigInt) -> Poly {
        Poly(vec![c.clone()])
    }
}

/// `q_t = q + (t, t², t³)` coordinate by coordinate.
fn perturbed(q: &[BigInt; 3]) -> [Poly; 3] {
    std::array::from_fn(|k| {
        let mut c = vec![BigInt::default(); k + 2];
        c[0] = q[k].clone();
        c[k + 1] = BigInt::from(1);
        Poly(c)
    })
}

/// Sign of the 2D orientation `det((a − q_t)_xy, (b − q_t)_xy)` for `t → 0⁺`.
fn orient2d(qt: &[Poly; 3], a: &[BigInt; 3], b: &[BigInt; 3]) -> i32 {
    let ax = Poly::constant(&a[0]).sub(&qt[0]);
    let ay = Poly::constant(&a[1]).sub(&qt[1]);
    let bx = Poly::constant(&b[0]).sub(&qt[0]);
    let by = Poly::constant(&b[1]).sub(&qt[1]);
    ax.mul(&by).sub(&ay.mul(&bx)).sign()
}

/// Signed crossing of the ray `q_t + λ·z`, `λ > 0`, with the triangle `p`: `sign(n_z)` when it
/// crosses, else 0.
fn crossing(qt: &[Poly; 3], p: [&[BigInt; 3]; 3]) -> i32 {
    let o0 = orient2d(qt, p[0], p[1]);
    if o0 == 0 || orient2d(qt, p[1], p[2]) != o0 || orient2d(qt, p[2], p[0]) != o0 {
        return 0;
    }
    // The projection of q_t is strictly inside the projected triangle, whose orientation o0 is
    // sign(n_z) (the three orientations sum to n_z). The ray meets the plane at
    // λ = (p0 − q_t)·n / n_z: a crossing iff sign((p0 − q_t)·n) = sign(n_z).
    let n = cross(&sub(p[1], p[0]), &sub(p[2], p[0]));
    debug_assert_eq!(sign(&n[2]), o0);
    let mut depth = Poly(Vec::new());
    for k in 0..3 {
        let d = Poly::constant(&p[0][k]).sub(&qt[k]);
        depth = depth.add(&d.mul(&Poly::constant(&n[k])));
    }
    if depth.sign() == o0 { o0 } else { 0 }
}

fn sign(x: &BigInt) -> i32 {
    match x.sign() {
        Sign::Plus => 1,
        Sign::Minus => -1,
        Sign::NoSign => 0,
    }
}

fn sub(a: &[BigInt; 3], b: &[BigInt; 3]) -> [BigInt; 3] {
    std::array::from_fn(|k| &a[k] - &b[k])
}

fn cross(a: &[BigInt; 3], b: &[BigInt; 3]) -> [BigInt; 3] {
    [
        &a[1] * &b[2] - &a[2] * &b[1],
        &a[2] * &b[0] - &a[0] * &b[2],
        &a[0] * &b[1] - &a[1] * &b[0],
    ]
}

fn dot(a: &[BigInt; 3], b: &[BigInt; 3]) -> BigInt {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

fn is_zero(a: &[BigInt; 3]) -> bool {
    a.iter().all(|c| c.sign() == Sign::NoSign)
}

/// `(m, e)` with `x = m·2^e` and `m` odd (or `x = 0`).
fn decompose(x: f64) -> (i64, i64) {
    if x == 0.0 {
        return (0, 0);
    }
    let bits = x.to_bits();
    let neg = bits >> 63 == 1;
    let exp = ((bits >> 52) & 0x7ff) as i64;
    let frac = (bits & ((1u64 << 52) - 1)) as i64;
    let (mut m, mut e) = if exp == 0 {
        (frac, -1074)
    } else {
        (frac | (1 << 52), exp - 1075)
    };
    let tz = m.trailing_zeros() as i64;
    m >>= tz;
    e += tz;
    (if neg { -m } else { m }, e)
}

/// The smallest `s` with `x·2^s` an integer.
fn needed_scale(x: f64) -> i64 {
    let (m, e) = decompose(x);
    if m == 0 { i64::MIN / 4 } else { -e }
}

/// `x·2^scale` exactly (requires `scale ≥ needed_scale(x)`).
fn to_big(x: f64, scale: i64) -> BigInt {
    let (m, e) = decompose(x);
    let s = e + scale;
    debug_assert!(s >= 0 || m == 0);
    BigInt::from(m) << (s.max(0) as usize)
}

/// World → frame for big integers (a signed permutation, the same as [`RayAxis::to_frame`]).
fn to_frame_big(ray: RayAxis, v: &[BigInt; 3]) -> [BigInt; 3] {
    ray.map()
        .map(|(axis, neg)| if neg { -&v[axis] } else { v[axis].clone() })
}

/// An *approximate* oracle for the value at the perturbed point, independent of both the kernel
/// and the rational oracle: the direct solid-angle sum at the real points
/// `q + R·(t, t², t³)·scale` (`R` the ray frame's rotation to world) for `t = 1e-3` and `1e-4`,
/// Richardson-extrapolated to `t → 0` (the error of each sample is `O(t)`; the extrapolation
/// removes the linear term). Good to about 1e-5 on small integer-grid meshes; use a tolerance of
/// 1e-3 or so. Near a degenerate face the direct sum itself is the weak link, see
/// the exact kernel's `triangle_solid_angle_at`.
pub fn direct_at_perturbed(
    mesh: &Mesh,
    q: [f64; 3],
    ray: crate::kernel::frame::RayAxis,
    scale: f64,
) -> f64 {
    let at = |t: f64| {
        let d = ray.to_world([t * scale, t * t * scale, t * t * t * scale]);
        crate::eval::direct::winding_number_direct(mesh, [q[0] + d[0], q[1] + d[1], q[2] + d[2]])
    };
    let (w1, w2) = (at(1e-3), at(1e-4));
    w2 + (w2 - w1) / 9.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> Mesh {
        crate::testing::unit_cube(false)
    }

    #[test]
    fn decompose_is_exact() {
        for x in [1.0, -0.375, 3.0e-300, 5e-324, 1e300, -7.0] {
            let (m, e) = decompose(x);
            assert_eq!(m as f64 * 2f64.powi(e as i32), x);
        }
        assert_eq!(needed_scale(0.25), 2);
        assert_eq!(to_big(0.75, 3), BigInt::from(6));
    }

    #[test]
    fn closed_cube_gives_integers_and_open_cube_five_sixths() {
        let m = cube();
        for ray in RayAxis::ALL {
            let c = exact_winding_number_rational(&m, [0.5, 0.5, 0.5], ray);
            assert_eq!((c.lo, c.hi), (1.0, 1.0), "{ray:?}");
            let c = exact_winding_number_rational(&m, [1.5, 0.5, 0.5], ray);
            assert_eq!((c.lo, c.hi), (0.0, 0.0), "{ray:?}");
        }
        // On the faces x = 0 / x = 1 with ray +z: perturbed towards +x.
        assert_eq!(
            exact_winding_number_rational(&m, [0.0, 0.5, 0.5], RayAxis::PosZ).lo,
            1.0
        );
        assert_eq!(
            exact_winding_number_rational(&m, [1.0, 0.5, 0.5], RayAxis::PosZ).lo,
            0.0
        );
        let open = Mesh::from_slices(m.positions(), &m.triangles()[..10]).unwrap();
        for ray in RayAxis::ALL {
            let c = exact_winding_number_rational(&open, [0.5, 0.5, 0.5], ray);
            assert!(c.contains(5.0 / 6.0, 0.0), "{ray:?} {c:?}");
            assert!(c.hi - c.lo < 1e-14);
        }
    }

    fn big3(v: [i128; 3]) -> [BigInt; 3] {
        v.map(BigInt::from)
    }

    #[test]
    fn edge_terms_stay_narrow_where_the_denominator_cancels() {
        // The far end almost along +x from a query at the other end (seen along −x): D is
        // |r| − r_x − r_z, a difference of 2^50-sized terms worth 9.4; in f64 it was [0, π].
        let far = big3([1 << 50, 6, -9]);
        let at_q = big3([-1, 0, 0]);
        let a = edge_area_magnitude(&far, &at_q);
        let want = 6f64.atan2(9.0 + 117.0 / (2.0 * (1u64 << 50) as f64));
        assert!(
            a.hi - a.lo < 1e-14 && a.lo <= want && want <= a.hi,
            "{a:?} vs {want}"
        );
        // N = 0, ends on both sides of q's vertical line, the segment crossing it 2^-100/3
        // above q (D < 0 by ~2^-100 of its terms): the half-area is π, certainly.
        for (up, down, half) in [
            (
                [1 << 100, 0, 1],
                [-(1 << 101) - 1, 0, -2],
                std::f64::consts::PI,
            ),
            ([1 << 100, 0, 1], [-(1 << 101) + 1, 0, -2], 0.0),
        ] {
            let a = edge_area_magnitude(&big3(up), &big3(down));
            assert!(a.hi - a.lo < 1e-14 && a.lo <= half && half <= a.hi, "{a:?}");
        }
    }

    #[test]
    fn a_long_edge_through_the_query_is_a_quarter_turn() {
        // q inside a segment along x, 2^1124 long: the lune's half-area is π/2 (P = e2); N was
        // shifted like |v|³ and underflowed to 0, which gave [0, π].
        let a = big3([1, 0, 0]);
        let b = [
            -(BigInt::from(1) << 1123u32),
            BigInt::from(0),
            BigInt::from(0),
        ];
        let area = edge_area_magnitude(&a, &b);
        let quarter = std::f64::consts::FRAC_PI_2;
        assert!(
            area.hi - area.lo < 1e-14 && area.lo <= quarter && quarter <= area.hi,
            "{area:?}"
        );
    }

    #[test]
    fn integer_entry_point_matches() {
        let m = cube();
        let pos: Vec<[BigInt; 3]> = m
            .positions()
            .iter()
            .map(|p| p.map(|c| BigInt::from(c as i64 * 4)))
            .collect();
        let q = [1, 2, 3].map(BigInt::from);
        let c = exact_winding_number_integer(&pos, m.triangles(), &q, RayAxis::NegY);
        assert_eq!((c.lo, c.hi), (1.0, 1.0));
    }
}
