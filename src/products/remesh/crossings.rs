//! Where a short segment (a lattice edge of the band) crosses the input triangles: a binary BVH
//! over the triangles' boxes and a floating-point segment–triangle test. The same hierarchy
//! answers whether any triangle meets an octree cell ([`SegmentBvh::meets_box`]), which decides
//! where [`super::octree`] refines beyond the cells whose corners differ.
//!
//! This only *proposes* where an output vertex goes. [`super::place`] accepts a proposal only
//! after two evaluations of `w` on either side of it confirm a class change, so a rounding error
//! here, a missed triangle or a spurious hit costs evaluations (the edge falls back to
//! bisection), never a wrong placement.

use std::sync::OnceLock;

use crate::base::bounding_box::segment_meets_box;
use crate::eval::fast::{FastParams, FastWindingNumber};

/// Signed boundary edges, as a fraction of a closed mesh's edge count (`3F / 2`), from which
/// [`SegmentBvh::of_field_mesh`] screens probes with the Barnes–Hut approximation: faces of
/// mixed orientation everywhere, so that every probe is next to the signed boundary and the
/// exact evaluator pays its `O(B)` boundary sum in full (probes at res 256, exact → screened:
/// cgal-blobby-shuffled, half its edges, 6.9 → 0.07 s; cgal-oblong-shuffled, half, 3.5 →
/// 0.44 s). With the boundary in places the exact probes are cheap and the approximation is
/// not (it opens many nodes next to a printer bed's long triangles): cura-predator_platform,
/// 13 %, 2.1 → 11.5 s; cura-voron0_120_bed, closed, 0.03 → 0.79 s.
pub const SCREENED_BOUNDARY_FRACTION: f64 = 0.25;

/// Signed boundary edges from which [`SegmentBvh::of_field_mesh`] screens probes whatever their
/// fraction: next to so long a boundary an exact probe costs more than the approximation does
/// anywhere measured (wall time per probe on 2 threads, exact: pymeshlab-face000, 4,117 edges,
/// 26 µs; cgal-bunny00 with 10 % of its faces flipped, 20,377 edges, 390 µs; the approximation
/// at most 15 µs, on cura-predator_platform).
pub const SCREENED_BOUNDARY_EDGES: usize = 4096;

/// Triangles per leaf.
const LEAF_SIZE: usize = 4;

/// Relative slack of the box and barycentric tests: a triangle grazed by the segment counts as
/// hit (a spurious hit is rejected by the verification in `place`; a missed one would cost a
/// bisection instead of two evaluations).
const SLACK: f64 = 1e-9;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// Leaf: first triangle; inner: first child.
    first: u32,
    /// Inner: second child.
    second: u32,
    /// Triangles in a leaf; 0 for an inner node.
    count: u32,
}

/// A BVH over triangles for segment queries.
#[derive(Clone, Debug, Default)]
pub struct SegmentBvh {
    triangles: Vec<[[f64; 3]; 3]>,
    nodes: Vec<Node>,
    /// `Some` when the triangles are the surface of the field being remeshed
    /// ([`SegmentBvh::of_field_mesh`]): a Barnes–Hut approximation of their `w`, built on first
    /// use ([`SegmentBvh::approximate_winding_number`]).
    approximate: Option<OnceLock<FastWindingNumber>>,
}

