//! The Barnes–Hut engine shared by triangle soups and point clouds: per-node moments built
//! bottom-up by re-centring, and the traversal of Barill et al.'s Algorithm 1.

use rayon::prelude::*;
use wide::{CmpGt, CmpLt, f32x4};

use super::moments::{FarField, Moments};
#[cfg(target_arch = "x86_64")]
use super::packet::{Avx2, Avx8};
use super::packet::{EightLanes, Lanes8, PACKET};
use super::tree::{PARALLEL_GRAIN, Tree};

/// Which node size the admissibility test `‖q − p̃‖ > β · size` uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Admissibility {
    /// Barill et al.: `size = r`, the largest distance from the expansion centre `p̃` to any
    /// point of the node's elements. The expansion converges for `β > 1`.
    #[default]
    Radius,
    /// FOSSIL: `size` = the diagonal of the node's bounding box (always `≥ r`, so for the same β
    /// this is the more conservative test; see the module docs for the mapping).
    BoxDiagonal,
    /// libigl / Houdini (`UT_SolidAngle`): `size` = the distance from `p̃` to the farthest corner
    /// of the node's bounding box (always `≥ r`).
    BoxCorner,
    /// Whichever of Barill's and libigl's tests admits the node first: `size =
    /// min(r, BOX_CORNER_SCALE · ρ)`, `ρ` the [`Admissibility::BoxCorner`] size. At β it admits
    /// what `Radius` admits at β or `BoxCorner` admits at `6β/7`; at β = 2.8 that is the union
    /// of the two settings that each match libigl's accuracy on the corpus (2.8 and 2.4), and
    /// it does too (docs/fast.md, "β: FOSSIL vs Barill"). Why it pays: `ρ ≥ r`, and
    /// `6ρ/7 < r` on the nodes whose elements reach into their box's corners, which are
    /// common in CAD and scans; there the box test admits earlier.
    RadiusOrBoxCorner,
}

impl Admissibility {
    /// Every rule, in declaration order.
    pub const ALL: [Admissibility; 4] = [
        Admissibility::Radius,
        Admissibility::BoxDiagonal,
        Admissibility::BoxCorner,
        Admissibility::RadiusOrBoxCorner,
    ];

    /// The rule's name on the command line and in Python (`--rule`, `rule=`; parsed by
    /// `str::parse`, see [`crate::spec`]): `radius`, `box-diagonal`, `box-corner`,
    /// `radius-or-box-corner`.
    pub fn name(self) -> &'static str {
        match self {
            Admissibility::Radius => "radius",
            Admissibility::BoxDiagonal => "box-diagonal",
            Admissibility::BoxCorner => "box-corner",
            Admissibility::RadiusOrBoxCorner => "radius-or-box-corner",
        }
    }
}

impl std::fmt::Display for Admissibility {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// `RadiusOrBoxCorner`'s scale of the box-corner size: 2.4 / 2.8, the ratio of the two rules'
/// βs that match libigl's max error on the shared corpus (`tests/fast_curve2d/fast_vs_libigl.rs`).
pub const BOX_CORNER_SCALE: f64 = 6.0 / 7.0;

/// Parameters of the fast evaluation: the accuracy parameter `β` and the expansion order.
///
/// Barill et al. use `β = 2`, order 2 for triangles (RMS error about `1e-3`) and `β = 2.3` for
/// points. Larger `β` recurses more (slower, more accurate); higher order costs a few more
/// flops per far node and shrinks the error by about a factor `β` per order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FastParams {
    /// Accuracy parameter: a node is approximated when `‖q − p̃‖ > β · size`. Should be `> 1`
    /// (at `β ≤ 1` the expansion can be used inside its ball of convergence and the error is
    /// unbounded; a non-positive β approximates every node that does not contain `q` exactly at
    /// its centre). NaN or `+∞` evaluate every element exactly.
    pub beta: f64,
    /// Expansion order: 0 (dipole), 1 or 2. Larger values act as 2.
    pub order: u8,
    /// Node size used by the admissibility test.
    pub admissibility: Admissibility,
}

impl Default for FastParams {
    fn default() -> Self {
        FastParams {
            beta: 2.0,
            order: 2,
            admissibility: Admissibility::Radius,
        }
    }
}

impl FastParams {
    /// Barill's form: admissibility `‖q − p̃‖ > β r` with the given order.
    pub fn barill(beta: f64, order: u8) -> Self {
        FastParams {
            beta,
            order,
            admissibility: Admissibility::Radius,
        }
    }

