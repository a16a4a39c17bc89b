//! The fixed-point grid that makes the predicates exact.
//!
//! Every mesh vertex is snapped to the integer lattice `origin + cell·ℤ³`, where `cell` is a power
//! of two and `origin` a multiple of `cell`, chosen so that the mesh's bounding box grown by its
//! largest extent on every side (the *padded box*) fits in `±2^(bits−1)`. Because `cell` is a
//! power of two, dyadic coordinates with few significant bits (integer test meshes, most CAD
//! output) snap without error, so degenerate configurations in the input stay degenerate on the
//! grid and the perturbation resolves them exactly as it would in real arithmetic.
//!
//! Queries inside the padded box are snapped the same way, **exactly**: the nearest lattice point
//! of the true real value `(x − origin)/cell` (not of its rounded `f64` difference, which lost up
//! to `1e-16·|x|`, many cells when `|x| ≫ extent` or `|origin| ≫ |x|`). So a query moves by at
//! most half a cell (`cell ≈ 3·extent/2^bits`: about `3e-9·extent` for [`Precision::Bits30`],
//! `3e-18·extent` for [`Precision::Bits60`], below `f64` resolution of the mesh's own
//! coordinates), and a query that lies on the lattice — every point whose coordinates are
//! multiples of the cell, such as points on the faces of integer and dyadic meshes — is not moved
//! at all. Queries outside the padded box are *not* snapped in the offending axis: the evaluator
//! treats them by the clamp rules of the exact query (`kernel::exact_index`, module doc).
//!
//! Everything above happens in *grid space*, the world scaled by a power of two that brings the
//! mesh's extent into `[1, 2)` (exact; `w` is scale-invariant), so meshes of extent `1e-300` or
//! `1e300` are gridded like a unit mesh (an extent below `1e-291` used to hang `Grid::new`).
//!
//! Queries farther than `2^30` padded-box half-widths from the origin along an axis are first
//! moved to that distance along that axis ([`Grid::pull_in_far`]): beyond it the boundary
//! term's products would overflow `f64` (w was NaN at 1e100), and the move changes `w` by less
//! than `2^-60` (see there).

use super::input_predicates::{InputPoint, LatticeFrame};
use crate::base::bounding_box::BoundingBox;

/// Width of the fixed-point grid, and with it the integer type of the predicates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Precision {
    /// 30-bit grid: the 2D orientation fits `i64`, the depth test `i128`. Fastest; queries are
    /// snapped to about `3e-9` of the mesh extent.
    Bits30,
    /// 60-bit grid: the 2D orientation fits `i128`; the degree-3 depth test uses a floating
    /// filter with an exact big-integer fallback. Snapping is below `f64` resolution. Default.
    #[default]
    Bits60,
}

impl Precision {
    /// Number of bits of the grid.
    pub fn bits(self) -> u32 {
        match self {
            Precision::Bits30 => 30,
            Precision::Bits60 => 60,
        }
    }
}

/// Where a query coordinate falls relative to the grid's range along one axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Snap {
    /// Inside the padded box: the snapped integer coordinate.
    In(i64),
    /// Below the padded box.
    Low,
    /// Above the padded box.
    High,
}

impl Snap {
    /// The same position seen along the negated axis.
    pub fn negated(self) -> Snap {
        match self {
            Snap::In(v) => Snap::In(-v),
            Snap::Low => Snap::High,
            Snap::High => Snap::Low,
        }
    }
}

/// The fixed-point grid of one mesh.
///
/// Three spaces: *world* (the caller's coordinates), *grid space* (world × `2^k`, an exact
/// power-of-two scaling chosen so that the mesh's extent lies in `[1, 2)`; `w` is invariant under
/// it), and the *integer lattice* `origin + cell·ℤ³` in grid space. The scaling is what makes
/// meshes of extent `1e-300` or `1e300` work like meshes of extent 1: every `f64` quantity the
/// evaluator derives (cell, reciprocal, far-query distance, boundary magnitudes) stays normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// World → grid space.
    rescale: Rescale,
    /// Grid-space origin, a multiple of `cell`.
    origin: [f64; 3],
    /// `origin / cell`, exactly: `|origin_cells| < 2^115` (see [`Grid::new`]).
    origin_cells: [i128; 3],
    cell: f64,
    /// `cell = 2^cell_exp`.
    cell_exp: i32,
    inv_cell: f64,
    limit: i64,
    precision: Precision,
}

