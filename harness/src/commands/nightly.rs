//! `rtbench nightly --suite FILE --db FILE.sqlite [--out DIR]`: runs a suite, compares the night
//! with the history and records it (the night's measuring and detection are in `nightly/`).

use crate::cli::NightlyArgs;
use crate::error::{input, Failure, Result};
use crate::history::{dashboard, History, Night};
use crate::nightly::{
    compare_all, gate_findings, is_bad, measure, shard, suite, summary_markdown, suspects_of,
    Measured,
};
use crate::shard::ShardSpec;
use sha2::{Digest, Sha256};
use std::time::Instant;

/// `rtbench nightly`.
pub fn run(a: &NightlyArgs) -> Result<()> {
    let suite = suite::load_runnable(&a.suite)?;
    let spec = a
        .shard
        .as_deref()
        .map(|s| ShardSpec::parse(s, "--shard"))
        .transpose()?;
    if let Some(spec) = spec {
        return shard::run_shard(a, &suite, spec, |out| {
            measure(&suite, a, Some(spec), Some(out))
        });
    }
    let db = a.db.as_deref().ok_or_else(|| {
        input("nightly: --db FILE is required (the history the night is compared with and written to)")
    })?;
    // Open the history before running anything: a bad file is exit 2 at once.
    let mut history = History::open(db, true)?;
    let start = Instant::now();
    let Measured {
        env,
        fingerprint: fp,
        started_at,
        metrics,
        mut findings,
        wall_s: measured_s,
    } = match &a.from {
        Some(dir) => shard::load_merged(dir, &suite)?,
        None => measure(&suite, a, None, a.out.as_deref())?,
    };
    let prev = history.runs(Some(&fp), Some(&suite.name))?;
    if let Some(dir) = &a.from {
        // A merged night is one night: recording it again would count it twice.
        if let Some(r) = prev
            .iter()
            .find(|r| r.started_at == started_at && r.git_commit == env.git_commit)
        {
            return Err(input(format!(
                "{}: this night (started {started_at}) is already night {} of {}",
                dir.display(),
                r.id,
                db.display()
            )));
        }
    }
    let window: Vec<_> = prev
        .iter()
        .rev()
        .take(suite.baseline_nights)
        .rev()
        .collect();
    let mut baseline = Vec::new();
    for r in &window {
        baseline.push(history.metrics(r.id)?);
    }
    let suspects = match window.last() {
        Some(r) => suspects_of(&history.findings(r.id)?),
        None => Default::default(),
    };
    let earlier: Vec<i64> = prev.iter().map(|r| r.id).collect();
    findings.extend(gate_findings(&suite, &metrics, &earlier, window.len()));
    findings.extend(compare_all(&suite, &metrics, &baseline, &suspects));
    let wall_s = match &a.from {
        Some(_) => measured_s + start.elapsed().as_secs_f64(),
        None => start.elapsed().as_secs_f64(),
    };
    let night = Night {
        suite: suite.name.clone(),
        suite_sha256: crate::output::hex(&Sha256::digest(suite.text.as_bytes())),
        started_at,
        finished_at: crate::measure::environment::now_utc(),
        git_commit: env.git_commit.clone(),
        git_dirty: env.git_dirty,
        fingerprint: fp.clone(),
        env_json: serde_json::to_string(&env).expect("environment serialises"),
        wall_s,
        note: a.note.clone(),
        metrics: metrics.clone(),
        findings: findings.clone(),
    };
    let md = summary_markdown(
        &suite.name,
        &env.git_commit,
        wall_s,
        Some(window.len()),
        &metrics,
        &findings,
    );
    if a.no_record {
        eprintln!(
            "nightly: --no-record: the night is not written to {}",
            db.display()
        );
    } else {
        let id = history.append(&night)?;
        eprintln!("nightly: night {id} written to {}", db.display());
    }
    if let Some(d) = &a.out {
        crate::output::write_atomic(&d.join("nightly.md"), |w| {
            std::io::Write::write_all(w, md.as_bytes())
        })?;
        dashboard::write(&history, &d.join("dashboard"), suite.commit_url.as_deref())?;
        eprintln!(
            "nightly: summary {}, dashboard {}",
            d.join("nightly.md").display(),
            d.join("dashboard/index.html").display()
        );
    }
    if a.json {
        crate::output::print_json(&serde_json::json!({
            "fingerprint": fp,
            "wall_s": wall_s,
            "metrics": metrics.len(),
            "gated": metrics.iter().filter(|m| m.gated).count(),
            "baseline_nights": window.len(),
            "findings": findings,
        }));
    } else {
        print!("{md}");
    }
    let bad: Vec<String> = findings
        .iter()
        .filter(|f| is_bad(f))
        .map(|f| f.message.clone())
        .collect();
    if !bad.is_empty() {
        return Err(Failure::Check(format!(
            "nightly regression: {}",
            bad.join("; ")
        )));
    }
    Ok(())
}

/// `rtbench count-one`: the nightly's counted region (run under valgrind).
pub fn count_one(a: &crate::cli::CountOneArgs) -> Result<()> {
    let source = crate::source::Source::resolve(
        &a.scene.scene,
        a.scene.opts.sf,
        a.scene.opts.tessellate,
        a.scene.opts.hash,
    )?;
    let settings = crate::workload::parse_settings(&a.set)?;
    let rays = crate::nightly::count::count_one(&a.engine, settings, &source, a.size)?;
    println!("{{\"rays\":{rays}}}");
    Ok(())
}
