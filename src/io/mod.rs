//! Reading meshes (OBJ, STL, OFF, PLY, glTF/GLB) and query points (text, `.npy`), writing results.
//!
//! Every loader works on an in-memory byte slice ([`load_mesh_from_bytes`]), so fuzzing and
//! tests need no files, and every error is a [`LoadError`] naming the file and a location (line
//! for text, byte offset for binary data, face or vertex index for bad indices and coordinates).
//!
//! The loaders never repair: every face of the file is kept (degenerate, duplicated, flipped), and
//! polygons are fan-triangulated as `(v0, vi, vi+1)`. Only STL files are welded by default
//! (bit-identical positions merged), because STL stores every triangle's corners separately.
//! See `docs/formats.md` for what each reader accepts and rejects.
//!
//! ```
//! use gwn::io::{load_mesh_from_bytes, Format};
//! let off = b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
//! let loaded = load_mesh_from_bytes(off, "tri.off", Some(Format::Off))?;
//! assert_eq!(loaded.mesh.triangles().len(), 1);
//! # Ok::<(), gwn::error::LoadError>(())
//! ```

pub mod cloud;
pub mod detect;
mod gltf_scene;
mod obj;
mod off;
mod ply;
pub mod points;
mod stl;
pub mod tets;

use std::fmt;
use std::path::Path;

use crate::error::{LoadError, LoadErrorKind, LoadWarning, Location, MeshError};
use crate::mesh::Mesh;

pub use detect::{format_from_content, format_from_extension};
pub use points::{load_points, load_points_from_bytes};

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Wavefront OBJ (text).
    Obj,
    /// STL, ascii or binary.
    Stl,
    /// Object File Format (text).
    Off,
    /// Stanford PLY, ascii or binary (either endianness).
    Ply,
    /// glTF 2.0: `.glb` (binary) or `.gltf` (JSON); all mesh instances of the scene, transformed.
    Gltf,
}

impl Format {
    /// All formats, in a fixed order.
    pub const ALL: [Format; 5] = [
        Format::Obj,
        Format::Stl,
        Format::Off,
        Format::Ply,
        Format::Gltf,
    ];

    /// True for formats that are welded by default: STL, which stores every triangle's corners
    /// separately, and glTF, whose exporters split vertices wherever a normal or texture
    /// coordinate changes (every such seam would otherwise be a boundary edge).
    pub fn welds_by_default(self) -> bool {
        matches!(self, Format::Stl | Format::Gltf)
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Obj => "OBJ",
            Format::Stl => "STL",
            Format::Off => "OFF",
            Format::Ply => "PLY",
            Format::Gltf => "glTF",
        })
    }
}

/// Options for [`load_mesh_with`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Merge bit-identical positions after loading. `None`: the format's default (on for STL and
    /// glTF, off for OBJ, OFF and PLY).
    pub weld: Option<bool>,
}

/// A mesh as loaded from a file, with what the loader did to it.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    /// The mesh.
    pub mesh: Mesh,
    /// The format that was read.
    pub format: Format,
    /// Vertices removed by welding (0 when welding was off).
    pub welded_vertices: usize,
    /// Polygons with more than three corners that were fan-triangulated.
    pub polygons_triangulated: usize,
    /// What the reader accepted but ignored (e.g. unknown PLY header lines).
    pub warnings: Vec<LoadWarning>,
}

/// What a format reader hands back before validation: positions, triangles and the number of
/// polygons it fan-triangulated. Indices are already checked against the vertex count.
#[derive(Debug, Default)]
pub(crate) struct RawMesh {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub polygons: usize,
    pub warnings: Vec<LoadWarning>,
}

/// A reader error before the file name is attached.
pub(crate) type Fail = (Location, LoadErrorKind);

/// Capacity for `count` elements of at least `min_bytes` each from a file of `len` bytes: never
/// more than the file can hold, so a lying header cannot make us allocate gigabytes.
pub(crate) fn capped_capacity(count: u64, len: usize, min_bytes: usize) -> usize {
    let fit = (len / min_bytes.max(1)) as u64;
    count.min(fit) as usize
}