impl SegmentBvh {
    /// The hierarchy over `triangles` (median splits along the longest axis of the centroids).
    /// Triangles with a non-finite coordinate are left out (they cannot guide a placement).
    pub fn new(triangles: impl IntoIterator<Item = [[f64; 3]; 3]>) -> SegmentBvh {
        let mut triangles: Vec<[[f64; 3]; 3]> = triangles
            .into_iter()
            .filter(|t| t.iter().flatten().all(|v| v.is_finite()))
            .collect();
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF_SIZE + 1);
        if !triangles.is_empty() {
            build(&mut triangles, 0, &mut nodes);
        }
        SegmentBvh {
            triangles,
            nodes,
            approximate: None,
        }
    }

    /// The hierarchy over the triangles of `mesh`.
    pub fn of_mesh(mesh: &crate::Mesh) -> SegmentBvh {
        SegmentBvh::new((0..mesh.triangles().len()).map(|f| mesh.triangle_positions(f)))
    }

    /// [`SegmentBvh::of_mesh`] for a `mesh` whose own winding number is the field being
    /// remeshed (by any method; not a field derived from it, such as
    /// [`super::thicken::ThickenedSheets`]). Where that pays (an inconsistently oriented input
    /// or a long signed boundary: [`SCREENED_BOUNDARY_FRACTION`], [`SCREENED_BOUNDARY_EDGES`])
    /// the remesher screens its near-surface probes with a
    /// Barnes–Hut approximation of `w` ([`SegmentBvh::approximate_winding_number`]) and
    /// evaluates the field only where the approximation leaves the answer open.
    pub fn of_field_mesh(mesh: &crate::Mesh) -> SegmentBvh {
        let boundary = crate::mesh::geometric_boundary_edges(mesh).len() as f64;
        let edges = 1.5 * mesh.triangles().len() as f64;
        SegmentBvh {
            approximate: (edges > 0.0
                && (boundary >= SCREENED_BOUNDARY_FRACTION * edges
                    || boundary >= SCREENED_BOUNDARY_EDGES as f64))
                .then(OnceLock::new),
            ..SegmentBvh::of_mesh(mesh)
        }
    }

    /// A Barnes–Hut approximation (β = 2, order 2) of the triangles' winding number, built on
    /// the first call, when they were declared the field's surface
    /// ([`SegmentBvh::of_field_mesh`]); `None` otherwise. It only screens: what it says
    /// decides where to look, never a label.
    pub fn approximate_winding_number(&self) -> Option<&FastWindingNumber> {
        let cell = self.approximate.as_ref()?;
        Some(cell.get_or_init(|| {
            FastWindingNumber::from_triangles(self.triangles.clone(), FastParams::default())
        }))
    }

    /// Triangles held.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Whether it holds no triangle.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Pushes onto `out` the parameters `t ∈ [0, 1]` (clamped) at which the segment `p → q`
    /// crosses a triangle, in no particular order.
    pub fn crossings(&self, p: [f64; 3], q: [f64; 3], out: &mut Vec<f64>) {
        self.for_each_crossing(p, q, |t, _| out.push(t));
    }

    /// Calls `hit(t, triangle)` for each triangle the segment `p → q` crosses, with `t ∈ [0, 1]`
    /// (clamped), in the hierarchy's order (deterministic, not sorted by `t`).
    pub fn for_each_crossing(
        &self,
        p: [f64; 3],
        q: [f64; 3],
        mut hit: impl FnMut(f64, &[[f64; 3]; 3]),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let d = [0, 1, 2].map(|a| q[a] - p[a]);
        // Median splits keep the depth near log2(n / LEAF_SIZE): 64 levels hold any input.
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            if !segment_meets_box(p, d, 1.0, node.lo, node.hi, 0.0) {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                for tri in &self.triangles[first..first + node.count as usize] {
                    if let Some(t) = segment_triangle(p, d, tri) {
                        hit(t.clamp(0.0, 1.0), tri);
                    }
                }
            } else if top + 2 <= stack.len() {
                stack[top] = node.first;
                stack[top + 1] = node.second;
                top += 2;
            }
        }
    }
}

impl SegmentBvh {
    /// Whether some triangle may meet the closed box `lo..=hi`, conservatively: `true` whenever
    /// one does (a separating-axis test on a box grown by `pad` on every side, which absorbs the
    /// rounding of the projections), and possibly for a triangle that only passes within about
    /// `pad` of it. Only refinement depends on the answer, never a label, so a spurious `true`
    /// costs time and a `false` must never be wrong.
    pub fn meets_box(&self, lo: [f64; 3], hi: [f64; 3], pad: f64) -> bool {
        let (blo, bhi) = (
            [0, 1, 2].map(|a| lo[a] - pad),
            [0, 1, 2].map(|a| hi[a] + pad),
        );
        let mut met = false;
        self.visit_box(blo, bhi, |t| {
            met = triangle_meets_box(t, blo, bhi);
            met
        });
        met
    }

