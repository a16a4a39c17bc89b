//! Library errors as Python exceptions: every message is the library's one-line `Display`, so
//! Python users see the same text as CLI users.

use gwn::error::{LoadError, LoadErrorKind, MeshError};
use pyo3::PyErr;
use pyo3::exceptions::{PyOSError, PyValueError};

/// A file that could not be read is an `OSError` (missing, permissions); a file that was read
/// but is not a valid mesh / cloud / point list is a `ValueError`.
pub fn load_error(e: LoadError) -> PyErr {
    match e.kind {
        LoadErrorKind::Io(_) => PyOSError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// An invalid mesh (index out of range, non-finite coordinate) is a `ValueError`.
pub fn mesh_error(e: MeshError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// Any other library error whose `Display` is a complete sentence.
pub fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}
