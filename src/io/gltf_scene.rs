//! glTF 2.0 reader: `.glb` (binary container) and `.gltf` (JSON with data-URI or external
//! buffers). The JSON document is deserialized by the `gltf` crate (`gltf::json`); everything
//! after that is done here with checked indices and offsets, because the crate's validation and
//! readers index arrays and slice buffers unchecked and panic on a lying file.
//!
//! The result is one mesh per file: every mesh instance of the scene (the default scene, else the
//! first; every mesh once when the file has no scene), each with its node's world transform
//! applied in `f64`. Instances whose transform mirrors (negative determinant) have their triangles
//! reversed, as the glTF specification asks, so that outward stays outward. Triangle lists, strips
//! and fans are read; points and lines are an error, as are sparse accessors, non-float positions
//! and required extensions the `gltf` crate does not know (Draco, meshopt, quantization).
//! Materials, normals, skins and morph targets are ignored.

use std::borrow::Cow;
use std::path::Path;

use ::gltf::json::accessor::{ComponentType, Type};
use ::gltf::json::mesh::{Mode, Semantic};
use ::gltf::json::validation::Checked;
use ::gltf::json::{self, Index, Root};
use base64::Engine;

use super::{Fail, RawMesh};
use crate::error::{LoadErrorKind, Location};

/// Most triangles one file may instantiate: node hierarchies can reuse a mesh exponentially often
/// (a node with two children that are the same node, nested), so the total is capped before any
/// allocation.
pub(crate) const MAX_TRIANGLES: u64 = 1 << 26;

/// Required extensions that change the geometry; a file needing one is refused rather than read
/// wrongly. Other required extensions (textures, materials) do not affect triangles and are
/// ignored.
const GEOMETRY_EXTENSIONS: [&str; 4] = [
    "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",
    "KHR_mesh_quantization",
    "EXT_mesh_gpu_instancing",
];

/// Most node visits while walking the scene (instanced subtrees count once per instance); real
/// scenes have far fewer nodes, and a file nesting reuse exponentially is stopped early.
const MAX_NODE_VISITS: u64 = 1 << 20;

const GLB_MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

fn syntax(msg: impl Into<String>) -> Fail {
    (Location::File, LoadErrorKind::Syntax(msg.into()))
}

fn truncated(at: u64, msg: impl Into<String>) -> Fail {
    (Location::Byte(at), LoadErrorKind::Truncated(msg.into()))
}

/// An element of one of the root's arrays, or an error naming the dangling reference.
fn get<'r, T>(items: &'r [T], index: Index<T>, what: &str) -> Result<&'r T, Fail> {
    items.get(index.value()).ok_or_else(|| {
        syntax(format!(
            "{what} {} does not exist ({} defined)",
            index.value(),
            items.len()
        ))
    })
}

fn checked<'a, T>(c: &'a Checked<T>, what: &str) -> Result<&'a T, Fail> {
    match c {
        Checked::Valid(v) => Ok(v),
        Checked::Invalid => Err(syntax(format!("{what} has an invalid value"))),
    }
}

