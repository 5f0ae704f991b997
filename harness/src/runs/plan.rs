//! `rtbench run` and `rtbench sweep`: many (engine, scene, SF, settings, threads) runs, each in its
//! own child process (`rtbench run-one`), so that peak RSS is that run's alone and a crash, an
//! out-of-memory or a time-out costs one run, recorded as failed with its reason.
//!
//! Results go to `DIR/results.jsonl`, rewritten atomically (temp file, then rename) after every
//! run: killing `rtbench run` at any moment leaves a whole file, and `--resume` skips the runs it
//! already holds. `DIR/env.json` records the environment.

use crate::error::{input, Result};
use crate::output::{fmt_secs, write_atomic};
use rtbench_reports::{read_results, run_key, RunRecord, SceneInfo};
use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A scene file a plan traces (OBJ, PLY, glTF or NFF): the path as given, and its run label,
/// the file's name with its content hash ([`crate::source::Source::run_label`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneFile {
    pub path: String,
    pub label: String,
}

/// One scene of a plan's `--scenes` (or a suite's `scenes`): an SPD program, traced at each
/// size factor, or a scene file, traced once as it is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PlanScene {
    Program(rtbench_scenes::spd::Program),
    File(SceneFile),
}

impl PlanScene {
    /// `standard`, or a program name, or a path to a scene file; a bad name or path is one line.
    pub fn parse(s: &str) -> Result<PlanScene> {
        let s = s.trim();
        if let Ok(p) = s.parse::<rtbench_scenes::spd::Program>() {
            return Ok(PlanScene::Program(p));
        }
        let source = crate::source::Source::resolve(s, None, None, None)?;
        match &source {
            crate::source::Source::File(_) => {
                // Read once here, so a malformed file is one line and exit 2 before any run,
                // not a failed run per engine.
                source.load()?;
                Ok(PlanScene::File(SceneFile {
                    path: s.to_string(),
                    label: source.run_label()?,
                }))
            }
            // `room`, `roomN`: no size factor to plan.
            _ => Err(input(format!(
                "{s}: not an SPD program nor a scene file (the room runs with render or reproduce)"
            ))),
        }
    }

    /// A comma-separated list; `standard` in it is the seven standard programs.
    pub fn parse_list(list: &str) -> Result<Vec<PlanScene>> {
        let mut out = Vec::new();
        for item in list.split(',').filter(|x| !x.trim().is_empty()) {
            if item.trim() == "standard" {
                out.extend(
                    rtbench_scenes::spd::Program::STANDARD
                        .iter()
                        .map(|&p| PlanScene::Program(p)),
                );
            } else {
                out.push(PlanScene::parse(item)?);
            }
        }
        if out.is_empty() {
            return Err(input(format!("--scenes '{list}': no scene named")));
        }
        Ok(out)
    }

    /// The program's name, or the file's run label.
    pub fn name(&self) -> String {
        match self {
            PlanScene::Program(p) => p.name().to_string(),
            PlanScene::File(f) => f.label.clone(),
        }
    }
}

/// One planned run.
#[derive(Clone, Debug)]
pub struct Job {
    pub engine: String,
    pub settings: Vec<(String, String)>,
    /// The SPD program's name, or for a scene file its run label.
    pub program: String,
    /// The size factor (unused for a scene file).
    pub sf: u32,
    pub tessellate: Option<u32>,
    /// `None`: all cores.
    pub threads: Option<usize>,
    /// The scene file traced instead of a program.
    pub file: Option<SceneFile>,
}

/// The group a job of `run` is sharded with: its scene (program, SF, tessellation) and threads, so
/// Embree's run and the engines measured against it land on one machine.
pub fn run_group(j: &Job) -> (String, u32, Option<u32>, Option<usize>) {
    (j.program.clone(), j.sf, j.tessellate, j.threads)
}

/// What identifies a plan across its shards: the command, the shared settings, every job key.
pub fn plan_text(kind: &str, c: &Common, keys: &[String]) -> String {
    // `paired_threads` only when asked for, so plans written before it keep their text.
    let threads = match c.paired_threads {
        0 => String::new(),
        n => format!(" paired_threads={n}"),
    };
    let mut rounds = match c.rounds {
        1 => String::new(),
        n => format!(" rounds={n}"),
    };
    if c.max_rounds > c.rounds {
        rounds.push_str(&format!(
            " max_rounds={} target_ci={}",
            c.max_rounds, c.target_ci_pct
        ));
    }
    format!(
        "{kind} repeats={}{rounds} size={} check={} paired={}{threads} max_seconds={:?} max_memory={:?}\n{}",
        c.repeats,
        c.size,
        c.check,
        c.paired,
        c.max_seconds,
        c.max_memory,
        keys.join("\n")
    )
}

