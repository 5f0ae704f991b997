//! The nightly suite file (TOML): what `rtbench nightly` runs and which metrics gate.
//!
//! ```toml
//! name = "nightly"
//! engines = ["embree", "grid", "bvh4"]     # Embree is the yardstick of the time ratios: required
//! variants = ["bvh4:simd=off"]              # an engine with its settings, run beside the others
//! scenes = ["tetra", "balls"]
//! sf = [2, 3]
//! threads = [1]                             # counts or "all" (default [1])
//! repeats = 5
//! paired = 8                                # engine/Embree pairs timed back to back per run
//! size = 128                                # image side of the workload, pixels
//! gate = ["counters", "time_ratio", "instructions"]
//! false_alarm_budget = 0.03                 # accepted nights with a false alarm, per night
//! confirm_nights = 2                        # a time regression needs two nights in a row (1: one)
//!
//! [instructions]                            # valgrind (callgrind) instruction counts of the trace
//! engines = ["grid", "bvh4"]
//! scenes = ["tetra"]
//! sf = 1
//! size = 32
//! tolerance_pct = 0.1
//!
//! [criterion]                               # `cargo bench -p rtbench-engines --bench BENCH`
//! bench = "kernels"
//! args = ["--warm-up-time", "0.5", "--measurement-time", "1"]
//! ```
//!
//! Every problem (an unknown key, engine, scene or metric; a bad value) is one line naming the
//! file, and `rtbench` exits 2.

use crate::error::{input, Result};
use rtbench_scenes::spd::Program;
use serde::Deserialize;
use std::path::Path;