/// Parses a `.glb` or `.gltf` file. External buffer files are resolved against `base_dir`; without
/// one (bytes in memory) they are an error.
pub(crate) fn parse(bytes: &[u8], base_dir: Option<&Path>) -> Result<RawMesh, Fail> {
    let (json_bytes, blob) = if bytes.starts_with(GLB_MAGIC) {
        split_glb(bytes)?
    } else {
        (bytes, None)
    };
    let root: Root =
        json::deserialize::from_slice(json_bytes).map_err(|e| syntax(format!("glTF JSON: {e}")))?;
    if let Some(ext) = root
        .extensions_required
        .iter()
        .find(|e| GEOMETRY_EXTENSIONS.contains(&e.as_str()))
    {
        return Err(syntax(format!(
            "requires extension {ext}, which is not supported (geometry would be read wrongly)"
        )));
    }
    let buffers = load_buffers(&root, blob, base_dir)?;
    let instances = mesh_instances(&root)?;

    // Count first, so a file cannot make us allocate more than the cap.
    let mut total: u64 = 0;
    for (m, _) in &instances {
        let mesh = get(&root.meshes, *m, "mesh")?;
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let what = format!("mesh {} primitive {p}", m.value());
            total = total.saturating_add(triangle_count(&root, prim, &what)?);
        }
        if total > MAX_TRIANGLES {
            return Err(syntax(format!(
                "the scene instantiates more than {MAX_TRIANGLES} triangles"
            )));
        }
    }

    let mut raw = RawMesh::default();
    for (m, matrix) in &instances {
        let mirrored = determinant3(matrix) < 0.0;
        let mesh = get(&root.meshes, *m, "mesh")?;
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let what = format!("mesh {} primitive {p}", m.value());
            let mode = *checked(&prim.mode, &format!("{what}: mode"))?;
            let positions = position_accessor(&root, prim, &what)?;
            let base = raw.positions.len();
            let local = read_positions(&root, positions, &buffers, &what)?;
            raw.positions
                .extend(local.iter().map(|&p| transform_point(matrix, p)));
            let order: Vec<u32> = match prim.indices {
                Some(i) => {
                    read_indices(&root, get(&root.accessors, i, "accessor")?, &buffers, &what)?
                }
                None => {
                    let n = u32::try_from(local.len())
                        .map_err(|_| syntax(format!("{what}: too many vertices")))?;
                    (0..n).collect()
                }
            };
            let first_face = raw.triangles.len();
            for (k, mut t) in assemble(mode, &order, &what)?.into_iter().enumerate() {
                for &i in &t {
                    if i as usize >= local.len() {
                        return Err(super::index_error(
                            first_face + k,
                            u64::from(i),
                            local.len(),
                        ));
                    }
                }
                if mirrored {
                    t.swap(1, 2);
                }
                let off = |i: u32| {
                    u32::try_from(base + i as usize)
                        .map_err(|_| syntax("more vertices than 32-bit indices can address"))
                };
                raw.triangles.push([off(t[0])?, off(t[1])?, off(t[2])?]);
            }
        }
    }
    Ok(raw)
}

fn position_accessor<'r>(
    root: &'r Root,
    prim: &json::mesh::Primitive,
    what: &str,
) -> Result<&'r json::Accessor, Fail> {
    let i = prim
        .attributes
        .get(&Checked::Valid(Semantic::Positions))
        .ok_or_else(|| syntax(format!("{what} has no POSITION attribute")))?;
    get(&root.accessors, *i, "accessor")
}

/// Splits a GLB container into its JSON chunk and optional binary chunk.
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), Fail> {
    let u32_at = |at: usize| -> Result<u32, Fail> {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| truncated(at as u64, "GLB header or chunk header cut short"))
    };
    let version = u32_at(4)?;
    if version != 2 {
        return Err(syntax(format!(
            "GLB version {version} (only glTF 2.0 is read)"
        )));
    }
    let declared = u32_at(8)? as usize;
    if declared > bytes.len() {
        return Err(truncated(
            bytes.len() as u64,
            format!(
                "GLB header says {declared} bytes, the file has {}",
                bytes.len()
            ),
        ));
    }
    let bytes = &bytes[..declared];
    let mut at = 12usize;
    let mut json = None;
    let mut bin = None;
    while at < bytes.len() {
        let len = u32_at(at)? as usize;
        let kind = u32_at(at + 4)?;
        let start = at + 8;
        let data = start
            .checked_add(len)
            .and_then(|end| bytes.get(start..end))
            .ok_or_else(|| {
                truncated(
                    start as u64,
                    format!("GLB chunk of {len} bytes runs past the end of the file"),
                )
            })?;
        match kind {
            CHUNK_JSON if json.is_none() && at == 12 => json = Some(data),
            CHUNK_BIN if json.is_some() && bin.is_none() => bin = Some(data),
            CHUNK_JSON | CHUNK_BIN => {
                return Err((
                    Location::Byte(at as u64),
                    LoadErrorKind::Syntax("GLB chunks out of order".into()),
                ));
            }
            // Unknown chunk types are skipped, as the specification requires.
            _ => {}
        }
        at = start + len;
    }
    let json = json.ok_or_else(|| syntax("GLB file without a JSON chunk"))?;
    Ok((json, bin))
}

