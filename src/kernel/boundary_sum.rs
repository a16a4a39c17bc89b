//! The boundary term of the Antipodal formula for one query: `Σ_k w_k·Area(A_k, B_k, x1)` over all
//! signed boundary edges — the hot loop of open meshes.
//!
//! Four edges at a time (`wide::f64x4`, or AVX2 intrinsics chosen at run time): offsets from the
//! query, the `f64` orientation `d` with a rigorous error bound, lengths and the cancellation-free
//! denominator. Instead of one `atan2` per edge, the terms `den + i·num` go into one [`AngleSum`]
//! (a complex product with turn counting; one `atan2` at the end): `atan2` dominated the loop
//! before (docs/benchmarks.md, "Design measurements").
//!
//! Lanes whose `|d|` does not clear the bound (the query is within ~1e-15·extent of the edge's
//! line through the ray, or a degenerate configuration) and edges of weight above
//! `MAX_CHAINED_WEIGHT` are recomputed one by one with the exact integer predicate and the limit
//! formulas of [`super::spherical::antipodal_edge_area`]. Either way the numerator's sign is the
//! exact sign of [`super::predicates::perturbed_orient2d`], so the branch agrees with the
//! crossing test.

use wide::f64x4;

use super::angle_sum::AngleSum;
#[cfg(target_arch = "x86_64")]
use super::angle_sum::AngleSumAvx2;
use super::double_double::DoubleDouble;
use super::input_predicates::{
    InputPoint, LatticeFrame, along_the_ray_off_its_line, exact_edge_moment,
    input_flat_denominator_sign, input_inside_segment, input_orient2d, parallel_to_the_ray,
};
#[cfg(target_arch = "x86_64")]
use super::lanes::Avx2;
use super::lanes::{Portable, edge_term, horizontal_sq, projected_dot, vertex_factors};
use super::predicates::{
    ORIENT2D_FILTER_CONVERSION, ORIENT2D_FILTER_RELATIVE, Orient2d, Width, orient2d_filter_lanes,
    perturbed_orient2d_at, query_inside_segment_at,
};
use super::spherical::{EdgeSigns, antipodal_edge_area, antipodal_edge_area_accurate};
use crate::base::compensated::NeumaierSum;
use crate::bvh::RayBvh;

/// Four consecutive values from `v[j]`.
#[inline(always)]
fn lanes4(v: &[f64], j: usize) -> [f64; 4] {
    <[f64; 4]>::try_from(&v[j..j + 4]).unwrap()
}

/// Lanes 1, 2, 3 of `a` followed by lane 0 of `b`.
#[inline]
fn shift_one(a: f64x4, b: f64x4) -> f64x4 {
    let (a, b) = (a.to_array(), b.to_array());
    f64x4::from([a[1], a[2], a[3], b[0]])
}

/// [`shift_one`] in AVX2: the permute brings `[a2, a3, b0, b1]`, the shuffle interleaves.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn shift_one_avx2(
    a: std::arch::x86_64::__m256d,
    b: std::arch::x86_64::__m256d,
) -> std::arch::x86_64::__m256d {
    use std::arch::x86_64::*;
    let mid = _mm256_permute2f128_pd::<0x21>(a, b);
    _mm256_shuffle_pd::<0b0101>(a, mid)
}

/// The coordinates the boundary loops compute their offsets in (one per evaluator).
///
/// Why not the lattice points: an offset `fl(x) − fl(q)` of 59-bit lattice coordinates is off by
/// up to `2^6` cells from their conversions, and by half a cell per point from snapping, whatever
/// the offset's size. The near-edge tube ([`near_edge_pad`]) assumes relative error, so a query
/// a few cells beyond it from a short edge (a mesh of extent `1e15` with edges of length 10) got
/// magnitudes wrong in the fifth digit while every sign stayed exact. In
/// [`LoopFrame::Unshifted`] each point is its world coordinate times the grid's power of two:
/// exact (the input's own bits), so an offset is the exact difference rounded once.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) enum LoopFrame {
    /// Lattice coordinates (cells from the grid origin): the evaluated geometry of the 30-bit
    /// grid (exact in `f64` there), and the unit tests' edges.
    #[default]
    Lattice,
    /// `x_world · 2^shift` (cells, not shifted by the grid origin): exact, the input itself.
    /// `origin_z` (the origin's frame `z` in cells) places a query clamped along the ray.
    Unshifted { shift: i64, origin_z: f64 },
}

/// Centres farther than this from the world origin (in cells) cannot be held unshifted: points
/// of the padded box (`±2^59` cells around the centre) must stay far from `f64`'s range.
const UNSHIFTED_LIMIT: f64 = 1e280;

impl LoopFrame {
    /// The frame for a grid of `bits` with lattice frame `lattice`: unshifted at 60 bits
    /// unless the grid's origin is beyond [`UNSHIFTED_LIMIT`] (a mesh of extent `1` at
    /// `1e260`; there the lattice frame's rounding is the documented limit).
    pub fn for_grid(bits: u32, lattice: &LatticeFrame) -> LoopFrame {
        let far = lattice
            .origin_cells
            .iter()
            .any(|&c| (c as f64).abs() > UNSHIFTED_LIMIT);
        if bits <= 30 || far {
            LoopFrame::Lattice
        } else {
            LoopFrame::Unshifted {
                shift: lattice.shift,
                origin_z: lattice.origin_cells[2] as f64,
            }
        }
    }

    /// A vertex's coordinates in this frame.
    fn vertex(&self, p: &InputPoint) -> [f64; 3] {
        match *self {
            LoopFrame::Lattice => p.n.map(|c| c as f64),
            LoopFrame::Unshifted { shift, .. } => p.world.map(|c| scaled_by_power_of_two(c, shift)),
        }
    }

    /// The query `q` in this frame. When `z_exact` is false the query lies beyond the grid along
    /// the ray and `qz_units` is its `z` in cells from the origin (`f64`: it is farther than the
    /// extent from every vertex).
    pub fn query(&self, q: &InputPoint, z_exact: bool, qz_units: f64) -> [f64; 3] {
        let [x, y, z] = self.vertex(q);
        let z = match *self {
            _ if z_exact => z,
            LoopFrame::Lattice => qz_units,
            LoopFrame::Unshifted { origin_z, .. } => qz_units + origin_z,
        };
        [x, y, z]
    }
}

/// `x · 2^e`, exact unless the result is subnormal (then within `2^-1074`: a tiny coordinate of a
/// huge mesh, whose magnitude that does not change) or beyond `f64` (excluded by
/// [`UNSHIFTED_LIMIT`]). Two steps, so that `|e|` up to 2046 needs no intermediate overflow.
pub(crate) fn scaled_by_power_of_two(x: f64, e: i64) -> f64 {
    let power = |e: i64| f64::from_bits(((e + 1023) as u64) << 52);
    let half = (e / 2).clamp(-1022, 1023);
    let rest = (e - half).clamp(-1022, 1023);
    x * power(half) * power(rest)
}

/// Boundary edges of one mesh in the ray frame, in grid units.
///
/// The SIMD loop walks the edges as *chains* of vertices (`v0 → v1 → v2 …`, closed loops repeat
/// their first vertex), so the offset, length and denominator factors of each vertex are computed
/// once per query and shared by the two edges that meet there: one `sqrt` per boundary vertex
/// instead of two per edge. An edge of weight `k` appears `k` times. Consecutive chains are
/// separated by a non-edge slot (`link = 0`), whose lane contributes the identity factor.
#[derive(Clone, Debug, Default)]
pub struct BoundaryEdges {
    a: Vec<[i64; 3]>,
    b: Vec<[i64; 3]>,
    weight: Vec<f64>,
    /// Chain vertices (structure of arrays, cells in [`BoundaryEdges::frame`]), padded with
    /// copies of the last vertex so that every block reads in bounds.
    xs: Vec<f64>,
    ys: Vec<f64>,
    zs: Vec<f64>,
    /// The frame of `xs`, `ys`, `zs` (and of the query the loops subtract).
    frame: LoopFrame,
    /// Each edge's endpoints in that frame (the gradient's sum runs over edges, not chains).
    ends_in_frame: Vec<([f64; 3], [f64; 3])>,
    /// [`ray_tube`] of the frame.
    tube: i64,
    /// `link[j] = 1` when slot `j` → `j + 1` is an edge, `0` for a break or padding.
    link: Vec<f64>,
    /// The edge (index into `a`, `b`) of each linked slot, for the exact fallback.
    edge_of: Vec<u32>,
    /// The linked slots of each edge: `edge_slots[edge_slots_start[e]..edge_slots_start[e + 1]]`
    /// (the inverse of `edge_of`, for [`BoundaryEdges::area_sum_with_accurate_edges`]).
    edge_slots_start: Vec<u32>,
    edge_slots: Vec<u32>,
    /// Number of slots (`j → j + 1` pairs) to visit.
    slots: usize,
    /// Edges of weight above [`MAX_CHAINED_WEIGHT`]: one exact term each, times the weight.
    heavy: Vec<u32>,
    /// `2^(bits−1)`: the largest grid coordinate, for the error bound of the `f64` conversions.
    limit: f64,
    /// The edges' boxes grown by [`near_edge_pad`], in normalized coordinates: finds the edges
    /// near a query (see [`BoundaryEdges::needs_accurate_sum`]).
    near: RayBvh,
    /// The endpoints exactly as given, when some are off the lattice (`None`: every endpoint
    /// snapped without loss, and the lattice is the input).
    inputs: Option<EdgeInputs>,
    /// How exact values are rebuilt from world coordinates.
    lattice: LatticeFrame,
}

