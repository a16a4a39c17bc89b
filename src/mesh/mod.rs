//! The indexed triangle mesh every evaluator consumes: `f64` positions and `u32` triangles.
//!
//! A [`Mesh`] is plain data. It is validated once on construction (indices in range, finite
//! coordinates, vertex count fits `u32`) and never repaired: degenerate triangles (repeated
//! indices, zero area), duplicated and flipped faces, non-manifold fans and unreferenced vertices
//! are all legal input, because the winding number is defined for every one of them and the
//! users of this crate feed exactly such meshes.

mod point_cloud;
pub mod signed_boundary;
pub mod stats;
mod tet_mesh;

pub use point_cloud::{PointCloud, PointCloudError};
pub use signed_boundary::{
    BoundaryEdge, boundary_edges, boundary_welded_by, geometric_boundary_edges, signed_boundary,
};
pub use tet_mesh::TetMesh;

use crate::base::bounding_box::BoundingBox;
use crate::error::MeshError;

/// An indexed triangle mesh (possibly open, non-manifold, self-intersecting, a soup).
///
/// ```
/// use gwn::Mesh;
/// let mesh = Mesh::from_slices(
///     &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
///     &[[0, 1, 2]],
/// )?;
/// assert_eq!(mesh.triangles().len(), 1);
/// # Ok::<(), gwn::error::MeshError>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// Builds a mesh from owned vectors, validating indices and coordinates.
    pub fn new(positions: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        if positions.len() > u32::MAX as usize {
            return Err(MeshError::TooManyVertices {
                count: positions.len(),
            });
        }
        for (vertex, p) in positions.iter().enumerate() {
            for (axis, &c) in p.iter().enumerate() {
                if !c.is_finite() {
                    return Err(MeshError::NonFiniteCoordinate {
                        vertex,
                        axis,
                        value: c,
                    });
                }
            }
        }
        let n = positions.len() as u64;
        for (face, t) in triangles.iter().enumerate() {
            for &i in t {
                if u64::from(i) >= n {
                    return Err(MeshError::IndexOutOfRange {
                        face,
                        index: i as u64,
                        vertex_count: positions.len(),
                    });
                }
            }
        }
        Ok(Mesh {
            positions,
            triangles,
        })
    }

    /// Builds a mesh by copying plain slices.
    pub fn from_slices(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Self, MeshError> {
        Self::new(positions.to_vec(), triangles.to_vec())
    }

    /// Builds a mesh from glam vectors.
    pub fn from_glam(
        positions: &[glam::DVec3],
        triangles: &[glam::UVec3],
    ) -> Result<Self, MeshError> {
        Self::new(
            positions.iter().map(|p| p.to_array()).collect(),
            triangles.iter().map(|t| t.to_array()).collect(),
        )
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// Triangles as vertex-index triples (orientation: counter-clockwise seen from the side the
    /// normal points to).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// True when the mesh has no triangles.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The three corner positions of triangle `f`.
    pub fn triangle_positions(&self, f: usize) -> [[f64; 3]; 3] {
        let t = self.triangles[f];
        [
            self.positions[t[0] as usize],
            self.positions[t[1] as usize],
            self.positions[t[2] as usize],
        ]
    }

    /// Bounding box of the vertices that triangles reference (`None` for a mesh without
    /// triangles). Unreferenced vertices do not influence the winding number, so they are left
    /// out: a stray far vertex must not coarsen the quantization grid.
    pub fn bounding_box(&self) -> Option<BoundingBox> {
        BoundingBox::of_points(
            self.triangles
                .iter()
                .flat_map(|t| t.iter().map(|&i| &self.positions[i as usize])),
        )
    }

    /// Every triangle reversed (`[a, b, c]` → `[a, c, b]`): negates the winding number.
    pub fn flipped(&self) -> Mesh {
        Mesh {
            positions: self.positions.clone(),
            triangles: self.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect(),
        }
    }

    /// All positions moved by `offset`.
    pub fn translated(&self, offset: [f64; 3]) -> Mesh {
        Mesh {
            positions: self
                .positions
                .iter()
                .map(|p| [p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]])
                .collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// The union of two meshes as one (indices of `other` shifted): winding numbers add.
    pub fn concatenated(&self, other: &Mesh) -> Result<Mesh, MeshError> {
        let shift = self.positions.len() as u64;
        let total = self.positions.len() + other.positions.len();
        if total > u32::MAX as usize {
            return Err(MeshError::TooManyVertices { count: total });
        }
        let mut positions = self.positions.clone();
        positions.extend_from_slice(&other.positions);
        let mut triangles = self.triangles.clone();
        triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| t.map(|i| (u64::from(i) + shift) as u32)),
        );
        Ok(Mesh {
            positions,
            triangles,
        })
    }

    /// Merges vertices whose positions are bitwise identical (`-0.0` and `0.0` are merged too, as
    /// they are the same point). Returns the welded mesh and the number of vertices removed.
    ///
    /// STL files store every triangle's corners separately; without welding every edge of an STL
    /// would be a boundary edge and the exact evaluator would lose its speed (not its accuracy).
    pub fn welded(&self) -> (Mesh, usize) {
        use std::collections::HashMap;
        let key = |p: &[f64; 3]| p.map(|c| if c == 0.0 { 0u64 } else { c.to_bits() });
        let mut map: HashMap<[u64; 3], u32> = HashMap::with_capacity(self.positions.len());
        let mut remap = Vec::with_capacity(self.positions.len());
        let mut positions = Vec::new();
        for p in &self.positions {
            let id = *map.entry(key(p)).or_insert_with(|| {
                positions.push(*p);
                (positions.len() - 1) as u32
            });
            remap.push(id);
        }
        let removed = self.positions.len() - positions.len();
        let triangles = self
            .triangles
            .iter()
            .map(|t| t.map(|i| remap[i as usize]))
            .collect();
        (
            Mesh {
                positions,
                triangles,
            },
            removed,
        )
    }
}

/// Writes `mesh` as OBJ (`v x y z`, then 1-based `f i j k`), coordinates in Rust's shortest
/// round-trip form, so reading the file back gives the same `f64`s. The one OBJ writer of the
/// crate (face classification's `--mesh-out`, the testing kit's corpus files).
pub fn write_obj(mut w: impl std::io::Write, mesh: &Mesh) -> std::io::Result<()> {
    for p in mesh.positions() {
        writeln!(w, "v {:?} {:?} {:?}", p[0], p[1], p[2])?;
    }
    for t in mesh.triangles() {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    w.flush()
}