    /// Calls `f` on the triangles whose leaves' boxes meet the box `lo..=hi` (a superset of
    /// those that meet it) until it returns `true`.
    fn visit_box(&self, lo: [f64; 3], hi: [f64; 3], mut f: impl FnMut(&[[f64; 3]; 3]) -> bool) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            if (0..3).any(|a| node.lo[a] > hi[a] || node.hi[a] < lo[a]) {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                for t in &self.triangles[first..first + node.count as usize] {
                    if f(t) {
                        return;
                    }
                }
            } else if top + 2 <= stack.len() {
                stack[top] = node.first;
                stack[top + 1] = node.second;
                top += 2;
            }
        }
    }

    /// Up to `max` points where triangles cross the box `lo..=hi`, each with its triangle's
    /// unit normal: the vertex average of the triangle's part inside the box (a convex polygon,
    /// so the average lies in it). Degenerate triangles are skipped. Only refinement reads the
    /// points (they tell where to look for a class no corner of a cell has), never a label.
    pub fn surface_points_in_box(
        &self,
        lo: [f64; 3],
        hi: [f64; 3],
        max: usize,
    ) -> Vec<([f64; 3], [f64; 3])> {
        let mut out = Vec::new();
        if max == 0 {
            return out;
        }
        self.visit_box(lo, hi, |t| {
            if !triangle_meets_box(t, lo, hi) {
                return false;
            }
            let Some(n) = unit_normal(t) else {
                return false;
            };
            let part = clip_to_box(t, lo, hi);
            if part.is_empty() {
                return false;
            }
            let k = part.len() as f64;
            out.push((
                [0, 1, 2].map(|a| part.iter().map(|p| p[a]).sum::<f64>() / k),
                n,
            ));
            out.len() == max
        });
        out
    }

    /// `n` points drawn on the triangles uniformly by area (seeded), each with its triangle's
    /// unit normal; none when the triangles have no area.
    pub fn surface_samples(&self, n: usize, seed: u64) -> Vec<([f64; 3], [f64; 3])> {
        let mut cumulative = Vec::with_capacity(self.triangles.len());
        let mut total = 0.0;
        for t in &self.triangles {
            let c = cross(t);
            total += (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
            cumulative.push(total);
        }
        if !(total > 0.0 && total.is_finite()) {
            return Vec::new();
        }
        let mut rng = crate::base::splitmix::SplitMix64(seed);
        (0..n)
            .filter_map(|_| {
                let x = rng.unit() * total;
                let i = cumulative
                    .partition_point(|&c| c <= x)
                    .min(cumulative.len() - 1);
                let t = &self.triangles[i];
                let normal = unit_normal(t)?;
                let (mut u, mut v) = (rng.unit(), rng.unit());
                if u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                let p =
                    [0, 1, 2].map(|a| t[0][a] + u * (t[1][a] - t[0][a]) + v * (t[2][a] - t[0][a]));
                Some((p, normal))
            })
            .collect()
    }

    /// The plane (unit normal, a point) within `tolerance` of which the triangles meeting the
    /// box `lo..=hi` grown by `pad` lie inside it (the plane of the largest of them); `None`
    /// when they do not, or none or more than `max` meet it. Only refinement reads it (a flat
    /// cell may stay coarse), never a label.
    pub fn flat_in_box(
        &self,
        lo: [f64; 3],
        hi: [f64; 3],
        pad: f64,
        tolerance: f64,
        max: usize,
    ) -> Option<([f64; 3], [f64; 3])> {
        let (blo, bhi) = (
            [0, 1, 2].map(|a| lo[a] - pad),
            [0, 1, 2].map(|a| hi[a] + pad),
        );
        let mut met: Vec<[[f64; 3]; 3]> = Vec::new();
        let mut too_many = false;
        self.visit_box(blo, bhi, |t| {
            if triangle_meets_box(t, blo, bhi) {
                if met.len() == max {
                    too_many = true;
                    return true;
                }
                met.push(*t);
            }
            false
        });
        if too_many {
            return None;
        }
        let area2 = |t: &[[f64; 3]; 3]| {
            let n = cross(t);
            n[0] * n[0] + n[1] * n[1] + n[2] * n[2]
        };
        let largest = met.iter().max_by(|a, b| area2(a).total_cmp(&area2(b)))?;
        let n = unit_normal(largest)?;
        let p0 = largest[0];
        met.iter()
            .all(|t| {
                clip_to_box(t, blo, bhi).iter().all(|p| {
                    let d: f64 = (0..3).map(|a| n[a] * (p[a] - p0[a])).sum();
                    d.abs() <= tolerance
                })
            })
            .then_some((n, p0))
    }
}