/// The exact endpoints of the edges (see [`BoundaryEdges::with_inputs`]).
#[derive(Clone, Debug)]
struct EdgeInputs {
    a: Vec<InputPoint>,
    b: Vec<InputPoint>,
    /// Per edge: an endpoint is off the lattice.
    off_lattice: Vec<bool>,
}

/// How far around edge `a b` (grid units) a query gets the double-double term: `2^-7` of the
/// edge's largest extent, at least 16 cells (which also covers the one-cell reach of a residual,
/// see [`BoundaryEdges::needs_accurate_sum`]).
///
/// Error model of the `f64` term at distance `d` from the edge: the offsets are the exact
/// inputs' differences rounded once (relative `u = 2^-53`; at 60 bits, [`LoopFrame`]: before it
/// they were off by up to `2^6` cells whatever `d`, see there); near the segment both `atan2` arguments are
/// `≈ |a−q||b−q|·θ`, `θ ≈ d·len/(|a−q||b−q|)`, while their rounding errors are `≈ 2u·|a−q||b−q|`,
/// so the term errs by `≲ 2u/θ ≤ u·len/(2d)` (`|a−q||b−q| ≤ len²/4` on the segment, less
/// elsewhere; we allow `4u·len/d`). At `d ≥ 2^-7·len/√3` that is `≤ 900u = 1e-13`. Only a thin
/// tube around each boundary edge, proportional to its length, takes the slower path.
#[inline]
fn near_edge_pad(a: [i64; 3], b: [i64; 3]) -> i64 {
    let len = (0..3).map(|k| (a[k] - b[k]).abs()).max().unwrap_or(0);
    (len >> 7).max(16)
}

