//! A BVH over triangles for exact axis-aligned ray queries.
//!
//! The hierarchy is built by `obvhs` (PLOC, no pre-splits: a split triangle would be reported
//! twice and counted twice). Its own ray traversal is not used: it replaces `1/0` by
//! `1/f32::EPSILON`, so an axis-aligned ray whose origin lies within ~1e-7 of a box face can skip
//! the box. With the ray along `+z` of the frame the only test needed is exact and simple: the
//! query's two transverse coordinates lie inside the node's box and the box reaches past the
//! query along the ray. Boxes are stored in `f32` over normalized grid coordinates (`[-1, 1]`) and
//! padded by `2^-20`, far more than the `f32` rounding (`< 2^-24`) of either the boxes or the query,
//! so no triangle that the exact test would count is ever culled. Traversal never stops early.

use obvhs::{BvhBuildParams, aabb::Aabb, bvh2::builder::build_bvh2};
use wide::{CmpGe, CmpLe, f32x4};

/// Padding of every box in normalized grid coordinates.
const PAD: f32 = 1.0 / (1 << 20) as f32;

/// Scale applied to z before the build. The SAH cost of a box is its surface area, the
/// probability that a *random* ray meets it; for rays along `+z` that probability is the box's
/// projected xy area, which is what a box flattened along z measures. A small non-zero scale
/// keeps z as a tie-breaker (it lets the `hi_z` test cull the part of a column below the
/// query). The value was chosen by measurement (docs/benchmarks.md, "Design measurements").
const Z_SCALE: f32 = 0.1;

/// An inner node holding the boxes of up to four children, reduced to what an axis-aligned ray
/// along `+z` needs: the x and y extents and the top in z, one SIMD lane per child. All four
/// children are tested at once, so a query pays one branch per *node* instead of one per box
/// (mispredicted branches dominated the binary walk).
#[derive(Clone, Copy, Debug)]
struct Node {
    lo_x: f32x4,
    hi_x: f32x4,
    lo_y: f32x4,
    hi_y: f32x4,
    hi_z: f32x4,
    /// Child `c`: an inner node index, or `LEAF | first` for a leaf whose primitives are
    /// `prims[first..first + count[c]]`. Unused lanes have empty boxes (`lo = +∞`, `hi = −∞`).
    child: [u32; 4],
    count: [u32; 4],
}

impl Default for Node {
    fn default() -> Self {
        let inf = f32x4::splat(f32::INFINITY);
        Node {
            lo_x: inf,
            hi_x: -inf,
            lo_y: inf,
            hi_y: -inf,
            hi_z: -inf,
            child: [0; 4],
            count: [0; 4],
        }
    }
}

const LEAF: u32 = 1 << 31;

/// An `f32` box `(min, max)`.
type Box3 = ([f32; 3], [f32; 3]);

/// BVH over triangles given by normalized `f32` boxes.
#[derive(Clone, Debug, Default)]
pub struct RayBvh {
    nodes: Vec<Node>,
    prims: Vec<u32>,
    /// When the whole hierarchy is one leaf (tiny meshes): its box and primitive count.
    root_leaf: Option<(Box3, u32)>,
}