/// The metrics that can gate a night.
pub const GATES: [&str; 4] = ["counters", "time_ratio", "instructions", "criterion"];

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct RawSuite {
    name: Option<String>,
    engines: Vec<String>,
    #[serde(default)]
    variants: Vec<String>,
    scenes: Vec<String>,
    sf: Vec<u32>,
    #[serde(default)]
    threads: Option<Vec<toml::Value>>,
    repeats: Option<u32>,
    paired: Option<u32>,
    size: Option<u32>,
    gate: Vec<String>,
    false_alarm_budget: Option<f64>,
    min_change_pct: Option<f64>,
    baseline_nights: Option<usize>,
    confirm_nights: Option<u32>,
    max_seconds: Option<f64>,
    commit_url: Option<String>,
    instructions: Option<RawInstructions>,
    criterion: Option<RawCriterion>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct RawInstructions {
    engines: Vec<String>,
    scenes: Vec<String>,
    sf: Option<u32>,
    size: Option<u32>,
    tolerance_pct: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct RawCriterion {
    bench: Option<String>,
    #[serde(default)]
    args: Vec<String>,
}

/// An engine and its settings, as run: `bvh4` or `bvh4:simd=off`.
#[derive(Clone, Debug, PartialEq)]
pub struct Variant {
    pub engine: String,
    pub settings: Vec<(String, String)>,
}

impl Variant {
    /// `bvh4` or `bvh4[simd=off]`, as reports name it.
    pub fn label(&self) -> String {
        rtbench_reports::engine_label(&self.engine, self.settings.iter().map(|(k, v)| (k, v)))
    }
}

#[derive(Clone, Debug)]
pub struct Instructions {
    pub variants: Vec<Variant>,
    pub scenes: Vec<Program>,
    pub sf: u32,
    pub size: u32,
    pub tolerance_pct: f64,
}

#[derive(Clone, Debug)]
pub struct Criterion {
    pub bench: String,
    pub args: Vec<String>,
}

/// A checked suite.
#[derive(Clone, Debug)]
pub struct Suite {
    pub name: String,
    /// The file's text, hashed into the history so a changed suite is visible.
    pub text: String,
    pub variants: Vec<Variant>,
    pub scenes: Vec<Program>,
    pub sf: Vec<u32>,
    /// `None`: all cores.
    pub threads: Vec<Option<usize>>,
    pub repeats: u32,
    /// Pairs of engine and Embree traces timed back to back in each run (0: the ratio of an
    /// engine's round to Embree's round, which are separate processes).
    pub paired: u32,
    pub size: u32,
    pub gate: Vec<String>,
    pub false_alarm_budget: f64,
    pub min_change_pct: f64,
    pub baseline_nights: usize,
    /// 1: a time regression is reported on its first night; 2: the first night is a `suspect`
    /// (reported, not failing) and the regression is reported when the next night confirms it.
    pub confirm_nights: u32,
    pub max_seconds: Option<f64>,
    /// The dashboard's link of a commit: an http(s) URL holding `{commit}`.
    pub commit_url: Option<String>,
    pub instructions: Option<Instructions>,
    pub criterion: Option<Criterion>,
}

impl Suite {
    pub fn gates(&self, metric: &str) -> bool {
        self.gate.iter().any(|g| g == metric)
    }
}

/// Line and column (1-based) of a byte offset.
fn line_col(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map(|i| i + 1).unwrap_or(0) + 1;
    (line, col)
}

fn variant(file: &str, entry: &str) -> Result<Variant> {
    let registry = rtbench_engines::registry();
    let mut parts = entry.split(':');
    let name = parts.next().unwrap_or_default().trim();
    if !registry.iter().any(|e| e.name == name) {
        let known: Vec<&str> = registry.iter().map(|e| e.name).collect();
        return Err(input(format!(
            "{file}: unknown engine '{name}' (known: {})",
            known.join(", ")
        )));
    }
    let mut settings = Vec::new();
    if name == "plugin" {
        // plugin:PATH[:key=value…], as `--engines` takes it (crate::select); plugin:path=PATH too.
        let mut rest = parts.clone();
        if let Some(spec) = rest.next().map(str::trim).filter(|s| !s.contains('=')) {
            if spec.is_empty() {
                return Err(input(format!(
                    "{file}: variant '{entry}': expected plugin:PATH[:key=value…]"
                )));
            }
            rtbench_engines::plugin::resolve(spec).map_err(|e| input(format!("{file}: {e}")))?;
            settings.push(("path".to_string(), spec.to_string()));
            parts = rest;
        }
    }
    for kv in parts {
        let (k, v) = kv
            .split_once('=')
            .filter(|(k, _)| !k.trim().is_empty())
            .ok_or_else(|| {
                input(format!(
                    "{file}: variant '{entry}': expected engine:key=value"
                ))
            })?;
        settings.push((k.trim().to_string(), v.trim().to_string()));
    }
    Ok(Variant {
        engine: name.to_string(),
        settings,
    })
}

fn program(file: &str, s: &str) -> Result<Program> {
    s.trim()
        .parse::<Program>()
        .map_err(|e| input(format!("{file}: {}", e.replace("SPD program", "scene"))))
}

fn positive(file: &str, what: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(input(format!("{file}: {what} = {v}: must be positive")))
    }
}

/// Reads a suite file and checks that it can run here, before anything is measured: every
/// variant builds (its engine is available and takes its settings), the thread counts are ones
/// this machine runs, and each scene at each size factor fits in memory with its engine and
/// Embree (the estimate of `workload::footprint`).
pub fn load_runnable(path: &Path) -> Result<Suite> {
    let s = load(path)?;
    check_runnable(&path.display().to_string(), &s)?;
    Ok(s)
}

pub fn check_runnable(file: &str, s: &Suite) -> Result<()> {
    let probe = crate::suite::probe_input();
    let instr = s.instructions.iter().flat_map(|i| &i.variants);
    for v in s.variants.iter().chain(instr) {
        rtbench_engines::build_engine(&v.engine, &probe, v.settings.clone())
            .map_err(|e| input(format!("{file}: variant '{}': {e}", v.label())))?;
    }
    let most = crate::measure::threads::thread_limit();
    if let Some(n) = s.threads.iter().flatten().find(|&&n| n > most) {
        return Err(input(format!(
            "{file}: threads = {n}: more than the {most} this machine runs at once"
        )));
    }
    for &scene in &s.scenes {
        for &sf in &s.sf {
            let o = rtbench_scenes::spd::Options {
                size_factor: sf,
                ..rtbench_scenes::spd::Options::standard(scene)
            };
            let src = crate::source::Source::Program(scene, o);
            for v in &s.variants {
                let engines: &[&str] = if v.engine == "embree" {
                    &["embree"]
                } else {
                    &[&v.engine, "embree"]
                };
                crate::workload::check_scene_fits(&src, engines, false)
                    .map_err(|e| input(format!("{file}: sf = {sf}: {e}")))?;
            }
        }
    }
    Ok(())
}

/// Reads and checks a suite file.
pub fn load(path: &Path) -> Result<Suite> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| input(format!("{file}: {e}")))?;
    parse(&file, &text)
}

