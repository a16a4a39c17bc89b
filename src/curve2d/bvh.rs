//! A bounding volume hierarchy over the edges of a polygon that keeps the curve closed when far
//! nodes are approximated (Sun et al. 2024, Section 3.3, Supp. Algorithms 1–3).
//!
//! Each node holds a set of edges. Within a node, the edges form *chains*: maximal runs of
//! consecutive edges of one loop (by index, so coincident or non-manifold vertices — several loops
//! through one point — cannot confuse them). A node stores the entry → exit *chord* of each chain.
//! Replacing a chain from `a` to `b` by the chord `a → b` changes the curve by the closed loop
//! `chain − chord`, so the approximated curve stays closed and Lemma 3.1 still applies; a loop
//! that lies entirely inside the node has a degenerate chord and is dropped.
//!
//! **Value error bound.** The change of `W_σ(q)` from one replaced chain is
//! `∫ w_{chain−chord}(x) G(x − q) dx`. That loop lies in the node's box, at distance ≥ `D` from
//! `q`, so `G ≤ exp(−D²/2σ²)/(2πσ²)` there, and `∫|w| ≤ ∫w² ≤ L²/(4π)` (Banchoff–Pohl, `L` the
//! loop's length). A node is replaced by its chords only if
//! `Σ_chains (L_chain + |chord|)²/(4π) · exp(−D²/2σ²)/(2πσ²) ≤ tol`; [`CurveBvh::value_with_bound`]
//! returns the sum of these bounds over the replaced nodes, a rigorous bound on
//! `|W_bvh − W_exact|` (up to rounding).
//!
//! **Gradient cut-off.** Every gradient term of an edge is bounded by `∫_edge G ds`, so a node is
//! dropped from the gradient traversals when its distance exceeds `8σ` *and*
//! `L_node · exp(−D²/2σ²)/(2πσ²) ≤ grad_tol` (the σ-aware far test); the dropped part is at most
//! the sum of these terms.

use super::gauwn::{GauWn, Neumaier};
use super::polygon::{Point, Polygon, dist};
use std::f64::consts::PI;

const LEAF_SIZE: usize = 8;

#[derive(Clone, Debug)]
struct Node {
    bbox: [f64; 4],
    /// Children (internal) or `usize::MAX` (leaf).
    left: usize,
    right: usize,
    /// Edge range in `order`.
    lo: usize,
    hi: usize,
    /// Chord range in `chords`.
    c_lo: usize,
    c_hi: usize,
    /// Σ (L + |chord|)²/(4π) over the chains.
    area_bound: f64,
    /// Total edge length.
    length: f64,
}

/// The BVH of one polygon (rebuild it after moving the vertices).
#[derive(Clone, Debug)]
pub struct CurveBvh {
    poly: Polygon,
    nodes: Vec<Node>,
    order: Vec<usize>,
    chords: Vec<(usize, usize)>,
    /// Per-node tolerance of the value approximation.
    pub value_tol: f64,
    /// Per-node tolerance of the gradient cut-off.
    pub grad_tol: f64,
}

fn box_dist2(b: &[f64; 4], q: Point) -> f64 {
    let dx = (b[0] - q[0]).max(q[0] - b[2]).max(0.0);
    let dy = (b[1] - q[1]).max(q[1] - b[3]).max(0.0);
    dx * dx + dy * dy
}

impl CurveBvh {
    /// Builds the hierarchy (median split of edge midpoints along the longer box side). Default
    /// tolerances: `value_tol = 1e-13`, `grad_tol = 1e-15` per node.
    pub fn new(poly: &Polygon) -> Self {
        let n = poly.len();
        let p = poly.points();
        let ends: Vec<(Point, Point)> = (0..n).map(|i| (p[i], p[poly.next(i)])).collect();
        let mut order: Vec<usize> = (0..n).collect();
        let mut nodes = Vec::new();
        build(&ends, &mut order, 0, n, &mut nodes);
        // Chains per node.
        let mut pos = vec![0usize; n];
        for (k, &e) in order.iter().enumerate() {
            pos[e] = k;
        }
        let mut chords = Vec::new();
        for node in nodes.iter_mut() {
            node.c_lo = chords.len();
            let inside = |e: usize| (node.lo..node.hi).contains(&pos[e]);
            let mut area = 0.0;
            let mut length = 0.0;
            for &e in &order[node.lo..node.hi] {
                length += dist(ends[e].0, ends[e].1);
                if inside(poly.prev(e)) {
                    continue;
                }
                // Chain start: follow the loop while the edges stay in the node.
                let mut last = e;
                let mut len = dist(ends[e].0, ends[e].1);
                while inside(poly.next(last)) {
                    last = poly.next(last);
                    len += dist(ends[last].0, ends[last].1);
                }
                let (a, b) = (e, poly.next(last));
                let chord = dist(p[a], p[b]);
                area += (len + chord) * (len + chord) / (4.0 * PI);
                if p[a] != p[b] {
                    chords.push((a, b));
                }
            }
            // Loops entirely inside the node have no chain start: their chord is degenerate (they
            // are dropped), and their own length enters the bound.
            for &e in &order[node.lo..node.hi] {
                let k = poly.loop_of(e);
                let (s0, s1) = (poly.starts()[k], poly.starts()[k + 1]);
                if e == s0 && (s0..s1).all(inside) {
                    let l: f64 = (s0..s1).map(|i| dist(ends[i].0, ends[i].1)).sum();
                    area += l * l / (4.0 * PI);
                }
            }
            node.c_hi = chords.len();
            node.area_bound = area;
            node.length = length;
        }
        CurveBvh {
            poly: poly.clone(),
            nodes,
            order,
            chords,
            value_tol: 1e-13,
            grad_tol: 1e-15,
        }
    }

