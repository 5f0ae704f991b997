//! Hostile inputs of the third round, one test per class that needs the binary: limits (the
//! memory estimate under an address-space limit, output bounds, huge time budgets), compressed
//! stores' headers, duplicates and impossible figures in results, shards and suites, store
//! directories without a header, and `check --suite hard` with its default engines. Each input
//! is refused with exit 2 and one line, or gives the right answer; never a panic or an abort.

mod common;

use common::{expect_input_error, rtbench};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtbench-hard3-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// rtbench under an address-space limit of `kib` KiB.
fn limited(kib: u64, args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {kib}; exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_rtbench"))
        .args(args)
        .output()
        .expect("sh runs")
}

fn one_line_exit_2(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains(needle), "{err}");
}

#[test]
fn memory_is_estimated_against_the_address_space_limit() {
    let four_gb = 4_000_000;
    for (args, needle) in [
        (
            &[
                "render",
                "--scene",
                "balls",
                "--sf",
                "1",
                "--engine",
                "bvh4",
                "--tessellate",
                "1000",
                "--size",
                "8",
            ][..],
            "need about",
        ),
        (
            &[
                "render", "--scene", "gears", "--sf", "40", "--engine", "bvh4", "--size", "8",
            ][..],
            "need about",
        ),
        (
            &[
                "render",
                "--scene",
                "balls",
                "--sf",
                "1",
                "--engine",
                "breadth-first",
                "--set",
                "memory=4294967295",
                "--size",
                "8",
            ][..],
            "address space",
        ),
    ] {
        one_line_exit_2(&limited(four_gb, args), needle);
    }
}

