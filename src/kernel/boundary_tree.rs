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
    COEFFICIENTS, Expansion, MAX_ORDER, Moments, add_fan_triangle, coefficients_up_to, shifted,
    truncation_bound,
};
use super::boundary_sum::{BoundaryEdges, rounded_offset};
use super::input_predicates::InputPoint;
use super::predicates::{Width, orient2d_filtered};
use super::spherical::{FOUR_PI, INV_4PI};
use wide::f64x4;

/// Slots per leaf (a multiple of the SIMD loop's 4).
const LEAF_SLOTS: usize = 64;

/// More levels than any tree has (ranges halve down to [`LEAF_SLOTS`], slots fit in `u32`).
const MAX_DEPTH: usize = 64;

/// Cost of one chained edge in the SIMD loop, in nanoseconds as measured on the 2-core machine of
/// docs/benchmarks.md ("Certified boundary hierarchy"; only the ratios matter).
const EDGE_COST: f64 = 3.0;
/// Cost of one coefficient of [`Expansion::evaluate`] (monomial and product): 2.2 ns with the
/// coefficients in L1, about twice that in a traversal that touches many nodes (their 2.3 KB of
/// coefficients come from L2/L3: measured as expansions that did not pay on the synthetic scans).
const COEFFICIENT_COST: f64 = 4.5;
/// Cost of one spoke term (filtered sign, one complex product).
const SPOKE_COST: f64 = 15.0;
/// Fixed cost of expanding a node (distance, order choice, bound, the evaluation's set-up).
const NODE_COST: f64 = 100.0;

/// Relative rounding allowance of a node's radius: the distances from the centre are a handful
/// of `f64` operations on exact integer offsets (relative error `≲ 4u = 4.4e-16`), and the
/// radius only has to be an upper bound, so `1e-15` covers it (plus [`RADIUS_CELLS`]).
const RADIUS_ROUNDING: f64 = 1e-15;

/// Absolute allowance of a node's radius, in cells: the vertices' residuals off the lattice
/// (`≤ √3/2`) with room to spare; the radius is measured on the lattice points.
const RADIUS_CELLS: f64 = 4.0;

/// Relative rounding allowance of a node's fan area (the upper bound on its fan's total triangle
/// area that the truncation bound takes): a sum of non-negative terms, its children's areas and
/// the triangles added at its open ends, each a few roundings. Such a sum of `n` terms errs by at
/// most `(n + c)·u` relative (`u = 2^-53`); `1e-12` covers thousands of terms per node, far more
/// than two children plus a cluster's open ends, and every level applies it again, so a parent's
/// bound contains its children's.
const AREA_ROUNDING: f64 = 1e-12;

/// The reach of a node starts strictly outside its ball: a query at distance `≤ radius` could be
/// inside the cluster, where the expansion does not converge.
const REACH_MARGIN: f64 = 1e-9;

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
    /// Twice the centre of the ball holding `S` (`lo + hi`, cells, exact): offsets from the
    /// centre are computed from it without cancellation ([`TreeQuery::offset_from_centre`]).
    centre2: [i64; 3],
    /// Centre and radius of the ball holding `S` (normalized coordinates).
    centre: [f64; 3],
    radius: f64,
    /// Unsigned area of `S` (normalized units).
    area: f64,
    /// Apex of the fan (the exact vertex).
    apex: InputPoint,
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
    expansions: Vec<Expansion>,
    ends: Vec<(InputPoint, i32)>,
    /// The grid's `2^(bits−1)` (normalized coordinates are cells divided by it).
    limit: f64,
}

/// A query as the hierarchy sees it. Its offsets from the node centres
/// ([`TreeQuery::offset_from_centre`]) decide which nodes are expanded and where their expansions are
/// evaluated, so for a query in the grid they are computed from the exact query and the exact
/// doubled centre, relative to the offset: rounding `q` and the centre to normalized `f64` first
/// moved both by up to `2^6` cells, which a node `d` away turns into a relative error `2^6/d`
/// of its expansion's value — beyond the certified bound for small nodes of huge meshes.
#[derive(Clone, Copy, Debug)]
pub(crate) enum TreeQuery {
    /// A query in the grid across the ray: the exact point, and `qz_units` (its `z` in cells)
    /// when `z_exact` is false.
    Lattice {
        q: InputPoint,
        z_exact: bool,
        qz_units: f64,
    },
    /// A query whose ray cannot approach the mesh (normalized coordinates): farther than the
    /// extent from every node, where `f64` positions are accurate enough.
    Far([f64; 3]),
}

