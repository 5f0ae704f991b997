//! Partial progress of a long reproduction (`reproduce <id> --out DIR --resume`): a table saves each
//! finished step as `DIR/.partial/<id>/<key>.json` and, resumed, loads it instead of measuring it
//! again, so hours of tracing survive the end of a process. A run without `--resume` starts fresh
//! (the folder is emptied); the steps stay after a finished run, so that runs over parts of a
//! table (`scenes=`, `max-sf`) add up and a last `--resume` run writes the whole table from
//! them. Keys must name everything the step's measurement depends on (scene, size factor, image
//! size …).

use crate::error::{input, Result};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::{Path, PathBuf};

pub struct Checkpoint {
    dir: PathBuf,
    resume: bool,
    /// Steps loaded instead of measured by this process: a run with `--resume` that found
    /// nothing saved measured every row itself, and says so.
    loaded: std::sync::atomic::AtomicUsize,
}

impl Checkpoint {
    /// Opens `out/.partial/<id>`; without `resume` anything saved there before is removed.
    pub fn open(out: &Path, id: &str, resume: bool) -> Result<Checkpoint> {
        let dir = out.join(".partial").join(id);
        if !resume && dir.exists() {
            std::fs::remove_dir_all(&dir).map_err(|e| input(format!("{}: {e}", dir.display())))?;
        }
        Ok(Checkpoint {
            dir,
            resume,
            loaded: std::sync::atomic::AtomicUsize::new(0),
        })
    }

    /// `out/.partial/<id>`: where a table may also keep what its steps need between runs
    /// (scene stores), removed with the steps when a run starts without `--resume`.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// How many steps [`Checkpoint::load`] found saved.
    pub fn loaded(&self) -> usize {
        self.loaded.load(std::sync::atomic::Ordering::Relaxed)
    }

    fn file(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.json"))
    }

    /// The step saved under `key`, when resuming and it was saved; a file that does not parse is
    /// refused (exit 2) rather than silently measured again.
    pub fn load<T: DeserializeOwned>(&self, key: &str) -> Result<Option<T>> {
        if !self.resume {
            return Ok(None);
        }
        let f = self.file(key);
        match std::fs::read(&f) {
            Ok(bytes) => {
                let step = serde_json::from_slice(&bytes).map_err(|e| {
                    input(format!(
                        "{}: not a saved step ({e}); remove it to measure again",
                        f.display()
                    ))
                })?;
                self.loaded
                    .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                Ok(Some(step))
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(input(format!("{}: {e}", f.display()))),
        }
    }

    /// Saves a finished step (written to a temporary file and renamed: never half a step).
    pub fn save<T: Serialize>(&self, key: &str, step: &T) -> Result<()> {
        std::fs::create_dir_all(&self.dir)
            .map_err(|e| input(format!("{}: {e}", self.dir.display())))?;
        let f = self.file(key);
        let text = serde_json::to_vec_pretty(step).expect("steps serialise");
        crate::output::write_atomic(&f, |w| std::io::Write::write_all(w, &text))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_survives_only_a_resumed_run() {
        let out = std::env::temp_dir().join(format!("rtbench-checkpoint-{}", std::process::id()));
        let c = Checkpoint::open(&out, "t", false).unwrap();
        c.save("a", &vec![1u32, 2]).unwrap();
        assert_eq!(
            c.load::<Vec<u32>>("a").unwrap(),
            None,
            "not resuming: measure again"
        );
        let r = Checkpoint::open(&out, "t", true).unwrap();
        assert_eq!(r.load::<Vec<u32>>("a").unwrap(), Some(vec![1, 2]));
        assert_eq!(r.load::<Vec<u32>>("b").unwrap(), None);
        std::fs::write(out.join(".partial/t/bad.json"), "{").unwrap();
        assert!(r.load::<Vec<u32>>("bad").is_err());
        // Opened without --resume, the steps of an earlier run are cleared.
        Checkpoint::open(&out, "t", false).unwrap();
        assert!(!out.join(".partial/t/a.json").exists());
        let _ = std::fs::remove_dir_all(&out);
    }
}