/// Appends the fan triangulation `(v0, vi, vi+1)` of `poly` to `out`; returns true when the
/// polygon had more than three corners. Polygons with fewer than three corners add nothing.
pub(crate) fn fan(poly: &[u32], out: &mut Vec<[u32; 3]>) -> bool {
    if poly.len() < 3 {
        return false;
    }
    for i in 1..poly.len() - 1 {
        out.push([poly[0], poly[i], poly[i + 1]]);
    }
    poly.len() > 3
}

/// The error for a face index outside the vertex range.
pub(crate) fn index_error(face: usize, index: u64, vertex_count: usize) -> Fail {
    (
        Location::Face(face),
        LoadErrorKind::Mesh(MeshError::IndexOutOfRange {
            face,
            index,
            vertex_count,
        }),
    )
}

/// Loads a mesh, choosing the format by extension (case-insensitive) or, failing that, by
/// content; STL and glTF are welded, other formats are not. External glTF buffers are read
/// relative to the file's directory.
pub fn load_mesh(path: impl AsRef<Path>) -> Result<LoadedMesh, LoadError> {
    load_mesh_with(path, &LoadOptions::default())
}

/// Loads a mesh with explicit options.
pub fn load_mesh_with(
    path: impl AsRef<Path>,
    options: &LoadOptions,
) -> Result<LoadedMesh, LoadError> {
    let path = path.as_ref();
    let bytes = read_input(path)?;
    let base_dir = path.parent().unwrap_or(Path::new("."));
    load_mesh_from_bytes_in(
        &bytes,
        path,
        format_from_extension(path),
        options,
        Some(base_dir),
    )
}

/// What a mesh-or-cloud file holds ([`load_mesh_or_cloud`]; [`crate::input::load_input`] also
/// reads curved inputs, but keeps only the mesh of a [`LoadedMesh`]).
#[derive(Debug)]
pub enum MeshOrCloud {
    /// A triangle mesh.
    Mesh(LoadedMesh),
    /// An oriented point cloud and the reader's warnings.
    Cloud(crate::mesh::PointCloud, Vec<LoadWarning>),
}

/// Reads a mesh or an oriented point cloud, parsing the file once: text point formats
/// (by extension) are clouds; a PLY (by extension, or by content without one) is a mesh when it
/// has faces and a cloud otherwise; anything else is a mesh. What `gwn info` reads.
pub fn load_mesh_or_cloud(path: &Path, options: &LoadOptions) -> Result<MeshOrCloud, LoadError> {
    use cloud::CloudFormat;
    if cloud::cloud_format_from_extension(path) == Some(CloudFormat::Text) {
        let (cloud, warnings) = cloud::load_point_cloud_with_warnings(path)?;
        return Ok(MeshOrCloud::Cloud(cloud, warnings));
    }
    let bytes = read_input(path)?;
    let format = format_from_extension(path);
    let blank = bytes.iter().all(u8::is_ascii_whitespace);
    if !blank && format.or_else(|| format_from_content(&bytes)) == Some(Format::Ply) {
        let err = |(location, kind): Fail| LoadError::new(path, location, kind);
        let data = ply::read(&bytes, &cloud::PLY_MESH_OR_CLOUD).map_err(err)?;
        if data.triangles.is_empty() {
            let (cloud, warnings) = cloud::cloud_from_ply(data, path)?;
            return Ok(MeshOrCloud::Cloud(cloud, warnings));
        }
        let column = |k: usize| data.columns[k].as_deref().unwrap_or(&[]);
        let (x, y, z) = (column(0), column(1), column(2));
        let raw = RawMesh {
            positions: (0..x.len()).map(|i| [x[i], y[i], z[i]]).collect(),
            triangles: data.triangles,
            polygons: data.polygons,
            warnings: data.warnings,
        };
        return finish_mesh(raw, Format::Ply, path, options).map(MeshOrCloud::Mesh);
    }
    let base_dir = path.parent().unwrap_or(Path::new("."));
    load_mesh_from_bytes_in(&bytes, path, format, options, Some(base_dir)).map(MeshOrCloud::Mesh)
}