    /// The polygon this BVH was built for.
    pub fn polygon(&self) -> &Polygon {
        &self.poly
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    fn gmax(sigma: f64, d2: f64) -> f64 {
        (-d2 / (2.0 * sigma * sigma)).exp() / (2.0 * PI * sigma * sigma)
    }

    /// `W_σ(q)` with far nodes replaced by their chords.
    pub fn value(&self, g: &GauWn, q: Point) -> f64 {
        self.value_with_bound(g, q).0
    }

    /// `(W_σ(q) approximated, bound on |approximation − exact|)`.
    pub fn value_with_bound(&self, g: &GauWn, q: Point) -> (f64, f64) {
        let p = self.poly.points();
        let mut sum = Neumaier::default();
        let mut bound = 0.0;
        let mut stack = vec![0usize];
        while let Some(ni) = stack.pop() {
            let node = &self.nodes[ni];
            let leaf = node.left == usize::MAX;
            if leaf {
                for &e in &self.order[node.lo..node.hi] {
                    sum.add(g.segment_value(p[e], p[self.poly.next(e)], q));
                }
                continue;
            }
            let d2 = box_dist2(&node.bbox, q);
            let err = node.area_bound * Self::gmax(g.sigma, d2);
            if d2 > 0.0 && err <= self.value_tol {
                for &(a, b) in &self.chords[node.c_lo..node.c_hi] {
                    sum.add(g.segment_value(p[a], p[b], q));
                }
                bound += err;
                continue;
            }
            stack.push(node.left);
            stack.push(node.right);
        }
        (sum.value(), bound)
    }

    fn grad_far(&self, node: &Node, sigma: f64, q: Point) -> bool {
        let d2 = box_dist2(&node.bbox, q);
        d2 > 64.0 * sigma * sigma && node.length * Self::gmax(sigma, d2) <= self.grad_tol
    }

    /// `∇_q W_σ(q)`, dropping nodes by the σ-aware far test.
    pub fn gradient(&self, g: &GauWn, q: Point) -> Point {
        let p = self.poly.points();
        let mut out = [0.0; 2];
        let mut stack = vec![0usize];
        while let Some(ni) = stack.pop() {
            let node = &self.nodes[ni];
            if self.grad_far(node, g.sigma, q) {
                continue;
            }
            if node.left == usize::MAX {
                for &e in &self.order[node.lo..node.hi] {
                    let s = g.segment_spatial_gradient(p[e], p[self.poly.next(e)], q);
                    out[0] += s[0];
                    out[1] += s[1];
                }
            } else {
                stack.push(node.left);
                stack.push(node.right);
            }
        }
        out
    }

    /// `out[i] += scale · ∂W_σ(q)/∂v_i`, dropping nodes by the σ-aware far test.
    pub fn add_vertex_gradient(&self, g: &GauWn, q: Point, scale: f64, out: &mut [Point]) {
        let p = self.poly.points();
        let mut stack = vec![0usize];
        while let Some(ni) = stack.pop() {
            let node = &self.nodes[ni];
            if self.grad_far(node, g.sigma, q) {
                continue;
            }
            if node.left == usize::MAX {
                for &e in &self.order[node.lo..node.hi] {
                    let j = self.poly.next(e);
                    let (g0, g1) = g.segment_vertex_gradients(p[e], p[j], q);
                    out[e][0] += scale * g0[0];
                    out[e][1] += scale * g0[1];
                    out[j][0] += scale * g1[0];
                    out[j][1] += scale * g1[1];
                }
            } else {
                stack.push(node.left);
                stack.push(node.right);
            }
        }
    }

    /// `∂W_σ(q)/∂v_i` for every vertex.
    pub fn vertex_gradient(&self, g: &GauWn, q: Point) -> Vec<Point> {
        let mut out = vec![[0.0; 2]; self.poly.len()];
        self.add_vertex_gradient(g, q, 1.0, &mut out);
        out
    }
}

fn build(
    ends: &[(Point, Point)],
    order: &mut [usize],
    lo: usize,
    hi: usize,
    nodes: &mut Vec<Node>,
) -> usize {
    let mut bbox = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
    for &e in &order[lo..hi] {
        for p in [ends[e].0, ends[e].1] {
            bbox[0] = bbox[0].min(p[0]);
            bbox[1] = bbox[1].min(p[1]);
            bbox[2] = bbox[2].max(p[0]);
            bbox[3] = bbox[3].max(p[1]);
        }
    }
    let id = nodes.len();
    nodes.push(Node {
        bbox,
        left: usize::MAX,
        right: usize::MAX,
        lo,
        hi,
        c_lo: 0,
        c_hi: 0,
        area_bound: 0.0,
        length: 0.0,
    });
    if hi - lo <= LEAF_SIZE {
        return id;
    }
    let axis = if bbox[2] - bbox[0] >= bbox[3] - bbox[1] {
        0
    } else {
        1
    };
    let mid = (lo + hi) / 2;
    let key = |e: &usize| ends[*e].0[axis] + ends[*e].1[axis];
    order[lo..hi].select_nth_unstable_by(mid - lo, |a, b| key(a).total_cmp(&key(b)));
    let left = build(ends, order, lo, mid, nodes);
    let right = build(ends, order, mid, hi, nodes);
    nodes[id].left = left;
    nodes[id].right = right;
    id
}
