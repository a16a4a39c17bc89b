//! Vertex placement along each output vertex's lattice edge, on `w > ½`.
//!
//! Across a sheet `w` jumps (by 1 across a closed surface, by less across an open one), so the
//! linear interpolation of `w` between the edge's corners, marching cubes' usual rule, puts the
//! vertex at a fraction that has nothing to do with where the sheet is.
//!
//! Positions along an edge are integer *ticks* `k / T`, `T = 2^(steps+1)`: tick 0 is the inside
//! corner (`w > ½`), tick `T` the outside one. Every edge keeps a bracket `[lo, hi]` of ticks
//! whose `lo` end is known inside and `hi` end known outside, and the vertex goes to a tick of the
//! final bracket strictly between the corners (`1 ≤ k ≤ T − 1`), which keeps every triangle inside
//! its tetrahedron (the no-self-intersection argument of `docs/remesh.md` needs nothing else).
//! The final bracket is at most 2 ticks wide, so the vertex is within one tick,
//! `|edge| / 2^(steps+1)`, of a point where the class changes. Every evaluation is at a tick
//! strictly inside the bracket and only ever narrows it, so how a probe is chosen costs
//! evaluations, never the guarantee. Rounds of probes, one parallel batch each, choose per edge:
//! - **a crossing** (when the input triangles are given, or the evaluator proposes them:
//!   [`CrossingSource`]): the segment's crossings with the input triangles ([`SegmentBvh`]),
//!   or with the surface as the evaluator finds them ([`Evaluator::segment_crossings`]: a STEP
//!   model's or a Bézier patch set's ray hits), rounded to ticks, are where `w` may jump. With one of
//!   them, `k`, inside the bracket, two evaluations at `k − 1` and `k + 1` (fewer next to a
//!   known end) *verify* it; with several (thin parts, double walls), one evaluation between the
//!   middle two says on which side of it the change is. A crossing that does not verify leaves
//!   the bracket on one side of it.
//! - **the field** (no crossing inside the bracket: a hole, an inconsistently oriented sheet, a
//!   point cloud, a patch's collapsed edge): away from the triangles `w` is harmonic, hence smooth,
//!   and the bracket's ends carry its values (the corners' from [`super::octree`]), so the
//!   probe is the ITP step (interpolate, truncate, project; Oliveira & Takahashi 2020) on
//!   `w − ½`: regula falsi where `w` is smooth, and never more than one evaluation over
//!   bisection's count where it is not.
//!   Across a closed sheet (`w` = 1 and 0 at the ends) regula falsi *is* bisection.
//!
//! Ticks are dyadic, so each vertex is exact in fixed point: lattice units times `T`
//! ([`Placement::fixed`]), which the exact self-intersection check of [`super::intersect`] uses.
//! With planar levels (cubes `2^planar` cells wide, `steps` raised by `planar`), an edge
//! shorter than those cubes searches only every [`stride`]-th tick, so that every vertex lies
//! on one grid, as fine as the largest cubes' ticks, whatever its edge's level; "a tick"
//! above is then one stride.

use rayon::prelude::*;

use super::crossings::SegmentBvh;
use super::lattice::{Corner, Lattice};
use super::levels::Comparisons;
use crate::eval::Evaluator;

/// ITP's truncation constant `κ1`, times the bracket's width when the field steps begin (the
/// paper's suggested `0.2 / (b − a)`).
const ITP_KAPPA1_WIDTHS: f64 = 0.2;

/// ITP's slack `n0`: evaluations allowed over bisection's count per edge.
const ITP_SLACK: u32 = 1;

/// Placed vertices.
#[derive(Clone, Debug, Default)]
pub struct Placement {
    /// World positions.
    pub positions: Vec<[f64; 3]>,
    /// Exact positions in lattice units times [`Placement::ticks_per_cell`].
    pub fixed: Vec<[i64; 3]>,
    /// `T = 2^(steps+1)`: ticks per lattice edge.
    pub ticks_per_cell: i64,
    /// Evaluations of `w` spent.
    pub evaluations: usize,
    /// Vertices placed by a verified crossing.
    pub guided: usize,
    /// Per vertex placed at a verified crossing, the plane of the input triangle crossed there
    /// (world coordinates); `None` for the others. The simplification's quadrics take it in
    /// place of the marching-tetrahedra faces' planes, which cut across sharp edges.
    pub planes: Vec<Option<Plane>>,
}

