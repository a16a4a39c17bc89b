//! Signed distance to a triangle mesh, signed by the winding number.
//!
//! The unsigned part is the Euclidean distance to the closest point of the closest triangle,
//! found by a best-first traversal of a BVH (topology by `obvhs`, boxes recomputed in `f64` from
//! the triangles so the box distance is a true lower bound) and computed per triangle in `f64`
//! (projection onto the plane when it falls inside the triangle, otherwise the closest of the
//! three edges; degenerate triangles use their edges only).
//!
//! The sign is `−` where the exact winding number is above 0.5 ([`WindingNumber`]) and `+`
//! elsewhere (also at exactly 0.5). Unlike pseudo-normal or ray-parity signs this stays right on
//! open, self-intersecting and inconsistently oriented meshes: the sign flips exactly on the
//! `w = 0.5` level set, which near a hole is a smooth membrane across it rather than a sign decided
//! by whichever triangle happens to be closest.
//!
//! ```
//! use gwn::{Mesh, products::sdf::SignedDistance};
//! let p = [[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.],[0.,0.,1.],[1.,0.,1.],[1.,1.,1.],[0.,1.,1.]];
//! let t = [[0,2,1],[0,3,2],[0,1,5],[0,5,4],[1,2,6],[1,6,5],[2,3,7],[2,7,6],[3,0,4],[3,4,7],[4,5,6],[4,6,7]];
//! let sdf = SignedDistance::new(&Mesh::from_slices(&p, &t)?)?;
//! assert_eq!(sdf.eval([0.5, 0.5, 0.5]), -0.5);
//! assert_eq!(sdf.eval([0.5, 0.5, 3.0]), 2.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::base::vec3::{cross, dot, sub};
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::sync::atomic::{AtomicBool, Ordering as AtomicOrdering};

use obvhs::{BvhBuildParams, aabb::Aabb, bvh2::builder::build_bvh2};
use rayon::prelude::*;

use crate::eval::Evaluator;
use crate::eval::antipodal::{BuildError, Options, WindingNumber};
use crate::grid::GridSpec;
use crate::mesh::Mesh;

/// Where on a triangle the closest point lies (corner indices `0..3` of the triangle).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feature {
    /// The interior of the face.
    Face,
    /// The interior of the edge between corners `.0` and `.1`.
    Edge(u8, u8),
    /// Corner `.0`.
    Vertex(u8),
}

/// The closest point of the mesh to a query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    /// Euclidean distance.
    pub distance: f64,
    /// The closest point.
    pub point: [f64; 3],
    /// Index of the triangle it lies on.
    pub face: usize,
    /// Which feature of that triangle.
    pub feature: Feature,
}

#[derive(Clone, Copy, Debug)]
struct Node {
    min: [f64; 3],
    max: [f64; 3],
    first: u32,
    count: u32,
}

/// Signed distance evaluator: build once, query from many threads. The sign comes from any
/// [`Evaluator`] (by default the exact one).
#[derive(Clone, Debug)]
pub struct SignedDistance<E = WindingNumber> {
    /// The triangles, in `frame`'s coordinates when there is one.
    tris: Vec<[[f64; 3]; 3]>,
    nodes: Vec<Node>,
    prims: Vec<u32>,
    wn: E,
    /// The frame the distances are computed in (`None` without triangles).
    frame: Option<Frame>,
}

/// Peak bytes per cell of [`SignedDistance::eval_grid`]: the winding-number grid
/// ([`crate::grid::EVALUATE_BYTES_PER_CELL`]), the sample points and the distances. The CLI and
/// the Python package check this against the available memory
/// ([`GridSpec::check_memory`]), the CLI adding its `f32` copy.
pub const GRID_BYTES_PER_CELL: usize = crate::grid::EVALUATE_BYTES_PER_CELL + 24 + 8;

/// Half-extents between which distances are computed in world coordinates (unchanged bits).
/// Outside, squared distances and the degree-4 terms of the closest-point test under- or
/// overflow (a cube of side 1e-170 had distance 0, one of side 1e160 distance ∞).
const MODERATE_EXTENT: std::ops::RangeInclusive<f64> = 1e-30..=1e30;