impl RayBvh {
    /// Builds the hierarchy over boxes `[min, max]` (normalized coordinates), one per primitive.
    pub fn build(boxes: &[([f32; 3], [f32; 3])]) -> RayBvh {
        if boxes.is_empty() {
            return RayBvh::default();
        }
        // Equal boxes are one primitive for the build, expanded into a leaf of all of them
        // afterwards (`groups`). PLOC pairs equal boxes into a chain: 6,000 boundary edges of a
        // 40-unit hole in a mesh of extent `1e15` (one `f32` box) gave a tree 5,600 deep, whose
        // traversal visits every node and whose debug-build validation in `obvhs` overflowed the
        // stack; stacks of duplicated faces do the same. Equal boxes are hit together anyway.
        let (unique, groups) = equal_box_groups(boxes);
        let padded: Vec<Box3> = unique
            .iter()
            .map(|(lo, hi)| (lo.map(|v| v - PAD), hi.map(|v| v + PAD)))
            .collect();
        let aabbs: Vec<Aabb> = padded
            .iter()
            .map(|(lo, hi)| {
                let flat = |v: &[f32; 3]| glam::Vec3A::new(v[0], v[1], v[2] * Z_SCALE);
                Aabb::new(flat(lo), flat(hi))
            })
            .collect();
        let mut t = std::time::Duration::ZERO;
        // Single-triangle leaves: a node test is cheap, a triangle test three exact
        // orientations, so the traversal should cull down to (nearly) single triangles.
        let params = BvhBuildParams {
            max_prims_per_leaf: 1,
            collapse_traversal_cost: 1.0,
            ..BvhBuildParams::fast_build()
        };
        let mut bvh = build_bvh2(&aabbs, params, &mut t);
        // True (unflattened) padded boxes of every source node, children before parents.
        let boxes = true_boxes(&bvh.nodes, &bvh.primitive_indices, &padded);
        let prims = groups.expand(&mut bvh.nodes, &bvh.primitive_indices);
        let src = &bvh.nodes;
        if src[0].prim_count > 0 {
            return RayBvh {
                nodes: Vec::new(),
                root_leaf: Some((boxes[0], src[0].prim_count)),
                prims,
            };
        }
        // Collapse the binary tree into a 4-wide one: open the inner child with the largest
        // projected area until a node has four children (the child a ray is most likely to
        // enter gains most from being tested together with its siblings).
        let xy_area = |i: usize| {
            let (lo, hi) = boxes[i];
            (hi[0] - lo[0]) * (hi[1] - lo[1])
        };
        let mut nodes: Vec<Node> = vec![Node::default()];
        let mut queue: Vec<(usize, usize)> = vec![(0, 0)];
        while let Some((s, out)) = queue.pop() {
            let first = src[s].first_index as usize;
            let mut kids: Vec<usize> = vec![first, first + 1];
            while kids.len() < 4 {
                let open = kids
                    .iter()
                    .enumerate()
                    .filter(|&(_, &k)| src[k].prim_count == 0)
                    .max_by(|a, b| xy_area(*a.1).total_cmp(&xy_area(*b.1)))
                    .map(|(i, _)| i);
                let Some(i) = open else { break };
                let k = kids.swap_remove(i);
                let f = src[k].first_index as usize;
                kids.extend([f, f + 1]);
            }
            let mut lanes: [[f32; 4]; 5] = [
                [f32::INFINITY; 4],
                [f32::NEG_INFINITY; 4],
                [f32::INFINITY; 4],
                [f32::NEG_INFINITY; 4],
                [f32::NEG_INFINITY; 4],
            ];
            let mut node = Node::default();
            for (c, &k) in kids.iter().enumerate() {
                let (lo, hi) = boxes[k];
                lanes[0][c] = lo[0];
                lanes[1][c] = hi[0];
                lanes[2][c] = lo[1];
                lanes[3][c] = hi[1];
                lanes[4][c] = hi[2];
                if src[k].prim_count > 0 {
                    node.child[c] = LEAF | src[k].first_index;
                    node.count[c] = src[k].prim_count;
                } else {
                    node.child[c] = nodes.len() as u32;
                    queue.push((k, nodes.len()));
                    nodes.push(Node::default());
                }
            }
            node.lo_x = f32x4::from(lanes[0]);
            node.hi_x = f32x4::from(lanes[1]);
            node.lo_y = f32x4::from(lanes[2]);
            node.hi_y = f32x4::from(lanes[3]);
            node.hi_z = f32x4::from(lanes[4]);
            nodes[out] = node;
        }
        RayBvh {
            nodes,
            prims,
            root_leaf: None,
        }
    }

    /// Renumbers the primitives in leaf order: returns the permutation (`new index → old index`)
    /// and makes the BVH report new indices, so callers can store per-primitive data contiguously
    /// in traversal order.
    pub fn renumber_in_leaf_order(&mut self) -> Vec<u32> {
        let order = std::mem::take(&mut self.prims);
        self.prims = (0..order.len() as u32).collect();
        order
    }