/// The most bytes read from a file that is not a regular file (a pipe, a device): such a file has
/// no size to check first, and some never end (`/dev/zero`). Regular files are read whole.
pub const MAX_STREAM_BYTES: u64 = 1 << 28;

/// Reads a whole input file for a loader. Regular files are read whole; anything else (pipes,
/// devices, `/dev/stdin`) at most [`MAX_STREAM_BYTES`], beyond which it is a
/// [`LoadErrorKind::TooLong`] error instead of reading until memory runs out.
///
/// The file is opened without blocking (`O_NONBLOCK` on Unix), so a FIFO that no program writes
/// to reads as empty instead of hanging; a pipe or terminal whose writer is alive is read until
/// its writer closes it, as any Unix tool would.
pub fn read_input(path: &Path) -> Result<Vec<u8>, LoadError> {
    use std::io::Read;
    let io_err = |e| LoadError::new(path, Location::File, LoadErrorKind::Io(e));
    let file = crate::base::file::open_nonblocking(path).map_err(io_err)?;
    let meta = file.metadata().map_err(io_err)?;
    let mut bytes = Vec::new();
    if meta.is_file() {
        bytes.reserve(usize::try_from(meta.len()).unwrap_or(0));
        (&file).read_to_end(&mut bytes).map_err(io_err)?;
    } else {
        crate::base::file::read_stream(&file, &mut bytes, MAX_STREAM_BYTES + 1).map_err(io_err)?;
        if bytes.len() as u64 > MAX_STREAM_BYTES {
            return Err(LoadError::new(
                path,
                Location::File,
                LoadErrorKind::TooLong {
                    limit: MAX_STREAM_BYTES,
                },
            ));
        }
    }
    Ok(bytes)
}

/// What kind of non-regular file `meta` describes, for error messages.
fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "a special file"
}

/// The error for a file that is not a regular file, saying what it is.
fn not_regular(meta: &std::fs::Metadata) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!("not a regular file ({})", file_kind(meta)),
    )
}

/// The metadata of `path` (symlinks followed) if it is a regular file; otherwise an
/// `InvalidInput` error saying what it is (`not a regular file (a FIFO)`). Nothing is opened.
pub fn regular_file_metadata(path: &Path) -> std::io::Result<std::fs::Metadata> {
    let meta = std::fs::metadata(path)?;
    if meta.is_file() {
        Ok(meta)
    } else {
        Err(not_regular(&meta))
    }
}

/// Opens `path` only if it is a regular file (symlinks are followed): checked before opening (so
/// platforms without a known `O_NONBLOCK` do not block on a FIFO either) and again through the
/// opened handle (the path may have been swapped in between); the open itself never blocks.
pub fn open_regular(path: &Path) -> std::io::Result<std::fs::File> {
    regular_file_metadata(path)?;
    let file = crate::base::file::open_nonblocking(path)?;
    let after = file.metadata()?;
    if !after.is_file() {
        return Err(not_regular(&after));
    }
    Ok(file)
}

/// Loads a mesh from bytes in memory. `name_for_errors` is what errors call the file;
/// `format_hint` forces a format, `None` detects it from the content.
pub fn load_mesh_from_bytes(
    bytes: &[u8],
    name_for_errors: impl AsRef<Path>,
    format_hint: Option<Format>,
) -> Result<LoadedMesh, LoadError> {
    load_mesh_from_bytes_with(bytes, name_for_errors, format_hint, &LoadOptions::default())
}

/// [`load_mesh_from_bytes`] with explicit options. A glTF file whose buffers are external files
/// is an error here (use [`load_mesh_with`]).
pub fn load_mesh_from_bytes_with(
    bytes: &[u8],
    name_for_errors: impl AsRef<Path>,
    format_hint: Option<Format>,
    options: &LoadOptions,
) -> Result<LoadedMesh, LoadError> {
    load_mesh_from_bytes_in(bytes, name_for_errors, format_hint, options, None)
}