impl Placement {
    /// [`Placement::planes`] in lattice units, as [`super::simplify::simplify_with_planes`]
    /// takes them.
    pub fn planes_in_lattice_units(&self, lattice: &Lattice) -> Vec<Option<Plane>> {
        self.planes
            .iter()
            .map(|p| p.and_then(|p| lattice.plane_in_lattice_units(p)))
            .collect()
    }
}

/// A plane `n·x + d = 0` as `[n_x, n_y, n_z, d]` with `|n| = 1`.
pub type Plane = [f64; 4];

/// The plane of a triangle (a zero normal for a degenerate one: its quadric is 0).
fn plane_of(t: &[[f64; 3]; 3]) -> Plane {
    use crate::base::vec3::{cross, norm, sub};
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let len = norm(n);
    if len == 0.0 || !len.is_finite() {
        return [0.0; 4];
    }
    let n = n.map(|x| x / len);
    [
        n[0],
        n[1],
        n[2],
        -(n[0] * t[0][0] + n[1] * t[0][1] + n[2] * t[0][2]),
    ]
}

/// Where [`place_vertices`] takes the crossings it verifies.
#[derive(Clone, Copy, Debug)]
pub enum CrossingSource<'a> {
    /// None: every vertex is found by the field's search.
    None,
    /// The input triangles' crossings with each edge.
    Triangles(&'a SegmentBvh),
    /// The evaluator's own ([`Evaluator::segment_crossings`]: the trimmed B-rep and Bézier
    /// patch set evaluators' segment hits); edges where it answers `None` have none.
    Evaluator,
}

/// The plane through `p` with unit normal `n` (zero for a zero normal, like [`plane_of`]).
fn plane_through(p: [f64; 3], n: [f64; 3]) -> Plane {
    [n[0], n[1], n[2], -(n[0] * p[0] + n[1] * p[1] + n[2] * p[2])]
}

/// One edge's search: the bracket, `w` at its ends, and the ITP state.
#[derive(Clone, Copy, Debug)]
struct Search {
    /// Highest tick known inside.
    lo: i64,
    /// Lowest tick known outside.
    hi: i64,
    w_lo: f64,
    w_hi: f64,
    /// Field steps made.
    itp_steps: u32,
    /// Field steps allowed before bisection (set at the first field step).
    itp_budget: u32,
    /// Bracket width at the first field step.
    itp_width: i64,
    /// The bracket closed on a verified crossing.
    verified: bool,
}

impl Search {
    fn is_open(&self) -> bool {
        self.hi - self.lo > 2
    }

    /// A probe's answer: it narrows the bracket when it lies inside it (a verification pair's
    /// second probe may not, after the first moved `hi` past it).
    fn narrow(&mut self, tick: i64, w: f64) {
        if self.lo < tick && tick < self.hi {
            if super::inside(w) {
                (self.lo, self.w_lo) = (tick, w);
            } else {
                (self.hi, self.w_hi) = (tick, w);
            }
        }
    }

    /// The ITP probe (ε = 1 tick: bisection closes the bracket to 2 ticks in
    /// `⌈log2(width / 2)⌉` steps).
    fn field_probe(&mut self) -> i64 {
        let (lo, hi) = (self.lo, self.hi);
        if self.w_hi.is_nan() {
            // A border corner: outside by declaration, `w` there unknown (and often above ½:
            // then the change is at the corner, and a bisection would spend every step getting
            // there). One probe next to it settles that case, and gives the field's value
            // there for the other, where the ITP steps start afresh.
            return hi - 1;
        }
        let width = (hi - lo) as f64;
        if self.itp_steps == 0 {
            self.itp_width = hi - lo;
            self.itp_budget = (width / 2.0).log2().ceil() as u32 + ITP_SLACK;
        }
        let half = 0.5 * (lo + hi) as f64;
        let x = if self.itp_steps >= self.itp_budget {
            half
        } else {
            // w_lo > level ≥ w_hi (super::inside), so the denominator is positive.
            let (y_lo, y_hi) = (
                self.w_lo - super::INSIDE_LEVEL,
                self.w_hi - super::INSIDE_LEVEL,
            );
            let falsi = lo as f64 + y_lo / (y_lo - y_hi) * width;
            if !falsi.is_finite() {
                half
            } else {
                let sigma = (half - falsi).signum();
                let delta = ITP_KAPPA1_WIDTHS / self.itp_width as f64 * width * width;
                let truncated = if delta <= (half - falsi).abs() {
                    falsi + sigma * delta
                } else {
                    half
                };
                let radius = (f64::from(1u32 << (self.itp_budget - self.itp_steps).min(31))
                    - 0.5 * width)
                    .max(0.0);
                if (truncated - half).abs() <= radius {
                    truncated
                } else {
                    half - sigma * radius
                }
            }
        };
        self.itp_steps += 1;
        // The end game: with the estimate within 2 ticks of an end, a probe 2 ticks from that
        // end closes the bracket if the estimate is right (rounding the estimate would move
        // the near end again and leave the far one for another probe).
        let probe = if x - (lo as f64) < 2.0 {
            lo + 2
        } else if (hi as f64) - x < 2.0 {
            hi - 2
        } else {
            x.round() as i64
        };
        probe.clamp(lo + 1, hi - 1)
    }
}

