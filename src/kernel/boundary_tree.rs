//! The certified hierarchy over the boundary chains (docs/boundary.md): a binary tree over
//! ranges of the chain slots of [`BoundaryEdges`], so that each node is a few runs of consecutive
//! boundary edges. A node the ray misses and that lies far enough from the query contributes
//! `Ω_S(q) − Σ_v m_v·Area(p, v)` (Eq. 2): the expansion of [`super::boundary_multipole`] for the
//! fan surface `S` from the node's apex `p`, and one exact spoke term per open end `v` of its
//! runs, through the same perturbed predicate as every other term. Nodes the ray passes, near
//! nodes, and nodes where the expansion would cost more than its edges run the exact SIMD loop.
//!
//! **Budget.** With tolerance `τ` on `w`, a node of `n` of the `N` chained edges may err by
//! `4π·τ·n/N` in area units; the nodes used are disjoint, so the reported bound (the sum of their
//! bounds) never exceeds `τ` (Eq. 10).
//!
//! **Cost model.** A node is expanded only at an order whose evaluation is cheaper than its
//! edges' loop ([`EDGE_COST`] units); the distance at which each order becomes admissible is
//! precomputed per node, so a query visits only nodes that can pay.

use super::angle_sum::AngleSum;
use super::boundary_multipole::{
    COEFFICIENTS, EVALUATION_ROUNDING, MAX_ORDER, Moments, add_fan_triangle, coefficients_up_to,
    evaluate, shifted, truncation_bound,
};
use super::boundary_sum::{BoundaryEdges, segment_area};
use super::predicates::Width;
use super::spherical::INV_4PI;

/// Slots per leaf (a multiple of the SIMD loop's 4).
const LEAF_SLOTS: usize = 32;

/// More levels than any tree has (ranges halve down to [`LEAF_SLOTS`], slots fit in `u32`).
const MAX_DEPTH: usize = 64;

/// Cost of one chained edge in the SIMD loop, in the units of the costs below (nanoseconds on the
/// machine of docs/benchmarks.md, "Boundary hierarchy": only the ratios matter).
const EDGE_COST: f64 = 2.0;
/// Cost of one coefficient of [`evaluate`] (recurrence and product).
const COEFFICIENT_COST: f64 = 1.6;
/// Cost of one spoke term (exact predicate, `atan2`).
const SPOKE_COST: f64 = 40.0;
/// Fixed cost of expanding a node (distance, order choice, bound).
const NODE_COST: f64 = 30.0;

/// One node: the slots `j0..j1`, their geometry and expansion.
#[derive(Clone, Debug)]
struct Node {
    j0: u32,
    j1: u32,
    /// Chained edges in the range.
    edges: u32,
    /// Children (`None` for a leaf).
    children: Option<(u32, u32)>,
    /// Integer box of the node's vertices (frame).
    lo: [i64; 3],
    hi: [i64; 3],
    /// Centre and radius of the ball holding `S` (normalized coordinates).
    centre: [f64; 3],
    radius: f64,
    /// Unsigned area of `S` (normalized units).
    area: f64,
    /// Apex of the fan.
    apex: [i64; 3],
    /// Open ends `(v, m_v)`: `ends[e0..e1]`.
    ends: (u32, u32),
    /// The area budget of the node at the evaluator's tolerance.
    budget: f64,
    /// `reach[k − 1]`: the distance from which order `k` meets the budget (infinite where the
    /// order cannot pay).
    reach: [f64; MAX_ORDER],
    /// The smallest reach in the subtree: closer than that, nothing below can be expanded.
    subtree_reach: f64,
}

/// The hierarchy of one evaluator's boundary at one tolerance.
#[derive(Clone, Debug)]
pub struct BoundaryTree {
    nodes: Vec<Node>,
    moments: Vec<Moments>,
    ends: Vec<([i64; 3], i32)>,
    tolerance: f64,
}

/// What the hierarchy did for one query: the boundary sum, its certified error bound on `w`, and
/// how many nodes were expanded.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TreeSum {
    /// `Σ k·Area` (area units, like [`BoundaryEdges::area_sum`]).
    pub area: f64,
    /// Bound on `|w − w_exact-loop|` (already divided by 4π).
    pub bound: f64,
    /// Nodes replaced by their expansion.
    pub expanded: u32,
}