    /// Calls `f` for every primitive whose padded box contains `(x, y)` transversally and reaches
    /// `z_min` or above along `+z` (`z_min = −∞` gives the whole column). Each primitive at most
    /// once. Always inlined: it is the crossing loop's body, and as an out-of-line call per ray
    /// (with the visitor a call per candidate) it cost ~10 % of a closed mesh's query.
    #[inline(always)]
    pub fn for_each_on_ray(&self, x: f32, y: f32, z_min: f32, mut f: impl FnMut(u32)) {
        if let Some(((lo, hi), count)) = self.root_leaf {
            if x >= lo[0] && x <= hi[0] && y >= lo[1] && y <= hi[1] && hi[2] >= z_min {
                self.prims[..count as usize].iter().for_each(|&p| f(p));
            }
            return;
        }
        if self.nodes.is_empty() {
            return;
        }
        let (xs, ys, zs) = (f32x4::splat(x), f32x4::splat(y), f32x4::splat(z_min));
        let mut stack = [0u32; 64];
        let mut sp = 1;
        let mut overflow: Vec<u32> = Vec::new();
        loop {
            let idx = if sp > 0 {
                sp -= 1;
                stack[sp]
            } else if let Some(i) = overflow.pop() {
                i
            } else {
                break;
            };
            let n = &self.nodes[idx as usize];
            let hit = xs.cmp_ge(n.lo_x)
                & xs.cmp_le(n.hi_x)
                & ys.cmp_ge(n.lo_y)
                & ys.cmp_le(n.hi_y)
                & n.hi_z.cmp_ge(zs);
            let mut bits = hit.move_mask() as u32;
            while bits != 0 {
                let c = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let ch = n.child[c];
                if ch & LEAF != 0 {
                    let s = (ch & !LEAF) as usize;
                    for &p in &self.prims[s..s + n.count[c] as usize] {
                        f(p);
                    }
                } else if sp < stack.len() {
                    stack[sp] = ch;
                    sp += 1;
                } else {
                    overflow.push(ch);
                }
            }
        }
    }
}

/// The primitives of each distinct box: `members[start[u]..start[u + 1]]` have box `u`.
struct BoxGroups {
    start: Vec<u32>,
    members: Vec<u32>,
}

/// The distinct boxes of `boxes` (by their bits) and the primitives of each.
fn equal_box_groups(boxes: &[Box3]) -> (Vec<Box3>, BoxGroups) {
    let key = |b: &Box3| {
        let (lo, hi) = b;
        [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]].map(f32::to_bits)
    };
    let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
    order.sort_unstable_by_key(|&i| (key(&boxes[i as usize]), i));
    let mut unique = Vec::new();
    let mut start = Vec::new();
    for (k, &i) in order.iter().enumerate() {
        let b = boxes[i as usize];
        if k == 0 || key(&b) != key(&boxes[order[k - 1] as usize]) {
            unique.push(b);
            start.push(k as u32);
        }
    }
    start.push(order.len() as u32);
    (
        unique,
        BoxGroups {
            start,
            members: order,
        },
    )
}

impl BoxGroups {
    /// Rewrites the leaves of a hierarchy built over the distinct boxes (`prims`: its primitive
    /// order, distinct-box indices) to ranges of the original primitives; returns their order.
    fn expand(&self, nodes: &mut [obvhs::bvh2::node::Bvh2Node], prims: &[u32]) -> Vec<u32> {
        let size = |u: u32| self.start[u as usize + 1] - self.start[u as usize];
        // `offset[k]`: where distinct box `prims[k]`'s members begin in the expanded order.
        let mut offset = Vec::with_capacity(prims.len() + 1);
        let mut expanded = Vec::with_capacity(self.members.len());
        for &u in prims {
            offset.push(expanded.len() as u32);
            let (s, e) = (self.start[u as usize], self.start[u as usize + 1]);
            expanded.extend_from_slice(&self.members[s as usize..e as usize]);
        }
        offset.push(expanded.len() as u32);
        for n in nodes.iter_mut().filter(|n| n.prim_count > 0) {
            let (first, count) = (n.first_index as usize, n.prim_count as usize);
            debug_assert_eq!(
                offset[first + count] - offset[first],
                prims[first..first + count]
                    .iter()
                    .map(|&u| size(u))
                    .sum::<u32>()
            );
            n.first_index = offset[first];
            n.prim_count = offset[first + count] - offset[first];
        }
        expanded
    }
}