/// Whether `q` may lie within `reach` of the segment `a b` (grid units): the tube of
/// [`near_edge_pad`]'s error model, whose `d` is the distance to the segment, not to its box.
/// The box alone (the test before this one) flagged every query in the box of a long oblique
/// edge: on inconsistently oriented meshes, whose every edge is a boundary edge, that was 20 %
/// of a remesh band's queries, each 30× slower (docs/benchmarks.md, "Near-edge tube").
///
/// Soft and conservative: callers pass `reach ≥ 2·pad`; past the box test (the segment's box
/// grown by `reach`) `|q − a|` and `|b − a|` are at most `√3·(len + reach)` with
/// `pad ≥ len/128`, so the `f64` rounding of the differences and of the projection (a few
/// `u = 2^-53` relative of that) is below `2^-40·reach`: a query it lets through is more than
/// `reach/2 ≥ pad` from the segment.
#[inline]
fn within_reach_of_segment(q: [i64; 3], a: [i64; 3], b: [i64; 3], reach: i64) -> bool {
    if !(0..3).all(|k| q[k] >= a[k].min(b[k]) - reach && q[k] <= a[k].max(b[k]) + reach) {
        return false;
    }
    let d: [f64; 3] = std::array::from_fn(|k| (b[k] - a[k]) as f64);
    let v: [f64; 3] = std::array::from_fn(|k| (q[k] - a[k]) as f64);
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let vd = v[0] * d[0] + v[1] * d[1] + v[2] * d[2];
    let t = if dd > 0.0 {
        (vd / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let e: [f64; 3] = std::array::from_fn(|k| v[k] - t * d[k]);
    let reach = reach as f64;
    e[0] * e[0] + e[1] * e[1] + e[2] * e[2] <= reach * reach
}

/// Pads (of [`near_edge_pad`]) within which a query takes the double-double path: twice the
/// error model's distance, the margin that [`within_reach_of_segment`]'s rounding needs.
const FLAG_PADS: i64 = 2;

/// Pads within which a query on the double-double path gets an edge's term in double-double;
/// farther edges take the `f64` term (exact signs, `f64` magnitudes), which errs by at most
/// `4u·len/d ≤ 64u = 7e-15` there ([`near_edge_pad`]'s model at `d = 8·len/128`), instead of
/// the loop's `900u` at the flagging distance: the path stays more accurate than the loop.
const ACCURATE_TERM_PADS: i64 = 8;

/// Whether the `f64` term of edge `a b` at the lattice query `qi` can err beyond the loop's
/// model: an endpoint in the column above the query ([`ray_tube`], half-width `tube`), or
/// (`z_exact`) the query within `pads` pads ([`near_edge_pad`]) of the segment.
#[inline]
fn ill_conditioned(
    a: [i64; 3],
    b: [i64; 3],
    qi: [i64; 3],
    z_exact: bool,
    tube: i64,
    pads: i64,
) -> bool {
    let near_ray = |p: [i64; 3]| {
        (p[0] - qi[0]).abs() <= tube
            && (p[1] - qi[1]).abs() <= tube
            && (!z_exact || p[2] >= qi[2] - 1)
    };
    near_ray(a)
        || near_ray(b)
        || (z_exact && within_reach_of_segment(qi, a, b, pads * near_edge_pad(a, b)))
}

/// Half-width (grid units) of the column above each boundary vertex in which a query takes the
/// double-double path, for the loops' frame.
///
/// Why: a vertex `v` seen almost along the ray (transverse offset `h ≪ |v − q|`) enters its
/// terms through the azimuth of `v − q` around the ray (the on-ray limit of
/// docs/robustness.md §3), so an error `δ` in the transverse offset moves the term by `≈ 2δ/h`
/// whatever the distance along the ray. In the lattice frame that error is absolute, `δ ≤ 2^7`
/// cells at 60 bits (two conversions of 59-bit integers to `f64`, half a cell of snapping): the
/// column is `limit / 2^14` (`2^45` cells, about `1e-5` of the extent), outside which the term
/// errs by `≤ 2·2^7/2^45 = 2^-37` in area, `≤ 6e-13` on `w`. In the unshifted frame each
/// transverse offset is its exact value rounded once, `δ ≤ u·h`, so the azimuth errs by `~2u`
/// whatever `h`: no column beyond the query's own lattice one (where `h` may be below a cell).
/// The column had been the slow path of meshes with small parts in a huge box: `2^-14` of a
/// `1e15` extent is `6e10` units, so every query near a 40-unit hole took the double-double
/// terms of all its edges (docs/benchmarks.md, "Exact magnitudes").
fn ray_tube(frame: LoopFrame, limit: f64) -> i64 {
    match frame {
        LoopFrame::Lattice => (limit as i64) >> 14,
        LoopFrame::Unshifted { .. } => 0,
    }
}

/// Whether edge `a → b` is parallel to the ray (equal `x, y` in the frame; zero length included).
///
/// Its term is exactly zero for every query, so the loops leave it out: both ε coefficients of
/// its perturbed orientation vanish (`a_y − b_y = b_x − a_x = 0`) and the unperturbed determinant
/// is zero too (`a − q` and `b − q` have equal `x, y`), so [`perturbed_orient2d`] gives sign 0,
/// for which [`antipodal_edge_area`] returns 0 (the query's projection, perturbed, never lies on
/// the edge's projection, a point). The `f64` filter could never sign such an edge, so before
/// this every one of them took the exact path on every query: CAD plates with vertical walls
/// spent half their time there (docs/benchmarks.md).
#[inline]
pub(crate) fn is_parallel_to_ray(a: [i64; 3], b: [i64; 3]) -> bool {
    a[0] == b[0] && a[1] == b[1]
}

/// Edges up to this weight are repeated in the chains; heavier ones (stacks of duplicated faces:
/// one shared mesh has an edge of weight 466) take one exact scalar term times the weight.
const MAX_CHAINED_WEIGHT: f64 = 4.0;

impl BoundaryEdges {
    /// Packs edges `a[i] → b[i]` with positive integer weights `weight[i]` (grid coordinates, ray
    /// frame). The evaluator builds with [`BoundaryEdges::with_inputs`]; the unit tests use this.
    #[cfg(test)]
    pub fn new(a: Vec<[i64; 3]>, b: Vec<[i64; 3]>, weight: Vec<f64>, bits: u32) -> Self {
        Self::build(a, b, weight, bits, None, LatticeFrame::default())
    }

    /// [`BoundaryEdges::new`] whose loops run in the unshifted frame of `lattice`
    /// ([`LoopFrame::Unshifted`]) with the endpoints `(a_in, b_in)` (the column tests).
    #[cfg(test)]
    pub fn unshifted(
        a: Vec<[i64; 3]>,
        b: Vec<[i64; 3]>,
        weight: Vec<f64>,
        (a_in, b_in): (Vec<InputPoint>, Vec<InputPoint>),
        lattice: LatticeFrame,
    ) -> Self {
        Self::with_inputs(a, b, weight, 60, (a_in, b_in), lattice)
    }

    /// [`BoundaryEdges::new`] with the exact endpoints (`a_in[i]`, `b_in[i]` of edge `i`, whose
    /// lattice points are `a[i]`, `b[i]`): kept when some endpoint is off the lattice. Every sign
    /// the loops cannot take from their `f64` filter is then decided on these (the filter's own
    /// decisions are already exact for them: see the snapping argument after
    /// `ORIENT2D_FILTER_RELATIVE` in `predicates.rs`), and an edge is left out as parallel to the
    /// ray only when its input endpoints are (a snapped edge can be vertical on the lattice and
    /// tilted in the input).
    pub fn with_inputs(
        a: Vec<[i64; 3]>,
        b: Vec<[i64; 3]>,
        weight: Vec<f64>,
        bits: u32,
        (a_in, b_in): (Vec<InputPoint>, Vec<InputPoint>),
        lattice: LatticeFrame,
    ) -> Self {
        debug_assert!(a_in.len() == a.len() && b_in.len() == b.len());
        Self::build(a, b, weight, bits, Some((a_in, b_in)), lattice)
    }

    fn build(
        a: Vec<[i64; 3]>,
        b: Vec<[i64; 3]>,
        weight: Vec<f64>,
        bits: u32,
        endpoints: Option<(Vec<InputPoint>, Vec<InputPoint>)>,
        lattice: LatticeFrame,
    ) -> Self {
        let frame = match endpoints {
            Some(_) => LoopFrame::for_grid(bits, &lattice),
            None => LoopFrame::Lattice,
        };
        let point = |e: u32, start: bool| match &endpoints {
            Some((a_in, b_in)) => {
                let p = if start {
                    &a_in[e as usize]
                } else {
                    &b_in[e as usize]
                };
                frame.vertex(p)
            }
            None => (if start { a[e as usize] } else { b[e as usize] }).map(|c| c as f64),
        };
        let coordinates: Vec<([f64; 3], [f64; 3])> = (0..a.len() as u32)
            .map(|e| (point(e, true), point(e, false)))
            .collect();
        let inputs = endpoints.and_then(|(a_in, b_in)| {
            let off_lattice: Vec<bool> = a_in
                .iter()
                .zip(&b_in)
                .map(|(p, q)| !p.on_lattice() || !q.on_lattice())
                .collect();
            off_lattice.iter().any(|&x| x).then_some(EdgeInputs {
                a: a_in,
                b: b_in,
                off_lattice,
            })
        });
        let parallel: Vec<bool> = (0..a.len())
            .map(|i| {
                // Off the lattice, only where the inputs are parallel too (the same argument:
                // `parallel_to_the_ray`; `along_the_ray_off_its_line` says why it matters).
                is_parallel_to_ray(a[i], b[i])
                    && inputs
                        .as_ref()
                        .is_none_or(|x| !x.off_lattice[i] || parallel_to_the_ray(&x.a[i], &x.b[i]))
            })
            .collect();
        // Chained where an edge's end and the next one's start are the same lattice point *and*
        // the same loop coordinates: the loop takes the next edge's start from the previous
        // edge's end, and two inputs a cell apart can share a lattice point (a chain joined
        // there summed one edge from the other input's position: a fractional error of 3e-5
        // on a 1e15 sheet, `sliver_at_1e15_magnitudes_under_a_mirrored_frame`).
        let key = |p: [i64; 3], c: [f64; 3]| (p, c.map(|x| (x + 0.0).to_bits()));
        let starts: Vec<_> = (0..a.len()).map(|e| key(a[e], coordinates[e].0)).collect();
        let ends: Vec<_> = (0..a.len()).map(|e| key(b[e], coordinates[e].1)).collect();
        let mut chains = chain_edges(&starts, &ends, &weight, &parallel);
        // Chains in Morton order of their first vertex: the hierarchy over slot ranges
        // (`boundary_tree`) then groups nearby chains (a scan's many small holes) into compact
        // nodes. The flat sum does not depend on the order (beyond rounding).
        chains.sort_by_cached_key(|chain| morton_key(a[chain[0] as usize], bits));
        let mut xs = Vec::new();
        let mut ys = Vec::new();
        let mut zs = Vec::new();
        let mut link = Vec::new();
        let mut edge_of = Vec::new();
        for chain in &chains {
            let v0 = chain[0];
            let mut push = |v: [f64; 3], l: f64, e: u32| {
                xs.push(v[0]);
                ys.push(v[1]);
                zs.push(v[2]);
                link.push(l);
                edge_of.push(e);
            };
            // A chain vertex is the end of one edge and the start of the next: the same lattice
            // point, and (but for two inputs snapped to one point) the same input.
            push(coordinates[v0 as usize].0, 1.0, v0);
            for (k, &e) in chain.iter().enumerate() {
                let last = k + 1 == chain.len();
                let next = if last { 0 } else { chain[k + 1] };
                push(
                    coordinates[e as usize].1,
                    if last { 0.0 } else { 1.0 },
                    if last { u32::MAX } else { next },
                );
            }
        }
        let slots = xs.len();
        let mut edge_slots_start = vec![0u32; a.len() + 1];
        for j in 0..slots {
            if link[j] != 0.0 {
                edge_slots_start[edge_of[j] as usize + 1] += 1;
            }
        }
        for e in 0..a.len() {
            edge_slots_start[e + 1] += edge_slots_start[e];
        }
        let mut edge_slots = vec![0u32; edge_slots_start[a.len()] as usize];
        let mut next = edge_slots_start.clone();
        for j in 0..slots {
            if link[j] != 0.0 {
                let e = edge_of[j] as usize;
                edge_slots[next[e] as usize] = j as u32;
                next[e] += 1;
            }
        }
        // Padding: the loop reads up to 7 vertices past the last slot.
        let pad = 8;
        let (lx, ly, lz) = (
            xs.last().copied().unwrap_or(0.0),
            ys.last().copied().unwrap_or(0.0),
            zs.last().copied().unwrap_or(0.0),
        );
        for _ in 0..pad {
            xs.push(lx);
            ys.push(ly);
            zs.push(lz);
            link.push(0.0);
            edge_of.push(u32::MAX);
        }
        let heavy = (0..weight.len() as u32)
            .filter(|&i| weight[i as usize] > MAX_CHAINED_WEIGHT && !parallel[i as usize])
            .collect();
        let limit = (1_i64 << (bits - 1)) as f64;
        let tube = ray_tube(frame, limit);
        let to_unit = 1.0 / limit;
        let near_boxes: Vec<([f32; 3], [f32; 3])> = a
            .iter()
            .zip(&b)
            .map(|(&p, &q)| {
                let pad = near_edge_pad(p, q);
                let pad = |k: usize| if k < 2 { pad.max(tube) } else { pad };
                let lo =
                    std::array::from_fn(|k| ((p[k].min(q[k]) - pad(k)) as f64 * to_unit) as f32);
                let hi =
                    std::array::from_fn(|k| ((p[k].max(q[k]) + pad(k)) as f64 * to_unit) as f32);
                (lo, hi)
            })
            .collect();
        let near = RayBvh::build(&near_boxes);
        BoundaryEdges {
            a,
            b,
            weight,
            xs,
            ys,
            zs,
            frame,
            ends_in_frame: coordinates,
            tube,
            link,
            edge_of,
            edge_slots_start,
            edge_slots,
            slots,
            heavy,
            limit,
            near,
            inputs,
            lattice,
        }
    }

    /// Number of edges.
    pub fn len(&self) -> usize {
        self.a.len()
    }

    /// True when there is no boundary.
    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }

    /// Edge `i` as (start, end, weight) in grid coordinates.
    pub fn edge(&self, i: usize) -> ([i64; 3], [i64; 3], f64) {
        (self.a[i], self.b[i], self.weight[i])
    }

    /// `Σ w·Area` for the query `qi` (grid coordinates, frame). When `z_exact` is false the
    /// query's z lies outside the grid: `qz_units` (its z in grid units, `f64`) is used for the
    /// magnitudes and `qi[2]` (clamped) for nothing but the predicates, which do not involve z.
    /// `r` is the query's exact residual (cells; `r[2] = 0` when `z_exact` is false): the
    /// magnitudes are the exact query's and the exact vertices' ([`LoopFrame`]), every sign the
    /// exact query's (see [`BoundaryEdges::exact_edge_area`]; the caller has checked with
    /// [`BoundaryEdges::needs_accurate_sum`] that `r` changes no lattice edge's sign).
    pub fn area_sum<W: Width>(&self, q: &InputPoint, z_exact: bool, qz_units: f64) -> f64 {
        if self.a.is_empty() {
            return 0.0;
        }
        let (angles, scalar) = self.range_area_sum::<W>(q, z_exact, qz_units, 0..self.slots);
        2.0 * angles.total() + scalar + self.heavy_area_sum::<W>(q, z_exact, qz_units)
    }

    /// The chained edges of the slots `range` (a multiple of 4 at the start; see
    /// [`BoundaryEdges::padded_slots`]): their `atan2` terms as one product (so that one `atan2`
    /// can serve many ranges, [`AngleSum::absorb`]) and the sum of the terms recomputed exactly.
    pub(crate) fn range_area_sum<W: Width>(
        &self,
        q_exact: &InputPoint,
        z_exact: bool,
        qz_units: f64,
        range: std::ops::Range<usize>,
    ) -> (AngleSum, f64) {
        debug_assert!(range.start.is_multiple_of(4) && range.end <= self.padded_slots());
        let q = self.frame.query(q_exact, z_exact, qz_units);
        let mut scalar = 0.0;
        let mut undecided = |e: u32| {
            scalar += self.exact_edge_area::<W>(e as usize, q_exact, z_exact, qz_units);
        };
        #[cfg(target_arch = "x86_64")]
        let range_angles = if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: `chain_angles_avx2` only needs the AVX2 instructions it is compiled
            // with, and the CPU was just checked to have them.
            #[allow(unsafe_code)]
            unsafe {
                self.chain_angles_avx2(q, range, &mut undecided)
            }
        } else {
            self.chain_angles(q, range, &mut undecided)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let range_angles = self.chain_angles(q, range, &mut undecided);
        (range_angles, scalar)
    }

    /// The edges too heavy to chain (each one exact term times its weight).
    pub(crate) fn heavy_area_sum<W: Width>(
        &self,
        q: &InputPoint,
        z_exact: bool,
        qz_units: f64,
    ) -> f64 {
        let mut sum = 0.0;
        for &e in &self.heavy {
            let e = e as usize;
            sum += self.weight[e] * self.exact_edge_area::<W>(e, q, z_exact, qz_units);
        }
        sum
    }

    /// Edges of weight above [`MAX_CHAINED_WEIGHT`] (not in any slot).
    pub(crate) fn heavy_edges(&self) -> impl Iterator<Item = usize> + '_ {
        self.heavy.iter().map(|&e| e as usize)
    }

    /// Number of slots (`j → j + 1` pairs) the loops visit.
    pub(super) fn slots(&self) -> usize {
        self.slots
    }

    /// The chain vertices' `x`, `y`, `z` (cells in the loops' frame, padded) and the slot links.
    pub(super) fn vertex_arrays(&self) -> (&[f64], &[f64], &[f64], &[f64]) {
        (&self.xs, &self.ys, &self.zs, &self.link)
    }

    /// The loops' frame.
    pub(super) fn frame(&self) -> LoopFrame {
        self.frame
    }

    /// Edge `i`'s endpoints in the loops' frame.
    pub(super) fn edge_in_frame(&self, i: usize) -> ([f64; 3], [f64; 3]) {
        self.ends_in_frame[i]
    }

    /// Slots rounded up to a multiple of 4: the end of the last range a loop may visit.
    pub(crate) fn padded_slots(&self) -> usize {
        self.slots.div_ceil(4) * 4
    }

    /// The edge of slot `j` (vertex `j` → vertex `j + 1`), or `None` for a break or padding.
    pub(crate) fn slot_edge(&self, j: usize) -> Option<usize> {
        (self.link[j] != 0.0).then(|| self.edge_of[j] as usize)
    }

    /// `2^(bits−1)`: grid coordinates divided by it are normalized to `[−1, 1]`.
    pub(crate) fn limit(&self) -> f64 {
        self.limit
    }

    /// Whether the query `qi + r` (lattice point, residual in cells; `r[2] = 0` when `z_exact` is
    /// false) needs [`BoundaryEdges::area_sum_accurate`] instead of [`BoundaryEdges::area_sum`]:
    /// - it lies within the near-edge distance of some edge (ill-conditioned `f64` term), or
    /// - it has a residual and some edge's projected line passes so close to the lattice point
    ///   that the residual could change the exact sign of that edge's numerator (or the
    ///   orientation is degenerate, where the segment test needs the exact z).
    ///
    /// Otherwise the loop has every sign of the exact query, and the magnitudes of the exact
    /// points within the error model of [`near_edge_pad`] ([`LoopFrame`]).
    pub fn needs_accurate_sum<W: Width>(&self, qi: [i64; 3], r: [f64; 3], z_exact: bool) -> bool {
        let mut flagged = false;
        self.for_each_flagged_edge(qi, r, z_exact, |_| {
            flagged = true;
            false
        });
        flagged
    }

    /// The edges of [`BoundaryEdges::needs_accurate_sum`]'s tests at `qi + r`, each once, in no
    /// particular order: the only terms [`BoundaryEdges::area_sum_with_accurate_edges`] computes
    /// apart from the loop.
    pub fn accurate_edges<W: Width>(&self, qi: [i64; 3], r: [f64; 3], z_exact: bool) -> Vec<u32> {
        let mut edges = Vec::new();
        self.for_each_flagged_edge(qi, r, z_exact, |e| {
            edges.push(e);
            true
        });
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    /// Calls `f` with each edge whose term the lattice loop may get wrong at `qi + r` (the tests
    /// of [`BoundaryEdges::needs_accurate_sum`]) until it returns false.
    fn for_each_flagged_edge(
        &self,
        qi: [i64; 3],
        r: [f64; 3],
        z_exact: bool,
        mut f: impl FnMut(u32) -> bool,
    ) {
        if self.a.is_empty() {
            return;
        }
        let residual = r != [0.0; 3];
        let tube = self.tube;
        let u = |v: i64| (v as f64 / self.limit) as f32;
        let z_min = if residual {
            f32::NEG_INFINITY
        } else {
            u(qi[2])
        };
        let mut going = true;
        self.near.for_each_on_ray(u(qi[0]), u(qi[1]), z_min, |e| {
            if !going {
                return;
            }
            let (a, b) = (self.a[e as usize], self.b[e as usize]);
            let flagged = ill_conditioned(a, b, qi, z_exact, tube, FLAG_PADS)
                || residual && {
                    let (u0, u1, v0, v1) = (a[0] - qi[0], a[1] - qi[1], b[0] - qi[0], b[1] - qi[1]);
                    let lattice = i128::from(u0) * i128::from(v1) - i128::from(u1) * i128::from(v0);
                    // |D(q + r) − D(q)| ≤ |e_x||r_y| + |e_y||r_x|; generous margins (a soft
                    // test).
                    let slack =
                        ((b[0] - a[0]) as f64 * r[1]).abs() + ((b[1] - a[1]) as f64 * r[0]).abs();
                    (lattice as f64).abs() <= 2.0 * slack + 2.0
                };
            if flagged {
                going = f(e);
            }
        });
    }

    /// [`BoundaryEdges::area_sum_accurate`] at a query whose residual is exact, with the edges
    /// that need it (`accurate`, from [`BoundaryEdges::accurate_edges`]) computed as there and
    /// every other edge by the loop: the loop is right for an edge that no test flags (the
    /// argument of [`BoundaryEdges::needs_accurate_sum`] is edge by edge), and on a long
    /// boundary the scalar path over every edge cost ~7× the loop for a query next to one of
    /// them (docs/benchmarks.md, "Decisive values"). The loop runs over whole blocks of 4 slots,
    /// so a block holding a flagged edge takes the accurate terms for all its edges.
    pub fn area_sum_with_accurate_edges<W: Width>(
        &self,
        q: &InputPoint,
        z_exact: bool,
        qz_units: f64,
        accurate: &[u32],
    ) -> f64 {
        let mut blocks: Vec<usize> = accurate
            .iter()
            .flat_map(|&e| self.slots_of_edge(e as usize))
            .map(|j| j / 4)
            .collect();
        blocks.sort_unstable();
        blocks.dedup();
        let mut angles: Option<AngleSum> = None;
        let mut scalar = 0.0;
        let mut terms = NeumaierSum::new();
        let mut run = |range: std::ops::Range<usize>, angles: &mut Option<AngleSum>| {
            if range.is_empty() {
                return;
            }
            let (a, s) = self.range_area_sum::<W>(q, z_exact, qz_units, range);
            match angles {
                Some(acc) => acc.absorb(&a),
                None => *angles = Some(a),
            }
            scalar += s;
        };
        let mut start = 0;
        for &block in &blocks {
            let j0 = 4 * block;
            run(start..j0, &mut angles);
            for j in j0..j0 + 4 {
                if let Some(e) = self.slot_edge(j) {
                    terms.add(self.accurate_edge_area::<W>(e, q, z_exact, qz_units));
                }
            }
            start = j0 + 4;
        }
        run(start..self.slots.max(start), &mut angles);
        for &e in &self.heavy {
            let e = e as usize;
            let term = if accurate.binary_search(&(e as u32)).is_ok() {
                self.accurate_edge_area::<W>(e, q, z_exact, qz_units)
            } else {
                self.exact_edge_area::<W>(e, q, z_exact, qz_units)
            };
            terms.add(self.weight[e] * term);
        }
        angles.map_or(0.0, |a| 2.0 * a.total()) + scalar + terms.value()
    }

    /// The slots holding edge `e` (one per unit of weight; none for heavy or parallel edges).
    fn slots_of_edge(&self, e: usize) -> impl Iterator<Item = usize> + '_ {
        let (from, to) = (self.edge_slots_start[e], self.edge_slots_start[e + 1]);
        self.edge_slots[from as usize..to as usize]
            .iter()
            .map(|&j| j as usize)
    }

    /// `Σ w·Area` at the exact query `q = qi + r` (see [`BoundaryEdges::needs_accurate_sum`]):
    /// every sign from the exact predicates (the `_at` ones on the lattice, the input ones for
    /// edges with an endpoint off the lattice or a query whose residual underflowed), every
    /// magnitude from double-double offsets of the exact points: in double-double for the edges
    /// near the query ([`ACCURATE_TERM_PADS`], and those with an endpoint in the ray's column),
    /// in `f64` from those offsets for the rest (a query near one edge of a long boundary paid
    /// ~30× the loop on every edge before). `O(B)` scalar.
    pub fn area_sum_accurate<W: Width>(&self, q: &InputPoint, z_exact: bool, qz_units: f64) -> f64 {
        let mut sum = NeumaierSum::new();
        for i in 0..self.a.len() {
            sum.add(self.weight[i] * self.accurate_edge_area::<W>(i, q, z_exact, qz_units));
        }
        sum.value()
    }

    /// The term of edge `i` (weight 1) of [`BoundaryEdges::area_sum_accurate`].
    fn accurate_edge_area<W: Width>(
        &self,
        i: usize,
        q: &InputPoint,
        z_exact: bool,
        qz_units: f64,
    ) -> f64 {
        let (pa, pb) = self.edge_points(i);
        let near = ill_conditioned(
            self.a[i],
            self.b[i],
            q.n,
            z_exact,
            self.tube,
            ACCURATE_TERM_PADS,
        );
        self.exact_segment_area::<W>(&pa, &pb, q, z_exact, qz_units, near)
    }

    /// The exact endpoints of edge `i`: its inputs when one is off the lattice, else its lattice
    /// points.
    pub(crate) fn edge_points(&self, i: usize) -> (InputPoint, InputPoint) {
        match self.inputs.as_ref().filter(|x| x.off_lattice[i]) {
            Some(x) => (x.a[i], x.b[i]),
            None => (
                InputPoint::lattice(self.a[i]),
                InputPoint::lattice(self.b[i]),
            ),
        }
    }

    /// `(a − q) × (b − q)` of edge `i` on the exact inputs, in cells squared, as
    /// [`exact_edge_moment`] gives it; for the gradient next to the edge's interior.
    pub(crate) fn edge_moment(&self, i: usize, q: &InputPoint) -> Option<([DoubleDouble; 3], i64)> {
        let (pa, pb) = self.edge_points(i);
        exact_edge_moment(q, &pa, &pb, &self.lattice)
    }

    /// The term `Area(A, B, x1)` of the segment `pa → pb` between exact points at the exact
    /// query `q` (a residual that underflowed included), through the exact predicates and the
    /// limit formulas: the lattice ones (the `_at` forms for a query off the lattice) when both
    /// ends are on the lattice and the query's residual is exact, the input ones otherwise. The
    /// magnitudes come from [`exact_offsets`]: in double-double when `accurate` (near the
    /// segment or its ray column), rounded once otherwise, the loop's error model
    /// ([`LoopFrame`]).
    pub(crate) fn exact_segment_area<W: Width>(
        &self,
        pa: &InputPoint,
        pb: &InputPoint,
        q: &InputPoint,
        z_exact: bool,
        qz_units: f64,
        accurate: bool,
    ) -> f64 {
        let (o, query_inside_segment) = if along_the_ray_off_its_line(q, pa, pb) {
            (
                Orient2d {
                    sign: 0,
                    degenerate: true,
                },
                false,
            )
        } else if pa.on_lattice() && pb.on_lattice() && q.residual_exact() {
            let (qi, r, a, b) = (q.n, q.r, pa.n, pb.n);
            let o = perturbed_orient2d_at::<W>(
                [qi[0], qi[1]],
                [r[0], r[1]],
                [a[0], a[1]],
                [b[0], b[1]],
            );
            let inside = o.degenerate && z_exact && query_inside_segment_at(qi, r, a, b);
            (o, inside)
        } else {
            let o = input_orient2d(q, pa, pb, &self.lattice);
            let inside = o.degenerate && z_exact && input_inside_segment(q, pa, pb, &self.lattice);
            (o, inside)
        };
        let signs = EdgeSigns {
            numerator: -o.sign,
            query_inside_segment,
            // Exactly collinear seen along the ray: the denominator's sign is a predicate too.
            flat_denominator: if o.degenerate && o.sign != 0 && !query_inside_segment {
                input_flat_denominator_sign(q, pa, pb, &self.lattice)
            } else {
                0
            },
        };
        let ra = exact_offsets(pa, q, z_exact, qz_units);
        let rb = exact_offsets(pb, q, z_exact, qz_units);
        if accurate {
            // The exact moment only where the query's residual and the ray coordinate are the
            // input's (a clamped query is far from every segment).
            let moment = || z_exact.then(|| exact_edge_moment(q, pa, pb, &self.lattice))?;
            antipodal_edge_area_accurate(ra, rb, signs, moment)
        } else {
            // `hi` is the offset rounded once (normalized pairs).
            antipodal_edge_area(ra.map(|x| x.hi), rb.map(|x| x.hi), signs)
        }
    }

    /// The bound constants of the `f64` orientation filter: error of an offset: conversions of a
    /// and q (≤ u·L each) and the subtraction (≤ u·|offset|), u = 2^-53. Error of
    /// d = ax·by − ay·bx: Σ |other factor|·(offset error) + 3u(|p1| + |p2|). We use twice that:
    /// `bound = conv·(|ax| + |ay| + |bx| + |by|) + rel·(|p1| + |p2|)`.
    pub(super) fn filter_constants(&self) -> (f64, f64) {
        (
            ORIENT2D_FILTER_CONVERSION * self.limit,
            ORIENT2D_FILTER_RELATIVE,
        )
    }

    /// The chained edges' terms for the query `q` (grid units, `f64`) multiplied into an
    /// [`AngleSum`]; `undecided(e)` is called for each edge the filter cannot sign.
    fn chain_angles(
        &self,
        q: [f64; 3],
        slots: std::ops::Range<usize>,
        undecided: &mut impl FnMut(u32),
    ) -> AngleSum {
        let o = Portable;
        let [qx, qy, qz] = q.map(f64x4::splat);
        let (conv, rel) = self.filter_constants();
        let (conv, rel) = (o.splat(conv), o.splat(rel));
        let zero = o.splat(0.0);
        let lanes = |v: &[f64], j: usize| f64x4::from(lanes4(v, j));
        // Offsets x, y and the factors s, p (`vertex_factors!`) of the 4 vertices from slot `j`.
        let vertices = |j: usize| {
            let x = o.sub(lanes(&self.xs, j), qx);
            let y = o.sub(lanes(&self.ys, j), qy);
            let z = o.sub(lanes(&self.zs, j), qz);
            let (s, p) = vertex_factors!(o, horizontal_sq!(o, x, y), z);
            [x, y, s, p]
        };
        let mut angles = AngleSum::new();
        let mut cur = vertices(slots.start);
        for j in slots.step_by(4) {
            // Edge slots j..j+4 run from these vertices to the next four, i.e. to lanes
            // shifted by one (the data is padded past the last slot).
            let next = vertices(j + 4);
            let [ax, ay, sa, pa] = cur;
            let [bx, by, sb, pb] = std::array::from_fn(|k| shift_one(cur[k], next[k]));
            cur = next;
            let real = o.gt(lanes(&self.link, j), zero);
            let (d, ok) = orient2d_filter_lanes!(o, [ax, ay, bx, by], real, conv, rel);
            let dot = projected_dot!(o, ax, ay, bx, by);
            let (t_re, t_im) = edge_term!(o, (sa, pa), (sb, pb), dot, o.sub(zero, d), ok);
            angles.push(t_re, t_im);
            if j % 8 == 4 {
                // Terms are at most ~2^250 (grid units): two pushes stay in range.
                angles.rescale();
            }
            self.report_undecided(j, real.move_mask() & !ok.move_mask(), undecided);
        }
        angles
    }

    /// [`Self::chain_angles`] written with AVX2 intrinsics: the same operations in the same
    /// order, so the result is bit-identical (tested), about twice as fast (`wide`'s 4-lane types
    /// are two SSE2 halves in a portable build; `docs/benchmarks.md` has the numbers). Only
    /// `area_sum` calls it, after checking that the CPU has AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn chain_angles_avx2(
        &self,
        q: [f64; 3],
        slots: std::ops::Range<usize>,
        undecided: &mut impl FnMut(u32),
    ) -> AngleSum {
        use std::arch::x86_64::*;
        let o = Avx2;
        let load = |v: &[f64], j: usize| -> __m256d { bytemuck::cast(lanes4(v, j)) };
        let [qx, qy, qz] = q.map(|c| o.splat(c));
        let (conv, rel) = self.filter_constants();
        let (conv, rel) = (o.splat(conv), o.splat(rel));
        let zero = o.splat(0.0);
        macro_rules! vertices {
            ($j:expr) => {{
                let x = o.sub(load(&self.xs, $j), qx);
                let y = o.sub(load(&self.ys, $j), qy);
                let z = o.sub(load(&self.zs, $j), qz);
                let (s, p) = vertex_factors!(o, horizontal_sq!(o, x, y), z);
                [x, y, s, p]
            }};
        }
        let mut angles = AngleSumAvx2::new();
        let mut cur = vertices!(slots.start);
        for j in slots.step_by(4) {
            let next = vertices!(j + 4);
            let [ax, ay, sa, pa] = cur;
            let (bx, by, sb, pb) = (
                shift_one_avx2(cur[0], next[0]),
                shift_one_avx2(cur[1], next[1]),
                shift_one_avx2(cur[2], next[2]),
                shift_one_avx2(cur[3], next[3]),
            );
            cur = next;
            let real = o.gt(load(&self.link, j), zero);
            let (d, ok) = orient2d_filter_lanes!(o, [ax, ay, bx, by], real, conv, rel);
            let dot = projected_dot!(o, ax, ay, bx, by);
            let (t_re, t_im) = edge_term!(o, (sa, pa), (sb, pb), dot, o.sub(zero, d), ok);
            angles.push(t_re, t_im);
            if j % 8 == 4 {
                // Terms are at most ~2^250 (grid units): two pushes stay in range.
                angles.rescale();
            }
            let mask = _mm256_movemask_pd(real) & !_mm256_movemask_pd(ok);
            self.report_undecided(j, mask, undecided);
        }
        angles.finish()
    }

    /// Calls `undecided(e)` for the edges of the slots `j..j+4` set in `mask`.
    #[inline]
    pub(super) fn report_undecided(&self, j: usize, mask: i32, undecided: &mut impl FnMut(u32)) {
        if mask != 0 {
            for l in 0..4 {
                if mask & (1 << l) != 0 {
                    undecided(self.edge_of[j + l]);
                }
            }
        }
    }

    /// One edge through the exact predicates and the limit formulas
    /// ([`BoundaryEdges::exact_segment_area`] at the query `qi + r`): the loop's fallback for the
    /// edges its filter cannot sign, and the heavy edges' terms.
    #[cold]
    pub(super) fn exact_edge_area<W: Width>(
        &self,
        i: usize,
        q: &InputPoint,
        z_exact: bool,
        qz_units: f64,
    ) -> f64 {
        let (pa, pb) = self.edge_points(i);
        self.exact_segment_area::<W>(&pa, &pb, q, z_exact, qz_units, false)
    }
}

