//! A binary median-split AABB tree over generic elements (triangles or points), shared by the
//! triangle-soup and the point-cloud evaluators and by the k-nearest-neighbour search of the area
//! estimation.
//!
//! Why our own tree rather than `obvhs`: the Barnes–Hut traversal needs, per node, a contiguous
//! range of elements (to compute the exact radius and the moments bottom-up) and `f64` geometry;
//! `obvhs` builds ray-tracing BVHs in `f32` with SAH splits and its own node layouts, which would
//! have to be re-walked and re-boxed in `f64` anyway. A median split on the longest axis of the
//! centroid box is `O(n log n)` to build, gives a depth of `⌈log₂(n / leaf)⌉ + 1` (bounded, so the
//! traversal stack is a fixed array) and balanced subtrees, which is what the far-field test
//! wants: compact clusters, not ray-friendly ones.

/// Upper bound of the traversal stack: a median split halves the element count at each level,
/// so the depth is at most 33 for `u32` element counts; the stack of a depth-first traversal
/// that pushes both children holds at most `depth + 1` entries.
pub(crate) const STACK: usize = 72;

/// One node: its elements are `order[start..end]`; children are `left` and `left + 1`
/// (`left == 0` marks a leaf, as the root is never a child).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Node {
    pub start: u32,
    pub end: u32,
    pub left: u32,
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Node {
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.left == 0
    }

    #[inline]
    pub fn range(&self) -> std::ops::Range<usize> {
        self.start as usize..self.end as usize
    }
}

/// The tree: nodes (root at 0) and the permutation of element ids in leaf order.
///
/// Numbering: an inner node's children get the next two free ids when the node is split, and
/// the nodes are split in depth-first pre-order, left child first. So the descendants of a node
/// are the contiguous ids `left .. left + 2·(inner nodes of its subtree)`: its two children, then
/// the left child's descendants, then the right child's. The numbering depends only on the
/// element counts, which is what lets [`Tree::build`] build subtrees on several threads and
/// still number them as one thread would, and lets `Hierarchy::build` hand each subtree its own
/// slice of the per-node arrays.
#[derive(Clone, Debug, Default)]
pub(crate) struct Tree {
    pub nodes: Vec<Node>,
    pub order: Vec<u32>,
}

/// A subtree over fewer elements than this is built on the current thread: below it the
/// `rayon::join` bookkeeping is not worth a task (a 4096-element subtree takes ~1 ms).
pub(crate) const PARALLEL_GRAIN: usize = 4096;

/// Number of inner nodes of the subtree over `count ≥ 1` elements, split at `count / 2` until at
/// most `leaf_size` remain. Each level of the split holds at most two adjacent counts (`⌊m/2⌋`
/// and `⌊m/2⌋ + 1`), so this recurses on the pair `(m, m + 1)`: `O(log count)`.
pub(crate) fn inner_nodes(count: usize, leaf_size: usize) -> usize {
    /// `(inner(m), inner(m + 1))`.
    fn pair(m: usize, leaf_size: usize) -> (usize, usize) {
        if m < leaf_size {
            return (0, 0);
        }
        let (a, b) = pair(m / 2, leaf_size); // inner(h), inner(h + 1), h = ⌊m/2⌋
        // m = 2h splits into (h, h) and m + 1 into (h, h + 1); m = 2h + 1 into (h, h + 1) and
        // m + 1 into (h + 1, h + 1).
        let (split_m, split_next) = if m.is_multiple_of(2) {
            (1 + 2 * a, 1 + a + b)
        } else {
            (1 + a + b, 1 + 2 * b)
        };
        (if m <= leaf_size { 0 } else { split_m }, split_next)
    }
    pair(count, leaf_size.max(1)).0
}

/// What a subtree build reads: the elements' boxes and the leaf size.
struct Split<'a> {
    boxes: &'a [([f64; 3], [f64; 3])],
    leaf_size: usize,
}