    /// FOSSIL's form: admissibility `‖q − p̃‖ > β · (node box diagonal)` with the first-order
    /// dipole (our order 0), and the far field with the correct sign.
    pub fn fossil(beta: f64) -> Self {
        FastParams {
            beta,
            order: 0,
            admissibility: Admissibility::BoxDiagonal,
        }
    }
}

/// Lanes per node of the query tree. A wider node would replace a far inner node that a query
/// admits whole by its 2–4 children: on the shared meshes 8-wide nodes cost 47 % more
/// expansions per query.
const WIDTH: usize = 4;
/// Marks a lane of a [`WideNode`] that refers to a leaf (its number in [`Hierarchy::leaves`]).
const LEAF: u32 = 1 << 31;
/// Marks an unused lane (always at the end of a node).
const EMPTY: u32 = u32::MAX;
/// Upper bound of the query stack: a visit pops one node and pushes at most `WIDTH`, and every
/// level of the query tree is at least one level of the binary tree (depth ≤ 34).
const WIDE_STACK: usize = WIDTH * 35 + WIDTH;

/// A node of the query tree: up to four nodes of the binary tree, one per lane, collapsed from
/// the levels below one binary node (the node's *anchor*), so that one pass over the lanes
/// decides their admissibilities and evaluates every admissible expansion. Structure of
/// arrays, as the lanes want it; the far-field coefficients live apart
/// ([`Hierarchy::wide_far`]), as do the admissibility sizes.
///
/// Why an anchor: the lanes' centres are stored in `f32` as offsets from the anchor's `f64`
/// centre, and a query forms `r = offset + (anchor − q)` with `anchor − q` rounded once to
/// `f32`. The offsets are at most the anchor's radius `R`, so `r` errs by about
/// `2^-24·(R + ‖r‖)`, and an admitted lane has `‖r‖ > β·r_lane`, `r_lane` a fair fraction of `R`:
/// a relative error near `1e-7`, as for the far field's own `f32` coefficients, wherever the node
/// lies. (Absolute `f32` centres would err by `2^-24` of the whole model, which is the size of a
/// small node.)
#[derive(Clone, Copy, Debug)]
pub(crate) struct WideNode {
    /// The anchor's centre.
    anchor: [f64; 3],
    /// The lanes' expansion centres `p̃` minus the anchor (NaN in unused lanes: never
    /// admissible).
    offset: [f32x4; 3],
    /// Per lane: a query-tree node, `LEAF | leaf number`, or `EMPTY`.
    child: [u32; WIDTH],
}

/// Tree plus per-node moments, and the 4-wide query tree derived from them.
#[derive(Clone, Debug, Default)]
pub(crate) struct Hierarchy {
    pub tree: Tree,
    pub moments: Vec<Moments>,
    /// Element ranges of the leaves of `tree`, in element order (`order[range]`).
    pub leaves: Vec<std::ops::Range<usize>>,
    /// The query tree; node 0 holds the root of `tree` in its first lane.
    wide: Vec<WideNode>,
    /// Per query-tree node, the lanes' admissibility sizes, one vector per [`Admissibility`]
    /// (`as usize`): a query reads only the one it uses.
    wide_size: [Vec<f32x4>; 4],
    wide_far: Vec<FarField<f32x4>>,
    /// Per query-tree node, the binary node of each lane (`EMPTY` when unused): the gradient
    /// differentiates the `f64` [`Moments`] of exactly the nodes the value expands.
    wide_binary: Vec<[u32; WIDTH]>,
}

impl Hierarchy {
    /// Computes the moments of every node of `tree`.
    ///
    /// - `area_centroid(e)`: the area and area centroid of element `e` (a point: its area and
    ///   position);
    /// - `elem_moments(e, c)`: the exact moments of element `e` about `c`;
    /// - `max_dist2(e, c)`: the largest squared distance from `c` to a point of element `e`.
    ///
    /// Leaves sum their elements' moments about the leaf centre; inner nodes sum their
    /// children's moments re-centred to the node centre (exact: the expansions are polynomial
    /// in the position). The radius is exact: the largest distance from the node centre to its
    /// elements, found by branch and bound over the node's subtree ([`farthest2`]).
    pub fn build(
        tree: Tree,
        area_centroid: impl Fn(usize) -> (f64, [f64; 3]) + Sync,
        elem_moments: impl Fn(usize, [f64; 3]) -> Moments + Sync,
        max_dist2: impl Fn(usize, [f64; 3]) -> f64 + Sync,
    ) -> Self {
        let n = tree.len();
        let mut moments = vec![Moments::default(); n];
        if n > 0 {
            let builder = MomentBuilder {
                tree: &tree,
                area_centroid: &area_centroid,
                elem_moments: &elem_moments,
                max_dist2: &max_dist2,
            };
            moments[0] = builder.subtree(0, &mut moments[1..]);
        }
        let mut h = Hierarchy {
            tree,
            moments,
            ..Hierarchy::default()
        };
        h.build_wide();
        h
    }

