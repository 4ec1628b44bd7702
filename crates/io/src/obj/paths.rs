//! Finding the files an OBJ or MTL names, as forgiving as Blender and assimp: Windows paths
//! (`.\tex.jpg`, `C:\models\tex.jpg`), a file name in another case than on disk, and a path from
//! the author's machine whose file lies beside the model.

use std::path::{Path, PathBuf};

/// Where `name` (as written in an OBJ or MTL file) may be, relative to `dir`, in the order to
/// try: the path with backslashes as separators, then its file name alone in `dir`.
pub fn candidates(dir: &Path, name: &str) -> Vec<PathBuf> {
    let normalized = name.trim().replace('\\', "/");
    let relative = normalized.trim_start_matches("./");
    let mut out = vec![dir.join(relative)];
    if let Some(file_name) = Path::new(relative).file_name() {
        let beside = dir.join(file_name);
        if !out.contains(&beside) {
            out.push(beside);
        }
    }
    out
}

/// `path` on disk: itself where it exists, else the path whose components match it ignoring
/// case (a model made on Windows or macOS names `Tex.JPG` for `tex.jpg`), else `path` unchanged
/// (so the error names what the file asked for).
pub fn on_disk(path: &Path) -> PathBuf {
    if path.exists() {
        return path.to_path_buf();
    }
    let mut found = PathBuf::new();
    for component in path.components() {
        let next = found.join(component);
        if next.exists() {
            found = next;
            continue;
        }
        let wanted = component.as_os_str().to_string_lossy().to_lowercase();
        let dir = if found.as_os_str().is_empty() {
            Path::new(".")
        } else {
            &found
        };
        let matched = std::fs::read_dir(dir).ok().and_then(|entries| {
            entries
                .flatten()
                .find(|e| e.file_name().to_string_lossy().to_lowercase() == wanted)
        });
        match matched {
            Some(entry) => found.push(entry.file_name()),
            None => return path.to_path_buf(),
        }
    }
    found
}