/// The (unnormalised) normal of a triangle, right-hand rule.
fn cross(t: &[[f64; 3]; 3]) -> [f64; 3] {
    let u = [0, 1, 2].map(|a| t[1][a] - t[0][a]);
    let v = [0, 1, 2].map(|a| t[2][a] - t[0][a]);
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

/// The unit normal of a triangle (right-hand rule), `None` if it is degenerate.
pub(super) fn unit_normal(t: &[[f64; 3]; 3]) -> Option<[f64; 3]> {
    let n = cross(t);
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    (len > 0.0 && len.is_finite()).then(|| n.map(|x| x / len))
}

/// The part of a triangle inside the box, as a polygon (Sutherland–Hodgman against the six
/// planes; empty when they do not meet).
fn clip_to_box(t: &[[f64; 3]; 3], lo: [f64; 3], hi: [f64; 3]) -> Vec<[f64; 3]> {
    let mut poly: Vec<[f64; 3]> = t.to_vec();
    for a in 0..3 {
        for (bound, keep_below) in [(lo[a], false), (hi[a], true)] {
            let inside = |p: &[f64; 3]| {
                if keep_below {
                    p[a] <= bound
                } else {
                    p[a] >= bound
                }
            };
            let mut next = Vec::with_capacity(poly.len() + 1);
            for i in 0..poly.len() {
                let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
                if inside(&p) {
                    next.push(p);
                }
                if inside(&p) != inside(&q) {
                    let s = (bound - p[a]) / (q[a] - p[a]);
                    let mut x = [0, 1, 2].map(|b| p[b] + s * (q[b] - p[b]));
                    x[a] = bound;
                    next.push(x);
                }
            }
            poly = next;
            if poly.is_empty() {
                return poly;
            }
        }
    }
    poly
}

/// The separating-axis test of a triangle against a box (Akenine-Möller): the box's 3 axes, the
/// triangle's normal and the 9 cross products of their edges. A degenerate axis (a zero cross
/// product) projects everything to 0 and separates nothing, so degenerate triangles fall back to
/// the remaining axes: the test errs towards `true`.
fn triangle_meets_box(tri: &[[f64; 3]; 3], lo: [f64; 3], hi: [f64; 3]) -> bool {
    let c = [0, 1, 2].map(|a| 0.5 * (lo[a] + hi[a]));
    let e = [0, 1, 2].map(|a| 0.5 * (hi[a] - lo[a]));
    let v = tri.map(|p| [p[0] - c[0], p[1] - c[1], p[2] - c[2]]);
    for a in 0..3 {
        let (mn, mx) = (
            v[0][a].min(v[1][a]).min(v[2][a]),
            v[0][a].max(v[1][a]).max(v[2][a]),
        );
        if mn > e[a] || mx < -e[a] {
            return false;
        }
    }
    let sub = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let cross = |x: [f64; 3], y: [f64; 3]| {
        [
            x[1] * y[2] - x[2] * y[1],
            x[2] * y[0] - x[0] * y[2],
            x[0] * y[1] - x[1] * y[0],
        ]
    };
    let separates = |axis: [f64; 3]| {
        let r = e[0] * axis[0].abs() + e[1] * axis[1].abs() + e[2] * axis[2].abs();
        let p = v.map(|q| q[0] * axis[0] + q[1] * axis[1] + q[2] * axis[2]);
        let (mn, mx) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        mn > r || mx < -r
    };
    let edges = [sub(v[1], v[0]), sub(v[2], v[1]), sub(v[0], v[2])];
    if separates(cross(edges[0], edges[1])) {
        return false;
    }
    for f in edges {
        for a in 0..3 {
            let mut unit = [0.0; 3];
            unit[a] = 1.0;
            if separates(cross(unit, f)) {
                return false;
            }
        }
    }
    true
}

/// Builds the subtree over `triangles` (whose first one is triangle `offset` of the whole
/// array) and returns its node index.
fn build(triangles: &mut [[[f64; 3]; 3]], offset: usize, nodes: &mut Vec<Node>) -> u32 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut clo = [f64::INFINITY; 3];
    let mut chi = [f64::NEG_INFINITY; 3];
    for t in triangles.iter() {
        for a in 0..3 {
            for v in t {
                lo[a] = lo[a].min(v[a]);
                hi[a] = hi[a].max(v[a]);
            }
            let c = t[0][a] + t[1][a] + t[2][a];
            clo[a] = clo[a].min(c);
            chi[a] = chi[a].max(c);
        }
    }
    // Pad by a relative slack so that rounding in the slab test never culls a grazed triangle.
    for a in 0..3 {
        let pad = SLACK
            * (hi[a] - lo[a])
                .max(lo[a].abs())
                .max(hi[a].abs())
                .max(1e-300);
        lo[a] -= pad;
        hi[a] += pad;
    }
    let index = nodes.len();
    nodes.push(Node {
        lo,
        hi,
        first: offset as u32,
        second: 0,
        count: triangles.len() as u32,
    });
    if triangles.len() <= LEAF_SIZE {
        return index as u32;
    }
    let axis = (0..3)
        .max_by(|&a, &b| (chi[a] - clo[a]).total_cmp(&(chi[b] - clo[b])))
        .unwrap_or(0);
    let mid = triangles.len() / 2;
    let key = |t: &[[f64; 3]; 3]| t[0][axis] + t[1][axis] + t[2][axis];
    triangles.select_nth_unstable_by(mid, |x, y| key(x).total_cmp(&key(y)));
    let (left, right) = triangles.split_at_mut(mid);
    let first = build(left, offset, nodes);
    let second = build(right, offset + mid, nodes);
    nodes[index].first = first;
    nodes[index].second = second;
    nodes[index].count = 0;
    index as u32
}