/// The offset `p − q` of exact points (cells, frame) in double-double: the lattice difference is
/// exact and so is the residuals' (two-sum), so near a vertex (same lattice point) the offset is
/// exact however small — `1e-300` from a corner (the term's scaling is removed in the spherical
/// formula). When `z_exact` is false, `z` is taken from `qz_units` (the query lies beyond the
/// grid along the ray).
fn exact_offsets(
    p: &InputPoint,
    q: &InputPoint,
    z_exact: bool,
    qz_units: f64,
) -> [DoubleDouble; 3] {
    let along =
        |k: usize| DoubleDouble::from_i64(p.n[k] - q.n[k]) + DoubleDouble::diff(p.r[k], q.r[k]);
    let z = if z_exact {
        along(2)
    } else {
        DoubleDouble::from_i64(p.n[2]) + DoubleDouble::diff(p.r[2], qz_units)
    };
    [along(0), along(1), z]
}

/// The offset `p − q` of exact points (cells, frame) in `f64`: the integer difference and the
/// residuals' each rounded once, then their sum, so within `2u·|p − q| + 2^-50` cells
/// (`u = 2^-53`), the error model of the loop ([`LoopFrame`]); for the hierarchy's spokes.
pub(crate) fn rounded_offset(
    p: &InputPoint,
    q: &InputPoint,
    z_exact: bool,
    qz_units: f64,
) -> [f64; 3] {
    let along = |k: usize| (p.n[k] - q.n[k]) as f64 + (p.r[k] - q.r[k]);
    let z = if z_exact {
        along(2)
    } else {
        p.n[2] as f64 + (p.r[2] - qz_units)
    };
    [along(0), along(1), z]
}

