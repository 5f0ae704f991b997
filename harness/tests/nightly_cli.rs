//! `rtbench nightly` and `rtbench history` as a nightly job uses them: a tiny suite over a few
//! nights, bad suites and bad databases (exit 2, one line), a planted counter change (exit 1,
//! named), exports, and the dashboard loaded in headless Chromium: its plots, links and a
//! regression mark.

mod common;

use common::{expect_input_error, rtbench};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtbench-nightly-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const SUITE: &str = r#"
name = "tiny"
engines = ["embree", "grid", "bvh4"]
scenes = ["tetra"]
sf = [1]
repeats = 3
paired = 2
size = 24
gate = ["counters", "time_ratio"]
# A time change on one night is only a suspect, so the test's exit statuses do not hang on the
# machine's load; the planted counter change is a regression on its first night.
confirm_nights = 2
"#;

fn nightly(suite: &Path, db: &Path, extra: &[&str], plant: Option<&str>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rtbench"));
    c.args(["nightly", "--suite"])
        .arg(suite)
        .arg("--db")
        .arg(db)
        .args(extra);
    match plant {
        Some(p) => c.env("RTBENCH_PLANT", p),
        None => c.env_remove("RTBENCH_PLANT"),
    };
    c.output().expect("rtbench runs")
}

#[test]
fn bad_suites_and_bad_databases_are_exit_2_with_one_line() {
    let d = tmp("bad");
    let good = d.join("good.toml");
    std::fs::write(&good, SUITE).unwrap();
    let db = d.join("h.sqlite");
    let cases = [
        (
            SUITE.replace("\"grid\"", "\"gird\""),
            "unknown engine 'gird'",
        ),
        (
            SUITE.replace("tetra", "tetrahedron"),
            "unknown scene 'tetrahedron'",
        ),
        (
            SUITE.replace("\"counters\"", "\"latency\""),
            "unknown metric 'latency'",
        ),
        (format!("{SUITE}nights = 3\n"), "unknown field `nights`"),
    ];
    for (i, (text, needle)) in cases.iter().enumerate() {
        let f = d.join(format!("bad{i}.toml"));
        std::fs::write(&f, text).unwrap();
        let (fs, dbs) = (f.display().to_string(), db.display().to_string());
        expect_input_error(&["nightly", "--suite", &fs, "--db", &dbs], needle);
        expect_input_error(&["nightly", "--suite", &fs, "--db", &dbs], &fs);
    }
    // Not SQLite.
    let junk = d.join("junk.sqlite");
    std::fs::write(&junk, "not a database\n".repeat(100)).unwrap();
    let (gs, js) = (good.display().to_string(), junk.display().to_string());
    expect_input_error(&["nightly", "--suite", &gs, "--db", &js], "not a database");
    expect_input_error(&["history", "list", "--db", &js], "not a database");
    // A newer schema.
    let newer = d.join("newer.sqlite");
    rusqlite::Connection::open(&newer)
        .unwrap()
        .execute_batch("CREATE TABLE x(a); PRAGMA user_version = 99;")
        .unwrap();
    let ns = newer.display().to_string();
    expect_input_error(&["history", "list", "--db", &ns], "schema 99 is newer");
    expect_input_error(
        &["nightly", "--suite", &gs, "--db", &ns],
        "schema 99 is newer",
    );
    expect_input_error(
        &["history", "list", "--db", "/nonexistent/h.sqlite"],
        "no such history",
    );
}