    /// Numbers the leaves and collapses the binary tree into the 4-wide query tree: a binary
    /// node's lanes start as its two children, and the widest (largest radius) inner lane is
    /// replaced by its own two children until there are four lanes or only leaves.
    fn build_wide(&mut self) {
        let nodes = &self.tree.nodes;
        if nodes.is_empty() {
            return;
        }
        let mut leaf_of = vec![u32::MAX; nodes.len()];
        // The leaves in element order: a depth-first walk, left child first (children split
        // their parent's range in order), in place of a sort by start.
        let mut leaves: Vec<usize> = Vec::with_capacity(nodes.len() / 2 + 1);
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let left = nodes[i].left as usize;
            if nodes[i].is_leaf() {
                leaves.push(i);
            } else {
                stack.extend([left + 1, left]);
            }
        }
        debug_assert!(leaves.is_sorted_by_key(|&i| nodes[i].start));
        assert!(
            leaves.len() < LEAF as usize,
            "too many leaves for the query tree"
        );
        for (k, &i) in leaves.iter().enumerate() {
            leaf_of[i] = k as u32;
        }
        self.leaves = leaves.iter().map(|&i| nodes[i].range()).collect();
        let m = &self.moments;
        // The shape of the query tree first (cheap, one thread: the numbering is the order of a
        // work stack), then the per-node data from it (the costly part, in parallel).
        // A query-tree node: its anchor (the binary node it was collapsed from; `None` for the
        // root, anchored at the root's own centre) and its lanes' binary nodes.
        let capacity = nodes.len() / (WIDTH - 1) + 2;
        let mut shape: Vec<(Option<usize>, Lanes)> = Vec::with_capacity(capacity);
        let mut child: Vec<[u32; WIDTH]> = Vec::with_capacity(capacity);
        // (query-tree node, lane, binary inner node whose query-tree node is linked there).
        let mut work: Vec<(usize, usize, usize)> = Vec::new();
        let mut push = |anchor: Option<usize>, lanes: &[usize], work: &mut Vec<_>| {
            let id = shape.len();
            let mut c = [EMPTY; WIDTH];
            for (l, &b) in lanes.iter().enumerate() {
                if nodes[b].is_leaf() {
                    c[l] = LEAF | leaf_of[b];
                } else {
                    work.push((id, l, b));
                }
            }
            let mut fixed = Lanes {
                binary: [0; WIDTH],
                len: lanes.len(),
            };
            fixed.binary[..lanes.len()].copy_from_slice(lanes);
            shape.push((anchor, fixed));
            child.push(c);
            id
        };
        push(None, &[0], &mut work);
        let mut links: Vec<(usize, usize, u32)> = Vec::new();
        while let Some((parent, lane, b)) = work.pop() {
            let mut lanes = [nodes[b].left as usize, nodes[b].left as usize + 1, 0, 0];
            let mut len = 2;
            while len < WIDTH {
                let widest = (0..len)
                    .filter(|&i| !nodes[lanes[i]].is_leaf())
                    .max_by(|&i, &j| m[lanes[i]].radius.total_cmp(&m[lanes[j]].radius));
                let Some(i) = widest else { break };
                let l = nodes[lanes[i]].left as usize;
                lanes[i] = l;
                lanes[len] = l + 1;
                len += 1;
            }
            let id = push(Some(b), &lanes[..len], &mut work);
            links.push((parent, lane, id as u32));
        }
        for (parent, lane, id) in links {
            child[parent][lane] = id;
        }
        let anchor = |a: Option<usize>| a.map_or(m[0].center, |b| m[b].center);
        // Every admissibility size of binary node `b`, in `Admissibility` order.
        let sizes_of = |b: usize| -> [f64; 4] {
            let (n, c) = (&nodes[b], m[b].center);
            let (mut corner2, mut diag2) = (0.0, 0.0);
            for ((&c, &lo), &hi) in c.iter().zip(&n.min).zip(&n.max) {
                corner2 += (c - lo).max(hi - c).powi(2);
                diag2 += (hi - lo).powi(2);
            }
            let (radius, corner) = (m[b].radius, corner2.sqrt());
            [
                radius,
                diag2.sqrt(),
                corner,
                radius.min(BOX_CORNER_SCALE * corner),
            ]
        };
        debug_assert_eq!(Admissibility::Radius as usize, 0);
        debug_assert_eq!(Admissibility::BoxDiagonal as usize, 1);
        debug_assert_eq!(Admissibility::BoxCorner as usize, 2);
        debug_assert_eq!(Admissibility::RadiusOrBoxCorner as usize, 3);
        // All of a query-tree node's data in one pass: each lane's 280-byte moments and its box
        // are read once (in a pass per size and per record this step took 186 ms at 0.8M
        // triangles, the four size passes 52 of them; in one, ~137: docs/benchmarks.md, "The
        // tree build at 0.8M triangles"). Unused lanes: NaN sizes (never admissible) and
        // offsets, zero far fields.
        let (sizes, (far, wide)): (Vec<_>, (Vec<_>, Vec<_>)) = shape
            .par_iter()
            .zip(&child)
            .map(|((a, lanes), &child)| {
                let lanes = lanes.get();
                let mut sizes = [[f32::NAN; WIDTH]; 4];
                let mut far = [FarField::default(); WIDTH];
                let mut offset = [[f32::NAN; WIDTH]; 3];
                let anchor = anchor(*a);
                for (l, &b) in lanes.iter().enumerate() {
                    for (rule, size) in sizes_of(b).into_iter().enumerate() {
                        sizes[rule][l] = size as f32;
                    }
                    far[l] = FarField::new(&m[b]);
                    for k in 0..3 {
                        offset[k][l] = (m[b].center[k] - anchor[k]) as f32;
                    }
                }
                let refs: [&FarField; WIDTH] = std::array::from_fn(|l| &far[l]);
                (
                    sizes.map(f32x4::from),
                    (
                        FarField::lanes(&refs[..lanes.len()]),
                        WideNode {
                            anchor,
                            offset: offset.map(f32x4::from),
                            child,
                        },
                    ),
                )
            })
            .unzip();
        self.wide_size = std::array::from_fn(|rule| sizes.iter().map(|s| s[rule]).collect());
        self.wide_far = far;
        self.wide = wide;
        self.wide_binary = shape
            .iter()
            .map(|(_, lanes)| {
                std::array::from_fn(|l| lanes.get().get(l).map_or(EMPTY, |&b| b as u32))
            })
            .collect();
    }

    /// `r = p̃ − q` of the four lanes of query-tree node `id`: `offset + (anchor − q)`, with
    /// `anchor − q` rounded once to `f32`.
    #[inline(always)]
    fn lane_offsets(&self, id: usize, q: [f64; 3]) -> [f32x4; 3] {
        let node = &self.wide[id];
        std::array::from_fn(|k| node.offset[k] + f32x4::splat((node.anchor[k] - q[k]) as f32))
    }

    /// Every used lane's admissibility size under `rule`, node by node (for tests).
    #[cfg(test)]
    pub(crate) fn lane_sizes(&self, rule: Admissibility) -> Vec<f32> {
        self.wide
            .iter()
            .zip(&self.wide_size[rule as usize])
            .flat_map(|(node, size)| {
                let size = size.to_array();
                (0..WIDTH)
                    .filter(move |&l| node.child[l] != EMPTY)
                    .map(move |l| size[l])
            })
            .collect()
    }

    /// The lanes of query-tree node `id` whose expansion is admissible (bit `l` for lane `l`):
    /// `‖r‖ > β·size`, in `f32`, with `r` from [`Hierarchy::lane_offsets`]. `β·size < 0`
    /// (β ≤ 0) admits every lane not at `q`; NaN (unused lanes, NaN β) admits none. The value,
    /// the gradient and the packets all decide with these operations, so they expand the same
    /// nodes.
    #[inline(always)]
    fn admit(&self, id: usize, r: &[f32x4; 3], beta: f32, which: usize) -> u32 {
        let d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        let bs = f32x4::splat(beta) * self.wide_size[which][id];
        let zero = f32x4::ZERO;
        let admit = d2.cmp_gt(zero) & (bs.cmp_lt(zero) | d2.cmp_gt(bs * bs));
        admit.move_mask() as u32
    }

    /// FASTWN(q) (Algorithm 1), iteratively over the 4-wide query tree: the lanes far enough
    /// from `q` contribute their expansions (all four evaluated at once, the others masked
    /// out), a near leaf calls `leaf(number, range, sum)` to add its elements' exact
    /// contributions (`range` indexes the elements in leaf order), a near inner node is pushed.
    ///
    /// Runs the AVX2 instantiation of the traversal when the CPU has AVX2 (checked at run time,
    /// as the exact loops do) and the portable one otherwise; both do the same IEEE operations
    /// in the same order, so the value does not depend on the path.
    #[inline]
    pub fn eval(
        &self,
        q: [f64; 3],
        params: &FastParams,
        leaf: impl FnMut(usize, std::ops::Range<usize>, &mut f64),
    ) -> f64 {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: `eval_avx2` only needs the AVX2 instructions it is compiled with, and the
            // CPU was just checked to have them.
            #[allow(unsafe_code)]
            return unsafe { self.eval_avx2(q, params, leaf) };
        }
        self.eval_lanes(q, params, leaf)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn eval_avx2(
        &self,
        q: [f64; 3],
        params: &FastParams,
        leaf: impl FnMut(usize, std::ops::Range<usize>, &mut f64),
    ) -> f64 {
        self.eval_lanes(q, params, leaf)
    }

    /// The traversal of [`Hierarchy::eval`], inlined into each instantiation. The expansions
    /// are added to one `f64` sum in traversal order, a node's lanes in lane order (one sum, so
    /// that a packet keeps its eight in two registers); [`Hierarchy::eval_packet_lanes`] sums in
    /// exactly this order.
    #[inline(always)]
    pub(crate) fn eval_lanes(
        &self,
        q: [f64; 3],
        params: &FastParams,
        mut leaf: impl FnMut(usize, std::ops::Range<usize>, &mut f64),
    ) -> f64 {
        if self.wide.is_empty() {
            return 0.0;
        }
        let (mut far, mut sum) = (0.0f64, 0.0);
        self.walk_one(0, q, params, &mut far, |k| {
            leaf(k, self.leaves[k].clone(), &mut sum);
        });
        sum + far
    }

    /// One query's walk of the subtree of query-tree node `start`: adds the admitted
    /// expansions to `far` in traversal order (a node's lanes in lane order) and calls
    /// `near(leaf number)` for every near leaf, in traversal order. The packets walk one
    /// query's subtrees with it too ([`Hierarchy::eval_packet_lanes`]).
    #[inline(always)]
    fn walk_one(
        &self,
        start: usize,
        q: [f64; 3],
        params: &FastParams,
        far: &mut f64,
        mut near: impl FnMut(usize),
    ) {
        let beta = params.beta as f32;
        let order = params.order;
        let which = params.admissibility as usize;
        let mut stack = [0u32; WIDE_STACK];
        let mut top = 0usize;
        let mut id = start;
        loop {
            let r = self.lane_offsets(id, q);
            let mask = self.admit(id, &r, beta, which);
            if mask != 0 {
                let w = self.wide_far[id].eval(r, order).to_array();
                for (l, w) in w.into_iter().enumerate() {
                    if mask & (1 << l) != 0 {
                        *far += f64::from(w);
                    }
                }
            }
            for (l, &c) in self.wide[id].child.iter().enumerate() {
                if c == EMPTY {
                    break;
                }
                if mask & (1 << l) != 0 {
                    continue;
                }
                if c & LEAF != 0 {
                    near((c & !LEAF) as usize);
                } else {
                    stack[top] = c;
                    top += 1;
                }
            }
            if top == 0 {
                break;
            }
            top -= 1;
            id = stack[top] as usize;
        }
    }

    /// Whether a batch gains from Morton-ordered packets: not with a single query-tree node,
    /// which every query visits and nothing else ([`super::packet::eval_in_packets`]).
    pub fn packets_need_order(&self) -> bool {
        self.wide.len() > 1
    }

    /// [`Hierarchy::eval`] for a packet of neighbouring queries (bit `i` of `active` set for
    /// the queries to evaluate), walking the tree once for all of them: per node and lane, the
    /// admissibility of every query at once, and the lane's expansion evaluated for every query
    /// that admits it in one pass (the queries in the lanes of [`Lanes8`]). `near.add(query,
    /// number, sum)` adds a near leaf's exact terms for one query ([`NearLeaf`]). Each query
    /// gets exactly the value [`Hierarchy::eval`] gives it (module `packet`); inactive queries
    /// get 0.
    #[inline]
    pub fn eval_packet(
        &self,
        q: &[[f64; 3]; PACKET],
        active: u32,
        params: &FastParams,
        near: impl NearLeaf,
    ) -> [f64; PACKET] {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = Avx2::detect() {
            // SAFETY: as in `eval`: compiled for AVX2, and the CPU was just checked to have it.
            #[allow(unsafe_code)]
            return unsafe { self.eval_packet_avx2(avx2, q, active, params, near) };
        }
        self.eval_packet_lanes::<Lanes8>((), q, active, params, near)
    }

    /// The packet walk with the eight lanes in one AVX register ([`Avx8`]): the same IEEE
    /// operations as the portable [`Lanes8`], so the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn eval_packet_avx2(
        &self,
        avx2: Avx2,
        q: &[[f64; 3]; PACKET],
        active: u32,
        params: &FastParams,
        near: impl NearLeaf,
    ) -> [f64; PACKET] {
        self.eval_packet_lanes::<Avx8>(avx2, q, active, params, near)
    }

    /// The traversal of [`Hierarchy::eval_packet`]. Per query it makes the decisions of
    /// [`Hierarchy::eval_lanes`] with the same `f32` operations (`r`, `d²`, `β·size` and the
    /// comparisons of [`Hierarchy::admit`]) and adds the same terms to the same sums in the same
    /// order.
    ///
    /// The near leaves are not summed where the walk meets them but listed (with the queries
    /// that need them) and summed in the order met once the list is full or the walk is done:
    /// each query's near leaves are still added to its own sums in its own walk order (the
    /// far-field sums are apart), so the bits do not change, and the list lets the walk
    /// [`NearLeaf::prefetch`] each leaf's elements a few hundred nodes before they are read. A
    /// near leaf was the walk's costliest step on large meshes, mostly waiting for its
    /// elements (288 bytes per triangle leaf) to come from memory (docs/benchmarks.md).
    #[inline(always)]
    pub(crate) fn eval_packet_lanes<L: EightLanes>(
        &self,
        token: L::Token,
        q: &[[f64; 3]; PACKET],
        active: u32,
        params: &FastParams,
        mut near: impl NearLeaf,
    ) -> [f64; PACKET] {
        let mut sum = [0.0f64; PACKET];
        if self.wide.is_empty() || active == 0 {
            return sum;
        }
        let beta = params.beta as f32;
        let order = params.order;
        let which = params.admissibility as usize;
        let qk: [[f64; PACKET]; 3] = std::array::from_fn(|k| q.map(|p| p[k]));
        let mut far = L::zero_sums(token);
        let mut stack = [(0u32, 0u32); WIDE_STACK];
        stack[0] = (0, active);
        let mut top = 1usize;
        let mut listed = NearList::default();
        while top > 0 {
            top -= 1;
            let (id, mask) = (stack[top].0 as usize, stack[top].1);
            if mask.is_power_of_two() {
                // One query left below this node (a sixth of the visits on the large scans):
                // its own walk tests and evaluates a node's four lanes at once, where the
                // packet would take one eight-query pass per lane for one query. Same
                // operations per lane, same order of the sums, so the same bits.
                let i = mask.trailing_zeros() as usize;
                let mut sums = L::sums_to_array(far);
                self.walk_one(id, q[i], params, &mut sums[i], |k| {
                    listed.push(k, mask, &mut sum, &mut near);
                });
                far = L::sums_from_array(token, sums);
                continue;
            }
            let node = &self.wide[id];
            // Element by element, not `array::from_fn`: a closure the inliner leaves out of
            // line runs without AVX (see `FarField::lane`).
            let dq: [L; 3] = [
                L::difference(token, node.anchor[0], &qk[0]),
                L::difference(token, node.anchor[1], &qk[1]),
                L::difference(token, node.anchor[2], &qk[2]),
            ];
            let size = self.wide_size[which][id].as_array_ref();
            let far_lanes = &self.wide_far[id];
            let inv_s = far_lanes.inv_s().as_array_ref();
            // Two passes over the lanes: the tests and every admitted lane's square root and
            // division first, independent of each other, then the expansions and the sums in
            // lane order (the order of the sums, and so the bits, is that of one pass). In one
            // pass each lane's expansion waited on its own division (docs/benchmarks.md, "Far
            // field by Horner, square roots first").
            let zero = L::splat(token, 0.0);
            let mut admitted = [0u32; 4];
            let mut scaled = [([zero; 3], zero); 4];
            let mut lanes = 0;
            for (l, &c) in node.child.iter().enumerate() {
                if c == EMPTY {
                    break;
                }
                lanes = l + 1;
                let offset = |k: usize| L::splat(token, node.offset[k].as_array_ref()[l]);
                let r: [L; 3] = [offset(0) + dq[0], offset(1) + dq[1], offset(2) + dq[2]];
                let d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
                let bs = beta * size[l];
                admitted[l] = d2.admissible(bs) & mask;
                if admitted[l] != 0 {
                    scaled[l] = FarField::scale(r, L::splat(token, inv_s[l]));
                }
            }
            for l in 0..lanes {
                let c = node.child[l];
                if admitted[l] != 0 {
                    let (s, inv_d) = scaled[l];
                    let w = far_lanes
                        .lane(l, |v| L::splat(token, v))
                        .eval_scaled(s, inv_d, order);
                    far = w.add_where(far, admitted[l]);
                }
                let rest = mask & !admitted[l];
                if rest == 0 {
                    continue;
                }
                if c & LEAF != 0 {
                    listed.push((c & !LEAF) as usize, rest, &mut sum, &mut near);
                } else {
                    stack[top] = (c, rest);
                    top += 1;
                }
            }
        }
        listed.add(&mut sum, &mut near);
        let far = L::sums_to_array(far);
        std::array::from_fn(|i| sum[i] + far[i])
    }
}