/// The loader; `base_dir` resolves external glTF buffers.
fn load_mesh_from_bytes_in(
    bytes: &[u8],
    name_for_errors: impl AsRef<Path>,
    format_hint: Option<Format>,
    options: &LoadOptions,
    base_dir: Option<&Path>,
) -> Result<LoadedMesh, LoadError> {
    let name = name_for_errors.as_ref();
    let err = |(location, kind): Fail| LoadError::new(name, location, kind);
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(err((Location::File, LoadErrorKind::Empty)));
    }
    let format = format_hint
        .or_else(|| format_from_content(bytes))
        .ok_or_else(|| err((Location::File, LoadErrorKind::UnknownFormat)))?;
    let raw = match format {
        Format::Obj => obj::parse(bytes),
        Format::Stl => stl::parse(bytes),
        Format::Off => off::parse(bytes),
        Format::Ply => ply::parse(bytes),
        Format::Gltf => gltf_scene::parse(bytes, base_dir),
    }
    .map_err(err)?;
    finish_mesh(raw, format, name, options)
}

/// Validates and (as `options` say) welds what a reader returned.
fn finish_mesh(
    raw: RawMesh,
    format: Format,
    name: &Path,
    options: &LoadOptions,
) -> Result<LoadedMesh, LoadError> {
    let err = |(location, kind): Fail| LoadError::new(name, location, kind);
    if raw.triangles.is_empty() {
        return Err(err((Location::File, LoadErrorKind::Empty)));
    }
    let polygons_triangulated = raw.polygons;
    let warnings = raw.warnings;
    let mesh = Mesh::new(raw.positions, raw.triangles).map_err(|e| {
        let location = match e {
            MeshError::IndexOutOfRange { face, .. } => Location::Face(face),
            MeshError::NonFiniteCoordinate { vertex, .. } => Location::Vertex(vertex),
            MeshError::TooManyVertices { .. } => Location::File,
        };
        err((location, LoadErrorKind::Mesh(e)))
    })?;
    let (mesh, welded_vertices) = if options.weld.unwrap_or(format.welds_by_default()) {
        mesh.welded()
    } else {
        (mesh, 0)
    };
    Ok(LoadedMesh {
        mesh,
        format,
        welded_vertices,
        polygons_triangulated,
        warnings,
    })
}

/// Splits text into lines `(1-based number, line without terminator)`; accepts `\n`, `\r\n` and
/// a lone `\r` (classic Mac OS files, which otherwise read as one long line with a misleading
/// error), so every text format reads them and errors name the right line.
pub(crate) fn text_lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    let mut rest = Some(bytes);
    let mut number = 0usize;
    std::iter::from_fn(move || {
        let r = rest?;
        number += 1;
        match r.iter().position(|&b| b == b'\n' || b == b'\r') {
            Some(i) => {
                let skip = if r[i] == b'\r' && r.get(i + 1) == Some(&b'\n') {
                    2
                } else {
                    1
                };
                rest = Some(&r[i + skip..]);
                Some((number, &r[..i]))
            }
            None => {
                rest = None;
                Some((number, r))
            }
        }
    })
}

/// Whitespace-separated tokens of a line (ASCII whitespace only; other bytes are kept): the
/// tokenizer of the mesh formats, and of the column files with [`COLUMN_SEPARATORS`].
pub(crate) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    tokens_separated_by(line, b"")
}

/// What separates values in query-point and point-cloud text files besides whitespace.
pub(crate) const COLUMN_SEPARATORS: &[u8] = b",;";

/// Tokens of a line separated by ASCII whitespace or any byte of `extra`.
pub(crate) fn tokens_separated_by<'a>(
    line: &'a [u8],
    extra: &'a [u8],
) -> impl Iterator<Item = &'a [u8]> {
    line.split(move |b| b.is_ascii_whitespace() || extra.contains(b))
        .filter(|t| !t.is_empty())
}

/// Parses a number token (`f64` or integer type) from bytes.
pub(crate) fn parse_num<T: std::str::FromStr>(tok: &[u8]) -> Option<T> {
    std::str::from_utf8(tok).ok()?.parse().ok()
}

/// A token shown in an error message (lossy, shortened).
pub(crate) fn show(tok: &[u8]) -> String {
    let s = String::from_utf8_lossy(tok);
    if s.chars().count() > 40 {
        format!("{}…", s.chars().take(40).collect::<String>())
    } else {
        s.into_owned()
    }
}
