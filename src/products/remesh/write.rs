//! Writers for the remeshed surface, chosen by extension: OBJ (the crate's one OBJ writer,
//! [`crate::mesh::write_obj`]), PLY (binary little-endian) and STL (binary).

use std::io::{self, Write};
use std::path::Path;

/// An output format of `gwn remesh`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceFormat {
    /// Wavefront OBJ (text, shortest round-trip coordinates).
    Obj,
    /// Binary little-endian PLY, `double` coordinates.
    Ply,
    /// Binary STL (`f32` coordinates, one facet normal per triangle).
    Stl,
}

impl SurfaceFormat {
    /// The format of `path` by its extension, `None` for other extensions.
    pub fn of_path(path: &Path) -> Option<SurfaceFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(SurfaceFormat::Obj),
            "ply" => Some(SurfaceFormat::Ply),
            "stl" => Some(SurfaceFormat::Stl),
            _ => None,
        }
    }
}

/// Writes `mesh` in `format`.
pub fn write_surface(
    mut w: impl Write,
    format: SurfaceFormat,
    mesh: &crate::mesh::Mesh,
) -> io::Result<()> {
    let (positions, triangles) = (mesh.positions(), mesh.triangles());
    match format {
        SurfaceFormat::Obj => return crate::mesh::write_obj(w, mesh),
        SurfaceFormat::Ply => {
            write!(
                w,
                "ply\nformat binary_little_endian 1.0\ncomment gwn remesh\nelement vertex {}\n\
                 property double x\nproperty double y\nproperty double z\nelement face {}\n\
                 property list uchar uint vertex_indices\nend_header\n",
                positions.len(),
                triangles.len()
            )?;
            for p in positions {
                for c in p {
                    w.write_all(&c.to_le_bytes())?;
                }
            }
            for t in triangles {
                w.write_all(&[3u8])?;
                for i in t {
                    w.write_all(&i.to_le_bytes())?;
                }
            }
        }
        SurfaceFormat::Stl => {
            let mut header = [0u8; 80];
            header[..11].copy_from_slice(b"gwn remesh ");
            w.write_all(&header)?;
            let count = u32::try_from(triangles.len()).map_err(|_| {
                io::Error::new(io::ErrorKind::InvalidInput, "too many triangles for STL")
            })?;
            w.write_all(&count.to_le_bytes())?;
            for t in triangles {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                let u = [0, 1, 2].map(|k| b[k] - a[k]);
                let v = [0, 1, 2].map(|k| c[k] - a[k]);
                let n = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                let n = if len > 0.0 {
                    n.map(|x| x / len)
                } else {
                    [0.0; 3]
                };
                for x in n.iter().chain(&a).chain(&b).chain(&c) {
                    w.write_all(&(*x as f32).to_le_bytes())?;
                }
                w.write_all(&[0, 0])?;
            }
        }
    }
    w.flush()
}
