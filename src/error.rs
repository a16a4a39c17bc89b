//! Error types, one enum per concern, each carrying the context a user needs to find the problem.

use std::fmt;
use std::path::PathBuf;

/// A mesh that cannot be evaluated as given.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshError {
    /// A triangle references a vertex that does not exist.
    IndexOutOfRange {
        /// Triangle (0-based).
        face: usize,
        /// The offending index.
        index: u64,
        /// Number of vertices in the mesh.
        vertex_count: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    NonFiniteCoordinate {
        /// Vertex (0-based).
        vertex: usize,
        /// Axis 0, 1 or 2.
        axis: usize,
        /// The value found.
        value: f64,
    },
    /// More vertices than a `u32` index can address.
    TooManyVertices {
        /// Number of vertices.
        count: usize,
    },
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshError::IndexOutOfRange {
                face,
                index,
                vertex_count,
            } => write!(
                f,
                "face {face} references vertex {index}, but the mesh has {vertex_count} vertices"
            ),
            MeshError::NonFiniteCoordinate {
                vertex,
                axis,
                value,
            } => write!(
                f,
                "vertex {vertex} has a non-finite coordinate {value} on axis {}",
                ["x", "y", "z"][*axis]
            ),
            MeshError::TooManyVertices { count } => {
                write!(f, "{count} vertices do not fit 32-bit indices")
            }
        }
    }
}

impl std::error::Error for MeshError {}

/// Where in a file a problem was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// 1-based line of a text file.
    Line(usize),
    /// Byte offset in a binary file.
    Byte(u64),
    /// 0-based face (element) index.
    Face(usize),
    /// 0-based vertex (element) index.
    Vertex(usize),
    /// No finer location is known.
    File,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(l) => write!(f, "line {l}"),
            Location::Byte(b) => write!(f, "byte {b}"),
            Location::Face(i) => write!(f, "face {i}"),
            Location::Vertex(i) => write!(f, "vertex {i}"),
            Location::File => write!(f, "file"),
        }
    }
}

/// A file that could not be read as a mesh or as points.
#[derive(Debug)]
pub struct LoadError {
    /// The file.
    pub path: PathBuf,
    /// Where in the file.
    pub location: Location,
    /// What is wrong.
    pub kind: LoadErrorKind,
}

/// What went wrong while loading.
#[derive(Debug)]
pub enum LoadErrorKind {
    /// The operating system refused to read the file.
    Io(std::io::Error),
    /// A file the file refers to (a glTF buffer's `.bin`) could not be read.
    Referenced {
        /// What refers to it, e.g. `buffer 0`.
        what: String,
        /// The referenced file.
        file: PathBuf,
        /// Why it could not be read.
        error: std::io::Error,
    },
    /// The format could not be determined from extension or content.
    UnknownFormat,
    /// The file ends before the data its header or structure promises.
    Truncated(String),
    /// The content does not follow the format.
    Syntax(String),
    /// The data parsed but does not form a valid mesh.
    Mesh(MeshError),
    /// The mesh file holds no triangles (including empty files).
    Empty,
    /// The points or point-cloud file holds no points (empty, or only comments and a header).
    NoPoints,
    /// A file that is not a regular file (pipe, device) gave more bytes than the reader takes
    /// from such a source (`/dev/zero` never ends).
    TooLong {
        /// The limit in bytes.
        limit: u64,
    },
}

/// Something a loader accepted but the user may want to know, e.g. an ignored PLY header line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadWarning {
    /// Where in the file.
    pub location: Location,
    /// What was ignored or assumed.
    pub message: String,
}

impl fmt::Display for LoadWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.location {
            Location::File => write!(f, "{}", self.message),
            ref l => write!(f, "{l}: {}", self.message),
        }
    }
}

impl LoadError {
    /// Convenience constructor.
    pub fn new(path: impl Into<PathBuf>, location: Location, kind: LoadErrorKind) -> Self {
        LoadError {
            path: path.into(),
            location,
            kind,
        }
    }
}

impl fmt::Display for LoadErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LoadErrorKind::Io(e) => write!(f, "cannot read: {e}"),
            LoadErrorKind::Referenced { what, file, error } => {
                write!(f, "{what}: cannot read {}: {error}", file.display())
            }
            LoadErrorKind::UnknownFormat => {
                f.write_str("unknown format (expected .obj, .stl, .off, .ply, .gltf or .glb)")
            }
            LoadErrorKind::Truncated(s) => write!(f, "truncated: {s}"),
            LoadErrorKind::Syntax(s) => f.write_str(s),
            LoadErrorKind::Mesh(e) => write!(f, "{e}"),
            LoadErrorKind::Empty => f.write_str("contains no triangles"),
            LoadErrorKind::NoPoints => f.write_str("contains no points"),
            LoadErrorKind::TooLong { limit } => write!(
                f,
                "not a regular file and longer than {limit} bytes (the limit for pipes and \
                 devices)"
            ),
        }
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let p = self.path.display();
        match (&self.location, &self.kind) {
            // A mesh error names its face or vertex itself.
            (Location::File, _) | (_, LoadErrorKind::Mesh(_)) => write!(f, "{p}: {}", self.kind),
            (l, _) => write!(f, "{p}: {l}: {}", self.kind),
        }
    }
}

impl std::error::Error for LoadError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            LoadErrorKind::Io(e) => Some(e),
            LoadErrorKind::Referenced { error, .. } => Some(error),
            LoadErrorKind::Mesh(e) => Some(e),
            _ => None,
        }
    }
}