impl Job {
    fn scene_label(&self) -> String {
        if let Some(f) = &self.file {
            return f.label.clone();
        }
        let mut s = format!("{}{}", self.program, self.sf);
        if let Some(r) = self.tessellate {
            s.push_str(&format!("-tess{r}"));
        }
        s
    }

    /// The engine with its settings, as reports name it: `bvh4[simd=off]`.
    fn label(&self) -> String {
        rtbench_reports::engine_label(&self.engine, self.settings.iter().map(|(k, v)| (k, v)))
    }

    fn threads_count(&self) -> usize {
        self.threads.unwrap_or_else(|| {
            std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1)
        })
    }

    pub fn key(&self) -> String {
        let settings: BTreeMap<String, String> = self.settings.iter().cloned().collect();
        run_key(
            &self.engine,
            &settings,
            &self.scene_label(),
            self.threads_count(),
        )
    }
}

/// What every run of a plan shares.
#[derive(Clone, Debug)]
pub struct Common {
    /// Timed repeats of each job, over all its rounds.
    pub repeats: u32,
    /// Rounds each job is spread over (`run --rounds`; 1: one process does all the repeats).
    pub rounds: u32,
    /// Rounds a job may take in all: beyond `rounds`, one more at a time while its figure's
    /// interval is wider than ±`target_ci_pct` (`run --max-rounds`; `rounds`: none more).
    pub max_rounds: u32,
    pub target_ci_pct: f64,
    pub size: u32,
    pub check: bool,
    /// Pairs of engine and Embree traces timed back to back in the child (0: none).
    pub paired: u32,
    /// Pairs of one-thread and N-thread traces timed back to back in the child (0: none).
    pub paired_threads: u32,
    /// Exactly the pairs asked for, not more for fast traces (`run-one --pairs-exact`).
    pub pairs_exact: bool,
    /// The wall time fast traces' pairs span at least in each child (`run-one --pair-span`).
    pub pair_span_s: f64,
    pub max_seconds: Option<f64>,
    pub max_memory: Option<u64>,
}

/// The results directory: `results.jsonl` kept whole.
pub struct ResultsDir {
    pub dir: PathBuf,
    pub records: Vec<RunRecord>,
}

impl ResultsDir {
    pub fn open(dir: &Path, resume: bool) -> Result<ResultsDir> {
        std::fs::create_dir_all(dir)
            .map_err(|e| input(format!("{}: cannot create: {e}", dir.display())))?;
        let records = read_results(dir).map_err(|e| input(e.to_string()))?;
        if !resume && !records.is_empty() {
            eprintln!(
                "rtbench: {} holds {} runs; runs with the same key are replaced (use --resume to skip them)",
                dir.display(),
                records.len()
            );
        }
        let mut env = crate::measure::environment::capture();
        if resume && !records.is_empty() {
            // The directory's runs began when its first run did: a resumed run keeps that
            // start (reports date the results by it).
            // (An unreadable env.json is rewritten whole, as on a fresh start.)
            let before = rtbench_reports::read_environment(dir).ok().flatten();
            if let Some(before) = before.filter(|b| !b.started_at.is_empty()) {
                env.started_at = before.started_at;
            }
        }
        let text = serde_json::to_string_pretty(&env).expect("environment serialises");
        write_atomic(&dir.join("env.json"), |w| {
            std::io::Write::write_all(w, text.as_bytes())
        })?;
        Ok(ResultsDir {
            dir: dir.to_path_buf(),
            records,
        })
    }

    pub fn has(&self, key: &str) -> bool {
        self.records.iter().any(|r| r.key == key)
    }

    /// Adds (or replaces) a record and rewrites the file atomically.
    pub fn put(&mut self, rec: RunRecord) -> Result<()> {
        self.records.retain(|r| r.key != rec.key);
        self.records.push(rec);
        rtbench_reports::attach_ratios(&mut self.records);
        let mut text = String::new();
        for r in &self.records {
            text.push_str(&serde_json::to_string(r).expect("records serialise"));
            text.push('\n');
        }
        write_atomic(&self.dir.join("results.jsonl"), |w| {
            std::io::Write::write_all(w, text.as_bytes())
        })
    }
}