/// The bytes of every buffer, in document order.
fn load_buffers<'a>(
    root: &Root,
    blob: Option<&'a [u8]>,
    base_dir: Option<&Path>,
) -> Result<Vec<Cow<'a, [u8]>>, Fail> {
    root.buffers
        .iter()
        .enumerate()
        .map(|(i, buffer)| {
            let data: Cow<'a, [u8]> = match &buffer.uri {
                None => Cow::Borrowed(blob.ok_or_else(|| {
                    syntax(format!(
                        "buffer {i} refers to the GLB binary chunk, which the file lacks"
                    ))
                })?),
                Some(uri) => Cow::Owned(read_uri(uri, base_dir, i, buffer.byte_length.0)?),
            };
            let declared = buffer.byte_length.0;
            if (data.len() as u64) < declared {
                return Err(truncated(
                    data.len() as u64,
                    format!(
                        "buffer {i} has {} bytes, its byteLength is {declared}",
                        data.len()
                    ),
                ));
            }
            Ok(data)
        })
        .collect()
}

/// A buffer URI: `data:...;base64,...` or a relative file path (percent-encoded). Files come
/// from an untrusted document, so the path is percent-decoded, then resolved lexically (`.` and
/// `..` applied to the text) and refused if it leaves the model's folder; only a regular file is
/// opened (never blocking on a FIFO), and at most `byte_length` bytes of it are read.
fn read_uri(
    uri: &str,
    base_dir: Option<&Path>,
    buffer: usize,
    byte_length: u64,
) -> Result<Vec<u8>, Fail> {
    use std::io::Read;
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) = rest.split_once(";base64,").ok_or_else(|| {
            syntax(format!(
                "buffer {buffer}: only base64 data URIs are supported"
            ))
        })?;
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| syntax(format!("buffer {buffer}: bad base64 data URI: {e}")));
    }
    let relative = String::from_utf8(percent_decode(uri)).map_err(|_| {
        syntax(format!(
            "buffer {buffer}: URI {uri:?} is not UTF-8 once percent-decoded"
        ))
    })?;
    if relative.contains("://")
        || relative.starts_with(['/', '\\'])
        || Path::new(&relative).has_root()
        || Path::new(&relative).is_absolute()
    {
        return Err(syntax(format!(
            "buffer {buffer}: URI {uri:?} is neither a data URI nor a relative file path"
        )));
    }
    let dir = base_dir.ok_or_else(|| {
        syntax(format!(
            "buffer {buffer} is the external file {relative:?}, which cannot be resolved for bytes in memory"
        ))
    })?;
    let path = resolve_inside(dir, &relative).ok_or_else(|| {
        syntax(format!(
            "buffer {buffer}: URI {uri:?} points outside the model's folder (refused)"
        ))
    })?;
    // Its own kind (not a syntax error), so that callers can tell a missing or unreadable `.bin`
    // (an OS error, `FileNotFoundError` in Python) from a malformed file.
    let cannot = |error: std::io::Error| {
        (
            Location::File,
            LoadErrorKind::Referenced {
                what: format!("buffer {buffer}: URI {uri:?}"),
                file: path.clone(),
                error,
            },
        )
    };
    let file = super::open_regular(&path).map_err(cannot)?;
    let mut data = Vec::new();
    file.take(byte_length)
        .read_to_end(&mut data)
        .map_err(cannot)?;
    Ok(data)
}

/// `dir` joined with the `/`-separated `relative`, with `.` and `..` applied to the text; `None`
/// when a `..` climbs above `dir` or nothing but `dir` itself remains. Lexical on purpose: a
/// symlink inside the folder is the folder owner's choice (and is followed), while the document
/// only gets to name files below it.
fn resolve_inside(dir: &Path, relative: &str) -> Option<std::path::PathBuf> {
    let mut parts: Vec<&str> = Vec::new();
    for part in relative.split('/') {
        match part {
            "" | "." => {}
            ".." => {
                parts.pop()?;
            }
            // On Windows a backslash also separates and `C:` names a drive: such a part could leave
            // the folder after the join below, so it is refused there.
            p if cfg!(windows) && p.contains(['\\', ':']) => return None,
            p => parts.push(p),
        }
    }
    if parts.is_empty() {
        return None;
    }
    Some(parts.iter().fold(dir.to_path_buf(), |p, part| p.join(part)))
}

