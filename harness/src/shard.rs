//! Sharding a run plan over machines (`--shard K/N`), for a cluster scheduler (Slurm job arrays,
//! `scripts/slurm/`) to run the shards and `rtbench merge` to join them. rtbench has no scheduler
//! of its own: a shard is a deterministic slice of the plan, computed alike on every node.
//!
//! The unit of a slice is a **group**: the jobs that are compared with one another. For `run` and
//! `nightly` a group is one (scene, SF, tessellation, threads), Embree's run with the engines
//! measured against it, so every ratio to Embree is measured on one machine; for `sweep` it is a
//! whole scene (every engine at every SF), so "stop at the first SF past the limit" still holds per
//! scene. Groups are dealt round-robin in plan order: group g goes to shard (g mod N) + 1.
//!
//! Each shard writes `shard.json` ([`Manifest`]) into its results directory before its first run:
//! the plan's SHA-256, every job key of the plan and of the shard, the commit and the machine, so
//! `merge` can refuse shards of different commits or plans, a missing shard or a shard given twice
//! (`runs/merge.rs`).

use crate::error::{input, Result};
use crate::output::write_atomic;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::Path;

/// The file a shard leaves in its results directory.
pub const MANIFEST_FILE: &str = "shard.json";

/// Largest N of `--shard K/N` (a Slurm array of more tasks than this is a mistake).
pub const MAX_SHARDS: u32 = 10_000;

/// `--shard K/N`: the K-th of N slices, 1 ≤ K ≤ N.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardSpec {
    pub k: u32,
    pub n: u32,
}

impl ShardSpec {
    /// Parses `K/N` (the flag's name goes into the error).
    pub fn parse(s: &str, flag: &str) -> Result<ShardSpec> {
        let bad = || {
            input(format!(
                "{flag} '{s}': expected K/N with 1 ≤ K ≤ N ≤ {MAX_SHARDS}, e.g. 2/4"
            ))
        };
        let (k, n) = s.trim().split_once('/').ok_or_else(bad)?;
        let k: u32 = k.trim().parse().map_err(|_| bad())?;
        let n: u32 = n.trim().parse().map_err(|_| bad())?;
        if k == 0 || n == 0 || k > n || n > MAX_SHARDS {
            return Err(bad());
        }
        Ok(ShardSpec { k, n })
    }

    /// Whether group number `g` (0-based, in plan order) belongs to this shard.
    pub fn owns_group(&self, g: usize) -> bool {
        (g % self.n as usize) as u32 + 1 == self.k
    }

    /// The items of this shard: `items` cut into groups of consecutive equal `group` keys (plan
    /// order keeps a group's jobs together), every N-th group kept.
    pub fn select<T: Clone, K: PartialEq>(&self, items: &[T], group: impl Fn(&T) -> K) -> Vec<T> {
        let mut out = Vec::new();
        let mut g = 0usize;
        let mut last: Option<K> = None;
        for item in items {
            let key = group(item);
            if let Some(l) = &last {
                if *l != key {
                    g += 1;
                }
            }
            if self.owns_group(g) {
                out.push(item.clone());
            }
            last = Some(key);
        }
        out
    }
}

/// How many groups a plan has (the most shards that each get work).
pub fn group_count<T, K: PartialEq>(items: &[T], group: impl Fn(&T) -> K) -> usize {
    let mut n = 0;
    let mut last: Option<K> = None;
    for item in items {
        let key = group(item);
        if last.as_ref() != Some(&key) {
            n += 1;
        }
        last = Some(key);
    }
    n
}

/// What a shard records about itself (`DIR/shard.json`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Manifest {
    /// `run`, `sweep`, `nightly` or `tile`.
    pub kind: String,
    pub shard: u32,
    pub of: u32,
    /// SHA-256 of the whole plan (kind, every job key in order, the shared settings): equal in every
    /// shard of one plan.
    pub plan_sha256: String,
    /// Every job key of the plan, in plan order (for `merge` to order and to check completeness).
    pub plan_jobs: Vec<String>,
    /// The job keys of this shard.
    pub jobs: Vec<String>,
    pub git_commit: String,
    pub git_dirty: bool,
    pub hostname: String,
    pub started_at: String,
    /// Set when the shard has run every job (`merge` refuses a shard without it).
    #[serde(default)]
    pub finished_at: Option<String>,
    /// Kind-specific extras (a nightly suite's name and SHA-256, a tile's image size …).
    #[serde(default)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

