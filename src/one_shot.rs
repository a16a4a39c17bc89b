//! [`winding_number`]: the exact winding numbers of a triangle mesh given as plain slices, in one
//! call, for users who do not want to learn the module tree.

use crate::error::MeshError;
use crate::eval::antipodal::{BuildError, WindingNumber};
use crate::mesh::Mesh;

/// A point accepted by [`winding_number`]: `[f64; 3]`, `[f32; 3]`, `glam::DVec3`, `glam::Vec3`.
pub trait Position: Copy {
    /// The coordinates in `f64`.
    fn to_f64(self) -> [f64; 3];
}

impl Position for [f64; 3] {
    fn to_f64(self) -> [f64; 3] {
        self
    }
}

impl Position for [f32; 3] {
    fn to_f64(self) -> [f64; 3] {
        self.map(f64::from)
    }
}

impl Position for glam::DVec3 {
    fn to_f64(self) -> [f64; 3] {
        self.to_array()
    }
}

impl Position for glam::Vec3 {
    fn to_f64(self) -> [f64; 3] {
        self.as_dvec3().to_array()
    }
}

/// A triangle's corner indices accepted by [`winding_number`]: `[u32; 3]`, `[usize; 3]`,
/// `glam::UVec3`.
pub trait TriangleIndices: Copy {
    /// The indices as `u64` (checked against the vertex count by the caller).
    fn to_u64(self) -> [u64; 3];
}

impl TriangleIndices for [u32; 3] {
    fn to_u64(self) -> [u64; 3] {
        self.map(u64::from)
    }
}

impl TriangleIndices for [usize; 3] {
    fn to_u64(self) -> [u64; 3] {
        self.map(|i| i as u64)
    }
}

impl TriangleIndices for glam::UVec3 {
    fn to_u64(self) -> [u64; 3] {
        self.to_array().map(u64::from)
    }
}

/// Why [`winding_number`] could not evaluate.
#[derive(Clone, Debug, PartialEq)]
pub enum WindingNumberError {
    /// The mesh is invalid (index out of range, non-finite coordinate, too many vertices).
    Mesh(MeshError),
    /// The mesh's coordinates cannot be quantized for the exact evaluator.
    Build(BuildError),
}

impl std::fmt::Display for WindingNumberError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WindingNumberError::Mesh(e) => write!(f, "invalid mesh: {e}"),
            WindingNumberError::Build(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for WindingNumberError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            WindingNumberError::Mesh(e) => Some(e),
            WindingNumberError::Build(e) => Some(e),
        }
    }
}

impl From<MeshError> for WindingNumberError {
    fn from(e: MeshError) -> Self {
        WindingNumberError::Mesh(e)
    }
}

impl From<BuildError> for WindingNumberError {
    fn from(e: BuildError) -> Self {
        WindingNumberError::Build(e)
    }
}

/// The exact winding number of the mesh `(positions, triangles)` at every query, in parallel
/// (the exact Antipodal evaluator, [`WindingNumber`]; build it yourself to query many times).
/// NaN for a non-finite query; an invalid mesh is an error.
///
/// ```
/// // The unit cube without its top face: w = 5/6 at the centre; below it, the missing face is
/// // seen from outside, w = −Ω/4π with Ω = 4·atan(1/(8·√4.5)) the face's solid angle.
/// let p = [[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.],[0.,0.,1.],[1.,0.,1.],[1.,1.,1.],[0.,1.,1.]];
/// let t: [[usize; 3]; 10] =
///     [[0,2,1],[0,3,2],[0,1,5],[0,5,4],[1,2,6],[1,6,5],[2,3,7],[2,7,6],[3,0,4],[3,4,7]];
/// let w = gwn::winding_number(&p, &t, &[[0.5, 0.5, 0.5], [0.5, 0.5, -1.0]])?;
/// let below = -(1.0_f64 / (8.0 * 4.5_f64.sqrt())).atan() / std::f64::consts::PI;
/// assert!((w[0] - 5.0 / 6.0).abs() < 1e-14 && (w[1] - below).abs() < 1e-14);
/// assert!(gwn::winding_number(&p, &[[0usize, 1, 8]], &[[0.0; 3]]).is_err());
/// # Ok::<(), gwn::WindingNumberError>(())
/// ```
pub fn winding_number<P: Position, T: TriangleIndices, Q: Position>(
    positions: &[P],
    triangles: &[T],
    queries: &[Q],
) -> Result<Vec<f64>, WindingNumberError> {
    let positions: Vec<[f64; 3]> = positions.iter().map(|p| p.to_f64()).collect();
    let vertex_count = positions.len();
    if u32::try_from(vertex_count).is_err() {
        return Err(MeshError::TooManyVertices {
            count: vertex_count,
        }
        .into());
    }
    let triangles = triangles
        .iter()
        .enumerate()
        .map(|(face, t)| {
            let idx = t.to_u64();
            let mut out = [0u32; 3];
            for k in 0..3 {
                out[k] = u32::try_from(idx[k]).map_err(|_| MeshError::IndexOutOfRange {
                    face,
                    index: idx[k],
                    vertex_count,
                })?;
            }
            Ok(out)
        })
        .collect::<Result<Vec<[u32; 3]>, MeshError>>()?;
    let mesh = Mesh::new(positions, triangles)?;
    let evaluator = WindingNumber::new(&mesh)?;
    let queries: Vec<[f64; 3]> = queries.iter().map(|q| q.to_f64()).collect();
    Ok(evaluator.eval_batch(&queries))
}