/// An element as the splits move it: its centroid travels with its id, so that the median
/// selections read memory in order. With ids alone each comparison read the centroid array at
/// random, a cache miss on large inputs: the tree was a third of a 0.8M-triangle build
/// (docs/benchmarks.md, "The tree build at 0.8M triangles"). The comparisons, and so the
/// permutation, are the same.
#[derive(Clone, Copy)]
struct Element {
    centroid: [f64; 3],
    id: u32,
}

impl Split<'_> {
    /// Builds the subtree of the node whose elements are `order` (at `start` in the whole
    /// order): splits it, fills `below` (its descendants, ids from `first` on, in the numbering
    /// of [`Tree`]) and returns its bounding box (the union of its elements' boxes).
    ///
    /// The split is the one of the single-threaded build: the centroids' box picks the longest
    /// axis, `select_nth_unstable_by` puts the median at `count / 2` (deterministic: the same
    /// slice gives the same permutation, whichever thread runs it). Boxes are merged bottom-up,
    /// left child first. So the tree is the same bit for bit at any thread count.
    fn subtree(
        &self,
        order: &mut [Element],
        start: usize,
        below: &mut [Node],
        first: usize,
    ) -> ([f64; 3], [f64; 3]) {
        let count = order.len();
        if count <= self.leaf_size {
            debug_assert!(below.is_empty());
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for e in order.iter() {
                let (bmin, bmax) = self.boxes[e.id as usize];
                for k in 0..3 {
                    lo[k] = lo[k].min(bmin[k]);
                    hi[k] = hi[k].max(bmax[k]);
                }
            }
            return (lo, hi);
        }
        // The centroids' box picks the split; the element boxes are merged bottom-up below.
        let axis = split_axis(order);
        let half = count / 2;
        order.select_nth_unstable_by(half, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
        let (left_order, right_order) = order.split_at_mut(half);
        let left_inner = inner_nodes(half, self.leaf_size);
        let right_inner = inner_nodes(count - half, self.leaf_size);
        let (pair, rest) = below.split_at_mut(2);
        let (left_below, right_below) = rest.split_at_mut(2 * left_inner);
        debug_assert_eq!(right_below.len(), 2 * right_inner);
        let (left_first, right_first) = (first + 2, first + 2 + 2 * left_inner);
        let right_start = start + half;
        let ((llo, lhi), (rlo, rhi)) = if count >= PARALLEL_GRAIN {
            rayon::join(
                || self.subtree(left_order, start, left_below, left_first),
                || self.subtree(right_order, right_start, right_below, right_first),
            )
        } else {
            (
                self.subtree(left_order, start, left_below, left_first),
                self.subtree(right_order, right_start, right_below, right_first),
            )
        };
        let child = |s: usize, e: usize, inner: usize, child_first: usize, lo, hi| Node {
            start: s as u32,
            end: e as u32,
            left: if inner > 0 { child_first as u32 } else { 0 },
            min: lo,
            max: hi,
        };
        pair[0] = child(start, start + half, left_inner, left_first, llo, lhi);
        pair[1] = child(
            start + half,
            start + count,
            right_inner,
            right_first,
            rlo,
            rhi,
        );
        (
            std::array::from_fn(|k| llo[k].min(rlo[k])),
            std::array::from_fn(|k| lhi[k].max(rhi[k])),
        )
    }
}

impl Tree {
    /// Builds the tree over `n` elements with the given centroids and boxes; a node with more
    /// than `leaf_size` elements is split. Subtrees of at least [`PARALLEL_GRAIN`] elements are
    /// built in parallel on the current rayon pool; the tree (numbering, order, boxes) does not
    /// depend on the number of threads.
    pub fn build(centroids: &[[f64; 3]], boxes: &[([f64; 3], [f64; 3])], leaf_size: usize) -> Self {
        let n = centroids.len();
        debug_assert_eq!(n, boxes.len());
        assert!(n <= u32::MAX as usize, "too many elements for the tree");
        if n == 0 {
            return Tree::default();
        }
        let leaf_size = leaf_size.max(1);
        let mut order: Vec<Element> = centroids
            .iter()
            .enumerate()
            .map(|(id, &centroid)| Element {
                centroid,
                id: id as u32,
            })
            .collect();
        let inner = inner_nodes(n, leaf_size);
        let empty = Node {
            start: 0,
            end: 0,
            left: 0,
            min: [0.0; 3],
            max: [0.0; 3],
        };
        let mut nodes = vec![empty; 1 + 2 * inner];
        let split = Split { boxes, leaf_size };
        let (min, max) = split.subtree(&mut order, 0, &mut nodes[1..], 1);
        nodes[0] = Node {
            start: 0,
            end: n as u32,
            left: if inner > 0 { 1 } else { 0 },
            min,
            max,
        };
        let order = order.into_iter().map(|e| e.id).collect();
        Tree { nodes, order }
    }