/// The frame distances are computed in. For meshes outside [`MODERATE_EXTENT`]: translation to
/// the box centre and an exact power-of-two scaling to half-extent `[1, 2)`, so that the
/// distance, scaled back by the inverse power of two, is right to rounding at any magnitude.
/// Otherwise world coordinates, unchanged.
#[derive(Clone, Copy, Debug)]
struct Frame {
    /// The centre of the triangles' box (also the far-query fallback, see `closest`).
    center: [f64; 3],
    /// Whether the coordinates are translated and scaled (else world coordinates).
    scaled: bool,
    /// Two powers of two whose product is the scaling (the product may not be representable).
    to: [f64; 2],
    back: [f64; 2],
}

impl Frame {
    fn for_triangles(tris: &[[[f64; 3]; 3]]) -> Option<Frame> {
        let b = crate::base::bounding_box::BoundingBox::of_points(tris.iter().flatten())?;
        let center = std::array::from_fn(|i| 0.5 * b.min[i] + 0.5 * b.max[i]);
        let h = (0..3)
            .map(|k| 0.5 * b.max[k] - 0.5 * b.min[k])
            .fold(0.0_f64, f64::max);
        if h == 0.0 || !h.is_finite() || MODERATE_EXTENT.contains(&h) {
            return Some(Frame {
                center,
                scaled: false,
                to: [1.0; 2],
                back: [1.0; 2],
            });
        }
        let k = -(h.log2().floor() as i32);
        let pow2 = |e: i32| f64::from_bits(((e + 1023) as u64) << 52);
        let (k1, k2) = (k / 2, k - k / 2);
        Some(Frame {
            center,
            scaled: true,
            to: [pow2(k1), pow2(k2)],
            back: [pow2(-k1), pow2(-k2)],
        })
    }

    fn point(&self, p: [f64; 3]) -> [f64; 3] {
        if !self.scaled {
            return p;
        }
        std::array::from_fn(|i| (p[i] - self.center[i]) * self.to[0] * self.to[1])
    }

    fn world_point(&self, p: [f64; 3]) -> [f64; 3] {
        if !self.scaled {
            return p;
        }
        std::array::from_fn(|i| p[i] * self.back[0] * self.back[1] + self.center[i])
    }

    fn world_length(&self, d: f64) -> f64 {
        if !self.scaled {
            return d;
        }
        d * self.back[0] * self.back[1]
    }
}

impl SignedDistance {
    /// Builds the distance BVH and the exact winding-number evaluator (default options).
    pub fn new(mesh: &Mesh) -> Result<Self, BuildError> {
        Ok(Self::with_evaluator(mesh, WindingNumber::new(mesh)?))
    }

    /// Builds with explicit evaluator options.
    pub fn with_options(mesh: &Mesh, options: Options) -> Result<Self, BuildError> {
        Ok(Self::with_evaluator(
            mesh,
            WindingNumber::with_options(mesh, options)?,
        ))
    }
}

impl<E: Evaluator> SignedDistance<E> {
    /// Builds the distance BVH around an existing evaluator of the same mesh.
    pub fn with_evaluator(mesh: &Mesh, wn: E) -> Self {
        let tris: Vec<[[f64; 3]; 3]> = (0..mesh.triangles().len())
            .map(|f| mesh.triangle_positions(f))
            .collect();
        Self::from_triangles(tris, wn)
    }

    /// Distance to a set of points (e.g. an oriented point cloud), signed by `wn`: each point is
    /// stored as a triangle with three equal corners, whose closest point is the point itself.
    pub fn with_points(points: &[[f64; 3]], wn: E) -> Self {
        Self::from_triangles(points.iter().map(|&p| [p; 3]).collect(), wn)
    }

    fn from_triangles(tris: Vec<[[f64; 3]; 3]>, wn: E) -> Self {
        let frame = Frame::for_triangles(&tris);
        let tris = match frame {
            Some(f) if f.scaled => tris.iter().map(|t| t.map(|p| f.point(p))).collect(),
            _ => tris,
        };
        let (nodes, prims) = build_tree(&tris);
        SignedDistance {
            tris,
            nodes,
            prims,
            wn,
            frame,
        }
    }

    /// The winding-number evaluator used for the sign.
    pub fn winding_number(&self) -> &E {
        &self.wn
    }

    /// Signed distance at `q`: negative where `w(q) > 0.5`. `+∞` for a mesh without triangles,
    /// NaN for a non-finite query.
    pub fn eval(&self, q: [f64; 3]) -> f64 {
        signed(self.unsigned(q), self.wn.eval(q))
    }

    /// `(signed distance, winding number)` at `q`: both labels from one call, the sign taken from
    /// that same `w`.
    pub fn eval_with_winding(&self, q: [f64; 3]) -> (f64, f64) {
        let w = self.wn.eval(q);
        (signed(self.unsigned(q), w), w)
    }

