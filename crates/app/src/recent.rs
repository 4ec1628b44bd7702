//! The recent-files list, kept as JSON in the user's configuration folder (saved atomically).

use std::path::{Path, PathBuf};

const MAX_RECENT: usize = 10;
const FILE_NAME: &str = "recent.json";

#[derive(Default)]
pub struct RecentFiles {
    pub paths: Vec<PathBuf>,
    /// Where the list is stored; `None` keeps it in memory only (tests).
    store: Option<PathBuf>,
}

/// `$XDG_CONFIG_HOME/rt`, else `~/.config/rt` (`%APPDATA%\rt` on Windows).
pub fn default_config_dir() -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os("XDG_CONFIG_HOME").filter(|d| !d.is_empty()) {
        return Some(PathBuf::from(dir).join("rt"));
    }
    if let Some(dir) = std::env::var_os("APPDATA").filter(|d| !d.is_empty()) {
        return Some(PathBuf::from(dir).join("rt"));
    }
    std::env::var_os("HOME")
        .filter(|d| !d.is_empty())
        .map(|home| PathBuf::from(home).join(".config").join("rt"))
}

impl RecentFiles {
    /// Loads the list from `config_dir`; a missing or unreadable list is an empty one.
    pub fn load(config_dir: Option<&Path>) -> Self {
        let store = config_dir.map(|d| d.join(FILE_NAME));
        let paths = store
            .as_ref()
            .and_then(|p| std::fs::read(p).ok())
            .and_then(|bytes| serde_json::from_slice::<Vec<PathBuf>>(&bytes).ok())
            .unwrap_or_default();
        RecentFiles { paths, store }
    }

    /// Moves `path` to the front and saves the list.
    pub fn add(&mut self, path: &Path) {
        let path = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        self.paths.retain(|p| *p != path);
        self.paths.insert(0, path);
        self.paths.truncate(MAX_RECENT);
        self.save();
    }

    pub fn remove(&mut self, path: &Path) {
        self.paths.retain(|p| p != path);
        self.save();
    }

    fn save(&self) {
        let Some(store) = &self.store else { return };
        let result = store
            .parent()
            .map_or(Ok(()), std::fs::create_dir_all)
            .map_err(|e| e.to_string())
            .and_then(|()| serde_json::to_vec_pretty(&self.paths).map_err(|e| e.to_string()))
            .and_then(|bytes| {
                rt_core::output::write_atomically(store, &bytes).map_err(|e| e.to_string())
            });
        if let Err(e) = result {
            log::warn!("could not save the recent-files list: {e}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recent_files_persist_newest_first_without_duplicates() {
        let dir = std::env::temp_dir().join(format!("rt-recent-{}", std::process::id()));
        let mut recent = RecentFiles::load(Some(&dir));
        recent.add(Path::new("/a.obj"));
        recent.add(Path::new("/b.obj"));
        recent.add(Path::new("/a.obj"));
        let loaded = RecentFiles::load(Some(&dir));
        assert_eq!(
            loaded.paths,
            vec![PathBuf::from("/a.obj"), PathBuf::from("/b.obj")]
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
