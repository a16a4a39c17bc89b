//! Oriented point clouds: the dipole sum of Barill et al. 2018, Eq. 5,
//! `w(q) = Σᵢ aᵢ (pᵢ − q)·n̂ᵢ / (4π ‖pᵢ − q‖³)`, and its Barnes–Hut evaluation with the same tree
//! and expansions as triangle soups.

use super::InputScale;
use super::area::estimate_areas;
use super::barnes_hut::{FastParams, Hierarchy, NearLeaf};
use super::moments::Moments;
use super::packet::{PACKET, eval_in_packets, prefetch};
use super::soup::dist2;
use super::tree::Tree;
use crate::base::bounding_box::BoundingBox;
use crate::base::compensated::NeumaierSum;
use crate::mesh::PointCloud;

use crate::kernel::spherical::INV_4PI;

/// Largest number of points in a leaf. Barill et al. found clouds fastest with tiny cells.
pub const POINT_LEAF_SIZE: usize = 4;

/// Neighbours used by the area estimation (Barill et al.: `k = 20`).
pub const DEFAULT_AREA_NEIGHBOURS: usize = 20;

impl PointCloud {
    /// The given areas, or areas estimated with `k` neighbours ([`estimate_areas`]).
    pub fn areas_or_estimate(&self, k: usize) -> Vec<f64> {
        match self.areas() {
            Some(a) => a.to_vec(),
            None => estimate_areas(self.positions(), self.normals(), k),
        }
    }
}

/// The exact dipole sum (Eq. 5), `O(n)` per query: the ground truth for point clouds. A point
/// coinciding with `q` contributes 0 (principal value).
pub fn winding_number_points_direct(
    positions: &[[f64; 3]],
    normals: &[[f64; 3]],
    areas: &[f64],
    q: [f64; 3],
) -> f64 {
    let mut sum = NeumaierSum::new();
    for ((p, n), a) in positions.iter().zip(normals).zip(areas) {
        let an = n.map(|v| v * a);
        sum.add(dipole(*p, an, q));
    }
    sum.value()
}

#[inline]
fn dipole(p: [f64; 3], an: [f64; 3], q: [f64; 3]) -> f64 {
    let r = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    let d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    if d2 == 0.0 {
        return 0.0;
    }
    let d3 = d2 * d2.sqrt();
    (an[0] * r[0] + an[1] * r[1] + an[2] * r[2]) / d3 * INV_4PI
}

/// `∇_q` of [`dipole`]: with `r = p − q`, `−(a n/d³ − 3 (a n·r) r/d⁵)/(4π)`; 0 at the point.
#[inline]
fn dipole_gradient(p: [f64; 3], an: [f64; 3], q: [f64; 3]) -> [f64; 3] {
    let r = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    let d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    if d2 == 0.0 {
        return [0.0; 3];
    }
    let inv_d3 = 1.0 / (d2 * d2.sqrt());
    let nr = an[0] * r[0] + an[1] * r[1] + an[2] * r[2];
    std::array::from_fn(|k| -(an[k] - 3.0 * nr * r[k] / d2) * inv_d3 * INV_4PI)
}

/// Barnes–Hut evaluator of the winding number of an oriented point cloud (Barill et al. 2018,
/// Sections 3.1–3.2). `Send + Sync`.
///
/// ```
/// use gwn::eval::fast::PointCloudWindingNumber;
/// use gwn::mesh::PointCloud;
/// // Six points on the unit sphere, each carrying a sixth of its area.
/// let p = vec![[1., 0., 0.], [-1., 0., 0.], [0., 1., 0.], [0., -1., 0.], [0., 0., 1.], [0., 0., -1.]];
/// let a = vec![4.0 * std::f64::consts::PI / 6.0; 6];
/// let cloud = PointCloud::new(p.clone(), p, Some(a))?;
/// let fast = PointCloudWindingNumber::new(&cloud);
/// assert!((fast.eval([0.0, 0.0, 0.0]) - 1.0).abs() < 1e-12);
/// # Ok::<(), gwn::mesh::PointCloudError>(())
/// ```
#[derive(Clone, Debug)]
pub struct PointCloudWindingNumber {
    hierarchy: Hierarchy,
    /// Positions in leaf order.
    positions: Vec<[f64; 3]>,
    /// Area-weighted normals `aᵢ n̂ᵢ` in leaf order.
    weighted_normals: Vec<[f64; 3]>,
    areas: Vec<f64>,
    params: FastParams,
    /// World → the scaled coordinates positions and normals are stored in.
    scale: InputScale,
}

impl PointCloudWindingNumber {
    /// Builds with the cloud's areas (estimated with `k = 20` neighbours when absent) and
    /// Barill's point-cloud default β = 2.3, order 2.
    pub fn new(cloud: &PointCloud) -> Self {
        Self::with_params(cloud, FastParams::barill(2.3, 2))
    }

