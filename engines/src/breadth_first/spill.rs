//! The spill directory: a fresh subdirectory for the engine's temporary files (the store of an
//! in-memory scene), removed when the engine is dropped. An unwritable or missing parent is a
//! build error naming it.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static NEXT: AtomicU64 = AtomicU64::new(0);

pub struct SpillDir {
    path: PathBuf,
}

impl SpillDir {
    /// Creates `rtbench-bf-PID-N` under `parent` (the system temp dir when `None`).
    pub fn create(parent: Option<&Path>) -> Result<SpillDir, String> {
        let parent = parent
            .map(Path::to_path_buf)
            .unwrap_or_else(std::env::temp_dir);
        let path = parent.join(format!(
            "rtbench-bf-{}-{}",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir(&path)
            .map_err(|e| format!("spill directory {}: {e}", parent.display()))?;
        Ok(SpillDir { path })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The path as error messages show it.
    pub fn shown(&self) -> String {
        format!("spill directory {}", self.path.display())
    }
}

impl Drop for SpillDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.path);
    }
}
