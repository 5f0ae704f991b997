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
        remove_stale(&parent);
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

/// Removes the spill directories of processes that are gone (a run killed at its time limit
/// could not remove its own), where `/proc` tells which processes live.
fn remove_stale(parent: &Path) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|n| n.strip_prefix("rtbench-bf-"))
            .and_then(|n| n.split('-').next())
            .and_then(|p| p.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

impl Drop for SpillDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.path);
    }
}