/// The mesh's coordinates cannot be gridded (not finite, or their extent overflows `f64`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridRangeError;

impl Grid {
    /// The grid for a mesh with (world) bounding box `bbox`.
    ///
    /// Any finite box works, from a point-sized one at `1e-320` to `±f64::MAX`: the box is first
    /// scaled by a power of two to extent `[1, 2)`. Bounds used below: a box of extent `E > 0`
    /// around centre `c` has `|c| ≤ 2^53·E` (two distinct `f64` values near `c` differ by at least
    /// `ulp(c) ≥ 2^-52·|c|`, subnormals aside, where `|c|` is tiny anyway), so in grid space
    /// `|origin / cell| ≤ 2^54 · 2^61 < 2^115`, which fits `i128`.
    pub fn new(bbox: &BoundingBox, precision: Precision) -> Result<Grid, GridRangeError> {
        let finite = |v: &[f64; 3]| v.iter().all(|c| c.is_finite());
        if !finite(&bbox.min) || !finite(&bbox.max) {
            return Err(GridRangeError);
        }
        // Halves: `max − min` may overflow for boxes spanning ±1e308.
        let half_extent = (0..3)
            .map(|k| 0.5 * bbox.max[k] - 0.5 * bbox.min[k])
            .fold(0.0_f64, f64::max);
        // The bound `|c| ≤ 2^53·E` below holds per axis only where that axis's coordinates
        // differ; an axis where all are equal (a flat mesh on a plane `y = 3`) may sit any
        // distance from 0, and `origin / cell` overflowed `i128` for a mesh smaller than
        // `2^-53` of that distance (a `1e-32` triangle on `y = 3` failed to build). Such a box
        // is taken as wide as its centre needs: only the lattice gets coarser, and every vertex
        // keeps its exact residual.
        let centre_magnitude = (0..3)
            .map(|k| (0.5 * bbox.max[k] + 0.5 * bbox.min[k]).abs())
            .fold(0.0_f64, f64::max);
        let half_extent = half_extent.max(centre_magnitude * pow2(-54));
        let half_extent = if half_extent > 0.0 {
            half_extent
        } else {
            // All vertices coincide: any positive extent gives a valid grid; the point's own
            // magnitude keeps its coordinates representable on it.
            let mag = (0..3).fold(0.0_f64, |m, k| m.max(bbox.min[k].abs()));
            if mag > 0.0 { mag } else { 1.0 }
        };
        // Grid space: the extent `2·half_extent` scaled into [1, 2).
        let rescale = Rescale::for_half_extent(half_extent);
        let scale = rescale.factors;
        let to_grid = |v: f64| v * scale[0] * scale[1];
        let extent = half_extent * scale[0] * scale[1] * 2.0;
        debug_assert!((0.99..2.01).contains(&extent), "{extent}");
        let center: [f64; 3] =
            std::array::from_fn(|k| 0.5 * to_grid(bbox.min[k]) + 0.5 * to_grid(bbox.max[k]));
        // Padded box: bbox grown by `extent` per side ⇒ half-width ≤ 1.5·extent ≤ 3 around the
        // centre; the cell is the smallest power of two with `limit·cell ≥ half_width`.
        let half_width = 1.5 * extent;
        let limit: i64 = (1_i64 << (precision.bits() - 1)) - 4;
        let target = half_width / limit as f64;
        let mut cell_exp = exponent_of(target);
        if pow2(cell_exp) < target {
            cell_exp += 1;
        }
        let cell = pow2(cell_exp);
        let origin_cells: [i128; 3] = std::array::from_fn(|k| (center[k] / cell).round() as i128);
        let origin: [f64; 3] = std::array::from_fn(|k| origin_cells[k] as f64 * cell);
        if origin_cells.iter().any(|o| o.unsigned_abs() >= 1 << 115) {
            return Err(GridRangeError);
        }
        Ok(Grid {
            rescale,
            origin,
            origin_cells,
            cell,
            cell_exp,
            inv_cell: 1.0 / cell,
            limit,
            precision,
        })
    }

