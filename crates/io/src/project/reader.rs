//! Reading an archive safely: entry names checked against path traversal, and every entry read
//! through the caps of `LoadLimits` rather than the sizes the archive declares.

use std::io::{Cursor, Read};
use std::path::{Path, PathBuf};

use rt_core::error::{Error, Result};

/// Caps on what loading a project may decompress.
#[derive(Clone, Copy, Debug)]
pub struct LoadLimits {
    pub max_entry_bytes: u64,
    pub max_total_bytes: u64,
    pub max_entries: usize,
}

impl Default for LoadLimits {
    fn default() -> Self {
        LoadLimits {
            // A 16k x 16k RGBA texture decoded, or ~40M triangles: far above real projects,
            // far below what would take the machine down.
            max_entry_bytes: 1 << 30,
            max_total_bytes: 4 << 30,
            max_entries: 100_000,
        }
    }
}

/// An opened archive with its entry names checked and a running total of decompressed bytes.
pub(super) struct Archive<'a> {
    zip: zip::ZipArchive<Cursor<&'a [u8]>>,
    path: PathBuf,
    limits: LoadLimits,
    total: u64,
}

impl<'a> Archive<'a> {
    pub(super) fn open(bytes: &'a [u8], path: &Path, limits: &LoadLimits) -> Result<Self> {
        let error = |message: String| Error::File {
            path: path.into(),
            message,
        };
        let zip = zip::ZipArchive::new(Cursor::new(bytes))
            .map_err(|e| error(format!("not a readable project archive: {e}")))?;
        if zip.len() > limits.max_entries {
            return Err(error(format!(
                "has {} entries; the limit is {}",
                zip.len(),
                limits.max_entries
            )));
        }
        for name in zip.file_names() {
            let name = name.map_err(|e| error(format!("unreadable entry name: {e}")))?;
            check_entry_name(&name).map_err(|m| error(format!("entry '{name}': {m}")))?;
        }
        Ok(Archive {
            zip,
            path: path.into(),
            limits: *limits,
            total: 0,
        })
    }

    pub(super) fn error(&self, message: String) -> Error {
        Error::File {
            path: self.path.clone(),
            message,
        }
    }

    /// An entry's bytes, read through a cap so that a lying size field cannot exhaust memory.
    pub(super) fn read(&mut self, name: &str) -> Result<Vec<u8>> {
        check_entry_name(name).map_err(|m| self.error(format!("entry '{name}': {m}")))?;
        let remaining = self.limits.max_total_bytes.saturating_sub(self.total);
        let cap = self.limits.max_entry_bytes.min(remaining);
        let mut data = Vec::new();
        let result = match self.zip.by_name(name) {
            Ok(file) => file
                .take(cap + 1)
                .read_to_end(&mut data)
                .map_err(|e| format!("entry '{name}' is corrupt: {e}")),
            Err(zip::result::ZipError::FileNotFound) => Err(format!("entry '{name}' is missing")),
            Err(e) => Err(format!("entry '{name}': {e}")),
        };
        result.map_err(|m| self.error(m))?;
        if data.len() as u64 > cap {
            return Err(self.error(format!(
                "entry '{name}' decompresses to more than {} bytes (limits: {} per entry, {} in all)",
                cap, self.limits.max_entry_bytes, self.limits.max_total_bytes
            )));
        }
        self.total += data.len() as u64;
        Ok(data)
    }
}

/// Entry names must be plain relative paths: no absolute paths, drive letters, `..` or backslashes.
fn check_entry_name(name: &str) -> Result<(), &'static str> {
    if name.is_empty() || name.contains('\0') {
        return Err("empty or contains NUL");
    }
    if name.starts_with('/') || name.contains('\\') || name.as_bytes().get(1) == Some(&b':') {
        return Err("absolute or non-portable path (possible path traversal)");
    }
    if name.split('/').any(|part| part == "..") {
        return Err("contains '..' (path traversal)");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_names_that_could_escape_are_rejected() {
        for name in ["../x", "a/../../x", "/etc/passwd", "C:/x", "a\\..\\x", ""] {
            assert!(check_entry_name(name).is_err(), "{name}");
        }
        assert!(check_entry_name("meshes/0.bin").is_ok());
    }
}
