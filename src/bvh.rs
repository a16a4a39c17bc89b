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

/// Padding of every box in normalized grid coordinates.
const PAD: f32 = 1.0 / (1 << 20) as f32;

/// An inner node holding the boxes of its two children, reduced to what an axis-aligned ray
/// along `+z` needs: the x and y extents and the top in z. Testing both children where the
/// parent is read halves the node loads of a plain BVH2 walk.
#[derive(Clone, Copy, Debug, Default)]
struct Node {
    lo_x: [f32; 2],
    hi_x: [f32; 2],
    lo_y: [f32; 2],
    hi_y: [f32; 2],
    hi_z: [f32; 2],
    /// Child `c`: an inner node index, or `LEAF | first` for a leaf whose primitives are
    /// `prims[first..first + count[c]]`.
    child: [u32; 2],
    count: [u32; 2],
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
        let aabbs: Vec<Aabb> = boxes
            .iter()
            .map(|(lo, hi)| {
                Aabb::new(
                    glam::Vec3A::from_array(lo.map(|v| v - PAD)),
                    glam::Vec3A::from_array(hi.map(|v| v + PAD)),
                )
            })
            .collect();
        let mut t = std::time::Duration::ZERO;
        // Small leaves: a node test is four float comparisons, a triangle test three exact
        // orientations, so the traversal should cull down to (nearly) single triangles.
        let params = BvhBuildParams {
            max_prims_per_leaf: 1,
            collapse_traversal_cost: 1.0,
            ..BvhBuildParams::fast_build()
        };
        let bvh = build_bvh2(&aabbs, params, &mut t);
        let src = &bvh.nodes;
        let root = &src[0];
        if root.prim_count > 0 {
            return RayBvh {
                nodes: Vec::new(),
                prims: bvh.primitive_indices,
                root_leaf: Some((
                    (root.aabb.min.to_array(), root.aabb.max.to_array()),
                    root.prim_count,
                )),
            };
        }
        // Re-index inner nodes only; a leaf child is referenced through LEAF | first.
        let mut index = vec![u32::MAX; src.len()];
        let mut inner = 0u32;
        for (i, n) in src.iter().enumerate() {
            if n.prim_count == 0 {
                index[i] = inner;
                inner += 1;
            }
        }
        let mut nodes = vec![Node::default(); inner as usize];
        for (i, n) in src.iter().enumerate() {
            if n.prim_count > 0 {
                continue;
            }
            let mut node = Node::default();
            for c in 0..2 {
                let k = n.first_index as usize + c;
                let ch = &src[k];
                let (lo, hi) = (ch.aabb.min.to_array(), ch.aabb.max.to_array());
                node.lo_x[c] = lo[0];
                node.hi_x[c] = hi[0];
                node.lo_y[c] = lo[1];
                node.hi_y[c] = hi[1];
                node.hi_z[c] = hi[2];
                if ch.prim_count > 0 {
                    node.child[c] = LEAF | ch.first_index;
                    node.count[c] = ch.prim_count;
                } else {
                    node.child[c] = index[k];
                }
            }
            nodes[index[i] as usize] = node;
        }
        RayBvh {
            nodes,
            prims: bvh.primitive_indices,
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
    /// once.
    #[inline]
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
            for c in 0..2 {
                if x < n.lo_x[c]
                    || x > n.hi_x[c]
                    || y < n.lo_y[c]
                    || y > n.hi_y[c]
                    || n.hi_z[c] < z_min
                {
                    continue;
                }
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

#[cfg(test)]
mod tests {
    use super::*;

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