/// The stride, in ticks, of the search on an edge `l` finest cells long when the largest
/// (regular) cubes are `2^regular` finest cells ([`Lattice::sub_levels`]: the planar levels
/// above the resolution plus the sub-cell levels below it): the edges of the largest cubes
/// search every tick, shorter ones every `2^regular / l`-th. So every vertex lies on one grid
/// of `2^regular` fixed-point units (`1 / 2^(steps − planar + 1)` of a resolution cell, the
/// precision the steps were raised for) along every axis its edge moves along, whatever the
/// edge's level: a side of the input on an axis-aligned plane gets all its vertices on one
/// plane of that grid, whose vertex stars are then exactly flat for the simplification
/// (with a finer grid on the shorter edges, vertices on one side were off by different
/// fractions of a tick per level, and no star across levels was flat: the README's cube at
/// res 128 kept 1,756 faces with one sub-cell level, 920 without). Fewer steps on the short
/// edges also cost fewer evaluations of the field.
fn stride(l: i64, regular: u32) -> i64 {
    let grid = 1i64 << regular.min(30);
    let mut s = 1;
    while s * 2 * l <= grid {
        s *= 2;
    }
    s
}

/// Positions of the vertices on `edges` (inside corner, outside corner), within one stride
/// of ticks (`|edge| / 2^(steps+1)` on the longest edges, the same length on shorter ones:
/// see [`stride`]) of a class change; `corner_w` is `w` at each edge's two corners
/// (the first above ½, the second not or NaN for a corner declared outside without an
/// evaluation; only the number of evaluations depends on them), and `guide` proposes crossings
/// (see the module documentation). `None` once `deadline` has passed (checked between the
/// crossings' chunks and the search's rounds).
pub fn place_vertices<E: Evaluator + ?Sized>(
    evaluator: &E,
    lattice: &Lattice,
    edges: &[(Corner, Corner)],
    corner_w: &[[f64; 2]],
    steps: u32,
    guide: CrossingSource,
    deadline: Option<std::time::Instant>,
) -> Option<Placement> {
    let past = || deadline.is_some_and(|at| std::time::Instant::now() > at);
    assert_eq!(edges.len(), corner_w.len());
    let ticks: i64 = 1 << (steps + 1);
    // Each edge's search runs on its own units of `stride` ticks, `units(e)` of them.
    let stride_of = |(i, o): (Corner, Corner)| {
        let l = (0..3)
            .map(|a| (i64::from(o[a]) - i64::from(i[a])).abs())
            .max()
            .unwrap_or(1);
        stride(l, lattice.sub_levels).min(ticks / 4).max(1)
    };
    let units = |e: (Corner, Corner)| ticks / stride_of(e);
    let at = |e: (Corner, Corner), k: i64| -> [f64; 3] {
        let (i, o) = e;
        let t = k as f64 / units(e) as f64;
        lattice
            .position([0, 1, 2].map(|a| f64::from(i[a]) + t * (f64::from(o[a]) - f64::from(i[a]))))
    };
    // The crossings of the segment `a → b`: fraction `t` along it, plane of the surface there.
    let crossings_of = |a: [f64; 3], b: [f64; 3], out: &mut dyn FnMut(f64, Plane)| match guide {
        CrossingSource::None => {}
        CrossingSource::Triangles(bvh) => {
            bvh.for_each_crossing(a, b, |t, tri| out(t, plane_of(tri)));
        }
        CrossingSource::Evaluator => {
            for c in evaluator.segment_crossings(a, b).unwrap_or_default() {
                let p = [0, 1, 2].map(|k| a[k] + c.t * (b[k] - a[k]));
                out(c.t, plane_through(p, c.normal));
            }
        }
    };
    let proposes = match guide {
        CrossingSource::None => false,
        CrossingSource::Triangles(bvh) => !bvh.is_empty(),
        CrossingSource::Evaluator => true,
    };
    // Each edge's crossing ticks, sorted and distinct, as ranges of one list, with the plane of
    // the surface crossed there (a triangle's: the first in the hierarchy's order).
    let (crossings, crossing_planes, crossing_ranges): (Vec<i64>, Vec<Plane>, Vec<(u32, u32)>) =
        if !proposes {
            (Vec::new(), Vec::new(), vec![(0, 0); edges.len()])
        } else {
            // By chunks of edges (a `Vec` per edge cost ~100 bytes each at the peak).
            let chunks: Vec<(Vec<i64>, Vec<Plane>, Vec<u32>)> = edges
                .par_chunks(4096)
                .map(|chunk| {
                    let (mut ks, mut planes, mut counts) = (Vec::new(), Vec::new(), Vec::new());
                    // Past the deadline the placement is discarded: no crossings are looked
                    // for (millions of edges are seconds of hierarchy walks).
                    if past() {
                        return (ks, planes, vec![0; chunk.len()]);
                    }
                    let mut hits: Vec<(i64, Plane)> = Vec::new();
                    for &e in chunk {
                        hits.clear();
                        let n = units(e);
                        crossings_of(at(e, 0), at(e, n), &mut |t, plane| {
                            if t.is_finite() {
                                let k = ((t * n as f64).round() as i64).clamp(1, n - 1);
                                hits.push((k, plane));
                            }
                        });
                        // Stable: the first triangle in the hierarchy's order keeps its tick.
                        hits.sort_by_key(|&(k, _)| k);
                        hits.dedup_by_key(|&mut (k, _)| k);
                        counts.push(hits.len() as u32);
                        for &(k, plane) in &hits {
                            ks.push(k);
                            planes.push(plane);
                        }
                    }
                    (ks, planes, counts)
                })
                .collect();
            let n = chunks.iter().map(|c| c.0.len()).sum();
            let (mut all, mut planes) = (Vec::with_capacity(n), Vec::with_capacity(n));
            let mut ranges = Vec::with_capacity(edges.len());
            for (ks, ps, counts) in chunks {
                let mut start = all.len() as u32;
                for c in counts {
                    ranges.push((start, start + c));
                    start += c;
                }
                all.extend(ks);
                planes.extend(ps);
            }
            (all, planes, ranges)
        };
    if past() {
        return None;
    }
    let mut searches: Vec<Search> = edges
        .iter()
        .zip(corner_w)
        .map(|(&e, &[w_lo, w_hi])| Search {
            lo: 0,
            hi: units(e),
            w_lo,
            w_hi,
            itp_steps: 0,
            itp_budget: 0,
            itp_width: units(e),
            verified: false,
        })
        .collect();
    let mut evaluations = 0;
    let mut probes: Vec<(u32, i64)> = Vec::new();
    // Past the deadline there is no placement (the remesh ends with `RemeshError::TimeLimit`):
    // the rounds stop, since a deadlined evaluator's NaN would only walk each bracket down a
    // tick per round.
    loop {
        if past() {
            return None;
        }
        probes.clear();
        for (j, s) in searches.iter_mut().enumerate() {
            if !s.is_open() {
                continue;
            }
            let (first, end) = crossing_ranges[j];
            let ks = &crossings[first as usize..end as usize];
            // The crossings strictly inside the bracket.
            let a = ks.partition_point(|&k| k <= s.lo);
            let b = ks.partition_point(|&k| k < s.hi);
            let inside = &ks[a..b];
            let j = j as u32;
            match inside.len() {
                0 => probes.push((j, s.field_probe())),
                1 => {
                    let k = inside[0];
                    if k - 1 > s.lo {
                        probes.push((j, k - 1));
                    }
                    if k + 1 < s.hi {
                        probes.push((j, k + 1));
                    }
                }
                n => {
                    let (left, right) = (inside[n / 2 - 1], inside[n / 2]);
                    probes.push((j, ((left + right) / 2).clamp(s.lo + 1, s.hi - 1)));
                }
            }
        }
        if probes.is_empty() {
            break;
        }
        let points: Vec<[f64; 3]> = probes
            .par_iter()
            .map(|&(j, k)| at(edges[j as usize], k))
            .collect();
        let w = super::levels::decisive_values(evaluator, &points, Comparisons::Class);
        evaluations += points.len();
        for (&(j, k), w) in probes.iter().zip(w) {
            let s = &mut searches[j as usize];
            let was_open = s.is_open();
            s.narrow(k, w);
            // Closed by a probe next to a crossing: the crossing is verified.
            if was_open && !s.is_open() {
                let (first, end) = crossing_ranges[j as usize];
                let ks = &crossings[first as usize..end as usize];
                s.verified = s.hi - s.lo == 2 && ks.binary_search(&(s.lo + 1)).is_ok();
            }
        }
    }
    // The vertex tick: the middle of a 2-tick bracket, else the end that is not a corner.
    let tick = |s: &Search| -> i64 {
        if s.hi - s.lo == 2 {
            s.lo + 1
        } else if s.lo > 0 {
            s.lo
        } else {
            s.hi
        }
    };
    let positions = edges
        .par_iter()
        .zip(&searches)
        .map(|(&e, s)| at(e, tick(s)))
        .collect();
    let fixed = edges
        .par_iter()
        .zip(&searches)
        .map(|(&(i, o), s)| {
            let k = tick(s) * stride_of((i, o));
            [0, 1, 2].map(|a| i64::from(i[a]) * ticks + k * (i64::from(o[a]) - i64::from(i[a])))
        })
        .collect();
    let planes = searches
        .par_iter()
        .zip(&crossing_ranges)
        .map(|(s, &(first, end))| {
            let ks = &crossings[first as usize..end as usize];
            s.verified
                .then(|| ks.binary_search(&(s.lo + 1)).ok())
                .flatten()
                .map(|i| crossing_planes[first as usize + i])
        })
        .collect();
    Some(Placement {
        positions,
        fixed,
        ticks_per_cell: ticks,
        evaluations,
        guided: searches.iter().filter(|s| s.verified).count(),
        planes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::bounding_box::BoundingBox;

    /// A field given by a closure.
    struct Field<F>(F);

    impl<F: Fn([f64; 3]) -> f64 + Send + Sync> Evaluator for Field<F> {
        fn eval(&self, q: [f64; 3]) -> f64 {
            (self.0)(q)
        }
    }

    const STEPS: u32 = 8;
    const TICKS: i64 = 1 << (STEPS + 1);

    /// The unit cube in 8 cells: lattice units are eighths, corner `[0, 0, 0]` at the origin
    /// less a coarse margin.
    fn lattice() -> Lattice {
        let bounds = BoundingBox {
            min: [0.0; 3],
            max: [1.0; 3],
        };
        Lattice::new(bounds, 8).unwrap()
    }

    /// Every lattice edge (either direction of the 8³ cells around the cube) whose corner
    /// classes differ, inside corner first, with `w` at its corners.
    fn band_edges<E: Evaluator>(field: &E, lattice: &Lattice) -> Vec<((Corner, Corner), [f64; 2])> {
        let mut out = Vec::new();
        let n = lattice.cells.map(|c| c as u32);
        for z in 0..n[2] {
            for y in 0..n[1] {
                for x in 0..n[0] {
                    let a = [x, y, z];
                    for axis in 0..3 {
                        let mut b = a;
                        b[axis] += 1;
                        let (wa, wb) = (
                            field.eval(lattice.corner_position(a)),
                            field.eval(lattice.corner_position(b)),
                        );
                        match (super::super::inside(wa), super::super::inside(wb)) {
                            (true, false) => out.push(((a, b), [wa, wb])),
                            (false, true) => out.push(((b, a), [wb, wa])),
                            _ => {}
                        }
                    }
                }
            }
        }
        out
    }

    /// The guarantee: the vertex's tick and a tick next to it hold both classes (ticks 0 and
    /// `T` by their corners' declared classes).
    fn assert_within_a_tick_of_a_change<E: Evaluator>(
        field: &E,
        lattice: &Lattice,
        (i, o): (Corner, Corner),
        fixed: [i64; 3],
    ) {
        let axis = (0..3).find(|&a| i[a] != o[a]).unwrap();
        let k = (fixed[axis] - i64::from(i[axis]) * TICKS).abs();
        assert!(
            (1..TICKS).contains(&k),
            "tick {k} not strictly inside the edge"
        );
        let inside = |t: i64| {
            if t == 0 {
                return true;
            }
            if t == TICKS {
                return false;
            }
            let s = t as f64 / TICKS as f64;
            let p = [0, 1, 2].map(|a| f64::from(i[a]) + s * (f64::from(o[a]) - f64::from(i[a])));
            super::super::inside(field.eval(lattice.position(p)))
        };
        let classes = [inside(k - 1), inside(k), inside(k + 1)];
        assert!(
            classes.contains(&true) && classes.contains(&false),
            "no class change within a tick of tick {k} on {i:?} → {o:?}: {classes:?}"
        );
    }

    /// Places each edge alone (so that its evaluations are its own) and checks the guarantee;
    /// returns the evaluations per edge.
    fn place_one_by_one<E: Evaluator>(
        field: &E,
        lattice: &Lattice,
        edges: &[((Corner, Corner), [f64; 2])],
        guide: CrossingSource,
    ) -> Vec<usize> {
        edges
            .iter()
            .map(|&(e, w)| {
                let p = place_vertices(field, lattice, &[e], &[w], STEPS, guide, None).unwrap();
                assert_within_a_tick_of_a_change(field, lattice, e, p.fixed[0]);
                p.evaluations
            })
            .collect()
    }

    /// Every edge of a lattice whose largest cubes are `2^regular` finest cells lands on the
    /// grid of `2^regular` fixed-point units along the axes it moves along: stride × length is
    /// that grid wherever the length divides it, and the stride is 1 for the largest edges and
    /// any longer one.
    #[test]
    fn strides_put_every_level_on_the_largest_cubes_grid() {
        for regular in 0..7 {
            let grid = 1i64 << regular;
            for l in [1, 2, 4, 8, 16, 32, 64] {
                let s = stride(l, regular);
                assert!(s >= 1 && s.count_ones() == 1, "{l} {regular}: {s}");
                assert_eq!(s * l, grid.max(l), "{l} {regular}");
            }
            // An odd length (a transition's edge) gets the largest stride that stays within it.
            assert!(stride(3, regular) * 3 <= grid.max(3) && stride(3, regular) * 6 > grid);
        }
    }

    #[test]
    fn a_smooth_field_takes_three_fifths_of_bisections_evaluations_or_fewer() {
        // A smooth bump, `w = ½` on the sphere of radius 0.35 about the cube's centre.
        let field = Field(|q: [f64; 3]| {
            let r2: f64 = q.iter().map(|x| (x - 0.5) * (x - 0.5)).sum();
            1.0 / (1.0 + r2 / (0.35 * 0.35))
        });
        let lattice = lattice();
        let edges = band_edges(&field, &lattice);
        assert!(edges.len() > 100, "{}", edges.len());
        let evaluations = place_one_by_one(&field, &lattice, &edges, CrossingSource::None);
        let total: usize = evaluations.iter().sum();
        // 4.6 per edge here, against bisection's 8 (the first step is nearly always the
        // midpoint: ITP's truncation hedges against a poor interpolation).
        let bisection = STEPS as usize * edges.len();
        assert!(
            5 * total <= 3 * bisection,
            "{total} evaluations for {} edges (bisection: {bisection})",
            edges.len()
        );
        // All at once gives the same vertices as one by one (each edge's search is its own).
        let (e, w): (Vec<_>, Vec<_>) = edges.iter().copied().unzip();
        let together =
            place_vertices(&field, &lattice, &e, &w, STEPS, CrossingSource::None, None).unwrap();
        assert_eq!(together.evaluations, total);
        for (&edge, &fixed) in e.iter().zip(&together.fixed) {
            assert_within_a_tick_of_a_change(&field, &lattice, edge, fixed);
        }
    }

    /// A ball of radius `r` about the cube's centre (`w` 1 inside, 0 outside, a closed sheet)
    /// whose evaluator proposes where segments cross the sphere, each proposal moved by
    /// `error` along the segment (world units).
    struct BallWithCrossings {
        r: f64,
        error: f64,
    }

    impl Evaluator for BallWithCrossings {
        fn eval(&self, q: [f64; 3]) -> f64 {
            let r2: f64 = q.iter().map(|x| (x - 0.5) * (x - 0.5)).sum();
            f64::from(u8::from(r2 < self.r * self.r))
        }
        fn segment_crossings(
            &self,
            a: [f64; 3],
            b: [f64; 3],
        ) -> Option<Vec<crate::eval::SurfaceCrossing>> {
            // |a − c + t (b − a)|² = r²: the roots in [0, 1].
            let (d, m) = ([0, 1, 2].map(|k| b[k] - a[k]), a.map(|x| x - 0.5));
            let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
            let (qa, qb, qc) = (dot(d, d), 2.0 * dot(m, d), dot(m, m) - self.r * self.r);
            let disc = qb * qb - 4.0 * qa * qc;
            if disc < 0.0 {
                return Some(Vec::new());
            }
            let shift = self.error / qa.sqrt();
            Some(
                [-1.0, 1.0]
                    .map(|s| (-qb + s * disc.sqrt()) / (2.0 * qa))
                    .into_iter()
                    .filter(|t| (0.0..=1.0).contains(t))
                    .map(|t| {
                        let p = [0, 1, 2].map(|k| a[k] + t * d[k] - 0.5);
                        let n = p.map(|x| x / self.r);
                        crate::eval::SurfaceCrossing {
                            t: (t + shift).clamp(0.0, 1.0),
                            normal: n,
                        }
                    })
                    .collect(),
            )
        }
    }

    #[test]
    fn the_evaluators_crossings_are_verified_like_the_triangles() {
        let lattice = lattice();
        let exact = BallWithCrossings {
            r: 0.31,
            error: 0.0,
        };
        let edges = band_edges(&exact, &lattice);
        assert!(edges.len() > 100, "{}", edges.len());
        let (e, w): (Vec<_>, Vec<_>) = edges.iter().copied().unzip();
        // Right proposals: two evaluations per vertex (one next to an end of the edge), every
        // vertex verified, with the sphere's tangent plane (the normal at the crossing, and
        // the plane through it).
        let p = place_vertices(
            &exact,
            &lattice,
            &e,
            &w,
            STEPS,
            CrossingSource::Evaluator,
            None,
        )
        .unwrap();
        assert_eq!(p.guided, e.len());
        assert!(p.evaluations <= 2 * e.len(), "{}", p.evaluations);
        for ((&edge, &fixed), plane) in e.iter().zip(&p.fixed).zip(&p.planes) {
            assert_within_a_tick_of_a_change(&exact, &lattice, edge, fixed);
            let [a, b, c, d] = plane.expect("a verified crossing has a plane");
            assert!(((a * a + b * b + c * c).sqrt() - 1.0).abs() < 1e-12);
            // The plane touches the sphere: its distance from the centre is the radius.
            assert!((((a + b + c) * 0.5 + d).abs() - 0.31).abs() < 1e-9);
        }
        // Without them, the field's search: bisection across a closed sheet, 8 per vertex.
        let none =
            place_vertices(&exact, &lattice, &e, &w, STEPS, CrossingSource::None, None).unwrap();
        assert_eq!(
            (none.guided, none.evaluations),
            (0, STEPS as usize * e.len())
        );
        // Proposals off by 3 ticks' length: none verifies, and every vertex is still within a
        // tick of the change, at a bounded cost (the probes next to the proposal narrow the
        // bracket, and the field's search takes over).
        let tick = lattice.h[0] / TICKS as f64;
        for error in [3.0 * tick, -3.0 * tick] {
            let off = BallWithCrossings { r: 0.31, error };
            let p = place_vertices(
                &off,
                &lattice,
                &e,
                &w,
                STEPS,
                CrossingSource::Evaluator,
                None,
            )
            .unwrap();
            assert!(p.guided < e.len() / 10, "{} of {}", p.guided, e.len());
            assert!(p.evaluations <= (STEPS as usize + 2) * e.len());
            for (&edge, &fixed) in e.iter().zip(&p.fixed) {
                assert_within_a_tick_of_a_change(&off, &lattice, edge, fixed);
            }
        }
    }

    #[test]
    fn a_field_that_jumps_from_one_to_zero_is_bisected() {
        // A closed sheet crossed once: regula falsi between 1 and 0 is the midpoint, and each
        // edge takes exactly bisection's `STEPS` evaluations.
        let field = Field(|q: [f64; 3]| f64::from(u8::from(q[0] + 0.3 * q[1] < 0.61)));
        let lattice = lattice();
        let edges = band_edges(&field, &lattice);
        assert!(!edges.is_empty());
        for n in place_one_by_one(&field, &lattice, &edges, CrossingSource::None) {
            assert_eq!(n, STEPS as usize);
        }
    }

    #[test]
    fn rough_fields_cost_at_most_one_evaluation_over_bisection() {
        // Steps of pseudo-random heights, from 3 to 5,000 per cell along x and y: `w` crosses
        // ½ once or many times along an edge, and regula falsi's estimates are poor. Every
        // vertex still ends within a tick of a change, at a bounded cost.
        let mut most = 0;
        for (seed, per_cell) in (0..16u64).zip([3.0, 37.0, 300.0, 5000.0].iter().cycle()) {
            let per_unit = 8.0 * per_cell;
            let field = Field(move |q: [f64; 3]| {
                let cell = [0, 1].map(|a| (q[a] * per_unit).floor() as i64 as u64);
                let mut h = cell[0]
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    .wrapping_add(cell[1].wrapping_mul(0xC2B2_AE3D_27D4_EB4F))
                    .wrapping_add(seed);
                h ^= h >> 31;
                h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
                h ^= h >> 29;
                let noise = (h >> 11) as f64 / (1u64 << 53) as f64;
                // Inside the ball of radius 0.3 about the centre the heights lean above ½.
                let r2: f64 = q.iter().map(|x| (x - 0.5) * (x - 0.5)).sum();
                0.35 * noise + if r2 < 0.09 { 0.4 } else { 0.1 }
            });
            let lattice = lattice();
            let edges = band_edges(&field, &lattice);
            assert!(edges.len() > 50, "{}", edges.len());
            let n = place_one_by_one(&field, &lattice, &edges, CrossingSource::None);
            most = most.max(n.into_iter().max().unwrap());
        }
        assert!(most <= (STEPS + ITP_SLACK) as usize, "{most} evaluations");
    }

    #[test]
    fn a_border_corner_with_the_field_above_half_costs_one_evaluation() {
        // The outside corner is declared outside (NaN: never evaluated) but `w` is 0.7 all
        // along the edge: the change is at the corner, and one probe next to it finds that.
        let field = Field(|_: [f64; 3]| 0.7);
        let lattice = lattice();
        let edge = ([3, 4, 4], [4, 4, 4]);
        // The edge with `w` 0.7 at its inside corner and its outside corner not evaluated.
        fn place_from_border<E: Evaluator>(
            field: &E,
            lattice: &Lattice,
            edge: (Corner, Corner),
        ) -> Placement {
            let w = [[0.7, f64::NAN]];
            place_vertices(
                field,
                lattice,
                &[edge],
                &w,
                STEPS,
                CrossingSource::None,
                None,
            )
            .unwrap()
        }
        let p = place_from_border(&field, &lattice, edge);
        assert_eq!(p.evaluations, 1);
        assert_eq!(p.fixed[0][0], 4 * TICKS - 1);
        // With the change inside the edge after all (at its middle), the search goes on from
        // that probe.
        let (x0, h) = (lattice.corner_position(edge.0)[0], lattice.h[0]);
        let field = Field(move |q: [f64; 3]| 0.7 - 0.4 * (q[0] - x0) / h);
        let p = place_from_border(&field, &lattice, edge);
        let k = p.fixed[0][0] - 3 * TICKS;
        assert!((k - TICKS / 2).abs() <= 1, "{k}");
        assert!(p.evaluations <= 4, "{}", p.evaluations);
    }

    #[test]
    fn a_double_wall_is_told_apart_by_one_evaluation_between_the_walls() {
        // Two walls across the edge (x-parallel edges of the lattice cross the planes
        // x = 0.3 and 0.6 of the cell): `w` is 1 before the first, 0.8 between (an inner wall
        // that does not change the class), 0 after the second. One evaluation between the walls
        // puts the change beyond the middle, two verify the second wall.
        let lattice = lattice();
        let edge: (Corner, Corner) = ([3, 4, 4], [4, 4, 4]);
        let x0 = lattice.corner_position(edge.0)[0];
        let h = lattice.h[0];
        let walls = [x0 + 0.3 * h, x0 + 0.6 * h];
        let wall = |x: f64| [[x, -1.0, -1.0], [x, 3.0, -1.0], [x, -1.0, 3.0]];
        let guide = SegmentBvh::new(walls.map(wall));
        let field = Field(move |q: [f64; 3]| {
            if q[0] < walls[0] {
                1.0
            } else if q[0] < walls[1] {
                0.8
            } else {
                0.0
            }
        });
        let place = |source| {
            place_vertices(
                &field,
                &lattice,
                &[edge],
                &[[1.0, 0.0]],
                STEPS,
                source,
                None,
            )
            .unwrap()
        };
        let p = place(CrossingSource::Triangles(&guide));
        assert_eq!((p.evaluations, p.guided), (3, 1));
        assert_within_a_tick_of_a_change(&field, &lattice, edge, p.fixed[0]);
        let k = p.fixed[0][0] - 3 * TICKS;
        assert!((k as f64 - 0.6 * TICKS as f64).abs() <= 1.0, "{k}");
        // The vertex carries the plane of the wall it was verified on: x = walls[1].
        let [a, b, c, d] = p.planes[0].expect("a verified crossing has a plane");
        assert_eq!((a.abs(), b, c), (1.0, 0.0, 0.0));
        assert!((d / a + walls[1]).abs() < 1e-12, "{d}");
        // Without a guide no vertex has a plane.
        assert_eq!(place(CrossingSource::None).planes, vec![None]);
    }
}