fn rss_of(pid: u32) -> Option<u64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let kb: u64 = s
        .lines()
        .find(|l| l.starts_with("VmRSS:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()?;
    Some(kb * 1024)
}

fn failed(job: &Job, common: &Common, reason: String, wall_s: f64) -> RunRecord {
    RunRecord {
        key: job.key(),
        status: "failed".into(),
        reason: Some(reason),
        engine: job.engine.clone(),
        settings: job.settings.iter().cloned().collect(),
        scene: match &job.file {
            Some(f) => SceneInfo {
                name: f.label.clone(),
                file: Some(f.path.clone()),
                ..Default::default()
            },
            None => SceneInfo {
                name: job.scene_label(),
                program: Some(job.program.clone()),
                sf: Some(job.sf),
                tessellate: job.tessellate,
                ..Default::default()
            },
        },
        threads: job.threads_count(),
        repeats: common.repeats,
        size: common.size,
        wall_s,
        finished_at: crate::measure::environment::now_utc(),
        ..Default::default()
    }
}

/// Runs one job in a child process, enforcing the time and memory limits.
pub fn run_child(job: &Job, common: &Common) -> RunRecord {
    let exe = match std::env::current_exe() {
        Ok(e) => e,
        Err(e) => {
            return failed(
                job,
                common,
                format!("cannot find the rtbench binary: {e}"),
                0.0,
            )
        }
    };
    let mut cmd = Command::new(exe);
    cmd.args(["run-one", "--engine", &job.engine]);
    match &job.file {
        Some(f) => {
            cmd.args(["--scene", &f.path]);
        }
        None => {
            cmd.args(["--scene", &job.program, "--sf", &job.sf.to_string()]);
            if let Some(r) = job.tessellate {
                cmd.args(["--tessellate", &r.to_string()]);
            }
        }
    }
    for (k, v) in &job.settings {
        cmd.args(["--set", &format!("{k}={v}")]);
    }
    {
        let t = job.threads.map_or("all".to_string(), |t| t.to_string());
        cmd.args(["--threads", &t]);
    }
    cmd.args([
        "--repeat",
        &common.repeats.to_string(),
        "--size",
        &common.size.to_string(),
    ]);
    if !common.check {
        cmd.arg("--no-check");
    }
    if common.paired > 0 {
        cmd.args(["--paired", &common.paired.to_string()]);
    }
    if common.paired_threads > 0 {
        cmd.args(["--paired-threads", &common.paired_threads.to_string()]);
    }
    if common.pairs_exact {
        cmd.arg("--pairs-exact");
    }
    if common.pair_span_s != crate::measure::repeat::PAIR_SPAN_S {
        cmd.args(["--pair-span", &common.pair_span_s.to_string()]);
    }
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let start = Instant::now();
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => return failed(job, common, format!("cannot start the run: {e}"), 0.0),
    };
    // Drain both pipes on threads so a chatty child never blocks on a full pipe.
    let mut out = child.stdout.take().expect("piped");
    let mut err = child.stderr.take().expect("piped");
    let out_t = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out.read_to_string(&mut s);
        s
    });
    let err_t = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err.read_to_string(&mut s);
        s
    });
    let mut limit_hit = None;
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break Some(s),
            Ok(None) => {}
            Err(e) => {
                limit_hit = Some(format!("lost the run: {e}"));
                break None;
            }
        }
        let elapsed = start.elapsed().as_secs_f64();
        if let Some(max) = common.max_seconds {
            if elapsed > max {
                limit_hit = Some(format!("time limit: still running after {max} s"));
            }
        }
        if let (Some(max), Some(rss)) = (common.max_memory, rss_of(child.id())) {
            if rss > max {
                limit_hit = Some(format!(
                    "memory limit: RSS {} MiB over {} MiB",
                    rss >> 20,
                    max >> 20
                ));
            }
        }
        if limit_hit.is_some() {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let wall_s = start.elapsed().as_secs_f64();
    let stdout = out_t.join().unwrap_or_default();
    let stderr = err_t.join().unwrap_or_default();
    if let Some(reason) = limit_hit {
        return failed(job, common, reason, wall_s);
    }
    let status = status.expect("exited");
    if status.success() {
        match serde_json::from_str::<RunRecord>(stdout.trim()) {
            Ok(mut r) => {
                r.wall_s = wall_s;
                r
            }
            Err(e) => failed(
                job,
                common,
                format!("the run printed no record: {e}"),
                wall_s,
            ),
        }
    } else {
        // The child's own one-line error, or the panic message.
        let line = stderr
            .lines()
            .find(|l| l.contains("panicked at"))
            .map(|l| {
                let msg = stderr
                    .lines()
                    .skip_while(|x| !x.contains("panicked at"))
                    .nth(1)
                    .unwrap_or("");
                format!("panic: {} {}", l.trim(), msg.trim())
            })
            .or_else(|| {
                stderr
                    .lines()
                    .rev()
                    .find(|l| !l.trim().is_empty())
                    .map(|l| l.trim().to_string())
            })
            .unwrap_or_default();
        let how = match status.code() {
            Some(c) => format!("exit status {c}"),
            None => {
                use std::os::unix::process::ExitStatusExt;
                let sig = status.signal().unwrap_or(0);
                let name = match sig {
                    4 => " (SIGILL)",
                    6 => " (SIGABRT)",
                    7 => " (SIGBUS)",
                    8 => " (SIGFPE)",
                    9 => " (SIGKILL)",
                    11 => " (SIGSEGV)",
                    _ => "",
                };
                format!("killed by signal {sig}{name}")
            }
        };
        let reason = if line.is_empty() {
            how
        } else {
            format!("{how}: {line}")
        };
        failed(job, common, reason, wall_s)
    }
}