impl Hierarchy {
    /// The gradient of [`Hierarchy::eval`]'s approximation: the same traversal and the same
    /// admissibility decisions, with each admissible node's expansion differentiated
    /// ([`Moments::far_field_gradient`], in `f64`) and `leaf(range, gradient)` adding the exact
    /// gradients of a near leaf's elements.
    pub fn gradient(
        &self,
        q: [f64; 3],
        params: &FastParams,
        mut leaf: impl FnMut(std::ops::Range<usize>, &mut [f64; 3]),
    ) -> [f64; 3] {
        let mut g = [0.0; 3];
        if self.wide.is_empty() {
            return g;
        }
        let beta = params.beta as f32;
        let which = params.admissibility as usize;
        let mut stack = [0u32; WIDE_STACK];
        let mut top = 0usize;
        let mut id = 0usize;
        loop {
            let mask = self.admit(id, &self.lane_offsets(id, q), beta, which);
            for (l, &c) in self.wide[id].child.iter().enumerate() {
                if c == EMPTY {
                    break;
                }
                if mask & (1 << l) != 0 {
                    let b = self.wide_binary[id][l] as usize;
                    let e = self.moments[b].far_field_gradient(q, params.order);
                    for k in 0..3 {
                        g[k] += e[k];
                    }
                } else if c & LEAF != 0 {
                    leaf(self.leaves[(c & !LEAF) as usize].clone(), &mut g);
                } else {
                    stack[top] = c;
                    top += 1;
                }
            }
            if top == 0 {
                break;
            }
            top -= 1;
            id = stack[top] as usize;
        }
        g
    }
}