impl TreeQuery {
    /// `q − centre` of node `n`, normalized.
    #[inline]
    fn offset_from_centre(&self, n: &Node, limit: f64) -> [f64; 3] {
        match self {
            TreeQuery::Lattice {
                q,
                z_exact,
                qz_units,
            } => std::array::from_fn(|k| {
                if k == 2 && !z_exact {
                    (qz_units - n.centre2[2] as f64 * 0.5) / limit
                } else {
                    // Exact: |2q| ≤ 2^60 and |centre2| ≤ 2^60.
                    ((2 * q.n[k] - n.centre2[k]) as f64 * 0.5 + q.r[k]) / limit
                }
            }),
            TreeQuery::Far(q) => std::array::from_fn(|k| q[k] - n.centre[k]),
        }
    }
}

/// Moments of the nodes while building (in node order): values and magnitudes; and the leaves'.
struct Building {
    moments: Vec<Moments>,
    leaves: Vec<LeafMoments>,
    /// Every node's open ends, its apex included (sorted by lattice position).
    full_ends: Vec<Vec<(InputPoint, i32)>>,
}

/// The fan moments of one leaf chunk about its apex (the first edge's start).
struct LeafMoments {
    moments: Box<Moments>,
    area: f64,
}

fn leaf_moments(edges: &BoundaryEdges, range: std::ops::Range<usize>) -> LeafMoments {
    let limit = edges.limit();
    let mut m = Box::new([0.0; COEFFICIENTS]);
    let mut area = 0.0;
    let mut apex = None;
    for e in range.filter_map(|j| edges.slot_edge(j)) {
        let (a, b) = edges.edge_points(e);
        let p = *apex.get_or_insert(a);
        area += add_fan_triangle(&mut m, rel(&a, &p, limit), rel(&b, &p, limit), 1.0);
    }
    LeafMoments { moments: m, area }
}

/// Sorts open ends by position, sums the multiplicities of equal positions and drops the zeros.
/// Positions are the inputs' exact values (lattice point and residual; the world value where the
/// residual is not exact), not the lattice point alone: two inputs a cell apart can share one,
/// and merging their ends (`+1` at one and `-1` at the other cancel) would drop a spoke the
/// node's expansion needs (as the chains join edges, [`BoundaryEdges`]'s build). An end given as
/// its lattice point (an edge on the lattice) and the same vertex given as an input merge.
fn merge_ends(mut ends: Vec<(InputPoint, i32)>) -> Vec<(InputPoint, i32)> {
    let key = |v: &InputPoint| {
        let bits = |c: [f64; 3]| c.map(|x| (x + 0.0).to_bits());
        let world = if v.residual_exact() {
            [0; 3]
        } else {
            bits(v.world)
        };
        (v.n, bits(v.r), world)
    };
    ends.sort_by_key(|(v, _)| key(v));
    let mut merged: Vec<(InputPoint, i32)> = Vec::with_capacity(ends.len());
    for (v, m) in ends {
        match merged.last_mut() {
            Some((w, n)) if key(w) == key(&v) => *n += m,
            _ => merged.push((v, m)),
        }
    }
    merged.retain(|&(_, m)| m != 0);
    merged
}

/// The distance from which each order pays and meets the node's budget.
fn set_reach(node: &mut Node) {
    let ends = (node.ends.1 - node.ends.0) as f64;
    let loop_cost = node.edges as f64 * EDGE_COST;
    for k in 1..=MAX_ORDER {
        let cost = NODE_COST + coefficients_up_to(k) as f64 * COEFFICIENT_COST + ends * SPOKE_COST;
        if cost < loop_cost && node.edges > 0 {
            node.reach[k - 1] = reach(node.area, node.radius, k, node.budget);
        }
    }
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
    /// Nodes visited.
    pub visited: u32,
}