    /// The precision the grid was built for.
    pub fn precision(&self) -> Precision {
        self.precision
    }

    /// Edge length of a grid cell (grid space).
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// The grid origin (grid space; a multiple of the cell).
    pub fn origin(&self) -> [f64; 3] {
        self.origin
    }

    /// Largest absolute integer coordinate a snapped query may have.
    pub fn limit(&self) -> i64 {
        self.limit
    }

    /// World → grid space (exact, an overflow becomes `±∞`, which [`Grid::pull_in_far`] and
    /// [`Grid::snap`] treat as "far along that axis"; an underflow only happens to coordinates
    /// far below one cell, which snap to the same integer either way).
    #[inline]
    pub fn in_grid_space(&self, p: [f64; 3]) -> [f64; 3] {
        self.rescale.apply(p)
    }

    /// A gradient computed in grid space, in world units (`∇w` is homogeneous of degree −1).
    pub fn gradient_to_world(&self, g: [f64; 3]) -> [f64; 3] {
        self.rescale.apply(g)
    }

    /// Moves a grid-space query farther than `R = 2^30` padded-box half-widths from the origin
    /// along any axis to distance `R` along that axis (each coordinate clamped to `origin ± R`).
    ///
    /// Why this is harmless: every clamped coordinate stays outside the padded box along the
    /// whole segment from the query to the moved point, so the segment meets no triangle and `w`
    /// is continuous along it; both ends lie at distance `≥ R` from the mesh, where `|w|` and its
    /// change are bounded by the solid angle of the mesh, `O((extent/R)²) < 2^-60`. (Closed
    /// meshes: `w = 0` at both ends exactly.)
    #[inline]
    pub fn pull_in_far(&self, q: [f64; 3]) -> [f64; 3] {
        pull_in(q, self.origin, FAR * self.limit as f64 * self.cell)
    }

    /// Snaps one grid-space coordinate along `axis`: the lattice point nearest to `x` exactly,
    /// ties away from the origin, whatever the magnitudes of `x` and the origin. So a query moves
    /// by at most half a cell, and a query that lies on the lattice (integer and dyadic meshes'
    /// vertices, edges and faces, at any distance from the origin) does not move at all.
    #[cfg(test)]
    pub fn snap(&self, x: f64, axis: usize) -> Snap {
        self.snap_with_residual(x, axis).0
    }

    /// [`Grid::snap`] and the exact residual `x/cell − (origin/cell + n)` in cells (a dyadic
    /// rational with `|r| ≤ 1/2`, exactly representable because `x` has 53 significant bits),
    /// `0` unless the result is [`Snap::In`]. The predicates evaluate `n + r` exactly
    /// (`kernel::predicates::*_at`), so queries are exact to their last bit.
    #[inline]
    pub fn snap_with_residual(&self, x: f64, axis: usize) -> (Snap, f64) {
        let o = self.origin[axis];
        let d = x - o;
        // Fast path when the subtraction is exact (two-sum residual zero): then `d·inv_cell` is
        // exact too (power of two, no underflow in grid space) and rounding it is the exact
        // answer. Otherwise `x − o` lost bits (x much smaller or larger than o, issue #11) and the
        // integer path decides.
        let bp = d - x;
        let ap = d - bp;
        let lost = (x - ap) + (-o - bp);
        if lost != 0.0 || !d.is_finite() {
            return self.snap_exact(x, axis);
        }
        let v = d * self.inv_cell;
        if v.abs() < TRUNC_EXACT {
            let n = round_half_away(v);
            // Exact: `v` and `n` are within half a unit (Sterbenz for |v| ≥ 1; `n = 0` below).
            let residual = v - n as f64;
            self.classify(i128::from(n), residual)
        } else {
            // |v| ≥ 2^62 > limit.
            (if v > 0.0 { Snap::High } else { Snap::Low }, 0.0)
        }
    }