    /// Signed distances at many points, in parallel.
    pub fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        points.par_iter().map(|&q| self.eval(q)).collect()
    }

    /// Signed distances on a grid (the sign's winding numbers with ray reuse,
    /// [`crate::grid::evaluate`]); grid storage order.
    pub fn eval_grid(&self, spec: &GridSpec) -> Vec<f64> {
        self.eval_grid_with_progress(spec, |_| {})
    }

    /// [`SignedDistance::eval_grid`] with a progress callback: first the winding numbers (one
    /// call per batch of columns), then the distances (one call per batch of points).
    pub fn eval_grid_with_progress(
        &self,
        spec: &GridSpec,
        progress: impl Fn(usize) + Sync,
    ) -> Vec<f64> {
        let never = AtomicBool::new(false);
        self.eval_grid_until(spec, progress, &never)
            .unwrap_or_default()
    }

    /// [`SignedDistance::eval_grid_with_progress`] that gives up (`None`) when `stop` becomes
    /// true, as [`crate::grid::evaluate_until`] does.
    pub fn eval_grid_until(
        &self,
        spec: &GridSpec,
        progress: impl Fn(usize) + Sync,
        stop: &AtomicBool,
    ) -> Option<Vec<f64>> {
        let w = crate::grid::evaluate_until(&self.wn, spec, &progress, stop)?;
        let pts = spec.points();
        let values: Vec<f64> = pts
            .par_chunks(4096)
            .zip(w.par_chunks(4096))
            .flat_map_iter(|(p, w)| {
                if stop.load(AtomicOrdering::Relaxed) {
                    return Vec::new();
                }
                let out: Vec<f64> = p
                    .iter()
                    .zip(w)
                    .map(|(&q, &w)| signed(self.unsigned(q), w))
                    .collect();
                progress(p.len());
                out
            })
            .collect();
        (!stop.load(AtomicOrdering::Relaxed)).then_some(values)
    }

    /// Unsigned distance to the closest point of the mesh.
    pub fn unsigned(&self, q: [f64; 3]) -> f64 {
        self.closest(q).map_or(f64::INFINITY, |c| c.distance)
    }

    /// The closest point of the mesh (`None` for a mesh without triangles or a non-finite query).
    /// Right to rounding for meshes of any extent (1e-300 to 1e300). For a query so far that
    /// the squared distance overflows (≳1e150 extents away), the distance is the distance to the
    /// box centre (relative error below the extent ratio, ≲1e-120) and the point the first
    /// triangle's first corner.
    pub fn closest(&self, q: [f64; 3]) -> Option<Closest> {
        if q.iter().any(|c| !c.is_finite()) {
            return None;
        }
        let frame = self.frame?;
        let local = frame.point(q);
        if local.iter().all(|c| c.is_finite()) {
            if let Some(c) = self.closest_in_frame(local) {
                if c.distance.is_finite() {
                    return Some(Closest {
                        distance: frame.world_length(c.distance),
                        point: frame.world_point(c.point),
                        ..c
                    });
                }
            }
        }
        Some(Closest {
            distance: crate::base::vec3::norm_safe(sub(q, frame.center)),
            point: frame.world_point(self.tris[0][0]),
            face: 0,
            feature: Feature::Vertex(0),
        })
    }

    /// [`Self::closest`] in the coordinates the triangles are stored in.
    fn closest_in_frame(&self, q: [f64; 3]) -> Option<Closest> {
        let mut best: Option<(f64, [f64; 3], usize, Feature)> = None;
        let mut heap = BinaryHeap::new();
        heap.push(Entry {
            d2: box_dist2(&self.nodes[0], q),
            node: 0,
        });
        while let Some(Entry { d2, node }) = heap.pop() {
            if best.is_some_and(|b| d2 >= b.0) {
                break;
            }
            let n = self.nodes[node as usize];
            if n.count > 0 {
                let s = n.first as usize;
                for &f in &self.prims[s..s + n.count as usize] {
                    let (d2, p, feat) = closest_on_triangle(q, self.tris[f as usize]);
                    if best.is_none_or(|b| d2 < b.0 || (d2 == b.0 && (f as usize) < b.2)) {
                        best = Some((d2, p, f as usize, feat));
                    }
                }
            } else {
                for child in [n.first, n.first + 1] {
                    let d2 = box_dist2(&self.nodes[child as usize], q);
                    if best.is_none_or(|b| d2 < b.0) {
                        heap.push(Entry { d2, node: child });
                    }
                }
            }
        }
        best.map(|(d2, point, face, feature)| Closest {
            distance: d2.sqrt(),
            point,
            face,
            feature,
        })
    }
}