/// `%XX` escapes decoded byte-wise; malformed escapes are kept as written.
fn percent_decode(s: &str) -> Vec<u8> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    out
}

type Matrix = [[f64; 4]; 4];
const IDENTITY: Matrix = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// Every (mesh, world matrix) the scene draws, depth first in node order.
fn mesh_instances(root: &Root) -> Result<Vec<(Index<json::Mesh>, Matrix)>, Fail> {
    let scene = match root.scene {
        Some(i) => Some(get(&root.scenes, i, "scene")?),
        None => root.scenes.first(),
    };
    let Some(scene) = scene else {
        return Ok((0..root.meshes.len())
            .map(|m| (Index::new(m as u32), IDENTITY))
            .collect());
    };
    let node_count = root.nodes.len();
    let mut out = Vec::new();
    let mut stack: Vec<(Index<json::Node>, Matrix, usize)> = scene
        .nodes
        .iter()
        .rev()
        .map(|&n| (n, IDENTITY, 0))
        .collect();
    let mut visits = 0u64;
    while let Some((index, parent, depth)) = stack.pop() {
        let node = get(&root.nodes, index, "node")?;
        // A path longer than the node count repeats a node: the hierarchy has a cycle.
        if depth > node_count {
            return Err(syntax(format!(
                "node {} is its own ancestor (cyclic node hierarchy)",
                index.value()
            )));
        }
        visits += 1;
        if visits > MAX_NODE_VISITS {
            return Err(syntax(format!(
                "the node hierarchy instantiates more than {MAX_NODE_VISITS} nodes"
            )));
        }
        let world = multiply(&parent, &local_matrix(node));
        if world.iter().flatten().any(|v| !v.is_finite()) {
            return Err(syntax(format!(
                "node {} has a non-finite transform",
                index.value()
            )));
        }
        if let Some(m) = node.mesh {
            get(&root.meshes, m, "mesh")?;
            out.push((m, world));
        }
        for &child in node.children.iter().flatten().rev() {
            stack.push((child, world, depth + 1));
        }
    }
    Ok(out)
}

/// A node's local matrix in `f64`, column-major like glTF (`m[column][row]`): its `matrix`, or
/// translation · rotation · scale composed here in `f64`.
fn local_matrix(node: &json::Node) -> Matrix {
    if let Some(m) = node.matrix {
        return std::array::from_fn(|c| std::array::from_fn(|r| f64::from(m[4 * c + r])));
    }
    trs(
        node.translation.unwrap_or([0.0; 3]),
        node.rotation.map_or([0.0, 0.0, 0.0, 1.0], |q| q.0),
        node.scale.unwrap_or([1.0; 3]),
    )
}

fn trs(translation: [f32; 3], rotation: [f32; 4], scale: [f32; 3]) -> Matrix {
    let [x, y, z, w] = rotation.map(f64::from);
    // Unit quaternions are expected; normalizing keeps a sloppy exporter's rotation a rotation.
    let n = (x * x + y * y + z * z + w * w).sqrt();
    let (x, y, z, w) = if n > 0.0 && n.is_finite() {
        (x / n, y / n, z / n, w / n)
    } else {
        (0.0, 0.0, 0.0, 1.0)
    };
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y + z * w),
            2.0 * (x * z - y * w),
        ],
        [
            2.0 * (x * y - z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z + x * w),
        ],
        [
            2.0 * (x * z + y * w),
            2.0 * (y * z - x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    let s = scale.map(f64::from);
    let t = translation.map(f64::from);
    let mut m = IDENTITY;
    for c in 0..3 {
        for row in 0..3 {
            m[c][row] = r[c][row] * s[c];
        }
    }
    m[3] = [t[0], t[1], t[2], 1.0];
    m
}

fn multiply(a: &Matrix, b: &Matrix) -> Matrix {
    std::array::from_fn(|c| std::array::from_fn(|r| (0..4).map(|k| a[k][r] * b[c][k]).sum()))
}

fn determinant3(m: &Matrix) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

fn transform_point(m: &Matrix, p: [f32; 3]) -> [f64; 3] {
    let p = p.map(f64::from);
    std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r])
}

