//! A nightly suite sharded over machines: `rtbench nightly --suite S --shard K/N --out DIR` measures
//! one slice (whole scenes, each with its Embree runs; the instruction counts of those scenes;
//! criterion in shard 1) without touching the history; `rtbench merge` joins the N shards; and
//! `rtbench nightly --suite S --from MERGED --db F` compares the joined night with the history and
//! records it, as one night.
//!
//! The night's machine fingerprint is the shards' own when they all ran on one kind of machine (a
//! Slurm partition of identical nodes), else a fingerprint of the set of kinds: such a night is
//! compared only with nights of the same mix.

use super::{jobs, Measured, Suite};
use crate::cli::NightlyArgs;
use crate::error::{input, Result};
use crate::history::{Finding, Metric};
use crate::shard::Shard;
use crate::shard::{sha256_hex, Manifest, ShardSpec};
use rtbench_reports::Environment;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A shard's (or the merged night's) measurements besides its runs.
pub const MEASURED_FILE: &str = "measured.json";

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MeasuredFile {
    pub suite: String,
    pub suite_sha256: String,
    pub fingerprint: String,
    pub env: Environment,
    pub started_at: String,
    pub wall_s: f64,
    pub metrics: Vec<Metric>,
    pub findings: Vec<Finding>,
}

fn read_measured(dir: &Path) -> Result<MeasuredFile> {
    let p = dir.join(MEASURED_FILE);
    let text = std::fs::read_to_string(&p)
        .map_err(|e| input(format!("{}: cannot read: {e}", p.display())))?;
    serde_json::from_str(&text).map_err(|e| {
        input(format!(
            "{}: not a nightly shard's measurements: {e}",
            p.display()
        ))
    })
}

/// The plan of a suite, as its shards hash it.
fn plan_text(suite: &Suite) -> String {
    format!("nightly suite {}", sha256_hex(suite.text.as_bytes()))
}

/// `nightly --shard K/N --out DIR`.
pub fn run_shard(
    a: &NightlyArgs,
    suite: &Suite,
    spec: ShardSpec,
    measure: impl FnOnce(&Path) -> Result<Measured>,
) -> Result<()> {
    let out = a
        .out
        .as_deref()
        .ok_or_else(|| input("nightly --shard: give --out DIR (the shard's results)"))?;
    let all = jobs(suite);
    let mine = spec.select(&all, crate::runs::plan::run_group);
    let mut manifest = Manifest::new(
        "nightly",
        spec,
        &plan_text(suite),
        all.iter().map(|j| j.key()).collect(),
        mine.iter().map(|j| j.key()).collect(),
    );
    manifest
        .extra
        .insert("suite".into(), suite.name.clone().into());
    manifest.write(out)?;
    let m = measure(out)?;
    let file = MeasuredFile {
        suite: suite.name.clone(),
        suite_sha256: sha256_hex(suite.text.as_bytes()),
        fingerprint: m.fingerprint,
        env: m.env,
        started_at: m.started_at,
        wall_s: m.wall_s,
        metrics: m.metrics,
        findings: m.findings,
    };
    let text = serde_json::to_string_pretty(&file).expect("measurements serialise");
    crate::output::write_atomic(&out.join(MEASURED_FILE), |w| {
        std::io::Write::write_all(w, text.as_bytes())
    })?;
    manifest.finished_at = Some(crate::measure::environment::now_utc());
    manifest.write(out)?;
    eprintln!(
        "nightly: shard {}/{}: {} of {} runs, {} metrics in {}",
        spec.k,
        spec.n,
        mine.len(),
        all.len(),
        file.metrics.len(),
        out.display()
    );
    Ok(())
}

/// The shards' measurements joined (for `rtbench merge`).
pub fn merge_measured(shards: &[Shard]) -> Result<MeasuredFile> {
    let parts: Vec<MeasuredFile> = shards
        .iter()
        .map(|s| read_measured(&s.dir))
        .collect::<Result<_>>()?;
    let mut fps: Vec<&str> = parts.iter().map(|p| p.fingerprint.as_str()).collect();
    fps.sort();
    fps.dedup();
    let fingerprint = if fps.len() == 1 {
        fps[0].to_string()
    } else {
        sha256_hex(format!("mixed {}", fps.join(" ")).as_bytes())
    };
    let first = &parts[0];
    let mut metrics = Vec::new();
    let mut findings = Vec::new();
    for p in &parts {
        metrics.extend(p.metrics.iter().cloned());
        findings.extend(p.findings.iter().cloned());
    }
    Ok(MeasuredFile {
        suite: first.suite.clone(),
        suite_sha256: first.suite_sha256.clone(),
        fingerprint,
        env: first.env.clone(),
        started_at: parts
            .iter()
            .map(|p| p.started_at.clone())
            .min()
            .unwrap_or_default(),
        wall_s: parts.iter().map(|p| p.wall_s).fold(0.0, f64::max),
        metrics,
        findings,
    })
}

/// `nightly --from DIR`: a merged night, checked to be of this suite.
pub fn load_merged(dir: &Path, suite: &Suite) -> Result<Measured> {
    let m = read_measured(dir)?;
    let sha = sha256_hex(suite.text.as_bytes());
    if m.suite_sha256 != sha {
        return Err(input(format!(
            "{}: measured with another suite file than {} (suite SHA-256 {}…, this one {}…)",
            dir.display(),
            suite.name,
            crate::output::head(&m.suite_sha256, 12),
            crate::output::head(&sha, 12)
        )));
    }
    if dir.join(crate::shard::MANIFEST_FILE).is_file() {
        return Err(input(format!(
            "{}: a single shard; merge the shards first (rtbench merge DIR… --out MERGED)",
            dir.display()
        )));
    }
    Ok(Measured {
        env: m.env,
        fingerprint: m.fingerprint,
        started_at: m.started_at,
        metrics: m.metrics,
        findings: m.findings,
        wall_s: m.wall_s,
    })
}