/// `−d` where `w > 0.5`, `+d` elsewhere (NaN `w` gives NaN).
fn signed(d: f64, w: f64) -> f64 {
    if w.is_nan() {
        f64::NAN
    } else if w > 0.5 {
        -d
    } else {
        d
    }
}

/// Heap entry ordered so that the smallest distance pops first.
#[derive(Clone, Copy, Debug)]
struct Entry {
    d2: f64,
    node: u32,
}

impl PartialEq for Entry {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .d2
            .total_cmp(&self.d2)
            .then(other.node.cmp(&self.node))
    }
}

fn box_dist2(n: &Node, q: [f64; 3]) -> f64 {
    let mut d2 = 0.0;
    for ((&c, &lo), &hi) in q.iter().zip(&n.min).zip(&n.max) {
        let d = if c < lo {
            lo - c
        } else if c > hi {
            c - hi
        } else {
            0.0
        };
        d2 += d * d;
    }
    d2
}

/// Topology from obvhs, boxes recomputed exactly in `f64` (post-order).
fn build_tree(tris: &[[[f64; 3]; 3]]) -> (Vec<Node>, Vec<u32>) {
    if tris.is_empty() {
        return (Vec::new(), Vec::new());
    }
    let aabbs: Vec<Aabb> = tris
        .iter()
        .map(|t| {
            let lo: [f32; 3] = std::array::from_fn(|k| t[0][k].min(t[1][k]).min(t[2][k]) as f32);
            let hi: [f32; 3] = std::array::from_fn(|k| t[0][k].max(t[1][k]).max(t[2][k]) as f32);
            Aabb::new(glam::Vec3A::from_array(lo), glam::Vec3A::from_array(hi))
        })
        .collect();
    let mut time = std::time::Duration::ZERO;
    let bvh = build_bvh2(&aabbs, BvhBuildParams::fast_build(), &mut time);
    let mut nodes: Vec<Node> = bvh
        .nodes
        .iter()
        .map(|n| Node {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
            first: n.first_index,
            count: n.prim_count,
        })
        .collect();
    let prims = bvh.primitive_indices;
    // Iterative post-order: children's boxes are final before the parent's.
    let mut stack: Vec<(u32, bool)> = vec![(0, false)];
    while let Some((i, done)) = stack.pop() {
        let n = nodes[i as usize];
        if n.count > 0 {
            let s = n.first as usize;
            let (mut lo, mut hi) = (n.min, n.max);
            for &f in &prims[s..s + n.count as usize] {
                for p in &tris[f as usize] {
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
            }
            nodes[i as usize].min = lo;
            nodes[i as usize].max = hi;
        } else if done {
            let (a, b) = (nodes[n.first as usize], nodes[n.first as usize + 1]);
            nodes[i as usize].min = std::array::from_fn(|k| a.min[k].min(b.min[k]));
            nodes[i as usize].max = std::array::from_fn(|k| a.max[k].max(b.max[k]));
        } else {
            stack.push((i, true));
            stack.push((n.first, false));
            stack.push((n.first + 1, false));
        }
    }
    (nodes, prims)
}

/// Closest point on segment `ab` to `p`: `(squared distance, point, parameter t ∈ [0, 1])`.
fn closest_on_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> (f64, [f64; 3], f64) {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    let t = if len2 > 0.0 {
        (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = if t == 0.0 {
        a
    } else if t == 1.0 {
        b
    } else {
        [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]]
    };
    let d = sub(p, x);
    (dot(d, d), x, t)
}

/// Closest point of triangle `t` to `p`: `(squared distance, point, feature)`.
pub fn closest_on_triangle(p: [f64; 3], t: [[f64; 3]; 3]) -> (f64, [f64; 3], Feature) {
    let [a, b, c] = t;
    let ab = sub(b, a);
    let ac = sub(c, a);
    let n = cross(ab, ac);
    let nn = dot(n, n);
    // A face whose normal is lost in rounding is treated as its edges.
    if nn > 1e-24 * dot(ab, ab) * dot(ac, ac) && nn > 0.0 {
        let s0 = dot(n, cross(ab, sub(p, a)));
        let s1 = dot(n, cross(sub(c, b), sub(p, b)));
        let s2 = dot(n, cross(sub(a, c), sub(p, c)));
        if s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0 {
            let h = dot(sub(p, a), n);
            let k = h / nn;
            let x = [p[0] - k * n[0], p[1] - k * n[1], p[2] - k * n[2]];
            return (h * h / nn, x, Feature::Face);
        }
    }
    let mut best = (f64::INFINITY, a, Feature::Vertex(0));
    for (i, j) in [(0u8, 1u8), (1, 2), (2, 0)] {
        let (d2, x, s) = closest_on_segment(p, t[i as usize], t[j as usize]);
        if d2 < best.0 {
            let feat = if s == 0.0 {
                Feature::Vertex(i)
            } else if s == 1.0 {
                Feature::Vertex(j)
            } else {
                Feature::Edge(i, j)
            };
            best = (d2, x, feat);
        }
    }
    best
}

/// The classic angle-weighted pseudo-normal sign (Bærentzen & Aanæs), **for comparison only**:
/// the sign of `(q − c)·n` with `c` the closest point and `n` the pseudo-normal of the feature
/// it lies on (face normal; sum of the two adjacent face normals for an edge; angle-weighted sum
/// of incident face normals for a vertex). Correct for closed, consistently oriented manifold
/// meshes; on holes and dirty meshes it is what [`SignedDistance`] replaces.
#[derive(Clone, Debug)]
pub struct PseudoNormalSign {
    face_normals: Vec<[f64; 3]>,
    vertex_normals: Vec<[f64; 3]>,
    edge_normals: std::collections::HashMap<(u32, u32), [f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl PseudoNormalSign {
    /// Precomputes the pseudo-normals of `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        let unit = |v: [f64; 3]| {
            let l = dot(v, v).sqrt();
            if l > 0.0 { v.map(|c| c / l) } else { [0.0; 3] }
        };
        let mut vertex_normals = vec![[0.0; 3]; mesh.positions().len()];
        let mut edge_normals = std::collections::HashMap::new();
        let mut face_normals = Vec::with_capacity(mesh.triangles().len());
        for (f, t) in mesh.triangles().iter().enumerate() {
            let p = mesh.triangle_positions(f);
            let n = unit(cross(sub(p[1], p[0]), sub(p[2], p[0])));
            face_normals.push(n);
            for k in 0..3 {
                let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
                let (u, v) = (unit(sub(b, a)), unit(sub(c, a)));
                let angle = dot(u, v).clamp(-1.0, 1.0).acos();
                let vn = &mut vertex_normals[t[k] as usize];
                for j in 0..3 {
                    vn[j] += angle * n[j];
                }
                let (i, j) = (t[k], t[(k + 1) % 3]);
                let e: &mut [f64; 3] = edge_normals.entry((i.min(j), i.max(j))).or_insert([0.0; 3]);
                for j in 0..3 {
                    e[j] += n[j];
                }
            }
        }
        PseudoNormalSign {
            face_normals,
            vertex_normals,
            edge_normals,
            triangles: mesh.triangles().to_vec(),
        }
    }

    /// `−1` (inside) or `+1` (outside, also on a zero pseudo-normal) for `q` whose closest point
    /// is `closest`.
    pub fn sign(&self, q: [f64; 3], closest: &Closest) -> f64 {
        let t = self.triangles[closest.face];
        let n = match closest.feature {
            Feature::Face => self.face_normals[closest.face],
            Feature::Edge(i, j) => {
                let (a, b) = (t[i as usize], t[j as usize]);
                self.edge_normals
                    .get(&(a.min(b), a.max(b)))
                    .copied()
                    .unwrap_or([0.0; 3])
            }
            Feature::Vertex(i) => self.vertex_normals[t[i as usize] as usize],
        };
        if dot(sub(q, closest.point), n) < 0.0 {
            -1.0
        } else {
            1.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_regions() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let (d2, x, f) = closest_on_triangle([0.25, 0.25, 2.0], t);
        assert_eq!((d2, x, f), (4.0, [0.25, 0.25, 0.0], Feature::Face));
        let (d2, _, f) = closest_on_triangle([-1.0, -1.0, 0.0], t);
        assert_eq!((d2, f), (2.0, Feature::Vertex(0)));
        let (d2, x, f) = closest_on_triangle([0.5, -2.0, 0.0], t);
        assert_eq!((d2, x, f), (4.0, [0.5, 0.0, 0.0], Feature::Edge(0, 1)));
        // Degenerate (collinear) triangle: distance to its longest edge.
        let deg = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        let (d2, _, _) = closest_on_triangle([1.5, 1.0, 0.0], deg);
        assert_eq!(d2, 1.0);
    }
}