    /// Builds with explicit default parameters.
    pub fn with_params(cloud: &PointCloud, params: FastParams) -> Self {
        let areas = cloud.areas_or_estimate(DEFAULT_AREA_NEIGHBOURS);
        Self::from_parts(cloud.positions(), cloud.normals(), areas, params)
    }

    /// Builds from positions, unit normals and areas (all the same length).
    ///
    /// # Panics
    /// When the lengths differ (use [`PointCloud::new`] to validate input).
    pub fn from_parts(
        positions: &[[f64; 3]],
        normals: &[[f64; 3]],
        areas: Vec<f64>,
        params: FastParams,
    ) -> Self {
        assert!(positions.len() == normals.len() && positions.len() == areas.len());
        let scale = InputScale::new(BoundingBox::of_points(positions));
        let positions: Vec<[f64; 3]> = positions.iter().map(|&p| scale.point(p)).collect();
        let positions = &positions[..];
        // Areas scale with the square of lengths (so each dipole term is scale-invariant).
        let an: Vec<[f64; 3]> = normals
            .iter()
            .zip(&areas)
            .map(|(n, &a)| scale.point(scale.point(n.map(|v| v * a))))
            .collect();
        let boxes: Vec<_> = positions.iter().map(|&p| (p, p)).collect();
        let tree = Tree::build(positions, &boxes, POINT_LEAF_SIZE);
        let hierarchy = Hierarchy::build(
            tree,
            |e| (areas[e], positions[e]),
            |e, c| Moments::of_point(positions[e], an[e], c),
            |e, c| dist2(positions[e], c),
        );
        let order = &hierarchy.tree.order;
        let positions = order.iter().map(|&e| positions[e as usize]).collect();
        let weighted_normals = order.iter().map(|&e| an[e as usize]).collect();
        PointCloudWindingNumber {
            hierarchy,
            positions,
            weighted_normals,
            areas,
            params,
            scale,
        }
    }

    /// The areas used (given or estimated), in input order.
    pub fn areas(&self) -> &[f64] {
        &self.areas
    }

    /// The parameters [`Self::eval`] uses.
    pub fn params(&self) -> FastParams {
        self.params
    }

    /// Changes the parameters [`Self::eval`] uses.
    pub fn set_params(&mut self, params: FastParams) {
        self.params = params;
    }

    /// The approximate winding number at `q`.
    pub fn eval(&self, q: [f64; 3]) -> f64 {
        self.eval_with(q, self.params)
    }

    /// The approximate winding number at `q` with explicit parameters.
    pub fn eval_with(&self, q: [f64; 3], params: FastParams) -> f64 {
        let q = self.scale.query(q);
        let (p, an) = (&self.positions, &self.weighted_normals);
        self.hierarchy.eval(q, &params, |_, range, sum| {
            for i in range {
                *sum += dipole(p[i], an[i], q);
            }
        })
    }

    /// [`Self::eval`] for many points, in parallel (rayon).
    pub fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        self.eval_batch_with(points, self.params)
    }

    /// Gradient of the approximation at `q` with the stored parameters.
    pub fn gradient(&self, q: [f64; 3]) -> [f64; 3] {
        self.gradient_with(q, self.params)
    }

    /// Gradient of the approximation [`Self::eval_with`] computes: each admissible node's
    /// expansion differentiated ([`Moments::far_field_gradient`]) and near points by the exact
    /// dipole gradient. Tends to the gradient of the dipole sum as β grows.
    pub fn gradient_with(&self, q: [f64; 3], params: FastParams) -> [f64; 3] {
        let (p, an) = (&self.positions, &self.weighted_normals);
        self.scale.gradient(q, |q| {
            self.hierarchy.gradient(q, &params, |range, g| {
                for i in range {
                    let e = dipole_gradient(p[i], an[i], q);
                    for k in 0..3 {
                        g[k] += e[k];
                    }
                }
            })
        })
    }

    /// [`Self::eval_with`] for many points, in parallel (rayon): equal to it point by point,
    /// bit for bit, and faster, as neighbouring points walk the tree together in packets of
    /// eight (see `docs/fast.md`).
    pub fn eval_batch_with(&self, points: &[[f64; 3]], params: FastParams) -> Vec<f64> {
        eval_in_packets(
            points,
            self.hierarchy.packets_need_order(),
            |packet, active| {
                let q = packet.map(|x| self.scale.query(x));
                let near = NearPoints { cloud: self, q: &q };
                self.hierarchy.eval_packet(&q, active, &params, near)
            },
        )
    }

    /// Number of tree nodes (node 0 is the root).
    pub fn node_count(&self) -> usize {
        self.hierarchy.tree.len()
    }

    /// The expansion of node `id`.
    pub fn node_moments(&self, id: usize) -> &Moments {
        &self.hierarchy.moments[id]
    }

    /// The two children of node `id`, `None` for a leaf.
    pub fn node_children(&self, id: usize) -> Option<[usize; 2]> {
        let node = &self.hierarchy.tree.nodes[id];
        (!node.is_leaf()).then(|| [node.left as usize, node.left as usize + 1])
    }
}