    /// [`Grid::snap_with_residual`] in integers: `x = m·2^e` exactly, so `x/cell − origin/cell`
    /// is the rational `m·2^(e − cell_exp) − origin_cells`, rounded here with an exact remainder.
    #[cold]
    fn snap_exact(&self, x: f64, axis: usize) -> (Snap, f64) {
        if x.is_nan() {
            return (Snap::High, 0.0);
        }
        if x.is_infinite() {
            return (if x > 0.0 { Snap::High } else { Snap::Low }, 0.0);
        }
        let o = self.origin_cells[axis];
        let (m, e) = decompose(x);
        if m == 0 {
            return self.classify(-o, 0.0);
        }
        let shift = e - self.cell_exp;
        let bits = 64 - m.unsigned_abs().leading_zeros() as i32;
        if shift >= 0 {
            if bits + shift > 125 {
                // |x/cell| ≥ 2^124 ≫ |origin_cells| + limit.
                return (if m > 0 { Snap::High } else { Snap::Low }, 0.0);
            }
            return self.classify((i128::from(m) << shift) - o, 0.0);
        }
        let k = -shift;
        if k > 64 {
            // |x/cell| < 2^53·2^-65 < 1/2: the nearest lattice point is −o, no tie possible, and
            // the residual x/cell itself is exact (a power-of-two scaling of x).
            return self.classify(-o, x * self.inv_cell);
        }
        // x/cell = floor + rem/2^k with 0 ≤ rem < 2^k (arithmetic shift floors).
        let m = i128::from(m);
        let floor = m >> k;
        let rem = m - (floor << k);
        let half = 1_i128 << (k - 1);
        let up = rem > half || (rem == half && floor - o >= 0);
        let nearest = if up { floor + 1 } else { floor };
        // `x/cell` is exact in `f64` here (|x/cell| < 2^53, same significand as x), and so is
        // its difference with the nearest integer (Sterbenz, or that integer is 0).
        let residual = x * self.inv_cell - nearest as f64;
        self.classify(nearest - o, residual)
    }

    #[inline]
    fn classify(&self, n: i128, residual: f64) -> (Snap, f64) {
        let limit = i128::from(self.limit);
        if n > limit {
            (Snap::High, 0.0)
        } else if n < -limit {
            (Snap::Low, 0.0)
        } else {
            (Snap::In(n as i64), residual)
        }
    }

    /// Snaps a mesh vertex given in world coordinates (always inside the padded box by
    /// construction). The evaluator snaps with residuals ([`Grid::input_vertex`]); tests use this.
    #[cfg(test)]
    pub fn snap_vertex(&self, p: [f64; 3]) -> [i64; 3] {
        let p = self.in_grid_space(p);
        std::array::from_fn(|k| match self.snap(p[k], k) {
            Snap::In(v) => v,
            Snap::Low => -self.limit,
            Snap::High => self.limit,
        })
    }

    /// Whether the grid-space coordinate `g = in_grid_space(x)` holds the world coordinate `x`
    /// exactly. The power-of-two scaling is exact unless it shrinks a tiny coordinate of a huge
    /// mesh into the subnormal range (or to zero); then the residual of `g` is not the input's,
    /// and the exact predicates rebuild it from `x` ([`crate::kernel::input_predicates`]).
    #[inline]
    pub fn kept_exactly(&self, x: f64, g: f64) -> bool {
        g.abs() >= f64::MIN_POSITIVE || x == 0.0 || self.rescale.invert(g) == x
    }