/// Checks a suite's text; `file` names it in errors.
pub fn parse(file: &str, text: &str) -> Result<Suite> {
    let raw: RawSuite = toml::from_str(text).map_err(|e| {
        let at = e
            .span()
            .map(|s| {
                let (l, c) = line_col(text, s.start);
                format!(" (line {l}, column {c})")
            })
            .unwrap_or_default();
        let msg = e.message().lines().next().unwrap_or("invalid TOML").trim();
        input(format!("{file}: {msg}{at}"))
    })?;
    let mut variants = Vec::new();
    for e in raw.engines.iter().chain(&raw.variants) {
        let v = variant(file, e)?;
        if variants.contains(&v) {
            return Err(input(format!("{file}: '{e}' given twice")));
        }
        variants.push(v);
    }
    if !variants
        .iter()
        .any(|v| v.engine == "embree" && v.settings.is_empty())
    {
        return Err(input(format!(
            "{file}: engines must hold 'embree', the yardstick of the time ratios"
        )));
    }
    if raw.scenes.is_empty() || raw.sf.is_empty() {
        return Err(input(format!("{file}: scenes and sf must not be empty")));
    }
    let scenes = raw
        .scenes
        .iter()
        .map(|s| program(file, s))
        .collect::<Result<Vec<_>>>()?;
    if raw.sf.contains(&0) {
        return Err(input(format!("{file}: sf: size factors start at 1")));
    }
    let threads = match raw.threads {
        None => vec![crate::measure::threads::Threads::DEFAULT.count()],
        Some(t) if t.is_empty() => {
            return Err(input(format!("{file}: threads must not be empty")));
        }
        Some(t) => t
            .into_iter()
            .map(|v| {
                let text = match &v {
                    toml::Value::String(s) => s.clone(),
                    other => other.to_string(),
                };
                text.parse::<crate::measure::threads::Threads>()
                    .map(|t| t.count())
                    .map_err(|e| input(format!("{file}: {e}")))
            })
            .collect::<Result<Vec<_>>>()?,
    };
    for g in &raw.gate {
        if !GATES.contains(&g.as_str()) {
            return Err(input(format!(
                "{file}: unknown metric '{g}' in gate (known: {})",
                GATES.join(", ")
            )));
        }
    }
    let repeats = raw.repeats.unwrap_or(5);
    if !(2..=1000).contains(&repeats) {
        return Err(input(format!(
            "{file}: repeats = {repeats}: from 2 (a rank test needs samples) to 1000"
        )));
    }
    let paired = raw.paired.unwrap_or(0);
    if paired > crate::runs::one::MAX_PAIRS {
        return Err(input(format!(
            "{file}: paired = {paired}: at most {}",
            crate::runs::one::MAX_PAIRS
        )));
    }
    let size = raw.size.unwrap_or(128);
    crate::workload::check_size(size).map_err(|e| input(format!("{file}: {e}")))?;
    let budget = positive(
        file,
        "false_alarm_budget",
        raw.false_alarm_budget.unwrap_or(0.03),
    )?;
    if budget >= 1.0 {
        return Err(input(format!(
            "{file}: false_alarm_budget = {budget}: a probability per night, below 1"
        )));
    }
    let min_change_pct = raw.min_change_pct.unwrap_or(1.0);
    if !(min_change_pct.is_finite() && min_change_pct >= 0.0) {
        return Err(input(format!(
            "{file}: min_change_pct = {min_change_pct}: must be ≥ 0"
        )));
    }
    let baseline_nights = raw.baseline_nights.unwrap_or(10);
    if baseline_nights < 3 {
        return Err(input(format!(
            "{file}: baseline_nights = {baseline_nights}: at least 3"
        )));
    }
    let confirm_nights = raw.confirm_nights.unwrap_or(1);
    if !(1..=2).contains(&confirm_nights) {
        return Err(input(format!(
            "{file}: confirm_nights = {confirm_nights}: 1 or 2"
        )));
    }
    if let Some(s) = raw.max_seconds {
        positive(file, "max_seconds", s)?;
    }
    if let Some(t) = &raw.commit_url {
        crate::history::dashboard::check_commit_url(t)
            .map_err(|e| input(format!("{file}: {e}")))?;
    }
    let instructions = match raw.instructions {
        None => None,
        Some(i) => {
            let variants = i
                .engines
                .iter()
                .map(|e| variant(file, e))
                .collect::<Result<Vec<_>>>()?;
            let scenes = i
                .scenes
                .iter()
                .map(|s| program(file, s))
                .collect::<Result<Vec<_>>>()?;
            if variants.is_empty() || scenes.is_empty() {
                return Err(input(format!(
                    "{file}: [instructions] engines and scenes must not be empty"
                )));
            }
            let size = i.size.unwrap_or(32);
            crate::workload::check_size(size)
                .map_err(|e| input(format!("{file}: [instructions] {e}")))?;
            let tol = i.tolerance_pct.unwrap_or(0.1);
            if !(tol.is_finite() && tol >= 0.0) {
                return Err(input(format!(
                    "{file}: [instructions] tolerance_pct = {tol}: must be ≥ 0"
                )));
            }
            Some(Instructions {
                variants,
                scenes,
                sf: i.sf.unwrap_or(1).max(1),
                size,
                tolerance_pct: tol,
            })
        }
    };
    if raw.gate.iter().any(|g| g == "instructions") && instructions.is_none() {
        return Err(input(format!(
            "{file}: gate names 'instructions' but there is no [instructions] table"
        )));
    }
    let criterion = raw.criterion.map(|c| Criterion {
        bench: c.bench.unwrap_or_else(|| "kernels".into()),
        args: c.args,
    });
    if raw.gate.iter().any(|g| g == "criterion") && criterion.is_none() {
        return Err(input(format!(
            "{file}: gate names 'criterion' but there is no [criterion] table"
        )));
    }
    Ok(Suite {
        name: raw.name.unwrap_or_else(|| "nightly".into()),
        text: text.to_string(),
        variants,
        scenes,
        sf: raw.sf,
        threads,
        repeats,
        paired,
        size,
        gate: raw.gate,
        false_alarm_budget: budget,
        min_change_pct,
        baseline_nights,
        confirm_nights,
        max_seconds: raw.max_seconds,
        commit_url: raw.commit_url,
        instructions,
        criterion,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
engines = ["embree", "grid"]
variants = ["bvh4:simd=off"]
scenes = ["tetra"]
sf = [1]
gate = ["counters", "time_ratio"]
"#;

    fn err(text: &str) -> String {
        parse("s.toml", text).unwrap_err().to_string()
    }

    #[test]
    fn a_good_suite_parses_with_defaults() {
        let s = parse("s.toml", GOOD).unwrap();
        assert_eq!(s.variants.len(), 3);
        assert_eq!(s.variants[2].label(), "bvh4[simd=off]");
        assert_eq!(s.threads, vec![Some(1)]);
        assert_eq!(s.repeats, 5);
        assert!(s.gates("counters") && !s.gates("instructions"));
    }

    #[test]
    fn bad_suites_name_the_file_and_the_problem_in_one_line() {
        let cases = [
            (
                GOOD.replace("\"grid\"", "\"gridd\""),
                "unknown engine 'gridd'",
            ),
            (GOOD.replace("tetra", "tetraa"), "unknown scene 'tetraa'"),
            (
                GOOD.replace("\"counters\"", "\"speed\""),
                "unknown metric 'speed'",
            ),
            (format!("{GOOD}colour = 3\n"), "unknown field `colour`"),
            (GOOD.replace("\"embree\", ", ""), "must hold 'embree'"),
            (format!("{GOOD}repeats = 1\n"), "repeats = 1"),
            (
                GOOD.replace("\"time_ratio\"", "\"instructions\""),
                "no [instructions] table",
            ),
            ("engines = [".to_string(), "s.toml: "),
        ];
        for (text, want) in cases {
            let e = err(&text);
            assert!(e.starts_with("s.toml: "), "{e}");
            assert!(e.contains(want), "{e} lacks {want}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
    }

    #[test]
    fn a_plugin_is_named_by_its_path_as_on_the_command_line() {
        let lib = std::env::temp_dir().join(format!("rtbench-suite-{}.so", std::process::id()));
        std::fs::write(&lib, b"not loaded by parse").unwrap();
        let text = GOOD.replace(
            "\"bvh4:simd=off\"",
            &format!("\"plugin:{}:leaf=2\"", lib.display()),
        );
        let s = parse("s.toml", &text).unwrap();
        let v = &s.variants[2];
        assert_eq!(v.engine, "plugin");
        assert_eq!(
            v.settings,
            vec![
                ("path".to_string(), lib.display().to_string()),
                ("leaf".to_string(), "2".to_string())
            ]
        );
        std::fs::remove_file(&lib).unwrap();
        let e = err(&GOOD.replace("\"bvh4:simd=off\"", "\"plugin:/no/such/lib.so\""));
        assert!(
            e.starts_with("s.toml: ") && e.contains("no such file"),
            "{e}"
        );
    }
}