#[test]
fn generation_is_bounded_and_time_budgets_may_be_huge() {
    let d = dir("gen");
    expect_input_error(&["scene", "gen", "balls", "--sf", "20"], "--max-bytes");
    expect_input_error(
        &["scene", "gen", "balls", "--sf", "5", "--max-bytes", "100K"],
        "--max-bytes",
    );
    let out = d.join("big").display().to_string();
    expect_input_error(
        &["scene", "store", "mount", "--sf", "20", "-o", &out],
        "--max-bytes",
    );
    assert!(!Path::new(&out).exists());
    let st = d.join("st").display().to_string();
    let r = rtbench(&[
        "scene",
        "store",
        "tetra",
        "--sf",
        "3",
        "--segment",
        "16",
        "--max-seconds",
        "1e308",
        "-o",
        &st,
    ]);
    assert!(r.status.success(), "{r:?}");
    let st2 = d.join("st2").display().to_string();
    let r = rtbench(&[
        "scene",
        "store",
        "tetra",
        "--sf",
        "2",
        "--segment",
        "16",
        "--max-seconds",
        "inf",
        "-o",
        &st2,
    ]);
    assert!(r.status.success(), "{r:?}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_compressed_store_header_is_vouched_for_and_store_dirs_are_named() {
    let d = dir("crc");
    for c in ["gzip:1", "zstd"] {
        let s = d.join(c.replace(':', "")).display().to_string();
        let r = rtbench(&[
            "scene",
            "store",
            "balls",
            "--sf",
            "1",
            "--layout",
            "basic",
            "--compress",
            c,
            "-o",
            &s,
        ]);
        assert!(r.status.success(), "{r:?}");
        let h = Path::new(&s).join("header.json");
        let mut text = std::fs::read_to_string(&h).unwrap();
        text.push(' ');
        std::fs::write(&h, text).unwrap();
        expect_input_error(
            &[
                "render",
                "--scene",
                &s,
                "--engine",
                "breadth-first",
                "--set",
                "layout=basic",
                "--size",
                "8",
            ],
            "header.crc",
        );
    }
    let no_header = d.join("nohdr");
    std::fs::create_dir_all(&no_header).unwrap();
    std::fs::write(no_header.join("bbox.bin"), b"").unwrap();
    expect_input_error(
        &[
            "render",
            "--scene",
            no_header.to_str().unwrap(),
            "--engine",
            "bvh4",
        ],
        "without its header.json",
    );
    let _ = std::fs::remove_dir_all(&d);
}

fn copy_shard(to: &Path) {
    let from = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fuzz/corpus/shard");
    std::fs::create_dir_all(to).unwrap();
    for f in ["shard.json", "results.jsonl"] {
        std::fs::copy(from.join(f), to.join(f)).unwrap();
    }
}

#[test]
fn duplicates_empty_sets_and_impossible_times_are_refused() {
    let d = dir("dups");
    let shard = d.join("shard");
    copy_shard(&shard);
    let merged = d.join("merged");
    let r = rtbench(&[
        "merge",
        shard.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{r:?}");
    let text = std::fs::read_to_string(shard.join("results.jsonl")).unwrap();
    let first = text.lines().next().unwrap().to_string();
    std::fs::write(shard.join("results.jsonl"), format!("{text}{first}\n")).unwrap();
    let merged2 = d.join("merged2").display().to_string();
    expect_input_error(
        &["merge", shard.to_str().unwrap(), "--out", &merged2],
        "twice",
    );
    let m = merged.to_str().unwrap();
    expect_input_error(&["compare", m, shard.to_str().unwrap()], "twice");
    let empty = d.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    std::fs::write(empty.join("results.jsonl"), "").unwrap();
    expect_input_error(&["compare", m, empty.to_str().unwrap()], "no runs");
    expect_input_error(&["report", empty.to_str().unwrap()], "no runs");
    let neg = d.join("neg");
    std::fs::create_dir_all(&neg).unwrap();
    std::fs::write(
        neg.join("results.jsonl"),
        text.replace("\"median\":", "\"median\":-"),
    )
    .unwrap();
    expect_input_error(&["compare", m, neg.to_str().unwrap()], "negative");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn suites_are_checked_whole_before_measuring() {
    let d = dir("suite");
    let base =
        "engines = [\"embree\", \"grid\"]\nscenes = [\"tetra\"]\nsf = [1]\nrepeats = 2\nsize = 8\ngate = [\"counters\"]\n";
    for (bad, needle) in [
        ("engines = [\"embree\", \"grid:simd=off\"]", "simd"),
        ("threads = [1000000]", "threads"),
    ] {
        let key = bad.split(" =").next().unwrap();
        let text: String = base
            .lines()
            .filter(|l| !l.starts_with(key))
            .map(|l| format!("{l}\n"))
            .collect::<String>()
            + bad
            + "\n";
        let s = d.join("s.toml");
        std::fs::write(&s, text).unwrap();
        let db = d.join("h.sqlite");
        expect_input_error(
            &[
                "nightly",
                "--suite",
                s.to_str().unwrap(),
                "--db",
                db.to_str().unwrap(),
            ],
            needle,
        );
        assert!(!db.exists(), "a night was recorded");
        expect_input_error(&["plan", "nightly", "--suite", s.to_str().unwrap()], needle);
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// The default engine list of `check --suite hard` holds no engine that needs more than its
/// name (the plugin pseudo-engine did): the suite runs with it and passes.
#[test]
fn check_suite_hard_runs_with_its_default_engines() {
    let out = rtbench(&["check", "--suite", "hard", "--json"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(!err.contains("plugin"), "{err}");
}

#[test]
fn an_interrupted_store_leaves_no_temporary_directory() {
    let d = dir("sigterm");
    let out = d.join("st");
    let mut child = Command::new(env!("CARGO_BIN_EXE_rtbench"))
        .args(["scene", "store", "tetra", "--sf", "9", "-o"])
        .arg(&out)
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("rtbench starts");
    // Wait until the temporary directory exists, then interrupt the write.
    let started = std::time::Instant::now();
    let tmp_exists = || {
        std::fs::read_dir(&d).unwrap().any(|e| {
            e.unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with(".st.tmp-")
        })
    };
    while !tmp_exists() && started.elapsed().as_secs() < 60 {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    // SAFETY: sending a signal to our own child.
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let status = child.wait().unwrap();
    let left: Vec<String> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    if status.success() {
        // Finished before the signal: the store is whole and nothing else is left.
        assert_eq!(left, ["st"], "{left:?}");
    } else {
        assert!(left.is_empty(), "left behind: {left:?}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_merged_night_is_recorded_once() {
    let d = dir("from-twice");
    let suite = d.join("tiny.toml");
    std::fs::write(
        &suite,
        "name = \"tiny\"\nengines = [\"embree\", \"grid\"]\nscenes = [\"tetra\"]\nsf = [1]\n\
         repeats = 2\npaired = 2\nsize = 16\ngate = [\"counters\", \"time_ratio\"]\n",
    )
    .unwrap();
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_rtbench"))
            .args(args)
            .env_remove("RTBENCH_PLANT")
            .output()
            .expect("rtbench runs")
    };
    let s = |p: &Path| p.to_str().unwrap().to_string();
    for k in ["1/2", "2/2"] {
        let out = d.join(format!("shard{}", &k[..1]));
        let o = run(&[
            "nightly",
            "--suite",
            &s(&suite),
            "--shard",
            k,
            "--out",
            &s(&out),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let merged = d.join("merged");
    let o = run(&[
        "merge",
        &s(&d.join("shard1")),
        &s(&d.join("shard2")),
        "--out",
        &s(&merged),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let db = d.join("h.sqlite");
    let record = || {
        run(&[
            "nightly",
            "--suite",
            &s(&suite),
            "--from",
            &s(&merged),
            "--db",
            &s(&db),
        ])
    };
    let first = record();
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    one_line_exit_2(&record(), "is already night 1");
    let list = run(&["history", "list", "--db", &s(&db), "--json"]);
    let nights: serde_json::Value = serde_json::from_slice(&list.stdout).unwrap();
    assert_eq!(nights.as_array().map(Vec::len), Some(1), "{nights}");
    let _ = std::fs::remove_dir_all(&d);
}