/// Progress on stderr: a bar with the runs done and indicatif's estimate of the time left, drawn
/// only when stderr is a terminal, and one line per finished run
/// (`[3/42] bvh4 balls4 @1: ok, … (elapsed 12s, left ~1m 20s)`) above it, or alone in a log.
pub struct Progress {
    bar: indicatif::ProgressBar,
}

impl Progress {
    pub fn new(total: usize) -> Progress {
        let bar = indicatif::ProgressBar::with_draw_target(
            Some(total as u64),
            indicatif::ProgressDrawTarget::stderr(),
        );
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "[{pos}/{len}] {wide_bar} elapsed {elapsed}, left ~{eta}",
            )
            .expect("the template is valid"),
        );
        Progress { bar }
    }

    /// `n` runs more than the plan counted, with a line saying why.
    pub fn more(&mut self, n: usize, why: &str) {
        self.bar.inc_length(n as u64);
        if self.bar.is_hidden() {
            eprintln!("{why}");
        } else {
            self.bar.println(why);
        }
    }

    pub fn finish(&mut self, job: &Job, rec: &RunRecord, skipped: bool) {
        self.bar.inc(1);
        let (done, total) = (self.bar.position(), self.bar.length().unwrap_or(0));
        let elapsed = self.bar.elapsed().as_secs_f64();
        let left = if done < total {
            self.bar.eta().as_secs_f64()
        } else {
            0.0
        };
        let what = if skipped {
            "already done".to_string()
        } else if rec.ok() {
            let agree = rec
                .check
                .as_ref()
                .map(|c| format!(", agreement {:.6}", c.hit_agreement))
                .unwrap_or_default();
            format!(
                "ok, trace {:.3} s, {:.2} Mrays/s{agree}",
                rec.time_s.trace.median, rec.mrays_per_s
            )
        } else {
            format!("FAILED ({})", rec.reason.as_deref().unwrap_or(""))
        };
        let line = format!(
            "[{done}/{total}] {} {} @{}: {what} (elapsed {}, left ~{})",
            job.label(),
            job.scene_label(),
            job.threads_count(),
            fmt_secs(elapsed),
            fmt_secs(left)
        );
        if self.bar.is_hidden() {
            eprintln!("{line}");
        } else {
            self.bar.println(line);
        }
    }
}