/// Triangles a primitive will produce (an error for points and lines).
fn triangle_count(root: &Root, prim: &json::mesh::Primitive, what: &str) -> Result<u64, Fail> {
    let n = match prim.indices {
        Some(i) => get(&root.accessors, i, "accessor")?.count.0,
        None => position_accessor(root, prim, what)?.count.0,
    };
    match checked(&prim.mode, &format!("{what}: mode"))? {
        Mode::Triangles => Ok(n / 3),
        Mode::TriangleStrip | Mode::TriangleFan => Ok(n.saturating_sub(2)),
        mode => Err(syntax(format!(
            "{what}: mode {mode:?} has no triangles (triangle lists, strips and fans are read)"
        ))),
    }
}

/// Triangles of a primitive from its vertex order (glTF 2.0 §3.7.2.1).
fn assemble(mode: Mode, order: &[u32], what: &str) -> Result<Vec<[u32; 3]>, Fail> {
    let n = order.len();
    Ok(match mode {
        Mode::Triangles => {
            if !n.is_multiple_of(3) {
                return Err(syntax(format!(
                    "{what}: {n} indices are not a whole number of triangles"
                )));
            }
            order.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
        }
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|i| {
                let odd = i % 2;
                [order[i], order[i + 1 + odd], order[i + 2 - odd]]
            })
            .collect(),
        Mode::TriangleFan => (1..n.saturating_sub(1))
            .map(|i| [order[i], order[i + 1], order[0]])
            .collect(),
        mode => {
            return Err(syntax(format!("{what}: mode {mode:?} has no triangles")));
        }
    })
}

/// The byte window of an accessor: `(bytes from its first element on, stride, count)`, with every
/// offset checked against the buffer view and the buffer.
fn accessor_window<'b>(
    root: &Root,
    acc: &json::Accessor,
    buffers: &'b [Cow<'_, [u8]>],
    elem: usize,
    what: &str,
) -> Result<(&'b [u8], usize, usize), Fail> {
    if acc.sparse.is_some() {
        return Err(syntax(format!(
            "{what}: sparse accessors are not supported"
        )));
    }
    let count = usize::try_from(acc.count.0).map_err(|_| {
        syntax(format!(
            "{what}: accessor count {} is too large",
            acc.count.0
        ))
    })?;
    let view_index = acc
        .buffer_view
        .ok_or_else(|| syntax(format!("{what}: accessor without a buffer view")))?;
    let view = get(&root.buffer_views, view_index, "buffer view")?;
    let stride = view.byte_stride.map_or(elem, |s| s.0);
    if stride < elem {
        return Err(syntax(format!(
            "{what}: byteStride {stride} is smaller than an element ({elem} bytes)"
        )));
    }
    let buffer = buffers.get(view.buffer.value()).ok_or_else(|| {
        syntax(format!(
            "{what}: buffer {} does not exist",
            view.buffer.value()
        ))
    })?;
    let view_offset = view.byte_offset.map_or(0, |o| o.0);
    let view_bytes = view_offset
        .checked_add(view.byte_length.0)
        .and_then(|end| {
            let (start, end) = (
                usize::try_from(view_offset).ok()?,
                usize::try_from(end).ok()?,
            );
            buffer.get(start..end)
        })
        .ok_or_else(|| {
            truncated(
                view_offset,
                format!(
                    "{what}: buffer view {} runs past its buffer",
                    view_index.value()
                ),
            )
        })?;
    if count == 0 {
        return Ok((&[], stride, 0));
    }
    let offset = usize::try_from(acc.byte_offset.map_or(0, |o| o.0)).unwrap_or(usize::MAX);
    let span = (count - 1)
        .checked_mul(stride)
        .and_then(|s| s.checked_add(elem))
        .and_then(|s| s.checked_add(offset));
    match span {
        Some(end) if end <= view_bytes.len() => Ok((&view_bytes[offset..], stride, count)),
        _ => Err(truncated(
            view_offset,
            format!(
                "{what}: {count} elements run past buffer view {}",
                view_index.value()
            ),
        )),
    }
}