#[test]
fn nights_accumulate_and_a_planted_counter_change_is_named() {
    let d = tmp("nights");
    let suite = d.join("tiny.toml");
    std::fs::write(&suite, SUITE).unwrap();
    let db = d.join("h.sqlite");
    for _ in 0..4 {
        let o = nightly(&suite, &db, &["--json"], None);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let list = rtbench(&["history", "list", "--db", db.to_str().unwrap(), "--json"]);
    let runs: Value = serde_json::from_slice(&list.stdout).unwrap();
    assert_eq!(runs.as_array().unwrap().len(), 4);
    // Every pair of every round is stored: 3 rounds × 2 pairs of ratios per engine but Embree
    // (exactly the suite's pairs a round, however fast the trace).
    let show = rtbench(&["history", "show", "--db", db.to_str().unwrap(), "--json"]);
    let v: Value = serde_json::from_slice(&show.stdout).unwrap();
    let ratio = v["metrics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["name"] == "grid tetra1@1/time_ratio")
        .expect("a ratio");
    assert_eq!(ratio["samples"].as_array().unwrap().len(), 6, "{ratio}");
    assert!(v["environment"]["cpu_model"].is_string());

    // A planted counter change: exit 1, the counter named; --no-record leaves the history as it was.
    let o = nightly(&suite, &db, &["--no-record"], Some("counter:grid:tetra"));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("grid tetra1@1/counter.primitive_tests"),
        "{err}"
    );
    let list = rtbench(&["history", "list", "--db", db.to_str().unwrap(), "--json"]);
    let runs: Value = serde_json::from_slice(&list.stdout).unwrap();
    assert_eq!(runs.as_array().unwrap().len(), 4);

    // Exports.
    let csv = rtbench(&["history", "export", "--db", db.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&csv.stdout);
    assert!(text.starts_with("run_id,started_at,git_commit"));
    assert!(text.lines().count() > 4 * 10, "{text}");
    let bmf = rtbench(&[
        "history",
        "export",
        "--db",
        db.to_str().unwrap(),
        "--format",
        "bmf",
    ]);
    let v: Value = serde_json::from_slice(&bmf.stdout).unwrap();
    assert!(v["grid tetra1@1"]["time_ratio"]["value"].as_f64().unwrap() > 0.0);
    let check = rtbench(&["history", "check", "--db", db.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&check.stdout).contains("integrity_check ok"));

    // Replay: the detection again over the four nights, each against the nights before it.
    let replay = rtbench(&[
        "history",
        "replay",
        "--db",
        db.to_str().unwrap(),
        "--suite",
        suite.to_str().unwrap(),
        "--json",
    ]);
    let v: Value = serde_json::from_slice(&replay.stdout).unwrap();
    assert_eq!(v["nights"], 4, "{v}");
    let nights = v["nights_detail"].as_array().unwrap();
    let baselines: Vec<u64> = nights
        .iter()
        .map(|n| n["baseline_nights"].as_u64().unwrap())
        .collect();
    assert_eq!(baselines, [0, 1, 2, 3]);
    // Each night says which gates were active: time ratios from the fourth night (three
    // baseline nights), counters from the second.
    let gates = |i: usize| nights[i]["gates"].to_string();
    assert!(
        gates(0).contains("counters: not active yet"),
        "{}",
        gates(0)
    );
    assert!(
        gates(2).contains("counters: active since night 2"),
        "{}",
        gates(2)
    );
    assert!(
        gates(2).contains("time_ratio: not active yet: 2 of the 3"),
        "{}",
        gates(2)
    );
    assert!(
        gates(3).contains("time_ratio: active since"),
        "{}",
        gates(3)
    );

    // `history show` of the last night: its baseline nights, its gates, and what each gated
    // metric was compared against.
    let show = rtbench(&["history", "show", "--db", db.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&show.stdout);
    assert!(text.contains("3 baseline nights of this machine"), "{text}");
    assert!(text.contains("## Gates"), "{text}");
    assert!(text.contains("- time_ratio: active since"), "{text}");
    let row = text
        .lines()
        .find(|l| l.starts_with("| grid tetra1@1/time_ratio |"))
        .unwrap_or_else(|| panic!("no time ratio row: {text}"));
    // Whatever the machine's load made of the time ratio (ok, suspect or improvement), the row
    // names the baseline it was compared against.
    assert!(row.contains(" over 3 nights, interval ["), "{row}");
    let replay = rtbench(&[
        "history",
        "replay",
        "--db",
        db.to_str().unwrap(),
        "--suite",
        suite.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&replay.stdout);
    assert!(!text.contains("(, "), "{text}");
    assert!(
        text.contains("0 baseline nights; waiting: counters 0/1 nights"),
        "{text}"
    );

    // The dashboard, in headless Chromium, after a fifth night with a planted counter change
    // (recorded: a regression on night 5).
    let o = nightly(&suite, &db, &[], Some("counter:grid:tetra"));
    assert_eq!(o.status.code(), Some(1));
    let list = rtbench(&["history", "list", "--db", db.to_str().unwrap(), "--json"]);
    let runs: Value = serde_json::from_slice(&list.stdout).unwrap();
    let commit = runs[4]["git_commit"].as_str().unwrap().to_string();
    let night = runs[4]["id"].as_i64().unwrap();
    let out = d.join("dash");
    let dash = |extra: &[&str]| {
        let mut args = vec![
            "history",
            "dashboard",
            "--db",
            db.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        rtbench(&args)
    };
    // A template that cannot make a link is refused.
    expect_input_error(
        &[
            "history",
            "dashboard",
            "--db",
            db.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--commit-url",
            "https://example.org/commit/",
        ],
        "expected an http(s) URL holding {commit}",
    );
    let o = dash(&[
        "--commit-url",
        "https://git.example.org/rtbench/commit/{commit}",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let page = out.join("index.html");
    let show = rtbench(&["history", "show", "--db", db.to_str().unwrap(), "--json"]);
    let v: Value = serde_json::from_slice(&show.stdout).unwrap();
    // One plot per metric, but none for a counter the engine does not keep (0 on every night).
    let metrics = v["metrics"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| !(m["kind"] == "counter" && m["value"].as_f64() == Some(0.0)))
        .count();
    dashboard_in_chromium(&page, &d, metrics, &commit, night);
}

/// Loads a page in headless Chromium; returns its DOM and the console lines Chromium logged.
fn chromium(page: &Path, profile: &Path) -> Option<(String, Vec<String>)> {
    let o = Command::new("chromium")
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--disable-background-networking",
            "--enable-logging=stderr",
            "--v=0",
            "--dump-dom",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("file://{}", page.display()))
        .output()
        .ok()?;
    let err = String::from_utf8_lossy(&o.stderr);
    let console = err
        .lines()
        .filter(|l| l.contains(":CONSOLE"))
        .map(String::from)
        .collect();
    Some((String::from_utf8_lossy(&o.stdout).into_owned(), console))
}

/// The dashboard in headless Chromium: no console message; one drawn plot per metric, every kind
/// among them; the planted counter's plot marked as that night's regression; commit ids linked
/// through the template, in the nights table and in the hover line of a night named in the address.
fn dashboard_in_chromium(page: &Path, dir: &Path, metrics: usize, commit: &str, night: i64) {
    if std::env::var_os("RTBENCH_SKIP_CHROMIUM").is_some() {
        eprintln!("RTBENCH_SKIP_CHROMIUM set: the dashboard was not loaded in Chromium");
        return;
    }
    // The canary: a page that logs an error must be caught, or this check proves nothing.
    let canary = dir.join("canary.html");
    std::fs::write(
        &canary,
        "<html><body><script>console.error('canary')</script></body></html>",
    )
    .unwrap();
    let (_, msgs) = chromium(&canary, &dir.join("profile-canary")).expect(
        "chromium is not installed: scripts/test.sh installs it (apt-get install chromium), \
         or set RTBENCH_SKIP_CHROMIUM=1",
    );
    assert!(
        msgs.iter().any(|m| m.contains("canary")),
        "the canary error was not seen: {msgs:?}"
    );
    let address = format!("{}?night={night}", page.display());
    let (dom, msgs) = chromium(Path::new(&address), &dir.join("profile")).unwrap();
    assert!(msgs.is_empty(), "console messages: {msgs:?}");
    let head = &dom[..dom.len().min(400)];
    assert!(dom.contains("rtbench nightly: tiny"), "{head}");
    // One section per metric, and uPlot drew a plot in each of them.
    let sections = dom.matches("<section class=\"plot\"").count();
    assert_eq!(sections, metrics, "{head}");
    assert_eq!(
        dom.matches("<div class=\"uplot").count(),
        sections,
        "{head}"
    );
    for kind in ["time_ratio", "counter"] {
        assert!(
            dom.contains(&format!("data-kind=\"{kind}\"")),
            "no {kind} plot"
        );
    }
    // The regression mark on the planted counter's plot.
    let name = "grid tetra1@1/counter.primitive_tests";
    let at = dom
        .find(&format!("data-name=\"{name}\""))
        .unwrap_or_else(|| panic!("no plot of {name}"));
    let plot = &dom[at..at + dom[at..].find("</section>").unwrap()];
    assert!(plot.contains("data-flag=\"regression\""), "{plot}");
    assert!(plot.contains("<span class=\"mark regression\""), "{plot}");
    assert!(
        plot.contains(&format!("regression night {night}")),
        "{plot}"
    );
    // Commit links: in the nights table and in the held hover line, with the night's value.
    let link = format!("href=\"https://git.example.org/rtbench/commit/{commit}\"");
    assert!(dom.matches(&link).count() > sections, "{head}");
    let hover = &plot[plot.find("<p class=\"hover\">").expect("a hover line")..];
    assert!(hover.contains(&format!("night {night} (")), "{hover}");
    assert!(hover.contains(&link), "{hover}");
    assert!(hover.contains("regression: "), "{hover}");
}