    /// [`Grid::snap_with_residual`] of a world coordinate whose grid-space value underflowed
    /// ([`Grid::kept_exactly`] false): `|x·2^k| < 2^-1022`, so `|x/cell| < 1/2` and the nearest
    /// lattice point is the origin's, with residual `x/cell` taken from `x` itself (not from its
    /// underflowed grid value). Returns whether that residual is exact in `f64` (it is not when
    /// it is below `2^-1074` cells: a huge mesh and a tiny coordinate; the exact predicates then
    /// rebuild it from `x`).
    #[cold]
    pub fn snap_underflowed(&self, x: f64, axis: usize) -> (Snap, f64, bool) {
        let shift = self.rescale.exponent - self.cell_exp;
        let (a, b) = (shift / 2, shift - shift / 2);
        let r = x * pow2(a.clamp(-1022, 1023)) * pow2(b.clamp(-1022, 1023));
        let exact = (a.abs() <= 1022 && b.abs() <= 1022)
            && (r.abs() >= f64::MIN_POSITIVE
                || r / pow2(a.clamp(-1022, 1023)) / pow2(b.clamp(-1022, 1023)) == x);
        let (snap, r) = self.classify(-self.origin_cells[axis], r);
        (snap, r, exact)
    }

    /// How the exact predicates rebuild a frame coordinate in cells from its world value, for
    /// the ray frame that reads world axis `map[k].0`, negated when `map[k].1`.
    pub fn lattice_frame(&self, map: [(usize, bool); 3]) -> LatticeFrame {
        LatticeFrame {
            shift: i64::from(self.rescale.exponent) - i64::from(self.cell_exp),
            origin_cells: map.map(|(axis, neg)| {
                if neg {
                    -self.origin_cells[axis]
                } else {
                    self.origin_cells[axis]
                }
            }),
        }
    }

    /// A mesh vertex (world) in the ray frame exactly: lattice point, residual, world bits.
    pub fn input_vertex(&self, p: [f64; 3], map: [(usize, bool); 3]) -> InputPoint {
        let g = self.in_grid_space(p);
        let one = |(axis, neg): (usize, bool)| {
            let (s, r, exact) = if self.kept_exactly(p[axis], g[axis]) {
                let (s, r) = self.snap_with_residual(g[axis], axis);
                (s, r, true)
            } else {
                self.snap_underflowed(p[axis], axis)
            };
            let n = match s {
                Snap::In(v) => v,
                Snap::Low => -self.limit,
                Snap::High => self.limit,
            };
            let w = p[axis];
            if neg {
                (-n, -r, -w, exact)
            } else {
                (n, r, w, exact)
            }
        };
        let [a, b, c] = map.map(one);
        InputPoint {
            n: [a.0, b.0, c.0],
            r: [a.1, b.1, c.1],
            world: [a.2, b.2, c.2],
            exact: [a.3, b.3, c.3],
        }
    }

    /// The cell's edge length in world units.
    pub fn cell_in_world(&self) -> f64 {
        self.rescale.invert(self.cell)
    }

    /// The grid-space position of integer coordinate `v` along `axis`.
    #[inline]
    #[cfg(test)]
    pub fn unsnap(&self, v: i64, axis: usize) -> f64 {
        v as f64 * self.cell + self.origin[axis]
    }
}

/// `⌊log2 |x|⌋` for finite non-zero `x`, subnormals included.
fn exponent_of(x: f64) -> i32 {
    let (m, e) = decompose(x);
    e + 63 - m.unsigned_abs().leading_zeros() as i32
}

/// `x = m · 2^e` exactly, `|m| < 2^53` (`m = 0` for zero).
pub(crate) fn decompose(x: f64) -> (i64, i32) {
    let bits = x.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let frac = (bits & ((1 << 52) - 1)) as i64;
    let (m, e) = if biased == 0 {
        (frac, -1074)
    } else {
        (frac | (1 << 52), biased - 1075)
    };
    (if x.is_sign_negative() { -m } else { m }, e)
}