impl BoundaryTree {
    /// Builds the hierarchy for `edges` at tolerance `tolerance` (absolute, on `w`). `None` when
    /// no node could ever pay (too few edges, or a tolerance too small to expand anything).
    pub fn build(edges: &BoundaryEdges, tolerance: f64) -> Option<Self> {
        if tolerance.is_nan() || tolerance <= 0.0 || !tolerance.is_finite() {
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
            expansions: Vec::new(),
            ends: Vec::new(),
            limit: edges.limit(),
        };
        // The tolerance is on w = Σ/(4π): the area budget is 4π times it.
        let per_edge = FOUR_PI * tolerance / total as f64;
        // The leaves are the LEAF_SLOTS-aligned chunks (every split is aligned): their fan moments
        // are the bulk of the work, split over scoped OS threads (`scoped_map`), like the
        // expansions below.
        let slots = edges.padded_slots();
        let leaf_count = slots.div_ceil(LEAF_SLOTS);
        let leaf =
            |c: usize| leaf_moments(edges, c * LEAF_SLOTS..((c + 1) * LEAF_SLOTS).min(slots));
        let leaves: Vec<LeafMoments> = scoped_map(leaf_count, leaf);
        let mut building = Building {
            moments: Vec::new(),
            leaves,
            full_ends: Vec::new(),
        };
        tree.build_node(edges, 0, slots, per_edge, &mut building);
        tree.expansions = scoped_map(tree.nodes.len(), |i| {
            let n = &tree.nodes[i];
            Expansion::new(&building.moments[i], n.area, n.radius)
        });
        tree.nodes.iter_mut().for_each(set_reach);
        // Pre-order: children come after their parent.
        for i in (0..tree.nodes.len()).rev() {
            let below = tree.nodes[i].children.map_or(f64::INFINITY, |(l, r)| {
                tree.nodes[l as usize]
                    .subtree_reach
                    .min(tree.nodes[r as usize].subtree_reach)
            });
            let own = tree.nodes[i]
                .reach
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min);
            tree.nodes[i].subtree_reach = own.min(below);
        }
        (tree.nodes[0].subtree_reach.is_finite()).then_some(tree)
    }

    /// Whether the query `q` can expand any node: otherwise the flat loop is the same work
    /// without the traversal.
    pub fn reaches(&self, q: &TreeQuery) -> bool {
        let n = &self.nodes[0];
        let d = q.offset_from_centre(n, self.limit);
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() + n.radius >= n.subtree_reach
    }

    /// Builds the node of slots `j0..j1` and its subtree; returns its index.
    fn build_node(
        &mut self,
        edges: &BoundaryEdges,
        j0: usize,
        j1: usize,
        per_edge: f64,
        building: &mut Building,
    ) -> u32 {
        let index = self.nodes.len();
        let limit = edges.limit();
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
        let apex = slot_edges
            .first()
            .map_or(InputPoint::lattice([0; 3]), |&e| edges.edge_points(e).0);
        let centre2: [i64; 3] = if slot_edges.is_empty() {
            [0; 3]
        } else {
            std::array::from_fn(|k| lo[k] + hi[k])
        };
        let centre: [f64; 3] = std::array::from_fn(|k| centre2[k] as f64 * 0.5 / limit);
        let radius = endpoints()
            .map(|p| {
                // Exact integer offsets (|2p − centre2| ≤ 2^61), each rounded once.
                let d: [f64; 3] = std::array::from_fn(|k| (2 * p[k] - centre2[k]) as f64 * 0.5);
                (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
            })
            .fold(0.0, f64::max);
        let radius = (radius * (1.0 + RADIUS_ROUNDING) + RADIUS_CELLS) / limit;
        // Open ends: m_v = (edges leaving v) − (edges arriving), merged by position (sorted).
        // Leaves sort their edges' ends; parents merge their children's lists.
        let full_ends: Vec<(InputPoint, i32)> = if j1 - j0 <= LEAF_SLOTS {
            let mut ends: Vec<(InputPoint, i32)> = Vec::with_capacity(2 * slot_edges.len());
            for &e in &slot_edges {
                let (a, b) = edges.edge_points(e);
                ends.push((a, 1));
                ends.push((b, -1));
            }
            merge_ends(ends)
        } else {
            Vec::new()
        };
        building.full_ends.push(full_ends);
        self.nodes.push(Node {
            j0: j0 as u32,
            j1: j1 as u32,
            edges: slot_edges.len() as u32,
            children: None,
            lo,
            hi,
            centre2,
            centre,
            radius,
            area: 0.0,
            apex,
            ends: (0, 0),
            budget: per_edge * slot_edges.len() as f64,
            reach: [f64::INFINITY; MAX_ORDER],
            subtree_reach: f64::INFINITY,
        });
        building.moments.push([0.0; COEFFICIENTS]);
        // Moments about the apex, then shifted to the centre.
        let mut m = [0.0; COEFFICIENTS];
        let area = if j1 - j0 <= LEAF_SLOTS {
            let leaf = &building.leaves[j0 / LEAF_SLOTS];
            m = *leaf.moments;
            leaf.area
        } else {
            let mid = j0 + ((j1 - j0) / 2).div_ceil(LEAF_SLOTS) * LEAF_SLOTS;
            let left = self.build_node(edges, j0, mid, per_edge, building);
            let right = self.build_node(edges, mid, j1, per_edge, building);
            self.nodes[index].children = Some((left, right));
            let mut ends = building.full_ends[left as usize].clone();
            ends.extend_from_slice(&building.full_ends[right as usize]);
            building.full_ends[index] = merge_ends(ends);
            let mut area = 0.0;
            for child in [left, right] {
                let c = &self.nodes[child as usize];
                if c.edges == 0 {
                    continue;
                }
                let delta = centre_minus_point(c.centre2, &apex, limit);
                let moved = shifted(&building.moments[child as usize], delta);
                for i in 0..COEFFICIENTS {
                    m[i] += moved[i];
                }
                area += c.area;
                if (c.apex.n, c.apex.r) != (apex.n, apex.r) {
                    // S_child is the fan from the child's apex p_k; the node's fan from p adds,
                    // per open end v of the child, −m_v times the triangle (p, p_k, v) (Eq. 9).
                    let child_apex = c.apex;
                    for &(v, mv) in &building.full_ends[child as usize] {
                        let (ra, rb) = (rel(&child_apex, &apex, limit), rel(&v, &apex, limit));
                        let weight = -f64::from(mv);
                        for _ in 0..mv.unsigned_abs() {
                            area += add_fan_triangle(&mut m, ra, rb, weight.signum());
                        }
                    }
                }
            }
            area
        };
        let delta = centre_minus_point(centre2, &apex, limit).map(|c| -c);
        building.moments[index] = shifted(&m, delta);
        self.nodes[index].area = area * (1.0 + AREA_ROUNDING);
        let e0 = self.ends.len() as u32;
        self.ends.extend(
            building.full_ends[index]
                .iter()
                .filter(|&&(v, _)| v.n != apex.n),
        );
        self.nodes[index].ends = (e0, self.ends.len() as u32);
        index as u32
    }

    /// The boundary sum at the lattice query `qi` (the same arguments as
    /// [`BoundaryEdges::area_sum`]), with far nodes expanded.
    pub fn area_sum<W: Width>(
        &self,
        edges: &BoundaryEdges,
        q: &InputPoint,
        z_exact: bool,
        qz_units: f64,
    ) -> TreeSum {
        let limit = edges.limit();
        let qi = q.n;
        let at = TreeQuery::Lattice {
            q: *q,
            z_exact,
            qz_units,
        };
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
            let (a, s) = edges.range_area_sum::<W>(q, z_exact, qz_units, range);
            match &mut angles {
                Some(acc) => acc.absorb(&a),
                None => angles = Some(a),
            }
            scalar += s;
        };
        let mut spokes = SpokeSum::new(edges, *q, z_exact, qz_units, limit);
        let mut spoke = |p: &InputPoint, v: &InputPoint, m: i32| spokes.subtract::<W>(p, v, m);
        let mut sum = self.traverse(&at, misses, &mut run_exact, &mut spoke);
        let (spoke_angles, spoke_scalar) = spokes.finish();
        if let Some(a) = &mut angles {
            a.absorb(&spoke_angles);
        } else if sum.expanded > 0 {
            angles = Some(spoke_angles);
        }
        sum.area += angles.map_or(0.0, |a| 2.0 * a.total()) + scalar + spoke_scalar;
        sum.area += edges.heavy_area_sum::<W>(q, z_exact, qz_units);
        sum
    }

    /// Whether [`BoundaryTree::area_sum`] at this lattice query expands nothing and so equals
    /// [`BoundaryEdges::area_sum`] bit for bit (one range over every slot; the identity factors of
    /// the padding and of an empty spoke product are exact): the query is closer to the root than
    /// any node's reach. Column evaluation batches such queries.
    pub fn is_flat_at(&self, q: InputPoint, z_exact: bool, qz_units: f64) -> bool {
        !self.reaches(&TreeQuery::Lattice {
            q,
            z_exact,
            qz_units,
        })
    }

    /// The traversal shared by lattice and far queries: expanded nodes' terms and bounds; the
    /// slot ranges left to the exact loop go to `exact` (in slot order, adjacent ones merged).
    pub(crate) fn traverse(
        &self,
        q: &TreeQuery,
        misses: impl Fn([i64; 3], [i64; 3]) -> bool,
        exact: &mut impl FnMut(std::ops::Range<usize>),
        spoke: &mut impl FnMut(&InputPoint, &InputPoint, i32),
    ) -> TreeSum {
        let mut out = TreeSum::default();
        let mut pending: Option<std::ops::Range<usize>> = None;
        let mut flush = |range: std::ops::Range<usize>,
                         pending: &mut Option<std::ops::Range<usize>>| {
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
            out.visited += 1;
            if n.edges == 0 {
                continue;
            }
            let range = n.j0 as usize..n.j1 as usize;
            let d = q.offset_from_centre(n, self.limit);
            let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            // Every node below lies within the ball: closer than any reach below, loop over all.
            if r + n.radius < n.subtree_reach {
                flush(range, &mut pending);
                continue;
            }
            if r >= n.subtree_reach && misses(n.lo, n.hi) {
                if let Some(k) = (1..=MAX_ORDER).find(|&k| r >= n.reach[k - 1]) {
                    let bound = truncation_bound(n.area, n.radius, r, k);
                    let (omega, rounding) = self.expansions[i as usize].evaluate(d.map(|c| -c), k);
                    let bound = bound + rounding;
                    if bound <= n.budget {
                        let (e0, e1) = n.ends;
                        for (v, m) in &self.ends[e0 as usize..e1 as usize] {
                            spoke(&n.apex, v, *m);
                        }
                        out.area += omega;
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

/// `(0..count).map(f)`, split over scoped OS threads when there are many items (at least 64 per
/// thread). Not rayon: the evaluator builds the tree lazily inside a `OnceLock`, often from a
/// rayon worker, and a worker waiting for a parallel build would steal another query's job,
/// re-enter the `OnceLock` and deadlock; a scoped thread's join blocks without stealing.
fn scoped_map<T: Send>(count: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(8)
        .min(count / 64)
        .max(1);
    if threads == 1 {
        return (0..count).map(f).collect();
    }
    let per = count.div_ceil(threads);
    let f = &f;
    std::thread::scope(|scope| {
        let parts: Vec<_> = (0..threads)
            .map(|t| {
                let range = t * per..((t + 1) * per).min(count);
                scope.spawn(move || range.map(f).collect::<Vec<_>>())
            })
            .collect();
        parts
            .into_iter()
            .flat_map(|h| h.join().expect("tree building does not panic"))
            .collect()
    })
}

/// The spoke terms `−Σ m_v·Area(p, v)` of the expanded nodes at one lattice query, as one angle
/// product like the boundary loop's (no `atan2` per spoke). The ray misses the node's box, so the
/// term has no branch near: the `f64` form of the loop applies whenever the filter signs the
/// numerator, and the exact scalar term (the same perturbed predicate) otherwise.
struct SpokeSum<'a> {
    edges: &'a BoundaryEdges,
    q: InputPoint,
    z_exact: bool,
    qz_units: f64,
    limit: f64,
    angles: AngleSum,
    re: [f64; 4],
    im: [f64; 4],
    len: usize,
    scalar: f64,
}

impl<'a> SpokeSum<'a> {
    fn new(
        edges: &'a BoundaryEdges,
        q: InputPoint,
        z_exact: bool,
        qz_units: f64,
        limit: f64,
    ) -> Self {
        SpokeSum {
            edges,
            q,
            z_exact,
            qz_units,
            limit,
            angles: AngleSum::new(),
            re: [1.0; 4],
            im: [0.0; 4],
            len: 0,
            scalar: 0.0,
        }
    }

    /// Adds `−m·Area(p, v)` (exact points: the magnitudes of the input vertices, like the
    /// loop's, so that a node's spokes and the loop's terms at the same vertex agree).
    #[inline]
    fn subtract<W: Width>(&mut self, p: &InputPoint, v: &InputPoint, m: i32) {
        let offset = |a: &InputPoint| rounded_offset(a, &self.q, self.z_exact, self.qz_units);
        let (a, b) = (offset(p), offset(v));
        let Some(sign) = orient2d_filtered([a[0], a[1]], [b[0], b[1]], self.limit) else {
            self.scalar -= f64::from(m)
                * self.edges.exact_segment_area::<W>(
                    p,
                    v,
                    &self.q,
                    self.z_exact,
                    self.qz_units,
                    false,
                );
            return;
        };
        // The boundary loop's factors: s = |r| + |r_z|, (|r| − r_z)·s = h² or s².
        let factors = |r: [f64; 3]| {
            let h = r[0] * r[0] + r[1] * r[1];
            let s = (h + r[2] * r[2]).sqrt() + r[2].abs();
            (s, if r[2] > 0.0 { h } else { s * s })
        };
        let ((sa, pa), (sb, pb)) = (factors(a), factors(b));
        let d = a[0] * b[1] - a[1] * b[0];
        let s2 = sa * sb;
        let re = pa * pb + (a[0] * b[0] + a[1] * b[1]) * s2;
        // The numerator −d carries the filtered sign; subtracting m terms conjugates them.
        let im = -f64::from(sign) * d.abs() * s2 * -f64::from(m.signum());
        for _ in 0..m.unsigned_abs() {
            self.re[self.len] = re;
            self.im[self.len] = im;
            self.len += 1;
            if self.len == 4 {
                self.flush();
            }
        }
    }

    fn flush(&mut self) {
        self.angles.push(f64x4::from(self.re), f64x4::from(self.im));
        self.angles.rescale();
        self.re = [1.0; 4];
        self.im = [0.0; 4];
        self.len = 0;
    }

    fn finish(mut self) -> (AngleSum, f64) {
        if self.len > 0 {
            self.flush();
        }
        (self.angles, self.scalar)
    }
}

/// `b − a` of exact points in normalized coordinates (the integer difference and the residuals'
/// each rounded once, then their sum).
fn rel(b: &InputPoint, a: &InputPoint, limit: f64) -> [f64; 3] {
    std::array::from_fn(|k| ((b.n[k] - a.n[k]) as f64 + (b.r[k] - a.r[k])) / limit)
}

/// `centre − p` in normalized coordinates for a node's doubled centre `centre2` and an exact
/// point `p` (exact integer difference, then the residual).
fn centre_minus_point(centre2: [i64; 3], p: &InputPoint, limit: f64) -> [f64; 3] {
    std::array::from_fn(|k| ((centre2[k] - 2 * p.n[k]) as f64 * 0.5 - p.r[k]) / limit)
}

/// The distance from which order `k` meets `budget` (the bound decreases with the distance:
/// bisection on `r/a`).
fn reach(area: f64, radius: f64, order: usize, budget: f64) -> f64 {
    if area == 0.0 {
        return radius * (1.0 + REACH_MARGIN);
    }
    let (mut lo, mut hi) = (radius * (1.0 + REACH_MARGIN), radius * 2.0);
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