/// The Morton (Z-order) key of a grid point: the top 21 bits of each coordinate, interleaved.
fn morton_key(p: [i64; 3], bits: u32) -> u64 {
    let spread = |c: i64| -> u64 {
        // Offset to non-negative, keep 21 bits, spread them three apart.
        let v = ((c + (1_i64 << (bits - 1))) >> (bits.saturating_sub(21))) as u64 & 0x1f_ffff;
        (0..21).fold(0, |acc, i| acc | (((v >> i) & 1) << (3 * i)))
    };
    spread(p[0]) | (spread(p[1]) << 1) | (spread(p[2]) << 2)
}

/// Decomposes the edges (edge `i` repeated `weight[i]` times, heavy edges left out) into chains: sequences of edges,
/// each starting where the previous one ends. Vertices are identified by their keys `a[i]`
/// (start) and `b[i]` (end).
/// Returns, per chain, the edge indices in walking order.
fn chain_edges<K: Copy + Eq + std::hash::Hash>(
    a: &[K],
    b: &[K],
    weight: &[f64],
    parallel: &[bool],
) -> Vec<Vec<u32>> {
    use std::collections::HashMap;
    let mut out_edges: HashMap<K, Vec<u32>> = HashMap::new();
    let mut in_degree: HashMap<K, usize> = HashMap::new();
    for i in 0..a.len() {
        let copies = if parallel[i] {
            0
        } else if weight[i] <= MAX_CHAINED_WEIGHT {
            weight[i].max(0.0) as usize
        } else {
            0
        };
        for _ in 0..copies {
            out_edges.entry(a[i]).or_default().push(i as u32);
            *in_degree.entry(b[i]).or_default() += 1;
        }
    }
    // Start chains where more edges leave than arrive (open paths), then anywhere (loops); walk
    // greedily. Any decomposition is correct; fewer chains only means fewer break slots.
    let mut starts: Vec<K> = (0..a.len())
        .map(|i| a[i])
        .filter(|v| out_edges.get(v).map_or(0, Vec::len) > in_degree.get(v).copied().unwrap_or(0))
        .collect();
    starts.extend(a.iter().copied());
    let mut chains = Vec::new();
    for s in starts {
        // A vertex can start several chains (more edges leave it than one walk uses).
        loop {
            let mut v = s;
            let mut chain = Vec::new();
            while let Some(e) = out_edges.get_mut(&v).and_then(Vec::pop) {
                chain.push(e);
                v = b[e as usize];
            }
            if chain.is_empty() {
                break;
            }
            chains.push(chain);
        }
    }
    chains
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reason [`is_parallel_to_ray`] edges may be left out of the loops: the exact path
    /// gives them `0` for every query, on their line, at their ends and inside them included.
    #[test]
    fn edges_parallel_to_the_ray_add_exactly_zero() {
        use crate::kernel::predicates::W128;
        let mut checked = 0;
        for x in -2..=2_i64 {
            for [za, zb, qx, qz] in
                (0..625).map(|k| [k % 5, k / 5 % 5, k / 25 % 5, k / 125].map(|v| v as i64 - 2))
            {
                let (a, b, q) = ([x, 1, za], [x, 1, zb], [qx, 1, qz]);
                for z_exact in [true, false] {
                    let area = BoundaryEdges::default().exact_segment_area::<W128>(
                        &InputPoint::lattice(a),
                        &InputPoint::lattice(b),
                        &InputPoint::lattice(q),
                        z_exact,
                        qz as f64 + 0.25,
                        false,
                    );
                    assert_eq!(area, 0.0, "a {a:?} b {b:?} q {q:?}");
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 6250);
        // Off the lattice (residuals on every axis, the ends' equal on x and y), through both
        // paths: what lets `parallel_to_the_ray` inputs leave the loops too.
        let at = |n: [i64; 3], r: [f64; 3]| InputPoint {
            n,
            r,
            world: [0.0; 3],
            exact: [true; 3],
        };
        let residuals = [0.0, 0.25, -0.5 + 2f64.powi(-60), 2f64.powi(-70)];
        for k in 0..4096_usize {
            let pick = |shift: usize| residuals[(k >> shift) % 4];
            let (rx, ry) = (pick(0), pick(2));
            let a = at([1, -1, (k % 3) as i64], [rx, ry, pick(4)]);
            let b = at([1, -1, (k % 5) as i64 - 2], [rx, ry, pick(6)]);
            let q = at(
                [(k >> 8) as i64 % 3, -1 - (k >> 10) as i64 % 2, 0],
                [pick(8), pick(3), pick(5)],
            );
            assert!(parallel_to_the_ray(&a, &b));
            for (z_exact, accurate) in [(true, false), (true, true), (false, false)] {
                let area = BoundaryEdges::default()
                    .exact_segment_area::<W128>(&a, &b, &q, z_exact, 0.25, accurate);
                assert_eq!(area, 0.0, "a {a:?} b {b:?} q {q:?} {accurate}");
            }
        }
    }

    /// The split accurate path (the loop for every edge no test flags, the accurate terms for
    /// the flagged ones' blocks) agrees with the accurate path over every edge, on boundaries
    /// with heavy, vertical and repeated edges, at queries next to edges, on and above vertices,
    /// with and without residuals.
    #[test]
    fn accurate_edges_alone_give_the_accurate_sum() {
        use crate::kernel::input_predicates::InputPoint;
        use crate::kernel::predicates::W128;
        let mut rng = crate::kernel::test_rng::TestRng::new(29);
        // Vertices across the grid, as a mesh's are: the loop's magnitudes are those of the
        // lattice point, `2^-60·E/d` relative off those of `qi + r` (the model of
        // `needs_accurate_sum`), far below the bound only where `E` is the grid's extent.
        let scale = 1_i64 << 53;
        let mut split = 0;
        for case in 0..60 {
            let (mut a, mut b, mut weight) = (Vec::new(), Vec::new(), Vec::new());
            for _ in 0..(3 + rng.below(12)) {
                // A closed loop (or an open path) of 3 to 8 vertices, some steps vertical.
                let n = 3 + rng.below(6) as usize;
                let mut pts: Vec<[i64; 3]> = Vec::new();
                for _ in 0..n {
                    let p = std::array::from_fn(|_| (rng.below(64) as i64 - 32) * scale);
                    if rng.below(4) == 0
                        && let Some(&last) = pts.last()
                    {
                        pts.push([last[0], last[1], p[2]]);
                    }
                    pts.push(p);
                }
                let closed = rng.below(3) != 0;
                let w = [1.0, 1.0, 2.0, 5.0][rng.below(4) as usize];
                for k in 0..pts.len() - usize::from(!closed) {
                    a.push(pts[k]);
                    b.push(pts[(k + 1) % pts.len()]);
                    weight.push(w);
                }
            }
            let edges = BoundaryEdges::new(a.clone(), b.clone(), weight, 60);
            for _ in 0..40 {
                let e = rng.below(a.len() as u64) as usize;
                let t = rng.below(1001) as f64 / 1000.0;
                let pad = near_edge_pad(a[e], b[e]) as f64;
                let off = [1.0, -0.7, 0.4].map(|d: f64| d * pad * rng.below(40) as f64 / 10.0);
                let q: [i64; 3] = match rng.below(4) {
                    // On a vertex, or straight above one.
                    0 => a[e],
                    1 => [a[e][0], a[e][1], a[e][2] - 3 * scale],
                    _ => std::array::from_fn(|k| {
                        (a[e][k] as f64 + t * (b[e][k] - a[e][k]) as f64 + off[k]).round() as i64
                    }),
                };
                let r = if rng.below(2) == 0 {
                    [0.0; 3]
                } else {
                    std::array::from_fn(|_| (rng.below(1001) as f64 - 500.0) / 1000.0)
                };
                let input = InputPoint {
                    n: q,
                    r,
                    world: [0.0; 3],
                    exact: [true; 3],
                };
                let accurate = edges.accurate_edges::<W128>(q, r, true);
                if accurate.is_empty() {
                    continue;
                }
                split += 1;
                let all = edges.area_sum_accurate::<W128>(&input, true, 0.0);
                let parts =
                    edges.area_sum_with_accurate_edges::<W128>(&input, true, 0.0, &accurate);
                assert!(
                    (all - parts).abs() <= 1e-11,
                    "case {case}: q {q:?} r {r:?}: {all} vs {parts} ({} flagged)",
                    accurate.len()
                );
            }
        }
        assert!(split > 500, "{split} queries took the split path");
    }

    /// The near-edge test is a tube around the segment, not its box: a query in the box of a
    /// long oblique edge but far from it takes the `f64` loop, and that loop agrees there with
    /// the double-double sum within the error model of [`near_edge_pad`]; a query inside the
    /// tube is flagged.
    #[test]
    fn near_edge_test_is_a_tube_and_the_loop_is_accurate_outside_it() {
        use crate::kernel::input_predicates::InputPoint;
        use crate::kernel::predicates::W128;
        // Large enough that no vertex is in the ray tube above a query (`ray_tube`: 2^45).
        let l = 1_i64 << 57;
        // A closed oblique triangle's three edges (one boundary: an open triangle).
        let p = [[0, 0, 0], [l, l / 2, l], [l / 3, l, l / 5]];
        let a = vec![p[0], p[1], p[2]];
        let b = vec![p[1], p[2], p[0]];
        let edges = BoundaryEdges::new(a, b, vec![1.0; 3], 60);
        let pad = near_edge_pad(p[0], p[1]) as f64;
        // Unit normal-ish offset from the first edge, away from the triangle's other edges.
        let dir = [1.0, -2.0, 0.0];
        let norm = (5.0_f64).sqrt();
        let mut outside = 0;
        for (s, &(t, dist)) in [(0.5, 0.5), (0.5, 1.5), (0.5, 3.0), (0.3, 8.0), (0.7, 30.0)]
            .iter()
            .enumerate()
        {
            let q: [i64; 3] = std::array::from_fn(|k| {
                (p[1][k] as f64 * t + dir[k] / norm * dist * pad).round() as i64
            });
            let inside_box = (0..3).all(|k| q[k] >= 0 && q[k] <= l);
            assert!(inside_box, "case {s}: {q:?} is in the edge's box");
            let flagged = edges.needs_accurate_sum::<W128>(q, [0.0; 3], true);
            assert_eq!(flagged, dist <= 1.5, "case {s}: distance {dist} pads");
            if !flagged {
                outside += 1;
                let fast = edges.area_sum::<W128>(&InputPoint::lattice(q), true, 0.0);
                let accurate = edges.area_sum_accurate::<W128>(&InputPoint::lattice(q), true, 0.0);
                assert!(
                    (fast - accurate).abs() <= 1e-12,
                    "case {s}: {fast} vs {accurate}"
                );
            }
        }
        assert_eq!(outside, 3);
    }

    /// The chained sum equals the sum of exact per-edge terms on boundaries full of edges
    /// parallel to the ray (left out of the chains) and heavy ones.
    #[test]
    fn chains_without_parallel_edges_match_the_per_edge_sum() {
        use crate::kernel::predicates::W128;
        let mut rng = crate::kernel::test_rng::TestRng::new(11);
        let mut next = |m: u64| rng.below(m);
        let mut left_out = 0;
        for _ in 0..200 {
            let n = 2 + next(30) as usize;
            let mut pts: Vec<[i64; 3]> = Vec::new();
            for _ in 0..n {
                let p = [next(9) as i64 - 4, next(9) as i64 - 4, next(9) as i64 - 4];
                pts.push(p);
                if next(2) == 0 {
                    // A vertical step: the next vertex straight above or below.
                    pts.push([p[0], p[1], next(9) as i64 - 4]);
                }
            }
            let (a, b): (Vec<_>, Vec<_>) = pts.windows(2).map(|w| (w[0], w[1])).unzip();
            let weight: Vec<f64> = (0..a.len())
                .map(|_| [1.0, 2.0, 7.0][next(3) as usize])
                .collect();
            left_out += (0..a.len())
                .filter(|&i| is_parallel_to_ray(a[i], b[i]))
                .count();
            let edges = BoundaryEdges::new(a.clone(), b.clone(), weight.clone(), 60);
            for _ in 0..10 {
                let q = [
                    next(11) as i64 - 5,
                    next(11) as i64 - 5,
                    next(11) as i64 - 5,
                ];
                let want: f64 = (0..a.len())
                    .map(|i| {
                        let q = InputPoint::lattice(q);
                        weight[i] * edges.exact_edge_area::<W128>(i, &q, true, 0.0)
                    })
                    .sum();
                let got = edges.area_sum::<W128>(&InputPoint::lattice(q), true, 0.0);
                assert!((got - want).abs() < 1e-9, "q {q:?}: {got} vs {want}");
            }
        }
        assert!(left_out > 500, "{left_out}");
    }

    #[test]
    fn avx2_loop_is_bit_identical_to_the_portable_loop() {
        use crate::kernel::predicates::orient2d_filtered;
        #[cfg(target_arch = "x86_64")]
        {
            if !std::arch::is_x86_feature_detected!("avx2") {
                println!("skipping: this CPU has no AVX2");
                return;
            }
            struct Lcg(u64);
            impl Lcg {
                fn next(&mut self, m: u64) -> u64 {
                    self.0 = self
                        .0
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    (self.0 >> 33) % m
                }
                fn coord(&mut self, big: bool) -> i64 {
                    if big {
                        ((self.next(1 << 31) << 29) as i64) - (1_i64 << 59)
                    } else {
                        self.next(9) as i64 - 4
                    }
                }
            }
            let mut rng = Lcg(5);
            for case in 0..300 {
                // Small integer grids (coincidences, queries on vertices and edges) and full
                // 60-bit coordinates, boundaries of 1..40 edges with weights 1..3.
                let big = case % 2 == 1;
                let n = 1 + rng.next(40) as usize;
                let pts: Vec<[i64; 3]> = (0..=n)
                    .map(|_| [rng.coord(big), rng.coord(big), rng.coord(big)])
                    .collect();
                let a: Vec<[i64; 3]> = (0..n).map(|i| pts[i]).collect();
                let b: Vec<[i64; 3]> = (0..n)
                    .map(|i| pts[(i + 1 + rng.next(2) as usize) % (n + 1)])
                    .collect();
                let weight: Vec<f64> = (0..n).map(|_| (1 + rng.next(3)) as f64).collect();
                let edges = BoundaryEdges::new(a, b, weight, 60);
                for k in 0..20 {
                    let q = if k < 5 {
                        pts[rng.next(pts.len() as u64) as usize].map(|c| c as f64)
                    } else {
                        [rng.coord(big), rng.coord(big), rng.coord(big)].map(|c| c as f64)
                    };
                    let (mut u1, mut u2) = (Vec::new(), Vec::new());
                    let s1 = edges
                        .chain_angles(q, 0..edges.slots, &mut |e| u1.push(e))
                        .total();
                    #[allow(unsafe_code)]
                    // SAFETY: AVX2 was detected above.
                    let s2 =
                        unsafe { edges.chain_angles_avx2(q, 0..edges.slots, &mut |e| u2.push(e)) }
                            .total();
                    assert_eq!(
                        s1.to_bits(),
                        s2.to_bits(),
                        "case {case} q {q:?}: {s1} vs {s2}"
                    );
                    assert_eq!(u1, u2, "undecided edges differ");
                    // The loop's filter is `predicates::orient2d_filtered`, lane by lane.
                    let mut undecided: Vec<u32> = u1.clone();
                    undecided.sort_unstable();
                    undecided.dedup();
                    let by_scalar: Vec<u32> = (0..edges.len() as u32)
                        .filter(|&e| {
                            let (a, b, _) = edges.edge(e as usize);
                            let off = |p: [i64; 3]| [p[0] as f64 - q[0], p[1] as f64 - q[1]];
                            !is_parallel_to_ray(a, b)
                                && orient2d_filtered(off(a), off(b), edges.limit).is_none()
                        })
                        .collect();
                    assert_eq!(
                        undecided, by_scalar,
                        "case {case}: loop filter ≠ orient2d_filtered"
                    );
                }
            }
        }
    }

    #[test]
    fn chains_use_every_edge_copy_exactly_once_and_connect() {
        // Random multigraphs on few vertices (self-loops, parallel and heavy edges included).
        let mut rng = crate::kernel::test_rng::TestRng::new(99);
        let mut next = |m: u64| rng.below(m);
        for _ in 0..500 {
            let n = 1 + next(12) as usize;
            let vert = |k: u64| [k as i64, 0, 0];
            let a: Vec<[i64; 3]> = (0..n).map(|_| vert(next(5))).collect();
            let b: Vec<[i64; 3]> = (0..n).map(|_| vert(next(5))).collect();
            let weight: Vec<f64> = (0..n).map(|_| (1 + next(7)) as f64).collect();
            let parallel: Vec<bool> = (0..n).map(|i| is_parallel_to_ray(a[i], b[i])).collect();
            let chains = chain_edges(&a, &b, &weight, &parallel);
            let mut used = vec![0.0; n];
            for chain in &chains {
                for w in chain.windows(2) {
                    assert_eq!(b[w[0] as usize], a[w[1] as usize], "chain breaks");
                }
                for &e in chain {
                    used[e as usize] += 1.0;
                }
            }
            for i in 0..n {
                let want = if weight[i] <= MAX_CHAINED_WEIGHT && !is_parallel_to_ray(a[i], b[i]) {
                    weight[i]
                } else {
                    0.0
                };
                assert_eq!(used[i], want, "edge {i} of weight {}", weight[i]);
            }
        }
    }
}
