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
#[derive(Clone, Debug, Default)]
pub(crate) struct Tree {
    pub nodes: Vec<Node>,
    pub order: Vec<u32>,
}

impl Tree {
    /// Builds the tree over `n` elements with the given centroids and boxes; a node with more
    /// than `leaf_size` elements is split.
    pub fn build(centroids: &[[f64; 3]], boxes: &[([f64; 3], [f64; 3])], leaf_size: usize) -> Self {
        let n = centroids.len();
        debug_assert_eq!(n, boxes.len());
        assert!(n <= u32::MAX as usize, "too many elements for the tree");
        if n == 0 {
            return Tree::default();
        }
        let leaf_size = leaf_size.max(1);
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n.div_ceil(leaf_size));
        nodes.push(Node {
            start: 0,
            end: n as u32,
            left: 0,
            min: [0.0; 3],
            max: [0.0; 3],
        });
        let mut work = vec![0usize];
        while let Some(id) = work.pop() {
            let (start, end) = (nodes[id].start as usize, nodes[id].end as usize);
            let slice = &mut order[start..end];
            let count = end - start;
            if count <= leaf_size {
                continue;
            }
            // The centroids' box picks the split; the element boxes are merged bottom-up below.
            let (mut clo, mut chi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for &e in slice.iter() {
                let c = centroids[e as usize];
                for k in 0..3 {
                    clo[k] = clo[k].min(c[k]);
                    chi[k] = chi[k].max(c[k]);
                }
            }
            let ext = [0, 1, 2].map(|k| chi[k] - clo[k]);
            let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
                0
            } else if ext[1] >= ext[2] {
                1
            } else {
                2
            };
            let half = count / 2;
            slice.select_nth_unstable_by(half, |&a, &b| {
                centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
            });
            let left = nodes.len();
            nodes[id].left = left as u32;
            let mid = (start + half) as u32;
            nodes.push(Node {
                start: start as u32,
                end: mid,
                left: 0,
                min: [0.0; 3],
                max: [0.0; 3],
            });
            nodes.push(Node {
                start: mid,
                end: end as u32,
                left: 0,
                min: [0.0; 3],
                max: [0.0; 3],
            });
            work.push(left + 1);
            work.push(left);
        }
        // Children have larger ids than their parent: boxes bottom-up, each element box read once.
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

#[cfg(test)]
mod tests {
    use super::*;

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