/// The exact terms of the elements of a near leaf, for [`Hierarchy::eval_packet`].
pub(crate) trait NearLeaf {
    /// A hint that leaf `leaf`'s elements will soon be read ([`super::packet::prefetch`]).
    fn prefetch(&self, leaf: usize);
    /// Adds the exact terms of leaf `leaf`'s elements at query `query` of the packet to `sum`.
    fn add(&mut self, query: usize, leaf: usize, sum: &mut f64);
}

/// Near leaves a packet's walk lists before it sums them ([`Hierarchy::eval_packet_lanes`]):
/// `(leaf number, the queries it is near to)` in the order the walk met them. 32 triangle
/// leaves are 9 KiB, well inside the first-level cache with the walk's own data.
#[derive(Default)]
struct NearList {
    listed: [(u32, u32); 32],
    len: usize,
}

impl NearList {
    /// Lists leaf `k` for `queries` and prefetches it; sums the list when it is full.
    #[inline(always)]
    fn push(&mut self, k: usize, queries: u32, sum: &mut [f64; PACKET], near: &mut impl NearLeaf) {
        near.prefetch(k);
        self.listed[self.len] = (k as u32, queries);
        self.len += 1;
        if self.len == self.listed.len() {
            self.add(sum, near);
        }
    }

    /// Sums the listed leaves, in order, for the queries listed with each, and empties the list.
    #[inline(always)]
    fn add(&mut self, sum: &mut [f64; PACKET], near: &mut impl NearLeaf) {
        for &(k, queries) in &self.listed[..self.len] {
            for (i, sum) in sum.iter_mut().enumerate() {
                if queries & (1 << i) != 0 {
                    near.add(i, k as usize, sum);
                }
            }
        }
        self.len = 0;
    }
}

