//! `--thicken EPS`: open sheets (cloth, leaves, a single wall) have `w` near ½ on both sides and
//! no volume, so `{w > ½}` drops them. [`ThickenedSheets`] adds to the solid the points within
//! `eps` of the input triangles *where `w` says the surface is open*: where the class `w > ½`
//! does not change across the surface. A point `q` outside (`w(q) ≤ ½`) within `eps` of the
//! triangles, with closest point `c`, is thickened when its mirror image `2c − q` across the
//! surface is outside too. Next to a closed, consistently oriented surface the mirror of an
//! outside point is inside (`w` jumps by 1 across it, from ≈ 0 to ≈ 1 whatever other open parts
//! add), so solids, nested or disjoint, are never thickened; across an open sheet `w` jumps from
//! ≈ −½ to ≈ +½, both outside, so a sheet becomes a slab of thickness about `2·eps`, and a hole
//! in an almost closed mesh gets a thin rim. A point on the triangles (`q = c`) is thickened
//! when `w(q) < ¼`: on a closed surface `w = ½`, on the interior of an open sheet the mean of
//! its two sides, ≈ 0. The remesher sees an evaluator like any other, so every guarantee of the
//! output (closed, manifold, oriented, no self-intersection) holds unchanged.

use crate::eval::Evaluator;
use crate::products::sdf::SignedDistance;
use rayon::prelude::*;

/// On the triangles, `w` below this means an open sheet (a closed surface has `w = ½` there).
pub const OPEN_ON_SURFACE: f64 = 0.25;

/// `w` with open sheets thickened: `1` (inside) at an outside point within `eps` of the
/// triangles whose mirror image across them is outside too, `w` elsewhere (module docs).
///
/// ```
/// use gwn::{Mesh, eval::{Evaluator, direct::DirectWindingNumber}};
/// use gwn::products::remesh::thicken::ThickenedSheets;
/// // One open square: w is ±½ next to it, never above ½.
/// let sheet = Mesh::from_slices(
///     &[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
///     &[[0, 1, 2], [0, 2, 3]],
/// )?;
/// let wn = DirectWindingNumber::new(&sheet);
/// let thick = ThickenedSheets::new(&sheet, &wn, 0.05).expect("a positive eps");
/// assert!(wn.eval([0.5, 0.5, 0.01]) < 0.5);
/// assert_eq!(thick.eval([0.5, 0.5, 0.01]), 1.0);
/// assert!(thick.eval([0.5, 0.5, 0.2]) < 0.5);
/// # Ok::<(), gwn::error::MeshError>(())
/// ```
pub struct ThickenedSheets<'a, E: Evaluator + ?Sized> {
    distance: SignedDistance<&'a E>,
    eps: f64,
}

/// `eps` was not a positive finite number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BadThickness(pub f64);

impl std::fmt::Display for BadThickness {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "thickness {} is not a positive finite number", self.0)
    }
}

impl std::error::Error for BadThickness {}

impl<'a, E: Evaluator + ?Sized> ThickenedSheets<'a, E> {
    /// Thickens the open parts of `mesh` (whose winding number `wn` evaluates) by `eps` on each
    /// side.
    pub fn new(mesh: &crate::Mesh, wn: &'a E, eps: f64) -> Result<Self, BadThickness> {
        if !(eps.is_finite() && eps > 0.0) {
            return Err(BadThickness(eps));
        }
        Ok(ThickenedSheets {
            distance: SignedDistance::with_evaluator(mesh, wn),
            eps,
        })
    }

    /// The half-thickness of the slabs.
    pub fn eps(&self) -> f64 {
        self.eps
    }

    /// What thickening decides at `q`, where the winding number is `w`, before the mirror test.
    #[inline]
    fn candidate(&self, q: [f64; 3], w: f64) -> Candidate {
        // NaN (a non-finite query) stays as it is.
        if w.is_nan() || super::inside(w) {
            return Candidate::Keep;
        }
        match self.distance.closest(q) {
            Some(c) if c.distance < self.eps => {
                if c.distance == 0.0 {
                    if w < OPEN_ON_SURFACE {
                        Candidate::Inside
                    } else {
                        Candidate::Keep
                    }
                } else {
                    Candidate::Mirror(std::array::from_fn(|k| 2.0 * c.point[k] - q[k]))
                }
            }
            _ => Candidate::Keep,
        }
    }