impl BoundaryTree {
    /// Builds the hierarchy for `edges` at tolerance `tolerance` (absolute, on `w`). `None` when
    /// no node could ever pay (too few edges, or a tolerance too small to expand anything).
    pub fn build(edges: &BoundaryEdges, tolerance: f64) -> Option<Self> {
        if !(tolerance > 0.0) || !tolerance.is_finite() {
            return None;
        }
        let total = (0..edges.padded_slots())
            .filter(|&j| edges.slot_edge(j).is_some())
            .count();
        if (total as f64) * EDGE_COST < NODE_COST + coefficients_up_to(1) as f64 * COEFFICIENT_COST
        {
            return None;
        }
        let mut tree = BoundaryTree {
            nodes: Vec::new(),
            moments: Vec::new(),
            ends: Vec::new(),
            tolerance,
        };
        let per_edge = 4.0 * std::f64::consts::PI * tolerance / total as f64;
        tree.build_node(edges, 0, edges.padded_slots(), per_edge);
        (tree.nodes[0].subtree_reach.is_finite()).then_some(tree)
    }

    /// The tolerance it was built for.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// Builds the node of slots `j0..j1` and its subtree; returns its index.
    fn build_node(&mut self, edges: &BoundaryEdges, j0: usize, j1: usize, per_edge: f64) -> u32 {
        let index = self.nodes.len();
        let limit = edges.limit();
        let norm = |p: [i64; 3]| p.map(|c| c as f64 / limit);
        let slot_edges: Vec<usize> = (j0..j1).filter_map(|j| edges.slot_edge(j)).collect();
        let endpoints = || {
            slot_edges.iter().flat_map(|&e| {
                let (a, b, _) = edges.edge(e);
                [a, b]
            })
        };
        let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
        for p in endpoints() {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let apex = slot_edges.first().map_or([0; 3], |&e| edges.edge(e).0);
        let centre: [f64; 3] = if slot_edges.is_empty() {
            [0.0; 3]
        } else {
            std::array::from_fn(|k| (lo[k] as f64 * 0.5 + hi[k] as f64 * 0.5) / limit)
        };
        let radius = endpoints()
            .map(|p| {
                let v = norm(p);
                ((v[0] - centre[0]).powi(2) + (v[1] - centre[1]).powi(2) + (v[2] - centre[2]).powi(2))
                    .sqrt()
            })
            .fold(0.0, f64::max);
        // Rounding of the distances above: a relative 2^-50 is far more than their error.
        let radius = radius * (1.0 + 1e-15) + 4.0 / limit;
        // Open ends: m_v = (edges leaving v) − (edges arriving), merged by position.
        let mut ends: Vec<([i64; 3], i32)> = Vec::new();
        for &e in &slot_edges {
            let (a, b, _) = edges.edge(e);
            ends.push((a, 1));
            ends.push((b, -1));
        }
        ends.sort_unstable();
        let mut merged: Vec<([i64; 3], i32)> = Vec::new();
        for (v, m) in ends {
            match merged.last_mut() {
                Some((w, n)) if *w == v => *n += m,
                _ => merged.push((v, m)),
            }
        }
        merged.retain(|&(v, m)| m != 0 && v != apex);
        let e0 = self.ends.len() as u32;
        self.ends.extend_from_slice(&merged);
        let e1 = self.ends.len() as u32;
        self.nodes.push(Node {
            j0: j0 as u32,
            j1: j1 as u32,
            edges: slot_edges.len() as u32,
            children: None,
            lo,
            hi,
            centre,
            radius,
            area: 0.0,
            apex,
            ends: (e0, e1),
            budget: per_edge * slot_edges.len() as f64,
            reach: [f64::INFINITY; MAX_ORDER],
            subtree_reach: f64::INFINITY,
        });
        self.moments.push([0.0; COEFFICIENTS]);
        // Moments about the apex, then shifted to the centre.
        let (about_apex, area) = if j1 - j0 <= LEAF_SLOTS {
            let mut m = [0.0; COEFFICIENTS];
            let mut area = 0.0;
            for &e in &slot_edges {
                let (a, b, _) = edges.edge(e);
                area += add_fan_triangle(&mut m, rel(a, apex, limit), rel(b, apex, limit));
            }
            (m, area)
        } else {
            let mid = j0 + ((j1 - j0) / 2).div_ceil(LEAF_SLOTS) * LEAF_SLOTS;
            let left = self.build_node(edges, j0, mid, per_edge);
            let right = self.build_node(edges, mid, j1, per_edge);
            self.nodes[index].children = Some((left, right));
            let apex_c = norm(apex);
            let mut m = [0.0; COEFFICIENTS];
            let mut area = 0.0;
            for child in [left, right] {
                let c = &self.nodes[child as usize];
                if c.edges == 0 {
                    continue;
                }
                let delta = std::array::from_fn(|k| c.centre[k] - apex_c[k]);
                let moved = shifted(&self.moments[child as usize], delta);
                for i in 0..COEFFICIENTS {
                    m[i] += moved[i];
                }
                area += c.area;
                if c.apex != apex {
                    // S_child is the fan from the child's apex p_k; the node's fan from p adds,
                    // per open end v of the child, −m_v times the triangle (p, p_k, v) (Eq. 9).
                    let (c0, c1) = c.ends;
                    let child_apex = c.apex;
                    let ends: Vec<([i64; 3], i32)> = self.ends[c0 as usize..c1 as usize].to_vec();
                    for (v, mv) in ends {
                        let (ra, rb) = (rel(child_apex, apex, limit), rel(v, apex, limit));
                        for _ in 0..mv.unsigned_abs() {
                            // −m_v: the triangle's orientation flipped when m_v > 0.
                            area += if mv > 0 {
                                add_fan_triangle(&mut m, rb, ra)
                            } else {
                                add_fan_triangle(&mut m, ra, rb)
                            };
                        }
                    }
                }
            }
            (m, area)
        };
        let delta = std::array::from_fn(|k| norm(apex)[k] - centre[k]);
        self.moments[index] = shifted(&about_apex, delta);
        let node = &mut self.nodes[index];
        node.area = area * (1.0 + 1e-12);
        // Orders that can pay: evaluation cheaper than the node's loop.
        let ends = (node.ends.1 - node.ends.0) as f64;
        let loop_cost = node.edges as f64 * EDGE_COST;
        for k in 1..=MAX_ORDER {
            let cost = NODE_COST + coefficients_up_to(k) as f64 * COEFFICIENT_COST + ends * SPOKE_COST;
            if cost < loop_cost && node.edges > 0 {
                node.reach[k - 1] = reach(node.area, node.radius, k, node.budget);
            }
        }
        let own = node.reach.iter().copied().fold(f64::INFINITY, f64::min);
        let below = node.children.map_or(f64::INFINITY, |(l, r)| {
            self.nodes[l as usize]
                .subtree_reach
                .min(self.nodes[r as usize].subtree_reach)
        });
        self.nodes[index].subtree_reach = own.min(below);
        index as u32
    }

    /// The boundary sum at the lattice query `qi` (the same arguments as
    /// [`BoundaryEdges::area_sum`]), with far nodes expanded.
    pub fn area_sum<W: Width>(
        &self,
        edges: &BoundaryEdges,
        qi: [i64; 3],
        z_exact: bool,
        qz_units: f64,
    ) -> TreeSum {
        let limit = edges.limit();
        let q = [
            qi[0] as f64 / limit,
            qi[1] as f64 / limit,
            if z_exact { qi[2] as f64 } else { qz_units } / limit,
        ];
        // The ray from q (+z) misses a node's box, with a one-cell margin for the residual.
        let misses = |lo: [i64; 3], hi: [i64; 3]| {
            qi[0] < lo[0] - 1
                || qi[0] > hi[0] + 1
                || qi[1] < lo[1] - 1
                || qi[1] > hi[1] + 1
                || qi[2] > hi[2] + 1
        };
        let mut angles: Option<AngleSum> = None;
        let mut scalar = 0.0;
        let mut run_exact = |range: std::ops::Range<usize>| {
            let (a, s) = edges.range_area_sum::<W>(qi, z_exact, qz_units, range);
            match &mut angles {
                Some(acc) => acc.absorb(&a),
                None => angles = Some(a),
            }
            scalar += s;
        };
        let spoke = |p: [i64; 3], v: [i64; 3]| segment_area::<W>(p, v, qi, z_exact, qz_units);
        let mut sum = self.traverse(q, misses, &mut run_exact, spoke);
        sum.area += angles.map_or(0.0, |a| 2.0 * a.total()) + scalar;
        sum.area += edges.heavy_area_sum::<W>(qi, z_exact, qz_units);
        sum
    }

    /// The traversal shared by lattice and far queries: expanded nodes' terms and bounds; the
    /// slot ranges left to the exact loop go to `exact` (in slot order, adjacent ones merged).
    pub(crate) fn traverse(
        &self,
        q: [f64; 3],
        misses: impl Fn([i64; 3], [i64; 3]) -> bool,
        exact: &mut impl FnMut(std::ops::Range<usize>),
        spoke: impl Fn([i64; 3], [i64; 3]) -> f64,
    ) -> TreeSum {
        let mut out = TreeSum::default();
        let mut pending: Option<std::ops::Range<usize>> = None;
        let mut flush = |range: std::ops::Range<usize>, pending: &mut Option<std::ops::Range<usize>>| {
            match pending {
                Some(p) if p.end == range.start => p.end = range.end,
                _ => {
                    if let Some(p) = pending.take() {
                        exact(p);
                    }
                    *pending = Some(range);
                }
            }
        };
        // A fixed stack (no allocation per query): each level pushes two, the depth is below 64.
        let mut stack = [0u32; 2 * MAX_DEPTH];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let i = stack[top];
            let n = &self.nodes[i as usize];
            if n.edges == 0 {
                continue;
            }
            let range = n.j0 as usize..n.j1 as usize;
            let d: [f64; 3] = std::array::from_fn(|k| q[k] - n.centre[k]);
            let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            // Every node below lies within the ball: closer than any reach below, loop over all.
            if r + n.radius < n.subtree_reach {
                flush(range, &mut pending);
                continue;
            }
            if r >= n.subtree_reach && misses(n.lo, n.hi) {
                if let Some(k) = (1..=MAX_ORDER).find(|&k| r >= n.reach[k - 1]) {
                    let bound = truncation_bound(n.area, n.radius, r, k);
                    let (omega, magnitude) = evaluate(&self.moments[i as usize], n.centre, q, k);
                    let bound = bound + EVALUATION_ROUNDING * magnitude;
                    if bound <= n.budget {
                        let (e0, e1) = n.ends;
                        let spokes: f64 = self.ends[e0 as usize..e1 as usize]
                            .iter()
                            .map(|&(v, m)| f64::from(m) * spoke(n.apex, v))
                            .sum();
                        out.area += omega - spokes;
                        out.bound += bound * INV_4PI;
                        out.expanded += 1;
                        continue;
                    }
                }
            }
            match n.children {
                Some((l, r)) => {
                    stack[top] = r;
                    stack[top + 1] = l;
                    top += 2;
                }
                None => flush(range, &mut pending),
            }
        }
        if let Some(p) = pending {
            exact(p);
        }
        out
    }

}

/// `b − a` in normalized coordinates (exact integer difference, one rounding).
fn rel(b: [i64; 3], a: [i64; 3], limit: f64) -> [f64; 3] {
    std::array::from_fn(|k| (b[k] - a[k]) as f64 / limit)
}

/// The distance from which order `k` meets `budget` (the bound decreases with the distance:
/// bisection on `r/a`).
fn reach(area: f64, radius: f64, order: usize, budget: f64) -> f64 {
    if area == 0.0 {
        return radius * (1.0 + 1e-9);
    }
    let (mut lo, mut hi) = (radius * (1.0 + 1e-9), radius * 2.0);
    while truncation_bound(area, radius, hi, order) > budget {
        lo = hi;
        hi *= 2.0;
        if hi > radius * 1e12 {
            return f64::INFINITY;
        }
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if truncation_bound(area, radius, mid, order) > budget {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}
