//! Trimmed B-rep models from ISO 10303-21 (STEP) files: the Part 21 reader ([`part21`]), the
//! B-rep and geometry entities ([`brep`], [`surface`], [`nurbs`]), trimming ([`trim`]), the model
//! ([`model`]) and its evaluator ([`eval`]). See `docs/patches.md` ("Trimmed B-rep models").
//!
//! ```no_run
//! use gwn::patch::step::{load_step, StepWindingNumber};
//! let model = load_step(std::path::Path::new("part.step"))?;
//! let w = StepWindingNumber::new(&model).eval([0.0, 0.0, 0.0]);
//! # Ok::<(), gwn::patch::step::StepError>(())
//! ```

pub mod brep;
pub mod eval;
pub mod model;
pub mod nurbs;
pub mod part21;
pub mod surface;
pub mod tessellate;
pub mod trim;

use std::fmt;
use std::path::{Path, PathBuf};

pub use eval::{StepEvaluation, StepOptions, StepWindingNumber};
pub use model::{StepInfo, StepModel};

/// A STEP file that cannot be read or turned into a model. Displays as one line.
///
/// The kinds: [`Io`](StepError::Io) (the file cannot be read), parse errors
/// ([`TooLarge`](StepError::TooLarge), [`Syntax`](StepError::Syntax),
/// [`Dangling`](StepError::Dangling)), [`Unsupported`](StepError::Unsupported) (an entity the
/// reader does not know, with its name and `#id`), [`Invalid`](StepError::Invalid) (wrong
/// parameters), [`Geometry`](StepError::Geometry) (parameters that do not make a face or edge)
/// and [`NoFaces`](StepError::NoFaces). [`load_step`] wraps every one but `Io` (which has its
/// own path) in [`InFile`](StepError::InFile); [`StepError::cause`] unwraps it.
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// The file could not be read.
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error kind (`NotFound`, `PermissionDenied`, …).
        kind: std::io::ErrorKind,
        /// Its message.
        message: String,
    },
    /// Over the byte or entity cap ([`part21::MAX_BYTES`], [`part21::MAX_ENTITIES`]).
    TooLarge(String),
    /// Not Part 21 syntax.
    Syntax {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// `#id` refers to an instance the file does not define.
    Dangling {
        /// The referring instance.
        id: u64,
        /// The missing one.
        target: u64,
    },
    /// An entity the reader does not support where it occurs.
    Unsupported {
        /// Its `#id`.
        id: u64,
        /// Its name (complex entities as `(A B …)`).
        entity: String,
        /// Where it occurs, e.g. "as a face surface".
        context: String,
    },
    /// A supported entity with wrong parameters (types, counts, non-positive radii or
    /// weights, knots).
    Invalid {
        /// Its `#id`.
        id: u64,
        /// Its name.
        entity: String,
        /// What is wrong.
        message: String,
    },
    /// A supported entity whose parameters are well formed but do not make geometry: an edge's
    /// vertices running against its open curve, a face whose loops enclose no area.
    Geometry {
        /// Its `#id`.
        id: u64,
        /// Its name.
        entity: String,
        /// What is wrong.
        message: String,
    },
    /// No face to evaluate.
    NoFaces,
    /// One of the errors above in the file `path` (from [`load_step`]).
    InFile {
        /// The file.
        path: PathBuf,
        /// What is wrong with it (never `InFile` or `Io`).
        error: Box<StepError>,
    },
}

impl StepError {
    /// The error without the file it occurred in ([`StepError::InFile`] unwrapped).
    pub fn cause(&self) -> &StepError {
        match self {
            StepError::InFile { error, .. } => error,
            e => e,
        }
    }

    /// The file named by the error, if any.
    pub fn path(&self) -> Option<&Path> {
        match self {
            StepError::Io { path, .. } | StepError::InFile { path, .. } => Some(path),
            _ => None,
        }
    }
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StepError::Io { path, message, .. } => write!(f, "{}: {message}", path.display()),
            StepError::TooLarge(m) => write!(f, "{m}"),
            StepError::Syntax { line, message } => write!(f, "line {line}: {message}"),
            StepError::Dangling { id, target } => {
                write!(
                    f,
                    "#{id} refers to #{target}, which the file does not define"
                )
            }
            StepError::Unsupported {
                id,
                entity,
                context,
            } => write!(f, "#{id} {entity}: not supported {context}"),
            StepError::Invalid {
                id,
                entity,
                message,
            }
            | StepError::Geometry {
                id,
                entity,
                message,
            } => write!(f, "#{id} {entity}: {message}"),
            StepError::NoFaces => write!(f, "no B-rep face found (ADVANCED_FACE in shells)"),
            StepError::InFile { path, error } => write!(f, "{}: {error}", path.display()),
        }
    }
}

impl std::error::Error for StepError {}

/// Whether `path` has a STEP extension (`.step`, `.stp`, any case).
pub fn is_step_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("step") || e.eq_ignore_ascii_case("stp"))
}

/// Reads a STEP file into a trimmed model. Errors are one line naming the file:
/// [`StepError::Io`] if it cannot be read, else [`StepError::InFile`] around the reason.
pub fn load_step(path: &Path) -> Result<StepModel, StepError> {
    let io = |e: std::io::Error| StepError::Io {
        path: path.to_path_buf(),
        kind: e.kind(),
        message: e.to_string(),
    };
    let in_file = |e: StepError| StepError::InFile {
        path: path.to_path_buf(),
        error: Box::new(e),
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if meta.len() > part21::MAX_BYTES as u64 {
        return Err(in_file(StepError::TooLarge(format!(
            "{} bytes, more than the {} accepted",
            meta.len(),
            part21::MAX_BYTES
        ))));
    }
    let bytes = std::fs::read(path).map_err(io)?;
    // Part 21 is ISO 8859-1 / ASCII with escapes; non-UTF-8 bytes only occur inside strings,
    // which the reader does not interpret.
    let text = String::from_utf8_lossy(&bytes);
    parse_step(&text).map_err(in_file)
}

/// Parses STEP text into a trimmed model.
pub fn parse_step(text: &str) -> Result<StepModel, StepError> {
    let file = part21::parse(text)?;
    StepModel::from_part21(&file)
}

pub(crate) fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(crate) fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