    /// `w` at `points`, thickened: one batch for the points, one for the mirrors of the few
    /// within `eps` of the triangles.
    fn thicken_all(&self, points: &[[f64; 3]], mut w: Vec<f64>) -> Vec<f64> {
        let decisions: Vec<Candidate> = points
            .par_iter()
            .zip(&w)
            .map(|(&q, &w)| self.candidate(q, w))
            .collect();
        let (ids, mirrors): (Vec<usize>, Vec<[f64; 3]>) = decisions
            .iter()
            .enumerate()
            .filter_map(|(i, d)| match d {
                Candidate::Mirror(m) => Some((i, *m)),
                _ => None,
            })
            .unzip();
        let wm = self.distance.winding_number().eval_batch(&mirrors);
        for (i, d) in decisions.iter().enumerate() {
            if matches!(d, Candidate::Inside) {
                w[i] = 1.0;
            }
        }
        for (&i, &wm) in ids.iter().zip(&wm) {
            if !super::inside(wm) {
                w[i] = 1.0;
            }
        }
        w
    }
}

/// See [`ThickenedSheets::candidate`].
enum Candidate {
    Keep,
    Inside,
    /// Inside when the winding number at this mirror image is `≤ ½`.
    Mirror([f64; 3]),
}

impl<E: Evaluator + ?Sized> Evaluator for ThickenedSheets<'_, E> {
    fn eval(&self, q: [f64; 3]) -> f64 {
        let w = self.distance.winding_number().eval(q);
        self.thicken_all(&[q], vec![w])[0]
    }

    fn name(&self) -> &'static str {
        self.distance.winding_number().name()
    }

    fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        self.thicken_all(points, self.distance.winding_number().eval_batch(points))
    }

    fn column_axis(&self) -> Option<usize> {
        self.distance.winding_number().column_axis()
    }

    fn eval_column(&self, q: [f64; 3], axis: usize, ts: &[f64]) -> Vec<f64> {
        let w = self.distance.winding_number().eval_column(q, axis, ts);
        let points: Vec<[f64; 3]> = ts
            .iter()
            .map(|&t| {
                let mut p = q;
                p[axis] = t;
                p
            })
            .collect();
        self.thicken_all(&points, w)
    }
}

/// What a remesh of a triangle mesh runs on, thickened or not: the field, the guide, the box
/// and the reference of the report's distance ([`of_mesh`]).
pub struct MeshField<'a> {
    /// The mesh's own `w`, or the thickened sheets'.
    pub field: &'a dyn Evaluator,
    /// The input triangles, as the guide of [`super::remesh_guided`].
    pub guide: super::crossings::SegmentBvh,
    /// The box to remesh.
    pub bounds: crate::BoundingBox,
    /// What the report's Hausdorff distance measures against.
    pub reference: super::report::DistanceReference<'a>,
}

/// The [`MeshField`] of `mesh` (bounding box `bounds`, own field `own`) as `gwn remesh` sets it
/// up: without `sheets`, the mesh's own `w` is the field, so the guide may screen the thin-part
/// probes by an approximation of it ([`super::crossings::SegmentBvh::of_field_mesh`]), and the
/// distance is to where the mesh bounds the solid; with them, the slabs reach `eps` past the
/// mesh's box (the box grows, or they would be capped by it) and the mesh bounds nothing of
/// their solid, so every sample of the distance counts.
pub fn of_mesh<'a>(
    mesh: &'a crate::Mesh,
    own: &'a (dyn Evaluator + 'a),
    sheets: Option<&'a ThickenedSheets<'a, dyn Evaluator + 'a>>,
    bounds: crate::BoundingBox,
) -> MeshField<'a> {
    use super::crossings::SegmentBvh;
    use super::report::DistanceReference;
    match sheets {
        Some(t) => MeshField {
            field: t,
            guide: SegmentBvh::of_mesh(mesh),
            bounds: crate::BoundingBox {
                min: bounds.min.map(|x| x - t.eps()),
                max: bounds.max.map(|x| x + t.eps()),
            },
            reference: DistanceReference::Mesh(mesh),
        },
        None => MeshField {
            field: own,
            guide: SegmentBvh::of_field_mesh(mesh),
            bounds,
            reference: DistanceReference::BoundingMesh(mesh),
        },
    }
}