/// Where the segment `p + t d` crosses the triangle (Möller–Trumbore, with a small slack on the
/// barycentric bounds); `None` when it misses or is parallel to the triangle's plane.
fn segment_triangle(p: [f64; 3], d: [f64; 3], tri: &[[f64; 3]; 3]) -> Option<f64> {
    let sub = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let cross = |x: [f64; 3], y: [f64; 3]| {
        [
            x[1] * y[2] - x[2] * y[1],
            x[2] * y[0] - x[0] * y[2],
            x[0] * y[1] - x[1] * y[0],
        ]
    };
    let dot = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let e1 = sub(tri[1], tri[0]);
    let e2 = sub(tri[2], tri[0]);
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let tv = sub(p, tri[0]);
    let u = dot(tv, pv) * inv;
    if !(-SLACK..=1.0 + SLACK).contains(&u) {
        return None;
    }
    let qv = cross(tv, e1);
    let v = dot(d, qv) * inv;
    if v < -SLACK || u + v > 1.0 + SLACK {
        return None;
    }
    let t = dot(e2, qv) * inv;
    (-SLACK..=1.0 + SLACK).contains(&t).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn surface_samples_are_on_the_triangles_by_area() {
        // Areas 1/2 and 3/2 (the second in the plane z = 5), and a degenerate one (no area).
        let small = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let large = [[0.0, 0.0, 5.0], [3.0, 0.0, 5.0], [0.0, 1.0, 5.0]];
        let degenerate = [[0.5, 0.5, 0.5], [0.6, 0.6, 0.6], [0.7, 0.7, 0.7]];
        let bvh = SegmentBvh::new([small, degenerate, large]);
        let samples = bvh.surface_samples(4000, 7);
        assert_eq!(samples.len(), 4000);
        let mut on_large = 0;
        for (p, n) in &samples {
            assert!(p[0] >= 0.0 && p[1] >= 0.0, "{p:?}");
            if p[2] == 5.0 {
                on_large += 1;
                assert!(p[0] / 3.0 + p[1] <= 1.0 + 1e-12, "{p:?}");
            } else {
                assert_eq!(p[2], 0.0);
                assert!(p[0] + p[1] <= 1.0 + 1e-12, "{p:?}");
            }
            assert_eq!(*n, [0.0, 0.0, 1.0]);
        }
        // 3/4 of them on the large one (one standard deviation: 0.7 %).
        let share = f64::from(on_large) / 4000.0;
        assert!((share - 0.75).abs() < 0.03, "{share}");
        assert!(
            SegmentBvh::new([degenerate])
                .surface_samples(10, 7)
                .is_empty()
        );
    }

    #[test]
    fn flat_in_box_reads_only_the_parts_inside_the_box() {
        // Two triangles of one tilted plane through the unit box, and a third at 30 degrees to
        // it whose part inside the box is tiny (it enters near one corner) or absent.
        let plane = |x: f64, y: f64| [x, y, 0.4 + 0.1 * x + 0.05 * y];
        let a = [plane(-2.0, -2.0), plane(3.0, -2.0), plane(-2.0, 3.0)];
        let b = [plane(3.0, -2.0), plane(3.0, 3.0), plane(-2.0, 3.0)];
        let unit = ([0.0; 3], [1.0; 3]);
        let flat = SegmentBvh::new([a, b]);
        let (n, p0) = flat.flat_in_box(unit.0, unit.1, 1e-9, 1e-3, 8).unwrap();
        let d = |p: [f64; 3]| (0..3).map(|k| n[k] * (p[k] - p0[k])).sum::<f64>();
        assert!(d(plane(0.3, 0.7)).abs() < 1e-12);
        // A crossing plane whose part in the box is far off the first: not flat.
        let steep = [[0.5, -2.0, -2.0], [0.5, 3.0, -2.0], [0.5, -2.0, 3.0]];
        assert!(
            SegmentBvh::new([a, b, steep])
                .flat_in_box(unit.0, unit.1, 1e-9, 0.1, 8)
                .is_none()
        );
        // The same crossing plane cut off before the box (its part inside is empty): flat.
        let outside = [[0.5, 1.5, -2.0], [0.5, 3.0, -2.0], [0.5, 1.5, 3.0]];
        assert!(
            SegmentBvh::new([a, b, outside])
                .flat_in_box(unit.0, unit.1, 1e-9, 0.1, 8)
                .is_some()
        );
        // A bump of 0.05 over the plane: flat at a tolerance of 0.1, not at 0.01.
        let bump = [plane(0.2, 0.2), plane(0.8, 0.2), {
            let mut p = plane(0.5, 0.8);
            p[2] += 0.05;
            p
        }];
        let bumpy = SegmentBvh::new([a, b, bump]);
        assert!(bumpy.flat_in_box(unit.0, unit.1, 1e-9, 0.1, 8).is_some());
        assert!(bumpy.flat_in_box(unit.0, unit.1, 1e-9, 0.01, 8).is_none());
        // More triangles than allowed, nothing in the box, or only degenerate ones: not flat.
        assert!(bumpy.flat_in_box(unit.0, unit.1, 1e-9, 0.1, 2).is_none());
        assert!(flat.flat_in_box([5.0; 3], [6.0; 3], 1e-9, 0.1, 8).is_none());
        let degenerate = [[0.5, 0.5, 0.5], [0.6, 0.6, 0.6], [0.7, 0.7, 0.7]];
        assert!(
            SegmentBvh::new([degenerate])
                .flat_in_box(unit.0, unit.1, 1e-9, 0.1, 8)
                .is_none()
        );
    }

    #[test]
    fn surface_points_lie_on_the_triangles_inside_the_box() {
        // A large tilted triangle through the unit box, one far away, one degenerate.
        let tilted = [[-3.0, -3.0, 0.2], [4.0, -3.0, 0.6], [-3.0, 4.0, 0.9]];
        let far = [[10.0, 10.0, 10.0], [11.0, 10.0, 10.0], [10.0, 11.0, 10.0]];
        let flat = [[0.5, 0.5, 0.5], [0.6, 0.6, 0.6], [0.7, 0.7, 0.7]];
        let bvh = SegmentBvh::new([tilted, far, flat]);
        let points = bvh.surface_points_in_box([0.0; 3], [1.0; 3], 8);
        assert_eq!(points.len(), 1, "{points:?}");
        let (p, n) = points[0];
        assert!(p.iter().all(|&x| (0.0..=1.0).contains(&x)), "{p:?}");
        let n0 = unit_normal(&tilted).unwrap();
        assert!((0..3).all(|a| (n[a] - n0[a]).abs() < 1e-15));
        // On the triangle's plane.
        let d = (0..3).map(|a| (p[a] - tilted[0][a]) * n0[a]).sum::<f64>();
        assert!(d.abs() < 1e-12, "{d}");
        // The triangle's own centroid is far outside the box: the point is its clipped part's.
        assert!(tilted.iter().map(|v| v[0]).sum::<f64>() / 3.0 < -0.5);
        assert!(bvh.surface_points_in_box([5.0; 3], [6.0; 3], 8).is_empty());
        let many = SegmentBvh::new((0..10).map(|k| {
            let z = 0.05 + 0.09 * f64::from(k);
            [[-1.0, -1.0, z], [3.0, -1.0, z], [-1.0, 3.0, z]]
        }));
        assert_eq!(many.surface_points_in_box([0.0; 3], [1.0; 3], 3).len(), 3);
        assert_eq!(many.surface_points_in_box([0.0; 3], [1.0; 3], 30).len(), 10);
    }

    /// Brute force over every triangle, same test: the BVH must find exactly the same hits.
    #[test]
    fn bvh_finds_what_brute_force_finds() {
        let mut state = 7u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let tris: Vec<[[f64; 3]; 3]> = (0..500)
            .map(|_| {
                let c = [next(), next(), next()];
                std::array::from_fn(|_| std::array::from_fn(|a| c[a] + 0.1 * (next() - 0.5)))
            })
            .collect();
        let bvh = SegmentBvh::new(tris.clone());
        assert_eq!(bvh.len(), 500);
        for _ in 0..300 {
            let p = [next(), next(), next()];
            let q = [0, 1, 2].map(|a| p[a] + 0.2 * (next() - 0.5));
            let mut got = Vec::new();
            bvh.crossings(p, q, &mut got);
            let d = [0, 1, 2].map(|a| q[a] - p[a]);
            let mut want: Vec<f64> = tris
                .iter()
                .filter_map(|t| segment_triangle(p, d, t))
                .map(|t| t.clamp(0.0, 1.0))
                .collect();
            got.sort_by(f64::total_cmp);
            want.sort_by(f64::total_cmp);
            assert_eq!(got, want);
        }
    }

    /// Against dense point sampling: a box that holds a sample of a triangle must be met; a box
    /// more than the pad away from every triangle's box must not be.
    #[test]
    fn meets_box_is_conservative_and_culls_far_boxes() {
        let mut state = 11u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let tris: Vec<[[f64; 3]; 3]> = (0..40)
            .map(|_| {
                let c = [next(), next(), next()];
                std::array::from_fn(|_| std::array::from_fn(|a| c[a] + 0.3 * (next() - 0.5)))
            })
            .collect();
        let bvh = SegmentBvh::new(tris.clone());
        let (mut met, mut missed) = (0, 0);
        for _ in 0..400 {
            let lo = [next(), next(), next()];
            let s = 0.02 + 0.05 * next();
            let hi = lo.map(|x| x + s);
            let inside = |p: [f64; 3]| (0..3).all(|a| lo[a] <= p[a] && p[a] <= hi[a]);
            let holds_sample = tris.iter().any(|t| {
                (0..=20).any(|i| {
                    (0..=20 - i).any(|j| {
                        let (u, w) = (i as f64 / 20.0, j as f64 / 20.0);
                        inside(std::array::from_fn(|a| {
                            t[0][a] + u * (t[1][a] - t[0][a]) + w * (t[2][a] - t[0][a])
                        }))
                    })
                })
            });
            let got = bvh.meets_box(lo, hi, 1e-9);
            if holds_sample {
                assert!(got, "a box holding a point of a triangle was culled");
            }
            let far = tris.iter().all(|t| {
                (0..3).any(|a| {
                    t.iter().all(|p| p[a] > hi[a] + 1e-6) || t.iter().all(|p| p[a] < lo[a] - 1e-6)
                })
            });
            if far {
                assert!(!got, "a box away from every triangle's box was met");
            }
            if got { met += 1 } else { missed += 1 }
        }
        // Both answers occur, so the assertions above were exercised.
        assert!(met > 20 && missed > 20, "{met} {missed}");
        // A box just beside a tilted triangle's plane, inside its bounding box: only the normal
        // axis separates them.
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        let one = SegmentBvh::new([t]);
        assert!(!one.meets_box([0.6, 0.6, 0.0], [0.7, 0.7, 0.1], 1e-9));
        assert!(one.meets_box([0.2, 0.2, 0.3], [0.3, 0.3, 0.5], 1e-9));
        assert!(!SegmentBvh::default().meets_box([0.0; 3], [1.0; 3], 1.0));
    }

    #[test]
    fn axis_segment_through_a_triangle() {
        let bvh = SegmentBvh::new([[[0.0, 0.0, 0.5], [1.0, 0.0, 0.5], [0.0, 1.0, 0.5]]]);
        let mut t = Vec::new();
        bvh.crossings([0.25, 0.25, 0.0], [0.25, 0.25, 1.0], &mut t);
        assert_eq!(t, vec![0.5]);
        t.clear();
        bvh.crossings([0.75, 0.75, 0.0], [0.75, 0.75, 1.0], &mut t);
        assert!(t.is_empty());
    }
}
