//! Parsers from other crates (tobj, ply-rs) guarded: a panic inside one, triggered by odd input,
//! becomes an error naming the file, so bad input never takes the program down.

use std::path::Path;

use rt_core::error::{Error, Result};

/// Runs a parser, turning a panic inside it (a bug in a parser, triggered by odd input) into an
/// error naming the file, so bad input never takes the program down.
pub fn guard_parser<T>(path: &Path, format: &str, parse: impl FnOnce() -> T) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(parse)).map_err(|_| Error::File {
        path: path.into(),
        message: format!("the {format} parser failed on this file (malformed input)"),
    })
}
