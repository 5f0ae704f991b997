//! The nightly suite's two outside tools: valgrind's callgrind for instruction counts, and
//! `cargo bench` for the criterion kernels.

use super::suite::{Criterion, Variant};
use crate::history::Metric;
use rtbench_scenes::spd::Program;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

/// The environment variables the counted child keeps: the rest are cleared, so the count does
/// not depend on the environment's size or content (its strings sit on the stack and in
/// whatever reads them).
const KEPT_ENV: [&str; 3] = ["PATH", "LD_LIBRARY_PATH", "RTBENCH_PLANT"];

/// Instructions executed by the traced region of one `rtbench count-one` (the scene generated,
/// the engine built and the workload traced once before it, all uncounted, on one thread with no
/// pool; see [`super::count`]) under `valgrind --tool=callgrind --collect-atstart=no
/// --toggle-collect=…`, in a fixed environment, and the wall seconds valgrind took.
pub fn instructions(
    v: &Variant,
    program: Program,
    sf: u32,
    size: u32,
    scratch: &Path,
) -> Result<(u64, f64), String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot find rtbench: {e}"))?;
    let out = scratch.join(format!(
        "callgrind-{}-{}-{}.out",
        std::process::id(),
        v.label().replace(['[', ']', '=', ',', ':'], "_"),
        program.name()
    ));
    let mut cmd = Command::new("valgrind");
    cmd.env_clear();
    for k in KEPT_ENV {
        if let Some(val) = std::env::var_os(k) {
            cmd.env(k, val);
        }
    }
    cmd.env("LC_ALL", "C")
        .args(["--tool=callgrind", "--cache-sim=no", "--collect-atstart=no"])
        .arg(format!("--toggle-collect={}", super::count::COUNTED_SYMBOL))
        .arg(format!("--callgrind-out-file={}", out.display()))
        .arg(exe)
        .args([
            "count-one",
            "--engine",
            &v.engine,
            "--scene",
            program.name(),
        ])
        .args(["--sf", &sf.to_string(), "--size"])
        .arg(size.to_string());
    for (k, val) in &v.settings {
        cmd.args(["--set", &format!("{k}={val}")]);
    }
    let wall = run_tool(&mut cmd, "valgrind", " (apt-get install valgrind)")?;
    let text = std::fs::read_to_string(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let _ = std::fs::remove_file(&out);
    let ir = summary_ir(&text).ok_or_else(|| "callgrind wrote no summary line".to_string())?;
    if ir == 0 {
        return Err(format!(
            "callgrind counted no instruction in the traced region: is the binary stripped of the \
             symbol {}?",
            super::count::COUNTED_SYMBOL
        ));
    }
    Ok((ir, wall))
}

/// The instruction count of a callgrind or cachegrind output file (its `summary:` line, or the
/// `totals:` line where callgrind writes no summary).
fn summary_ir(text: &str) -> Option<u64> {
    let line = |p: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(p))
            .and_then(|s| s.split_whitespace().next())
            .and_then(|s| s.parse::<u64>().ok())
    };
    line("summary:").or_else(|| line("totals:"))
}

fn read_json(p: &Path) -> Option<serde_json::Value> {
    serde_json::from_str(&std::fs::read_to_string(p).ok()?).ok()
}

/// Runs `cargo bench -p rtbench-engines --bench BENCH -- ARGS` with its results in `home`
/// (CRITERION_HOME), from the current directory (the workspace), and reads back every
/// benchmark's mean estimate and samples (nanoseconds per iteration).
pub fn criterion(c: &Criterion, home: &Path, gated: bool) -> Result<(Vec<Metric>, f64), String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    // cargo runs a bench in its package's directory: a relative CRITERION_HOME (the default
    // `--out out/nightly` of scripts/nightly.sh) would land in engines/ and be read back from here.
    let home = &std::path::absolute(home).map_err(|e| format!("{}: {e}", home.display()))?;
    let _ = std::fs::remove_dir_all(home);
    let mut cmd = Command::new(cargo);
    cmd.args(["bench", "-p", "rtbench-engines", "--bench", &c.bench, "--"])
        .args(&c.args)
        .env("CRITERION_HOME", home);
    // The benches run for minutes with their output kept off stdout: say what is running.
    eprintln!(
        "nightly: cargo bench -p rtbench-engines --bench {} -- {}",
        c.bench,
        c.args.join(" ")
    );
    let wall = run_tool(&mut cmd, "cargo bench", "")?;
    let mut out = Vec::new();
    let mut stack = vec![home.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let Ok(rd) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in rd.flatten() {
            let p = e.path();
            if !p.is_dir() {
                continue;
            }
            if p.file_name().is_some_and(|n| n == "new") {
                let (Some(b), Some(est)) = (
                    read_json(&p.join("benchmark.json")),
                    read_json(&p.join("estimates.json")),
                ) else {
                    continue;
                };
                let (Some(id), Some(mean)) = (
                    b["full_id"].as_str(),
                    est["mean"]["point_estimate"].as_f64(),
                ) else {
                    continue;
                };
                let samples = read_json(&p.join("sample.json"))
                    .map(|s| {
                        let iters = s["iters"].as_array().cloned().unwrap_or_default();
                        let times = s["times"].as_array().cloned().unwrap_or_default();
                        iters
                            .iter()
                            .zip(&times)
                            .filter_map(|(i, t)| Some(t.as_f64()? / i.as_f64()?))
                            .collect()
                    })
                    .unwrap_or_default();
                out.push(Metric {
                    name: format!("{id}/criterion_ns"),
                    kind: "criterion".into(),
                    unit: "ns".into(),
                    value: mean,
                    gated,
                    samples,
                });
            } else {
                stack.push(p);
            }
        }
    }
    if out.is_empty() {
        return Err(format!(
            "cargo bench left no estimates in {}",
            home.display()
        ));
    }
    out.sort_by(|a, b| a.name.cmp(&b.name));
    Ok((out, wall))
}

/// Runs an external tool with no input and its output discarded; returns its wall seconds, or an
/// error with the last line it wrote to stderr.
fn run_tool(cmd: &mut Command, name: &str, hint: &str) -> Result<f64, String> {
    let t = Instant::now();
    let o = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .output()
        .map_err(|e| format!("cannot start {name}: {e}{hint}"))?;
    let wall = t.elapsed().as_secs_f64();
    if !o.status.success() {
        let err = String::from_utf8_lossy(&o.stderr);
        let last = err
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("");
        return Err(format!("{name} failed: {}", last.trim()));
    }
    Ok(wall)
}
