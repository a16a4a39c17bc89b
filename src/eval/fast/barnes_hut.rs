//! The Barnes–Hut engine shared by triangle soups and point clouds: per-node moments built
//! bottom-up by re-centring, and the traversal of Barill et al.'s Algorithm 1.

use wide::{CmpGt, CmpLt, f32x4, f64x4};

use super::moments::{FarField, Moments};
use super::tree::Tree;

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
}

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

/// Marks a lane of a [`WideNode`] that refers to a leaf (its number in [`Hierarchy::leaves`]).
const LEAF: u32 = 1 << 31;
/// Marks an unused lane (always at the end of a node).
const EMPTY: u32 = u32::MAX;
/// Upper bound of the query stack: a visit pops one node and pushes at most four, and every
/// level of the 4-wide tree is at least one level of the binary tree (depth ≤ 34).
const WIDE_STACK: usize = 3 * 35 + 4;

/// A node of the query tree: up to four nodes of the binary tree, one per lane, collapsed from
/// one or two levels below a binary node, so one `f64x4` test decides four admissibilities and
/// one `f64x4` expansion evaluates every admissible one. Structure of arrays, as the lanes want
/// it; the far-field coefficients live apart ([`Hierarchy::wide_far`]), since most visited lanes
/// are tested but not expanded.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WideNode {
    /// The lanes' expansion centres `p̃` (NaN in unused lanes: never admissible).
    center: [f64x4; 3],
    /// The lanes' admissibility sizes, indexed by [`Admissibility`] (`as usize`).
    size: [f64x4; 3],
    /// Per lane: a query-tree node, `LEAF | leaf number`, or `EMPTY`.
    child: [u32; 4],
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
    wide_far: Vec<FarField<f32x4>>,
    /// Per query-tree node, the binary node of each lane (`EMPTY` when unused): the gradient
    /// differentiates the `f64` [`Moments`] of exactly the nodes the value expands.
    wide_binary: Vec<[u32; 4]>,
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
    /// elements (`O(n log n)` in all).
    pub fn build(
        tree: Tree,
        area_centroid: impl Fn(usize) -> (f64, [f64; 3]),
        elem_moments: impl Fn(usize, [f64; 3]) -> Moments,
        max_dist2: impl Fn(usize, [f64; 3]) -> f64,
    ) -> Self {
        let n = tree.len();
        let mut moments = vec![Moments::default(); n];
        for id in (0..n).rev() {
            let node = tree.nodes[id];
            let elems = &tree.order[node.range()];
            let box_center = [0, 1, 2].map(|k| 0.5 * (node.min[k] + node.max[k]));
            let mut m = if node.is_leaf() {
                let mut area = 0.0;
                let mut acc = [0.0; 3];
                for &e in elems {
                    let (a, g) = area_centroid(e as usize);
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
                    m.accumulate(&elem_moments(e as usize, center));
                }
                m
            } else {
                let l = node.left as usize;
                let (a, b) = (&moments[l], &moments[l + 1]);
                let area = a.area + b.area;
                let acc = [0, 1, 2].map(|k| a.area * a.center[k] + b.area * b.center[k]);
                let center = centre(area, acc, box_center);
                let mut m = a.recentred(center);
                m.accumulate(&b.recentred(center));
                m
            };
            m.radius = elems
                .iter()
                .map(|&e| max_dist2(e as usize, m.center))
                .fold(0.0, f64::max)
                .sqrt();
            moments[id] = m;
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
        let mut leaves: Vec<usize> = (0..nodes.len()).filter(|&i| nodes[i].is_leaf()).collect();
        leaves.sort_by_key(|&i| nodes[i].start);
        assert!(
            leaves.len() < LEAF as usize,
            "too many leaves for the query tree"
        );
        for (k, &i) in leaves.iter().enumerate() {
            leaf_of[i] = k as u32;
        }
        self.leaves = leaves.iter().map(|&i| nodes[i].range()).collect();
        let far: Vec<FarField> = self.moments.iter().map(FarField::new).collect();
        let empty = FarField::default();
        // (query-tree node, lane) to link to the query-tree node of a binary inner node.
        let mut work: Vec<(usize, usize, usize)> = Vec::new();
        let make = |lanes: &[usize],
                    wide: &mut Vec<WideNode>,
                    wide_far: &mut Vec<_>,
                    wide_binary: &mut Vec<[u32; 4]>,
                    work: &mut Vec<_>| {
            let id = wide.len();
            let get = |f: &dyn Fn(usize) -> f64| {
                f64x4::from(std::array::from_fn::<f64, 4, _>(|l| {
                    lanes.get(l).map_or(f64::NAN, |&b| f(b))
                }))
            };
            let m = &self.moments;
            let corner = |b: usize| {
                let (n, c) = (&nodes[b], m[b].center);
                (0..3)
                    .map(|k| (c[k] - n.min[k]).max(n.max[k] - c[k]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            };
            let diag = |b: usize| {
                let n = &nodes[b];
                (0..3)
                    .map(|k| (n.max[k] - n.min[k]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            };
            let mut size = [f64x4::ZERO; 3];
            size[Admissibility::Radius as usize] = get(&|b| m[b].radius);
            size[Admissibility::BoxDiagonal as usize] = get(&diag);
            size[Admissibility::BoxCorner as usize] = get(&corner);
            let mut child = [EMPTY; 4];
            for (l, &b) in lanes.iter().enumerate() {
                if nodes[b].is_leaf() {
                    child[l] = LEAF | leaf_of[b];
                } else {
                    work.push((id, l, b));
                }
            }
            wide.push(WideNode {
                center: [0, 1, 2].map(|k| get(&|b| m[b].center[k])),
                size,
                child,
            });
            wide_far.push(FarField::lanes(std::array::from_fn(|l| {
                lanes.get(l).map_or(&empty, |&b| &far[b])
            })));
            wide_binary.push(std::array::from_fn(|l| {
                lanes.get(l).map_or(EMPTY, |&b| b as u32)
            }));
        };
        let mut wide = Vec::with_capacity(nodes.len() / 3 + 1);
        let mut wide_far = Vec::with_capacity(nodes.len() / 3 + 1);
        let mut wide_binary = Vec::with_capacity(nodes.len() / 3 + 1);
        make(&[0], &mut wide, &mut wide_far, &mut wide_binary, &mut work);
        while let Some((parent, lane, b)) = work.pop() {
            wide[parent].child[lane] = wide.len() as u32;
            let mut lanes = vec![nodes[b].left as usize, nodes[b].left as usize + 1];
            while lanes.len() < 4 {
                let widest = (0..lanes.len())
                    .filter(|&i| !nodes[lanes[i]].is_leaf())
                    .max_by(|&i, &j| {
                        let r = |i: usize| self.moments[lanes[i]].radius;
                        r(i).total_cmp(&r(j))
                    });
                let Some(i) = widest else { break };
                let l = nodes[lanes[i]].left as usize;
                lanes[i] = l;
                lanes.push(l + 1);
            }
            make(
                &lanes,
                &mut wide,
                &mut wide_far,
                &mut wide_binary,
                &mut work,
            );
        }
        self.wide = wide;
        self.wide_far = wide_far;
        self.wide_binary = wide_binary;
    }

    /// FASTWN(q) (Algorithm 1), iteratively over the 4-wide query tree: the lanes far enough
    /// from `q` contribute their expansions (all four evaluated at once, the others masked out),
    /// a near leaf calls `leaf(number, range, sum)` to add its elements' exact contributions
    /// (`range` indexes the elements in leaf order), a near inner node is pushed. Plain `f64`
    /// accumulation: the method is approximate to far more than the rounding of the sum.
    #[inline]
    pub fn eval(
        &self,
        q: [f64; 3],
        params: &FastParams,
        mut leaf: impl FnMut(usize, std::ops::Range<usize>, &mut f64),
    ) -> f64 {
        if self.wide.is_empty() {
            return 0.0;
        }
        let beta = f64x4::splat(params.beta);
        let order = params.order;
        let which = params.admissibility as usize;
        let qv = q.map(f64x4::splat);
        let zero = f64x4::ZERO;
        let mut far = zero;
        let mut sum = 0.0;
        let mut stack = [0u32; WIDE_STACK];
        let mut top = 0usize;
        let mut id = 0usize;
        loop {
            let node = &self.wide[id];
            let r = [0, 1, 2].map(|k| node.center[k] - qv[k]);
            let d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            let bs = beta * node.size[which];
            // `bs < 0` (β ≤ 0) admits everything not at the centre; NaN admits nothing.
            let admit = d2.cmp_gt(zero) & (bs.cmp_lt(zero) | d2.cmp_gt(bs * bs));
            let mask = admit.move_mask();
            if mask != 0 {
                let r32 = r.map(|v| {
                    let a = v.to_array();
                    f32x4::from([a[0] as f32, a[1] as f32, a[2] as f32, a[3] as f32])
                });
                let w = self.wide_far[id].eval(r32, order).to_array();
                let w = f64x4::from([w[0] as f64, w[1] as f64, w[2] as f64, w[3] as f64]);
                far += admit.blend(w, zero);
            }
            for (l, &c) in node.child.iter().enumerate() {
                if c == EMPTY {
                    break;
                }
                if mask & (1 << l) != 0 {
                    continue;
                }
                if c & LEAF != 0 {
                    let k = (c & !LEAF) as usize;
                    leaf(k, self.leaves[k].clone(), &mut sum);
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
        sum + far.reduce_add()
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
        let beta = f64x4::splat(params.beta);
        let which = params.admissibility as usize;
        let qv = q.map(f64x4::splat);
        let zero = f64x4::ZERO;
        let mut stack = [0u32; WIDE_STACK];
        let mut top = 0usize;
        let mut id = 0usize;
        loop {
            let node = &self.wide[id];
            let r = [0, 1, 2].map(|k| node.center[k] - qv[k]);
            let d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            let bs = beta * node.size[which];
            let mask = (d2.cmp_gt(zero) & (bs.cmp_lt(zero) | d2.cmp_gt(bs * bs))).move_mask();
            for (l, &c) in node.child.iter().enumerate() {
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