/// The padded boxes of every node of an `obvhs` hierarchy, recomputed from its primitives (the
/// hierarchy was built on boxes flattened along z).
fn true_boxes(src: &[obvhs::bvh2::node::Bvh2Node], prims: &[u32], padded: &[Box3]) -> Vec<Box3> {
    let empty = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    let union = |a: Box3, b: Box3| -> Box3 {
        (
            std::array::from_fn(|k| a.0[k].min(b.0[k])),
            std::array::from_fn(|k| a.1[k].max(b.1[k])),
        )
    };
    let mut out = vec![empty; src.len()];
    // Post-order without recursion: a node is finished when popped the second time.
    let mut stack = vec![(0usize, false)];
    while let Some((i, done)) = stack.pop() {
        let n = &src[i];
        if n.prim_count > 0 {
            let s = n.first_index as usize;
            out[i] = prims[s..s + n.prim_count as usize]
                .iter()
                .fold(empty, |acc, &p| union(acc, padded[p as usize]));
        } else if done {
            let c = n.first_index as usize;
            out[i] = union(out[c], out[c + 1]);
        } else {
            let c = n.first_index as usize;
            stack.extend([(i, true), (c, false), (c + 1, false)]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Depth of the 4-wide hierarchy (1 for a root leaf).
    fn depth(bvh: &RayBvh) -> usize {
        if bvh.nodes.is_empty() {
            return 1;
        }
        let mut deepest = 0;
        let mut stack = vec![(0u32, 1usize)];
        while let Some((i, d)) = stack.pop() {
            deepest = deepest.max(d);
            let n = &bvh.nodes[i as usize];
            for c in 0..4 {
                if n.child[c] & LEAF == 0 && n.count[c] == 0 && n.child[c] != 0 {
                    stack.push((n.child[c], d + 1));
                }
            }
        }
        deepest
    }

    /// Thousands of equal boxes (a small cluster in a huge box rounds to one `f32` box; stacks
    /// of duplicated faces) beside distinct ones: a shallow tree that still reports every box on
    /// the ray exactly once. Before, the build chained them (depth ~n; the debug build of
    /// `obvhs` then overflowed the stack validating it).
    #[test]
    fn equal_boxes_make_one_leaf_not_a_chain() {
        let mut boxes = vec![([0.25f32, 0.25, 0.25], [0.25f32, 0.25, 0.25]); 20_000];
        for i in 0..300 {
            let x = i as f32 / 300.0 - 0.5;
            boxes.push(([x, -0.5, 0.0], [x + 0.01, 0.5, 0.1]));
            boxes.push(([0.25 + x, 0.25, 0.25], [0.26 + x, 0.26, 0.26]));
        }
        let bvh = RayBvh::build(&boxes);
        assert!(depth(&bvh) <= 24, "depth {}", depth(&bvh));
        for (x, y, z) in [
            (0.25, 0.25, -1.0),
            (0.25, 0.25, 0.25),
            (0.0, 0.0, 0.0),
            (0.9, 0.9, 0.0),
        ] {
            let mut got = Vec::new();
            bvh.for_each_on_ray(x, y, z, |p| got.push(p));
            got.sort_unstable();
            let want: Vec<u32> = (0..boxes.len() as u32)
                .filter(|&i| {
                    let (lo, hi) = boxes[i as usize];
                    x >= lo[0] && x <= hi[0] && y >= lo[1] && y <= hi[1] && hi[2] >= z
                })
                .collect();
            // The padding may add boxes within 2^-20; none may be missed or repeated.
            let n = got.len();
            got.dedup();
            assert_eq!(n, got.len(), "duplicates at ({x}, {y}, {z})");
            assert!(
                want.iter().all(|w| got.binary_search(w).is_ok()),
                "missed at ({x}, {y}, {z})"
            );
        }
    }

    #[test]
    fn reports_every_box_on_the_ray_once() {
        // A 20×20 grid of unit boxes at various heights; ray through a shared corner.
        let mut boxes = Vec::new();
        for i in 0..20 {
            for j in 0..20 {
                let (x, y) = (i as f32 * 0.05 - 0.5, j as f32 * 0.05 - 0.5);
                let z = ((i * 7 + j * 3) % 11) as f32 * 0.05 - 0.25;
                boxes.push(([x, y, z], [x + 0.05, y + 0.05, z + 0.01]));
            }
        }
        let bvh = RayBvh::build(&boxes);
        for (x, y, z) in [
            (0.0, 0.0, -1.0),
            (0.1, 0.25, 0.0),
            (-0.5, -0.5, -1.0),
            (0.123, -0.377, 0.1),
        ] {
            let mut got = Vec::new();
            bvh.for_each_on_ray(x, y, z, |p| got.push(p));
            got.sort();
            let n = got.len();
            got.dedup();
            assert_eq!(n, got.len(), "duplicates");
            let want: Vec<u32> = (0..boxes.len() as u32)
                .filter(|&i| {
                    let (lo, hi) = boxes[i as usize];
                    x >= lo[0] && x <= hi[0] && y >= lo[1] && y <= hi[1] && hi[2] >= z
                })
                .collect();
            for w in &want {
                assert!(got.contains(w), "missed {w}");
            }
        }
    }
}
