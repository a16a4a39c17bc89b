//! Library errors as Python exceptions: every message is the library's one-line `Display`, so
//! Python users see the same text as CLI users.

use gwn::error::{LoadError, LoadErrorKind, MeshError};
use pyo3::PyErr;
use pyo3::exceptions::PyValueError;

/// A file that could not be read (the file itself or one it refers to, such as a glTF `.bin`)
/// is an `OSError` of the subclass Python uses for the same cause (`FileNotFoundError`,
/// `PermissionError`, ...); a file that was read but is not a valid mesh / cloud / point list is
/// a `ValueError`.
pub fn load_error(e: LoadError) -> PyErr {
    match &e.kind {
        LoadErrorKind::Io(io) | LoadErrorKind::Referenced { error: io, .. } => {
            os_error(io.kind(), e.to_string())
        }
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// An `OSError` of the subclass matching `kind` (pyo3's mapping of `std::io::Error`), with the
/// library's one-line message.
pub fn os_error(kind: std::io::ErrorKind, message: String) -> PyErr {
    std::io::Error::new(kind, message).into()
}

/// An invalid mesh (index out of range, non-finite coordinate) is a `ValueError`.
pub fn mesh_error(e: MeshError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// Any other library error whose `Display` is a complete sentence.
pub fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}