/// The near leaves of a packet ([`Hierarchy::eval_packet`]): their exact dipoles.
struct NearPoints<'a> {
    cloud: &'a PointCloudWindingNumber,
    q: &'a [[f64; 3]; PACKET],
}

impl NearLeaf for NearPoints<'_> {
    #[inline(always)]
    fn prefetch(&self, leaf: usize) {
        let start = self.cloud.hierarchy.leaves[leaf].start;
        if let (Some(p), Some(n)) = (
            self.cloud.positions.get(start),
            self.cloud.weighted_normals.get(start),
        ) {
            prefetch(p);
            prefetch(n);
        }
    }

    #[inline(always)]
    fn add(&mut self, query: usize, leaf: usize, sum: &mut f64) {
        let (p, an) = (&self.cloud.positions, &self.cloud.weighted_normals);
        for e in self.cloud.hierarchy.leaves[leaf].clone() {
            *sum += dipole(p[e], an[e], self.q[query]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::PointCloudError;

    #[test]
    fn validation_rejects_bad_input() {
        assert!(matches!(
            PointCloud::new(vec![[0.0; 3]], vec![], None),
            Err(PointCloudError::LengthMismatch { .. })
        ));
        assert!(matches!(
            PointCloud::new(vec![[0.0; 3]], vec![[1.0, 0.0, 0.0]], Some(vec![-1.0])),
            Err(PointCloudError::InvalidValue { what: "area", .. })
        ));
        let c = PointCloud::new(vec![[0.0; 3]], vec![[2.0, 0.0, 0.0]], None).unwrap();
        assert_eq!(c.normals()[0], [1.0, 0.0, 0.0]);
    }

    #[test]
    fn fast_equals_direct_with_huge_beta() {
        let n = 500;
        let mut p = Vec::new();
        for i in 0..n {
            let t = f64::from(i) * 0.7;
            p.push([t.sin() * 1.3, (t * 1.7).cos(), (t * 0.3).sin()]);
        }
        let nrm: Vec<[f64; 3]> = p.iter().map(|v| [v[1], v[2], v[0]]).collect();
        let a: Vec<f64> = (0..n).map(|i| 0.01 + f64::from(i % 7) * 0.001).collect();
        let cloud = PointCloud::new(p, nrm, Some(a.clone())).unwrap();
        let fast = PointCloudWindingNumber::new(&cloud);
        for q in [[0.0, 0.1, 0.2], [3.0, 0.0, 0.0], [0.5, -0.5, 0.1]] {
            let d = winding_number_points_direct(cloud.positions(), cloud.normals(), &a, q);
            let f = fast.eval_with(q, FastParams::barill(1e12, 2));
            assert!((d - f).abs() < 1e-12, "{d} vs {f}");
            let f2 = fast.eval_with(q, FastParams::barill(2.3, 2));
            assert!((d - f2).abs() < 1e-2, "{d} vs {f2}");
        }
    }

    #[test]
    fn batches_equal_points_one_by_one_bit_for_bit() {
        let n = 2000;
        let p: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let t = f64::from(i) * 0.37;
                [t.sin() * 1.3, (t * 1.7).cos(), (t * 0.3).sin()]
            })
            .collect();
        let nrm: Vec<[f64; 3]> = p.iter().map(|v| [v[1], v[2], v[0]]).collect();
        let cloud = PointCloud::new(p.clone(), nrm, None).unwrap();
        let fast = PointCloudWindingNumber::new(&cloud);
        let mut queries: Vec<[f64; 3]> = (0..700)
            .map(|i| {
                let t = f64::from(i);
                [
                    (t * 0.11).sin() * 1.6,
                    (t * 0.23).cos() * 1.2,
                    (t * 0.05).sin(),
                ]
            })
            .collect();
        queries.extend(p.iter().step_by(97));
        queries.push([f64::NAN; 3]);
        for params in [FastParams::barill(2.3, 2), FastParams::barill(1.2, 0)] {
            let batch = fast.eval_batch_with(&queries, params);
            for (q, b) in queries.iter().zip(batch) {
                let one = fast.eval_with(*q, params);
                assert!(
                    b.to_bits() == one.to_bits() || (b.is_nan() && one.is_nan()),
                    "{q:?} {params:?}: batch {b} vs alone {one}"
                );
            }
        }
    }
}