/// The points as integers in one fixed-point scale: `p = n · 2^e` exactly for every coordinate,
/// with the common exponent `e` as large as the finest coordinate allows, and `|n| < 2^max_bits`;
/// `None` when the coordinates span more bits than that (a value of `1` beside one of `1e-17`) or
/// one is not finite. Exact predicates on `n` are then exact on the points themselves.
#[cfg(feature = "products")] // The remesher's exact tests on an input's own coordinates.
pub(crate) fn common_fixed_point(points: &[[f64; 3]], max_bits: u32) -> Option<Vec<[i128; 3]>> {
    debug_assert!(max_bits <= 126);
    let mut finest = i32::MAX;
    let mut top = i32::MIN;
    for &x in points.iter().flatten() {
        if !x.is_finite() {
            return None;
        }
        if x != 0.0 {
            let (m, e) = decompose(x);
            let tz = m.trailing_zeros() as i32;
            finest = finest.min(e + tz);
            top = top.max(e + 64 - m.unsigned_abs().leading_zeros() as i32);
        }
    }
    if finest == i32::MAX {
        return Some(vec![[0; 3]; points.len()]);
    }
    // `|n| < 2^(top − finest)`.
    if top - finest > max_bits as i32 {
        return None;
    }
    let fixed = |x: f64| {
        let (m, e) = decompose(x);
        if m == 0 {
            return 0;
        }
        let tz = m.trailing_zeros() as i32;
        i128::from(m >> tz) << (e + tz - finest) as u32
    };
    Some(points.iter().map(|p| p.map(fixed)).collect())
}

/// `2^e` for `|e| ≤ 1022`.
fn pow2(e: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&e));
    f64::from_bits(((e + 1023) as u64) << 52)
}

/// `2^e` as two representable factors (`e` from −1077 to 1078 covers every finite extent).
fn split_power_of_two(e: i32) -> [f64; 2] {
    let a = e / 2;
    [pow2(a), pow2(e - a)]
}

/// Clamps each coordinate of `q` to `[c_k − r, c_k + r]`. Why this leaves a winding number
/// unchanged to `O((extent/r)²)` is argued at [`Grid::pull_in_far`]; the fast evaluators use it
/// with `r = 2^30` extents (their expansions overflowed beyond ~1e19).
#[inline]
pub fn pull_in(q: [f64; 3], c: [f64; 3], r: f64) -> [f64; 3] {
    std::array::from_fn(|k| {
        // `q − c` cannot overflow in halves (and `±∞` compares as far).
        if 0.5 * q[k] - 0.5 * c[k] > 0.5 * r {
            c[k] + r
        } else if 0.5 * q[k] - 0.5 * c[k] < -0.5 * r {
            c[k] - r
        } else {
            q[k]
        }
    })
}

/// An exact power-of-two scaling of world coordinates that brings a box's extent into `[1, 2)`
/// (winding numbers are scale-invariant): how every evaluator handles meshes of extent `1e-300`
/// or `1e300` without underflow or overflow in its own arithmetic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rescale {
    /// Two representable powers of two (their product may not be, e.g. `2^1074`).
    factors: [f64; 2],
    /// `log2` of their product.
    exponent: i32,
}

impl Rescale {
    /// The scaling for a box of half-extent `half_extent > 0` (finite).
    pub fn for_half_extent(half_extent: f64) -> Rescale {
        let exponent = -(exponent_of(half_extent) + 1);
        Rescale {
            factors: split_power_of_two(exponent),
            exponent,
        }
    }

    /// The scaling for a box (a point-sized or empty box gets the identity).
    pub fn for_box(b: &BoundingBox) -> Rescale {
        let h = (0..3)
            .map(|k| 0.5 * b.max[k] - 0.5 * b.min[k])
            .fold(0.0_f64, f64::max);
        if h > 0.0 && h.is_finite() {
            Self::for_half_extent(h)
        } else {
            Rescale {
                factors: [1.0; 2],
                exponent: 0,
            }
        }
    }

