//! The error type of `rt-core`: every variant names the file (and line) or the scene part at fault.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A syntax or range error at a line of a text file (OBJ, MTL).
    #[error("{}:{line}: {message}", path.display())]
    Parse {
        path: PathBuf,
        line: usize,
        message: String,
    },
    /// A problem with a whole file (a missing or corrupt texture, a bad camera file).
    #[error("{}: {message}", path.display())]
    File { path: PathBuf, message: String },
    /// The scene itself is invalid (names the object, vertex or field).
    #[error("{0}")]
    Scene(String),
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
