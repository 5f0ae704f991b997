//! Merging the shards of one plan (`run`, `sweep` or
//! `nightly` with `--shard K/N`, `render --tile K/N`) into one results set, as if one machine had
//! run the plan. Refused with one line, and nothing written, when the shards are not exactly the
//! N shards of one plan at one commit, each finished ([`crate::shard`]).
//!
//! - run, sweep: `results.jsonl` in plan order, each record marked with the machine it was
//!   measured on (a run and its Embree anchor always share a shard, so every ratio is one
//!   machine's); `env.json` of shard 1; `shards.json` (every shard's manifest and environment).
//!   `rtbench report OUT` then makes the report, with a machine column when there were several.
//! - nightly: the same, plus `measured.json` (every shard's metrics and failures), which
//!   `rtbench nightly --from OUT --db F` records and compares as one night.
//! - tile: the image (`image.png`) from the tiles' pixel corners, and `render.json` with the ray
//!   statistics and counters added up and each tile's times.

use crate::error::{input, Result};
use crate::output::write_atomic;
use crate::shard::{Manifest, Shard};
use rtbench_reports::{engine_label, read_environment, read_results, RunRecord};
use serde_json::json;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn short(s: &str) -> &str {
    crate::output::head(s, 12)
}

/// Reads the manifests and checks that they are the N finished shards of one plan at one commit.
pub fn load_shards(dirs: &[PathBuf]) -> Result<Vec<Shard>> {
    let mut shards = Vec::new();
    for d in dirs {
        shards.push(Shard {
            dir: d.clone(),
            m: Manifest::read(d)?,
        });
    }
    let first = &shards[0];
    for s in &shards[1..] {
        let (a, b) = (&first.m, &s.m);
        if a.kind != b.kind {
            return Err(input(format!(
                "{} is a {} shard, {} a {} shard: cannot merge them",
                first.dir.display(),
                a.kind,
                s.dir.display(),
                b.kind
            )));
        }
        if a.git_commit != b.git_commit || a.git_dirty != b.git_dirty {
            let c = |m: &Manifest| {
                format!(
                    "{}{}",
                    short(&m.git_commit),
                    if m.git_dirty { "+dirty" } else { "" }
                )
            };
            return Err(input(format!(
                "{} (commit {}) and {} (commit {}): shards of different commits",
                first.dir.display(),
                c(a),
                s.dir.display(),
                c(b)
            )));
        }
        if a.of != b.of {
            return Err(input(format!(
                "{} is shard {}/{}, {} shard {}/{}: split differently",
                first.dir.display(),
                a.shard,
                a.of,
                s.dir.display(),
                b.shard,
                b.of
            )));
        }
        if a.plan_sha256 != b.plan_sha256 {
            return Err(input(format!(
                "{} (plan {}) and {} (plan {}): shards of different plans (engines, scenes, settings or suite)",
                first.dir.display(),
                short(&a.plan_sha256),
                s.dir.display(),
                short(&b.plan_sha256)
            )));
        }
    }
    let n = first.m.of;
    let mut by_k: BTreeMap<u32, &Shard> = BTreeMap::new();
    for s in &shards {
        if let Some(prev) = by_k.insert(s.m.shard, s) {
            return Err(input(format!(
                "shard {}/{n} given twice: {} and {}",
                s.m.shard,
                prev.dir.display(),
                s.dir.display()
            )));
        }
    }
    let missing: Vec<String> = (1..=n)
        .filter(|k| !by_k.contains_key(k))
        .map(|k| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() {
        return Err(input(format!(
            "shard{} {} missing (given: {})",
            if missing.len() > 1 { "s" } else { "" },
            missing.join(", "),
            by_k.keys()
                .map(|k| k.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    for s in &shards {
        if s.m.finished_at.is_none() {
            return Err(input(format!(
                "{}: shard {}/{n} did not finish (run it again; run and sweep take --resume)",
                s.dir.display(),
                s.m.shard
            )));
        }
    }
    shards.sort_by_key(|s| s.m.shard);
    Ok(shards)
}

/// `OUT` must be new or an empty directory, and none of the inputs.
pub fn check_out(out: &Path, dirs: &[PathBuf]) -> Result<()> {
    for d in dirs {
        if let (Ok(a), Ok(b)) = (d.canonicalize(), out.canonicalize()) {
            if a == b {
                return Err(input(format!(
                    "--out {}: is one of the shards",
                    out.display()
                )));
            }
        }
    }
    if out.exists() {
        let empty = std::fs::read_dir(out)
            .map_err(|e| input(format!("--out {}: {e}", out.display())))?
            .next()
            .is_none();
        if !empty {
            return Err(input(format!(
                "--out {}: exists and is not empty (merge writes a new results set)",
                out.display()
            )));
        }
    }
    Ok(())
}

/// Files to write, by name: built whole before anything touches the disk.
pub type Files = Vec<(String, Vec<u8>)>;

/// Writes the files into a temporary directory beside OUT (`tempfile`, removed however this
/// returns), then renames it to OUT: an interrupted merge leaves no half-written results set.
pub fn write_all(out: &Path, files: Files) -> Result<()> {
    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent)
        .map_err(|e| input(format!("{}: cannot create: {e}", parent.display())))?;
    let name = out
        .file_name()
        .ok_or_else(|| input(format!("--out {}: not a directory name", out.display())))?;
    let tmp = tempfile::Builder::new()
        .prefix(&format!(".{}.merge-", name.to_string_lossy()))
        .tempdir_in(parent)
        .map_err(|e| input(format!("{}: cannot create: {e}", parent.display())))?;
    for (f, bytes) in &files {
        write_atomic(&tmp.path().join(f), |w| std::io::Write::write_all(w, bytes))?;
    }
    if out.exists() {
        std::fs::remove_dir(out).map_err(|e| input(format!("--out {}: {e}", out.display())))?;
    }
    let tmp = tmp.keep();
    std::fs::rename(&tmp, out).map_err(|e| {
        let _ = std::fs::remove_dir_all(&tmp);
        input(format!("--out {}: {e}", out.display()))
    })
}

pub fn jsonl(records: &[RunRecord]) -> Vec<u8> {
    let mut text = String::new();
    for r in records {
        text.push_str(&serde_json::to_string(r).expect("records serialise"));
        text.push('\n');
    }
    text.into_bytes()
}

/// The shards' records, each checked against its slice and marked with its machine, in plan order.
pub fn merged_records(shards: &[Shard]) -> Result<Vec<RunRecord>> {
    let kind = shards[0].m.kind.as_str();
    let plan = &shards[0].m.plan_jobs;
    let order: BTreeMap<&str, usize> = plan
        .iter()
        .enumerate()
        .map(|(i, k)| (k.as_str(), i))
        .collect();
    let mut all: Vec<(usize, u32, RunRecord)> = Vec::new();
    // A run (its key, at its size factor) once across all shards: a shard holding one twice, or
    // two shards holding the same, would count it twice.
    let mut runs: BTreeSet<(String, u32)> = BTreeSet::new();
    for s in shards {
        let records = read_results(&s.dir).map_err(|e| input(e.to_string()))?;
        if let Some(d) = rtbench_reports::duplicate(&records) {
            return Err(input(format!(
                "{}: shard {}/{} holds run {} twice (the same record)",
                s.dir.display(),
                s.m.shard,
                s.m.of,
                crate::output::head(&d.key, 120)
            )));
        }
        // A run re-run in the shard (same key, later line) replaces the earlier, as in reports.
        let records = rtbench_reports::latest_per_key(records);
        let mine: BTreeSet<&str> = s.m.jobs.iter().map(|k| k.as_str()).collect();
        // run and nightly: one record per job key; sweep: records per (engine, scene) unit.
        let unit_of = |r: &RunRecord| -> String {
            if kind == "sweep" {
                format!(
                    "{}/{}",
                    engine_label(&r.engine, &r.settings),
                    r.scene.program.clone().unwrap_or_default()
                )
            } else {
                r.key.clone()
            }
        };
        let mut seen = BTreeSet::new();
        for mut r in records {
            let unit = unit_of(&r);
            if !mine.contains(unit.as_str()) {
                return Err(input(format!(
                    "{}: shard {}/{} holds a run outside its slice of the plan: {}",
                    s.dir.display(),
                    s.m.shard,
                    s.m.of,
                    r.key
                )));
            }
            if !runs.insert((r.key.clone(), r.scene.sf.unwrap_or(0))) {
                return Err(input(format!(
                    "{}: shard {}/{} holds run {} a second time",
                    s.dir.display(),
                    s.m.shard,
                    s.m.of,
                    crate::output::head(&r.key, 120)
                )));
            }
            seen.insert(unit.clone());
            r.machine = Some(s.m.hostname.clone());
            // A manifest whose jobs are not the plan's (an edited shard.json) has no place in it.
            let Some(&at) = order.get(unit.as_str()) else {
                return Err(input(format!(
                    "{}: shard {}/{} lists job {} that its plan does not hold",
                    s.dir.display(),
                    s.m.shard,
                    s.m.of,
                    crate::output::head(&unit, 120)
                )));
            };
            all.push((at, r.scene.sf.unwrap_or(0), r));
        }
        let lacking: Vec<&str> = mine
            .iter()
            .filter(|k| !seen.contains(**k))
            .copied()
            .collect();
        if !lacking.is_empty() {
            return Err(input(format!(
                "{}: shard {}/{} lacks {} of its {} runs ({}{})",
                s.dir.display(),
                s.m.shard,
                s.m.of,
                lacking.len(),
                mine.len(),
                lacking[0],
                if lacking.len() > 1 { ", …" } else { "" }
            )));
        }
    }
    all.sort_by_key(|(i, sf, _)| (*i, *sf));
    Ok(all.into_iter().map(|(_, _, r)| r).collect())
}

/// `shards.json`: what each shard was, where it ran, with what.
pub fn shards_json(shards: &[Shard]) -> Result<Vec<u8>> {
    let mut v = Vec::new();
    for s in shards {
        let env = read_environment(&s.dir).map_err(|e| input(e.to_string()))?;
        v.push(json!({"dir": s.dir.display().to_string(), "manifest": s.m, "env": env}));
    }
    Ok(serde_json::to_vec_pretty(&v).expect("shards serialise"))
}

pub fn env_file(shards: &[Shard]) -> Result<Option<(String, Vec<u8>)>> {
    let p = shards[0].dir.join("env.json");
    match std::fs::read(&p) {
        Ok(b) => Ok(Some(("env.json".to_string(), b))),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(input(format!("{}: cannot read: {e}", p.display()))),
    }
}

/// A PNG of `pixels` in memory (the merged image is written with the other files, at once).
pub fn png_bytes(pixels: &[u8], size: u32) -> Result<Vec<u8>> {
    let mut c = std::io::Cursor::new(Vec::new());
    image::write_buffer_with_format(
        &mut c,
        pixels,
        size,
        size,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(|e| input(format!("merged image: {e}")))?;
    Ok(c.into_inner())
}