fn read_positions(
    root: &Root,
    acc: &json::Accessor,
    buffers: &[Cow<'_, [u8]>],
    what: &str,
) -> Result<Vec<[f32; 3]>, Fail> {
    let ty = checked(&acc.type_, &format!("{what}: POSITION type"))?;
    let ct = checked(
        &acc.component_type,
        &format!("{what}: POSITION componentType"),
    )?
    .0;
    if ct != ComponentType::F32 || *ty != Type::Vec3 {
        return Err(syntax(format!(
            "{what}: POSITION is {ct:?} {ty:?}, only float32 VEC3 is read"
        )));
    }
    let (bytes, stride, count) = accessor_window(root, acc, buffers, 12, what)?;
    Ok((0..count)
        .map(|i| {
            let e = &bytes[i * stride..i * stride + 12];
            std::array::from_fn(|k| {
                f32::from_le_bytes([e[4 * k], e[4 * k + 1], e[4 * k + 2], e[4 * k + 3]])
            })
        })
        .collect())
}

fn read_indices(
    root: &Root,
    acc: &json::Accessor,
    buffers: &[Cow<'_, [u8]>],
    what: &str,
) -> Result<Vec<u32>, Fail> {
    let ty = checked(&acc.type_, &format!("{what}: indices type"))?;
    if *ty != Type::Scalar {
        return Err(syntax(format!("{what}: indices are {ty:?}, not scalars")));
    }
    let size = match checked(
        &acc.component_type,
        &format!("{what}: indices componentType"),
    )?
    .0
    {
        ComponentType::U8 => 1,
        ComponentType::U16 => 2,
        ComponentType::U32 => 4,
        t => {
            return Err(syntax(format!(
                "{what}: indices of type {t:?} (expected unsigned integers)"
            )));
        }
    };
    let (bytes, stride, count) = accessor_window(root, acc, buffers, size, what)?;
    Ok((0..count)
        .map(|i| {
            let e = &bytes[i * stride..];
            match size {
                1 => u32::from(e[0]),
                2 => u32::from(u16::from_le_bytes([e[0], e[1]])),
                _ => u32::from_le_bytes([e[0], e[1], e[2], e[3]]),
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans() {
        let order = [0, 1, 2, 3, 4];
        let strip = assemble(Mode::TriangleStrip, &order, "t").unwrap();
        assert_eq!(strip, vec![[0, 1, 2], [1, 3, 2], [2, 3, 4]]);
        let fan = assemble(Mode::TriangleFan, &order, "t").unwrap();
        assert_eq!(fan, vec![[1, 2, 0], [2, 3, 0], [3, 4, 0]]);
        assert!(assemble(Mode::Triangles, &order, "t").is_err());
        assert!(assemble(Mode::Lines, &order, "t").is_err());
    }

    #[test]
    fn trs_matches_rotation_then_scale_then_translation() {
        // 90 degrees about z: x -> y.
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let m = trs([1.0, 2.0, 3.0], [0.0, 0.0, h, h], [2.0, 1.0, 1.0]);
        let p = transform_point(&m, [1.0, 0.0, 0.0]);
        let want = [1.0, 4.0, 3.0];
        for k in 0..3 {
            assert!((p[k] - want[k]).abs() < 1e-6, "{p:?}");
        }
        assert!(determinant3(&m) > 0.0);
    }

    #[test]
    fn percent_escapes() {
        assert_eq!(percent_decode("a%20b.bin"), b"a b.bin");
        assert_eq!(percent_decode("bad%zz%2"), b"bad%zz%2");
        assert_eq!(percent_decode("..%2F%2e%2E"), b"../..");
    }

    #[test]
    fn uris_resolve_lexically_inside_the_folder() {
        let d = Path::new("m");
        assert_eq!(
            resolve_inside(d, "a/./b/../c.bin"),
            Some(d.join("a").join("c.bin"))
        );
        assert_eq!(resolve_inside(d, "a/../../c.bin"), None);
        assert_eq!(resolve_inside(d, ".."), None);
        assert_eq!(resolve_inside(d, "a/.."), None);
        assert_eq!(resolve_inside(d, ""), None);
    }
}
