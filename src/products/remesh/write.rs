//! Writers for the remeshed surface, chosen by extension: OBJ (the crate's one OBJ writer,
//! [`crate::mesh::write_obj`]), PLY (binary little-endian), STL (binary) and GLB (binary glTF 2.0).

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
    /// Binary glTF 2.0 (`.glb`): one mesh, `f32` positions, `u32` indices.
    Glb,
}

impl SurfaceFormat {
    /// The format of `path` by its extension, `None` for other extensions.
    pub fn of_path(path: &Path) -> Option<SurfaceFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(SurfaceFormat::Obj),
            "ply" => Some(SurfaceFormat::Ply),
            "stl" => Some(SurfaceFormat::Stl),
            "glb" => Some(SurfaceFormat::Glb),
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
        SurfaceFormat::Glb => write_glb(&mut w, mesh)?,
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

/// A minimal GLB: a JSON chunk describing one triangle primitive and a binary chunk holding the
/// `f32` positions then the `u32` indices (the `gltf` crate reads glTF but does not write it).
/// An empty mesh gives a scene without nodes (glTF accessors cannot be empty).
fn write_glb(w: &mut impl Write, mesh: &crate::mesh::Mesh) -> io::Result<()> {
    let (positions, triangles) = (mesh.positions(), mesh.triangles());
    let too_big = || io::Error::new(io::ErrorKind::InvalidInput, "mesh too large for GLB");
    let mut bin: Vec<u8> = Vec::new();
    let json = if triangles.is_empty() {
        r#"{"asset":{"version":"2.0","generator":"gwn remesh"},"scene":0,"scenes":[{}]}"#
            .to_string()
    } else {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for p in positions {
            for k in 0..3 {
                let x = p[k] as f32;
                lo[k] = lo[k].min(x);
                hi[k] = hi[k].max(x);
                bin.extend_from_slice(&x.to_le_bytes());
            }
        }
        let vertex_bytes = bin.len();
        for t in triangles {
            for i in t {
                bin.extend_from_slice(&i.to_le_bytes());
            }
        }
        let index_bytes = bin.len() - vertex_bytes;
        let list = |v: [f32; 3]| format!("[{:?},{:?},{:?}]", v[0], v[1], v[2]);
        format!(
            r#"{{"asset":{{"version":"2.0","generator":"gwn remesh"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"mode":4}}]}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":{},"max":{}}},{{"bufferView":1,"componentType":5125,"count":{},"type":"SCALAR"}}],"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{vertex_bytes},"target":34962}},{{"buffer":0,"byteOffset":{vertex_bytes},"byteLength":{index_bytes},"target":34963}}],"buffers":[{{"byteLength":{}}}]}}"#,
            positions.len(),
            list(lo),
            list(hi),
            3 * triangles.len(),
            bin.len()
        )
    };
    let mut json = json.into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    // Both chunks are 4-byte multiples already (f32 and u32 data, padded JSON).
    let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin.len() };
    let total = u32::try_from(12 + 8 + json.len() + bin_chunk).map_err(|_| too_big())?;
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&total.to_le_bytes())?;
    w.write_all(&(json.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&json)?;
    if !bin.is_empty() {
        w.write_all(&(bin.len() as u32).to_le_bytes())?;
        w.write_all(b"BIN\0")?;
        w.write_all(&bin)?;
    }
    Ok(())
}
