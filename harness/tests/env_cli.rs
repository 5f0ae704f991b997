//! The environment variables and `--threads`: read once, listed by `rtbench env` and named by
//! `--help`; a malformed value is one line naming the accepted forms, exit 2.

mod common;

use common::{expect_input_error, rtbench};
use std::process::Command;

fn with_env(name: &str, value: &str, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rtbench"))
        .env(name, value)
        .args(args)
        .output()
        .expect("rtbench runs")
}

#[test]
fn a_malformed_variable_is_one_line_and_exit_2() {
    for (name, bad, forms) in [
        ("RTBENCH_MAX_THREADS", "abc", "a count from 1 to 64"),
        ("RTBENCH_PIN_THREADS", "yes", "1 (on) or 0 (off)"),
        ("RTBENCH_PLANT", "work:bvh8", "work:ENGINE:SCENE:FRACTION"),
    ] {
        let out = with_env(name, bad, &["engines"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}={bad}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(
            err.contains(&format!("{name}='{bad}'")) && err.contains(forms),
            "{err}"
        );
        assert!(out.stdout.is_empty());
    }
}

#[test]
fn a_malformed_thread_count_is_one_line_and_exit_2() {
    expect_input_error(
        &[
            "render",
            "--scene",
            "balls",
            "--sf",
            "1",
            "--engine",
            "bvh8",
            "--threads",
            "x",
        ],
        "expected a count of at least 1, or all",
    );
    expect_input_error(
        &[
            "render",
            "--scene",
            "balls",
            "--sf",
            "1",
            "--engine",
            "bvh8",
            "--threads",
            "0",
        ],
        "expected a count of at least 1, or all",
    );
    let d = common::Dir::new("env", "threads");
    let out = d.0.display().to_string();
    expect_input_error(
        &[
            "run",
            "--engines",
            "embree",
            "--scenes",
            "balls",
            "--threads",
            "1,zero",
            "--out",
            &out,
        ],
        "expected a count of at least 1, or all",
    );
}

#[test]
fn env_lists_every_variable_and_help_names_them() {
    let listed = rtbench(&["env", "--json"]);
    assert_eq!(listed.status.code(), Some(0));
    let rows: serde_json::Value = serde_json::from_slice(&listed.stdout).unwrap();
    let names: Vec<&str> = rows
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["name"].as_str().unwrap())
        .collect();
    assert!(names.len() >= 10, "{names:?}");
    let help = String::from_utf8_lossy(&rtbench(&["--help"]).stdout).to_string();
    for n in &names {
        assert!(help.contains(n), "--help does not name {n}");
    }
    // env shows a malformed value instead of stopping on it.
    let out = with_env("RTBENCH_SCHED", "yes", &["env"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stdout).contains("yes (not accepted"));
}
