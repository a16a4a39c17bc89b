//! The Barnes–Hut engine shared by triangle soups and point clouds: per-node moments built
//! bottom-up by re-centring, and the traversal of Barill et al.'s Algorithm 1.

use super::moments::{FarField, Moments};
use super::tree::{STACK, Tree};

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

/// The per-node data the traversal reads, packed together (one cache line): the expansion
/// centre, both admissibility sizes and the children / element range.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct HotNode {
    pub center: [f64; 3],
    pub radius: f64,
    pub diag: f64,
    /// First child (`0` for a leaf; children are `left` and `left + 1`).
    pub left: u32,
    pub start: u32,
    pub end: u32,
}

/// Tree plus per-node moments and box diagonals, and the compact query-time records derived
/// from them (`hot` for the traversal, `far` for the far-field evaluation).
#[derive(Clone, Debug, Default)]
pub(crate) struct Hierarchy {
    pub tree: Tree,
    pub moments: Vec<Moments>,
    pub hot: Vec<HotNode>,
    pub far: Vec<FarField>,
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
        let mut diag = vec![0.0; n];
        for id in (0..n).rev() {
            let node = tree.nodes[id];
            let elems = &tree.order[node.range()];
            let box_center = [0, 1, 2].map(|k| 0.5 * (node.min[k] + node.max[k]));
            diag[id] = [0, 1, 2]
                .map(|k| node.max[k] - node.min[k])
                .iter()
                .map(|d| d * d)
                .sum::<f64>()
                .sqrt();
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
        let hot = tree
            .nodes
            .iter()
            .zip(&moments)
            .zip(&diag)
            .map(|((node, m), &diag)| HotNode {
                center: m.center,
                radius: m.radius,
                diag,
                left: node.left,
                start: node.start,
                end: node.end,
            })
            .collect();
        let far = moments.iter().map(FarField::new).collect();
        Hierarchy {
            tree,
            moments,
            hot,
            far,
        }
    }

    /// FASTWN(q) (Algorithm 1), iteratively: a node far enough from `q` contributes its
    /// expansion, a near leaf calls `leaf(range, sum)` to add its elements' exact contributions
    /// (`range` indexes the elements in leaf order), a near inner node is opened. Both children
    /// of an opened node are tested before anything is pushed, so only near inner nodes go on
    /// the stack. Plain `f64` accumulation: the method is approximate to far more than the
    /// rounding of the sum.
    #[inline]
    pub fn eval(
        &self,
        q: [f64; 3],
        params: &FastParams,
        mut leaf: impl FnMut(std::ops::Range<usize>, &mut f64),
    ) -> f64 {
        if self.hot.is_empty() {
            return 0.0;
        }
        let beta = params.beta;
        let order = params.order;
        let use_diag = params.admissibility == Admissibility::BoxDiagonal;
        let hot = &self.hot[..];
        let far = &self.far[..];
        // `Some(r)` when node `id` is admissible (`r = p̃ − q`).
        let admissible = |n: &HotNode| -> Option<[f64; 3]> {
            let size = if use_diag { n.diag } else { n.radius };
            let r = [n.center[0] - q[0], n.center[1] - q[1], n.center[2] - q[2]];
            let d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            let bs = beta * size;
            // `bs < 0` (β ≤ 0) admits everything not at the centre; NaN admits nothing.
            (d2 > 0.0 && (bs < 0.0 || d2 > bs * bs)).then_some(r)
        };
        let mut sum = 0.0;
        let mut stack = [0u32; STACK];
        let mut top = 0usize;
        // The root is the only node tested after popping; every other node is tested by its
        // parent.
        let root = &hot[0];
        if let Some(r) = admissible(root) {
            return far[0].eval(r, order);
        }
        if root.left == 0 {
            leaf(root.start as usize..root.end as usize, &mut sum);
            return sum;
        }
        let mut id = 0usize;
        loop {
            let l = hot[id].left as usize;
            let mut next = usize::MAX;
            for c in [l, l + 1] {
                let n = &hot[c];
                if let Some(r) = admissible(n) {
                    sum += far[c].eval(r, order);
                } else if n.left == 0 {
                    leaf(n.start as usize..n.end as usize, &mut sum);
                } else if next == usize::MAX {
                    next = c;
                } else {
                    stack[top] = c as u32;
                    top += 1;
                }
            }
            if next != usize::MAX {
                id = next;
            } else if top > 0 {
                top -= 1;
                id = stack[top] as usize;
            } else {
                break;
            }
        }
        sum
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