    /// `p` scaled (exact, `±∞` on overflow).
    #[inline]
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        p.map(|c| c * self.factors[0] * self.factors[1])
    }

    /// The inverse scaling of one coordinate (exact when `g` came from [`Rescale::apply`]
    /// without underflow).
    #[inline]
    fn invert(&self, g: f64) -> f64 {
        g / self.factors[0] / self.factors[1]
    }
}

/// Distance, in padded-box half-widths, beyond which queries are pulled in.
const FAR: f64 = (1_u64 << 30) as f64;

/// Below this magnitude `v as i64` is exact truncation.
const TRUNC_EXACT: f64 = (1_u64 << 62) as f64;

/// `v.round()` (ties away from zero) as an integer, for `|v| < 2^62`. Without SSE4.1, `round` is
/// a libm call, visible in closed-mesh queries (docs/benchmarks.md, "Design measurements"); truncation and an exact remainder are not:
/// `v − trunc(v)` is exact because both lie in the same binade (or `trunc(v) = 0`).
#[inline]
fn round_half_away(v: f64) -> i64 {
    let t = v as i64;
    let frac = v - t as f64;
    t + i64::from(frac >= 0.5) - i64::from(frac <= -0.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every coordinate is its integer times the common power of two, exactly; the scale is
    /// the finest coordinate's last bit; a span past the limit is refused.
    #[test]
    #[cfg(feature = "products")]
    fn common_fixed_point_is_exact() {
        let points = [
            [1.0, -0.375, 0.0],
            [1.0 + f64::EPSILON, 3.0e5, -2.5],
            [-0.1, 1e-5, 7.0],
        ];
        let fixed = common_fixed_point(&points, 125).unwrap();
        // The finest bit: that of 1e-5 (exponent -17, 53 bits) at 2^-69 or below.
        let finest = points
            .iter()
            .flatten()
            .filter(|x| **x != 0.0)
            .map(|&x| {
                let (m, e) = decompose(x);
                e + m.trailing_zeros() as i32
            })
            .min()
            .unwrap();
        // `n` keeps the 53 bits of an `f64`, so `n as f64` is exact, and so is the power of two.
        for (p, n) in points.iter().zip(&fixed) {
            for k in 0..3 {
                assert_eq!(n[k] as f64 * 2f64.powi(finest), p[k]);
            }
        }
        assert_eq!(fixed[2][2], 7 << -finest);
        assert!(common_fixed_point(&points, 60).is_none());
        assert!(common_fixed_point(&[[1.0, 1e-300, 0.0]], 125).is_none());
        assert!(common_fixed_point(&[[f64::NAN, 0.0, 0.0]], 125).is_none());
        assert_eq!(common_fixed_point(&[[0.0; 3]], 8), Some(vec![[0; 3]]));
    }

    #[test]
    fn fast_rounding_matches_round() {
        let mut vals = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.49999999999999994,
            -0.49999999999999994,
        ];
        for e in [
            1.0,
            1e3,
            4503599627370495.5,
            4503599627370496.0,
            2.0f64.powi(61) + 1024.0,
        ] {
            for d in [-1.0, -0.5, -0.25, 0.0, 0.25, 0.5, 1.0] {
                vals.push(e + d);
                vals.push(-e + d);
            }
        }
        for v in vals {
            assert_eq!(round_half_away(v), v.round() as i64, "{v}");
        }
    }

    #[test]
    fn small_integer_coordinates_snap_exactly() {
        let b = BoundingBox {
            min: [-4.0, -4.0, -3.0],
            max: [4.0, 3.0, 4.0],
        };
        for p in [Precision::Bits30, Precision::Bits60] {
            let g = Grid::new(&b, p).unwrap();
            let grid_x = |x: f64| g.in_grid_space([x; 3])[0];
            for x in [-4.0, -1.0, 0.0, 0.5, 3.0, 4.0] {
                let (Snap::In(v), r) = g.snap_with_residual(grid_x(x), 0) else {
                    panic!()
                };
                assert_eq!((g.unsnap(v, 0), r), (grid_x(x), 0.0), "{p:?}");
            }
            assert!(matches!(g.snap(grid_x(1e6), 1), Snap::High));
            assert!(matches!(g.snap(grid_x(-1e6), 2), Snap::Low));
            // The padded box (one extent beyond the bbox) is inside the grid.
            assert!(matches!(g.snap(grid_x(-11.9), 0), Snap::In(_)));
        }
    }

    #[test]
    fn degenerate_and_huge_boxes() {
        let point = BoundingBox {
            min: [1.0; 3],
            max: [1.0; 3],
        };
        assert!(Grid::new(&point, Precision::Bits60).is_ok());
        // Every finite box is gridded (exact power-of-two scaling), from ±f64::MAX to 1e-320.
        for (lo, hi) in [
            (-f64::MAX, f64::MAX),
            (0.0, 1e-300),
            (0.0, 5e-324),
            (1e300, 1.0000001e300),
        ] {
            let b = BoundingBox {
                min: [lo; 3],
                max: [hi; 3],
            };
            for p in [Precision::Bits30, Precision::Bits60] {
                let g = Grid::new(&b, p).unwrap();
                let v = g.snap_vertex([hi; 3]);
                assert!(v.iter().all(|c| c.abs() <= g.limit()), "{lo} {hi} {p:?}");
            }
        }
        // A flat box far from 0 along its flat axis, far smaller than that distance.
        for (x, y) in [(7.3e-33, 3.0), (1e-300, -1e300), (5e-324, f64::MAX)] {
            let b = BoundingBox {
                min: [0.0, y, 0.0],
                max: [x, y, x],
            };
            for p in [Precision::Bits30, Precision::Bits60] {
                let g = Grid::new(&b, p).unwrap();
                let v = g.snap_vertex([x, y, x]);
                assert!(v.iter().all(|c| c.abs() <= g.limit()), "{x} {y} {p:?}");
            }
        }
        let nan = BoundingBox {
            min: [0.0; 3],
            max: [f64::NAN, 0.0, 0.0],
        };
        assert_eq!(Grid::new(&nan, Precision::Bits60), Err(GridRangeError));
    }

    #[test]
    fn snapping_is_exact_for_coordinates_far_below_or_above_the_origin() {
        // A unit box: origin near 0.5, cell 2^-58 in grid space (extent 1 → scale 1).
        let b = BoundingBox {
            min: [0.0; 3],
            max: [1.0; 3],
        };
        let g = Grid::new(&b, Precision::Bits60).unwrap();
        use num_bigint::BigInt;
        let o = (g.origin()[0] / g.cell()) as i64;
        // m·2^e scaled by 2^1200 as an exact integer.
        let exact = |x: f64| {
            let (m, e) = decompose(x);
            BigInt::from(m) << (e + 1200) as usize
        };
        for x in [
            -1e-17,
            1e-17,
            1e-50,
            -1e-300,
            5e-324,
            0.1,
            1.0 / 3.0,
            0.6666666666666666,
            -0.49999999999999994,
        ] {
            let (Snap::In(n), r) = g.snap_with_residual(x, 0) else {
                panic!("{x}")
            };
            assert!(r.abs() <= 0.5, "{x}: {r}");
            // x = (o + n + r)·cell exactly.
            let back = exact((o + n) as f64 * g.cell()) + exact(r * g.cell());
            assert_eq!(back, exact(x), "{x}");
        }
        // −1e-17 ≈ −2.88 cells (cell 2^-58): the nearest lattice point is three cells below 0.
        assert_eq!(g.cell(), 2f64.powi(-58));
        let (s, _) = g.snap_with_residual(-1e-17, 0);
        assert_eq!(s, Snap::In(-o - 3));
    }
}