/// The bar goes when the run does: `run` may add rounds after the planned count is reached.
impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// `rtbench run`: every job once per round ([`super::rounds`]), in plan order each round; the
/// record of a job holds its rounds so far after each one, so an interrupted run keeps them and
/// `--resume` runs only the rounds missing. Returns how many jobs failed.
pub fn run(jobs: &[Job], common: &Common, out: &mut ResultsDir, resume: bool) -> Result<usize> {
    let split = super::rounds::Split::of(
        common.rounds,
        common.repeats,
        common.paired,
        common.paired_threads,
    );
    let mut progress = Progress::new(jobs.len() * split.rounds as usize);
    // This invocation's record of each job (with --resume, what the directory holds).
    let mut records: Vec<Option<RunRecord>> = jobs
        .iter()
        .map(|j| {
            let key = j.key();
            resume
                .then(|| out.records.iter().find(|r| r.key == key).cloned())
                .flatten()
        })
        .collect();
    for round in 0..split.rounds as usize {
        let (repeats, paired, paired_threads) = split.round(round as u32);
        // The cross-check is the same in every round: the first one makes it.
        let child = Common {
            repeats,
            rounds: 1,
            paired,
            paired_threads,
            check: common.check && round == 0,
            // The rounds share the span fast traces' pairs take: more rounds, not more time.
            pair_span_s: common.pair_span_s / f64::from(split.rounds),
            ..common.clone()
        };
        for (job, slot) in jobs.iter().zip(records.iter_mut()) {
            let done = slot.as_ref().map_or(0, |r| {
                if r.ok() {
                    super::rounds::rounds_in(r)
                } else {
                    usize::MAX
                }
            });
            if done > round {
                progress.finish(job, slot.as_ref().expect("done"), true);
                continue;
            }
            let rec = run_child(job, &child);
            progress.finish(job, &rec, false);
            let rec = match slot.take() {
                Some(prev) => super::rounds::absorb(prev, rec),
                None => rec,
            };
            out.put(rec.clone())?;
            *slot = Some(rec);
        }
    }
    // Further rounds, one at a time, for the jobs whose figure is still wider than the target:
    // each such round runs those jobs once more, with the first round's share of repeats and pairs.
    let (repeats, paired, paired_threads) = split.round(0);
    let more = Common {
        repeats,
        rounds: 1,
        paired,
        paired_threads,
        check: false,
        pair_span_s: common.pair_span_s / f64::from(split.rounds),
        ..common.clone()
    };
    for round in split.rounds as usize..common.max_rounds as usize {
        let wanted: Vec<(usize, f64)> = records
            .iter()
            .enumerate()
            .filter_map(|(i, r)| {
                let r = r.as_ref()?;
                if super::rounds::rounds_in(r) > round {
                    return None;
                }
                Some((i, super::rounds::too_wide(r, common.target_ci_pct)?))
            })
            .collect();
        if wanted.is_empty() {
            break;
        }
        progress.more(
            wanted.len(),
            &format!(
                "round {}: {} job(s) not yet within ±{}% (widest ±{:.1}%)",
                round + 1,
                wanted.len(),
                common.target_ci_pct,
                wanted.iter().map(|w| w.1).fold(0.0, f64::max)
            ),
        );
        for (i, _) in wanted {
            let rec = run_child(&jobs[i], &more);
            progress.finish(&jobs[i], &rec, false);
            let rec = match records[i].take() {
                Some(prev) => super::rounds::absorb(prev, rec),
                None => rec,
            };
            out.put(rec.clone())?;
            records[i] = Some(rec);
        }
    }
    Ok(records.iter().flatten().filter(|r| !r.ok()).count())
}

/// `rtbench sweep`: for each scene and engine, raise the SF from `sf_start` until a run fails
/// (time or memory limit, crash) or takes longer than the time limit. A scene file has no size
/// factor to raise: it is run once.
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    engines: &[(String, Vec<(String, String)>)],
    scenes: &[PlanScene],
    sf_start: u32,
    sf_max: u32,
    threads: Option<usize>,
    common: &Common,
    out: &mut ResultsDir,
    resume: bool,
) -> Result<usize> {
    let mut runs = 0;
    let start = Instant::now();
    for scene in scenes {
        let (file, sfs) = match scene {
            PlanScene::Program(_) => (None, sf_start..=sf_max),
            PlanScene::File(f) => (Some(f.clone()), sf_start..=sf_start),
        };
        let program = scene.name();
        for (engine, settings) in engines {
            for sf in sfs.clone() {
                let job = Job {
                    engine: engine.clone(),
                    settings: settings.clone(),
                    program: program.clone(),
                    sf,
                    tessellate: None,
                    threads,
                    file: file.clone(),
                };
                let key = job.key();
                let rec = if resume && out.has(&key) {
                    out.records
                        .iter()
                        .find(|r| r.key == key)
                        .cloned()
                        .expect("has")
                } else {
                    let rec = run_child(&job, common);
                    runs += 1;
                    out.put(rec.clone())?;
                    rec
                };
                let verdict = if rec.ok() {
                    format!("ok, {:.2} s wall", rec.wall_s)
                } else {
                    format!("FAILED ({})", rec.reason.as_deref().unwrap_or(""))
                };
                eprintln!(
                    "sweep {engine} {}: {verdict} (elapsed {})",
                    job.scene_label(),
                    fmt_secs(start.elapsed().as_secs_f64())
                );
                let over_time = common.max_seconds.is_some_and(|m| rec.wall_s > m);
                if !rec.ok() || over_time {
                    break;
                }
            }
        }
    }
    Ok(runs)
}