    /// Number of nodes. Every child has a larger id than its parent, so a pass over the ids in
    /// reverse visits children before parents.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }
}

/// Squared distance from `q` to the box `[min, max]` (0 inside).
#[inline]
pub(crate) fn box_dist2(q: [f64; 3], min: [f64; 3], max: [f64; 3]) -> f64 {
    let mut d2 = 0.0;
    for k in 0..3 {
        let d = (min[k] - q[k]).max(q[k] - max[k]).max(0.0);
        d2 += d * d;
    }
    d2
}

/// The longest axis of the box of the centroids of `elems` (ties: the lower axis).
fn split_axis(elems: &[Element]) -> usize {
    let (mut clo, mut chi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for e in elems {
        for k in 0..3 {
            clo[k] = clo[k].min(e.centroid[k]);
            chi[k] = chi[k].max(e.centroid[k]);
        }
    }
    let ext = [0, 1, 2].map(|k| chi[k] - clo[k]);
    if ext[0] >= ext[1] && ext[0] >= ext[2] {
        0
    } else if ext[1] >= ext[2] {
        1
    } else {
        2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The single-threaded build this module had before subtrees were built in parallel (a
    /// work stack, children numbered when their parent is split, boxes bottom-up): the
    /// reference the parallel build must reproduce bit for bit.
    fn serial_build(
        centroids: &[[f64; 3]],
        boxes: &[([f64; 3], [f64; 3])],
        leaf_size: usize,
    ) -> Tree {
        let n = centroids.len();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let node = |start: usize, end: usize| Node {
            start: start as u32,
            end: end as u32,
            left: 0,
            min: [0.0; 3],
            max: [0.0; 3],
        };
        let mut nodes = vec![node(0, n)];
        let mut work = vec![0usize];
        while let Some(id) = work.pop() {
            let (start, end) = (nodes[id].start as usize, nodes[id].end as usize);
            let slice = &mut order[start..end];
            let count = end - start;
            if count <= leaf_size {
                continue;
            }
            // The longest axis of the centroids' box, ties to the lower axis (as the build).
            let elems: Vec<Element> = slice
                .iter()
                .map(|&e| Element {
                    centroid: centroids[e as usize],
                    id: e,
                })
                .collect();
            let axis = split_axis(&elems);
            let half = count / 2;
            slice.select_nth_unstable_by(half, |&a, &b| {
                centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
            });
            let left = nodes.len();
            nodes[id].left = left as u32;
            nodes.push(node(start, start + half));
            nodes.push(node(start + half, end));
            work.push(left + 1);
            work.push(left);
        }
        for id in (0..nodes.len()).rev() {
            let node = nodes[id];
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            if node.is_leaf() {
                for &e in &order[node.range()] {
                    let (bmin, bmax) = boxes[e as usize];
                    for k in 0..3 {
                        lo[k] = lo[k].min(bmin[k]);
                        hi[k] = hi[k].max(bmax[k]);
                    }
                }
            } else {
                let (a, b) = (nodes[node.left as usize], nodes[node.left as usize + 1]);
                lo = std::array::from_fn(|k| a.min[k].min(b.min[k]));
                hi = std::array::from_fn(|k| a.max[k].max(b.max[k]));
            }
            nodes[id].min = lo;
            nodes[id].max = hi;
        }
        Tree { nodes, order }
    }

    fn assert_same_tree(a: &Tree, b: &Tree, what: &str) {
        assert_eq!(a.order, b.order, "{what}: element order");
        assert_eq!(a.nodes.len(), b.nodes.len(), "{what}: node count");
        for (id, (x, y)) in a.nodes.iter().zip(&b.nodes).enumerate() {
            let bits = |v: [f64; 3]| v.map(f64::to_bits);
            assert_eq!(
                (x.start, x.end, x.left, bits(x.min), bits(x.max)),
                (y.start, y.end, y.left, bits(y.min), bits(y.max)),
                "{what}: node {id}"
            );
        }
    }

    #[test]
    fn inner_node_count_matches_the_recursive_split() {
        fn by_recursion(count: usize, leaf_size: usize) -> usize {
            if count <= leaf_size {
                0
            } else {
                1 + by_recursion(count / 2, leaf_size) + by_recursion(count - count / 2, leaf_size)
            }
        }
        for leaf_size in 1..=9 {
            for count in 1..=1200 {
                assert_eq!(
                    inner_nodes(count, leaf_size),
                    by_recursion(count, leaf_size),
                    "count {count}, leaf size {leaf_size}"
                );
            }
        }
    }

    #[test]
    fn parallel_build_is_the_serial_tree_at_any_thread_count() {
        // More elements than PARALLEL_GRAIN (so subtrees go to rayon::join), duplicated
        // centroids (ties in the median selection) and boxes larger than the centroids.
        let n = 3 * PARALLEL_GRAIN + 17;
        let pts: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let t = f64::from((i % (n / 3)) as u32);
                [(t * 0.37).sin(), (t * 0.11).cos(), (t * 0.07).sin() * 2.0]
            })
            .collect();
        let boxes: Vec<_> = pts
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                let r = 1e-3 * f64::from((i % 7) as u32);
                (p.map(|v| v - r), p.map(|v| v + r))
            })
            .collect();
        for leaf_size in [1, 4, 8] {
            let reference = serial_build(&pts, &boxes, leaf_size);
            for threads in [1, 2, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .expect("thread pool");
                let tree = pool.install(|| Tree::build(&pts, &boxes, leaf_size));
                assert_same_tree(
                    &tree,
                    &reference,
                    &format!("leaf size {leaf_size}, {threads} threads"),
                );
            }
        }
        for n in [1, 2, 3, 5, 9, 100] {
            let reference = serial_build(&pts[..n], &boxes[..n], 4);
            let tree = Tree::build(&pts[..n], &boxes[..n], 4);
            assert_same_tree(&tree, &reference, &format!("{n} elements"));
        }
    }

    #[test]
    fn ranges_partition_and_depth_is_logarithmic() {
        let pts: Vec<[f64; 3]> = (0..1000)
            .map(|i| {
                let t = f64::from(i);
                [(t * 0.37).sin(), (t * 0.11).cos(), (t * 0.07).sin() * 2.0]
            })
            .collect();
        let boxes: Vec<_> = pts.iter().map(|&p| (p, p)).collect();
        let tree = Tree::build(&pts, &boxes, 4);
        let mut seen = vec![false; pts.len()];
        let mut max_depth = 0;
        let mut stack = vec![(0usize, 1usize)];
        while let Some((id, depth)) = stack.pop() {
            max_depth = max_depth.max(depth);
            let node = tree.nodes[id];
            for &e in &tree.order[node.range()] {
                let p = pts[e as usize];
                assert!((0..3).all(|k| node.min[k] <= p[k] && p[k] <= node.max[k]));
            }
            if node.is_leaf() {
                assert!(node.range().len() <= 4);
                for &e in &tree.order[node.range()] {
                    assert!(!seen[e as usize]);
                    seen[e as usize] = true;
                }
            } else {
                let (l, r) = (
                    tree.nodes[node.left as usize],
                    tree.nodes[node.left as usize + 1],
                );
                assert_eq!((l.start, l.end, r.end), (node.start, r.start, node.end));
                stack.push((node.left as usize, depth + 1));
                stack.push((node.left as usize + 1, depth + 1));
            }
        }
        assert!(seen.iter().all(|&s| s));
        assert!(max_depth <= 9, "depth {max_depth}");
    }
}