impl Manifest {
    /// A manifest for shard `spec` of a plan whose identity is `plan_text` (hashed) and whose job
    /// keys are `plan_jobs`.
    pub fn new(
        kind: &str,
        spec: ShardSpec,
        plan_text: &str,
        plan_jobs: Vec<String>,
        jobs: Vec<String>,
    ) -> Manifest {
        let env = crate::measure::environment::capture();
        Manifest {
            kind: kind.to_string(),
            shard: spec.k,
            of: spec.n,
            plan_sha256: sha256_hex(plan_text.as_bytes()),
            plan_jobs,
            jobs,
            git_commit: env.git_commit,
            git_dirty: env.git_dirty,
            hostname: env.hostname,
            started_at: crate::measure::environment::now_utc(),
            finished_at: None,
            extra: Default::default(),
        }
    }

    /// Writes `DIR/shard.json` atomically. A directory that already holds another shard's manifest
    /// (another K/N or plan) is refused: results of two shards must never mix.
    pub fn write(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir)
            .map_err(|e| input(format!("{}: cannot create: {e}", dir.display())))?;
        if let Some(old) = Manifest::read_if_any(dir)? {
            if old.kind != self.kind
                || old.shard != self.shard
                || old.of != self.of
                || old.plan_sha256 != self.plan_sha256
            {
                return Err(input(format!(
                    "{}: holds shard {}/{} of another {} plan ({}…); use a directory of its own",
                    dir.display(),
                    old.shard,
                    old.of,
                    old.kind,
                    crate::output::head(&old.plan_sha256, 12)
                )));
            }
        }
        let text = serde_json::to_string_pretty(self).expect("manifest serialises");
        write_atomic(&dir.join(MANIFEST_FILE), |w| {
            std::io::Write::write_all(w, text.as_bytes())
        })
    }

    /// `DIR/shard.json`, or `None` when the directory has none.
    pub fn read_if_any(dir: &Path) -> Result<Option<Manifest>> {
        let path = dir.join(MANIFEST_FILE);
        match std::fs::read_to_string(&path) {
            Ok(t) => serde_json::from_str(&t)
                .map(Some)
                .map_err(|e| input(format!("{}: not a shard manifest: {e}", path.display()))),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(input(format!("{}: cannot read: {e}", path.display()))),
        }
    }

    /// `DIR/shard.json`, which must be there.
    pub fn read(dir: &Path) -> Result<Manifest> {
        Manifest::read_if_any(dir)?.ok_or_else(|| {
            input(format!(
                "{}: not a shard (no {MANIFEST_FILE}; made by --shard K/N or render --tile K/N)",
                dir.display()
            ))
        })
    }
}

/// A shard's directory and manifest.
pub struct Shard {
    pub dir: std::path::PathBuf,
    pub m: Manifest,
}

pub fn sha256_hex(bytes: &[u8]) -> String {
    crate::output::hex(&Sha256::digest(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_specs_parse_and_refuse() {
        assert_eq!(
            ShardSpec::parse("2/4", "--shard").unwrap(),
            ShardSpec { k: 2, n: 4 }
        );
        for bad in ["0/4", "5/4", "1/0", "x/2", "2", "1/10001", "-1/3"] {
            assert!(ShardSpec::parse(bad, "--shard").is_err(), "{bad}");
        }
    }

    #[test]
    fn every_item_in_exactly_one_shard_and_groups_stay_whole() {
        // 7 groups of 6 (a scene: Embree and five engines), dealt over 1…9 shards.
        let items: Vec<(u32, u32)> = (0..7).flat_map(|g| (0..6).map(move |e| (g, e))).collect();
        for n in 1..=9 {
            let mut seen = vec![0u32; items.len()];
            for k in 1..=n {
                let s = ShardSpec { k, n };
                let part = s.select(&items, |x| x.0);
                for x in &part {
                    seen[(x.0 * 6 + x.1) as usize] += 1;
                }
                // Whole groups only.
                for g in 0..7 {
                    let c = part.iter().filter(|x| x.0 == g).count();
                    assert!(c == 0 || c == 6, "n {n} k {k} group {g}: {c}");
                }
            }
            assert!(seen.iter().all(|&c| c == 1), "n {n}: {seen:?}");
        }
        assert_eq!(group_count(&items, |x| x.0), 7);
    }
}