/// The binary nodes of a query-tree node's lanes (the first `len` of `binary`).
#[derive(Clone, Copy, Debug)]
struct Lanes {
    binary: [usize; WIDTH],
    len: usize,
}

impl Lanes {
    fn get(&self) -> &[usize] {
        &self.binary[..self.len]
    }
}

/// The bottom-up moments pass of [`Hierarchy::build`], one subtree at a time.
struct MomentBuilder<'a, A, E, D> {
    tree: &'a Tree,
    area_centroid: &'a A,
    elem_moments: &'a E,
    max_dist2: &'a D,
}

impl<A, E, D> MomentBuilder<'_, A, E, D>
where
    A: Fn(usize) -> (f64, [f64; 3]) + Sync,
    E: Fn(usize, [f64; 3]) -> Moments + Sync,
    D: Fn(usize, [f64; 3]) -> f64 + Sync,
{
    /// The moments of node `id`, after filling `below` with those of its descendants (the ids
    /// `left ..` of [`Tree`]'s numbering: its two children, then the left child's descendants,
    /// then the right child's). Subtrees of at least [`PARALLEL_GRAIN`] elements go to
    /// `rayon::join`. Each node's moments are computed from its children's by the same
    /// operations whichever thread runs it, so the values do not depend on the thread count.
    fn subtree(&self, id: usize, below: &mut [Moments]) -> Moments {
        let node = self.tree.nodes[id];
        let box_center = [0, 1, 2].map(|k| 0.5 * (node.min[k] + node.max[k]));
        let mut m = if node.is_leaf() {
            debug_assert!(below.is_empty());
            let elems = &self.tree.order[node.range()];
            let mut area = 0.0;
            let mut acc = [0.0; 3];
            for &e in elems {
                let (a, g) = (self.area_centroid)(e as usize);
                area += a;
                for k in 0..3 {
                    acc[k] += a * g[k];
                }
            }
            let center = centre(area, acc, box_center);
            let mut m = Moments {
                center,
                ..Moments::default()
            };
            for &e in elems {
                m.accumulate(&(self.elem_moments)(e as usize, center));
            }
            m
        } else {
            let l = node.left as usize;
            let right = self.tree.nodes[l + 1];
            // The left child's descendants end where the right child's begin (its own children),
            // or at the end of `below` when the right child is a leaf.
            let left_span = if right.is_leaf() {
                below.len() - 2
            } else {
                right.left as usize - l - 2
            };
            let (pair, rest) = below.split_at_mut(2);
            let (left_below, right_below) = rest.split_at_mut(left_span);
            let (a, b) = if node.range().len() >= PARALLEL_GRAIN {
                rayon::join(
                    || self.subtree(l, left_below),
                    || self.subtree(l + 1, right_below),
                )
            } else {
                (
                    self.subtree(l, left_below),
                    self.subtree(l + 1, right_below),
                )
            };
            pair[0] = a;
            pair[1] = b;
            let (a, b) = (&pair[0], &pair[1]);
            let area = a.area + b.area;
            let acc = [0, 1, 2].map(|k| a.area * a.center[k] + b.area * b.center[k]);
            let center = centre(area, acc, box_center);
            let mut m = a.recentred(center);
            m.accumulate(&b.recentred(center));
            m
        };
        m.radius = farthest2(self.tree, id, m.center, self.max_dist2).sqrt();
        m
    }
}

