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

#[derive(Clone, Copy, Debug)]
struct Node {
    min: [f32; 3],
    max: [f32; 3],
    /// Leaf: first index into `prims`; inner: index of the first child (second is `+1`).
    first: u32,
    /// Number of primitives (0 for an inner node).
    count: u32,
}

/// BVH over triangles given by normalized `f32` boxes.
#[derive(Clone, Debug, Default)]
pub struct RayBvh {
    nodes: Vec<Node>,
    prims: Vec<u32>,
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
        let nodes = bvh
            .nodes
            .iter()
            .map(|n| Node {
                min: n.aabb.min.to_array(),
                max: n.aabb.max.to_array(),
                first: n.first_index,
                count: n.prim_count,
            })
            .collect();
        RayBvh {
            nodes,
            prims: bvh.primitive_indices,
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
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = [0u32; 64];
        let mut sp = 1;
        stack[0] = 0;
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
            if x < n.min[0] || x > n.max[0] || y < n.min[1] || y > n.max[1] || n.max[2] < z_min {
                continue;
            }
            if n.count > 0 {
                let s = n.first as usize;
                for &p in &self.prims[s..s + n.count as usize] {
                    f(p);
                }
            } else {
                for child in [n.first, n.first + 1] {
                    if sp < stack.len() {
                        stack[sp] = child;
                        sp += 1;
                    } else {
                        overflow.push(child);
                    }
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