/// The largest `max_dist2(e, c)` over the elements `e` below node `id`, exactly: a depth-first
/// search that skips every subtree whose bounding box cannot hold a point farther from `c` than
/// the best found so far. The bound is the farthest box corner's squared distance, computed with
/// the same operations as `dist2` on coordinates at least as far from `c` in every axis, so
/// (rounding being monotone) it is never below the `dist2` of any element point in the box.
/// Visiting all elements cost `O(n)` per node (`O(n log n)` in all, a third of the build); this
/// search visits a few leaves per node.
fn farthest2(
    tree: &Tree,
    id: usize,
    c: [f64; 3],
    max_dist2: &impl Fn(usize, [f64; 3]) -> f64,
) -> f64 {
    let mut best = 0.0_f64;
    let mut stack = [0u32; super::tree::STACK];
    stack[0] = id as u32;
    let mut top = 1;
    while top > 0 {
        top -= 1;
        let node = &tree.nodes[stack[top] as usize];
        let e: [f64; 3] = std::array::from_fn(|k| (c[k] - node.min[k]).max(node.max[k] - c[k]));
        let bound = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        if bound <= best {
            continue;
        }
        if node.is_leaf() {
            for &el in &tree.order[node.range()] {
                best = best.max(max_dist2(el as usize, c));
            }
        } else {
            stack[top] = node.left;
            stack[top + 1] = node.left + 1;
            top += 2;
        }
    }
    best
}

#[inline]
fn centre(area: f64, acc: [f64; 3], fallback: [f64; 3]) -> [f64; 3] {
    if area > 0.0 {
        let c = acc.map(|v| v / area);
        if c.iter().all(|v| v.is_finite()) {
            return c;
        }
    }
    fallback
}
