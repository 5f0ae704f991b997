//! `rtbench reproduce` for 001 (Kimura 2007): the new tables are listed, and `kimura-3.3 --quick`
//! writes node statistics in which the 4-ary tree is shallower than the binary one.

use serde_json::Value;
use std::path::PathBuf;
use std::process::{Command, Output};

fn rtbench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rtbench"))
        .args(args)
        .output()
        .expect("rtbench runs")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtbench-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn reproduce_list_has_the_kimura_tables() {
    let out = rtbench(&["reproduce", "list"]);
    assert!(out.status.success());
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(s.contains("kimura-3.3"), "{s}");
    assert!(s.contains("kimura-simd"), "{s}");
    // Options of one table are refused by the others, with one line and exit 2.
    for (extra, needle) in [
        (["--max-sf", "tree=3"], "option 'max-sf' does not apply"),
        (["--size", "64"], "option 'size' does not apply"),
        (["--set", "bogus=1"], "option 'bogus' does not apply"),
        (["--set", "novalue"], "expected key=value"),
    ] {
        let out = rtbench(
            &[
                &["reproduce", "kimura-3.3", "--out", "/nonexistent/x"][..],
                &extra[..],
            ]
            .concat(),
        );
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle) && err.lines().count() == 1, "{err}");
    }
}

#[test]
fn kimura_trees_quick_four_ary_is_shallower() {
    let dir = tmp("kimura-3.3");
    let out = rtbench(&[
        "reproduce",
        "kimura-3.3",
        "--quick",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.join("kimura-3.3.md").exists());
    let v: Value =
        serde_json::from_slice(&std::fs::read(dir.join("kimura-3.3.json")).unwrap()).unwrap();
    let rows = v["measured"].as_array().unwrap();
    assert!(!rows.is_empty());
    for builder in ["median", "sah-sweep"] {
        let depth = |w: u64| {
            rows.iter()
                .find(|r| r["builder"] == builder && r["width"] == w)
                .and_then(|r| r["stats"]["avg_leaf_depth"].as_f64())
                .unwrap_or_else(|| panic!("no {builder} N={w} row"))
        };
        assert!(
            depth(16) < depth(8),
            "{builder}: N=16 not shallower than N=8"
        );
        assert!(
            depth(4) < depth(2),
            "{builder}: N=4 depth {} not below N=2 depth {}",
            depth(4),
            depth(2)
        );
    }
    // Both memory readings and the render timings of Fig. 3.17 are there, each row labelled.
    let claims: Vec<(&str, &str)> = v["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["claim"].as_str().unwrap(), r["subject"].as_str().unwrap()))
        .collect();
    for reading in ["empty nodes counted", "empty nodes not counted"] {
        assert!(
            claims
                .iter()
                .any(|(c, s)| *c == "memory-less-than-binary" && s.ends_with(reading)),
            "no memory row for '{reading}'"
        );
    }
    assert_eq!(
        claims
            .iter()
            .filter(|(c, _)| *c == "sah-renders-faster")
            .count(),
        3
    );
    assert!(claims.iter().any(|(c, _)| *c == "integer-depth-b10"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every table of the registry is listed with its seed, source, fidelity counts and runtime class; every
/// declared claim carries a fidelity label.
#[test]
fn reproduce_list_json_labels_every_claim() {
    let out = rtbench(&["reproduce", "list", "--json"]);
    assert!(out.status.success());
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let tables = v.as_array().unwrap();
    assert!(tables.len() >= 9, "{} tables", tables.len());
    let labels = ["faithful", "substituted", "model", "not reproducible"];
    for t in tables {
        let id = t["id"].as_str().unwrap();
        assert!(t["seed"].is_string() && t["table"].is_string(), "{id}");
        assert!(t["runtime"]["quick"].is_string(), "{id}");
        let claims = t["claims"].as_array().unwrap();
        assert!(!claims.is_empty(), "{id} declares no claim");
        let total: u64 = labels
            .iter()
            .map(|l| t["fidelity"][l].as_u64().unwrap())
            .sum();
        assert_eq!(total as usize, claims.len(), "{id}");
        for c in claims {
            assert!(
                labels.contains(&c["fidelity"].as_str().unwrap()),
                "{id}: {c}"
            );
        }
    }
}

/// A table that has nothing to measure runs in well under a second: kimura-3.2's exact counts, with
/// the printed 12^6 erratum caught, rows labelled, and the report in Markdown, JSON and HTML.
#[test]
fn kimura_3_2_counts_and_the_erratum() {
    let dir = tmp("kimura-3.2");
    let out = rtbench(&[
        "reproduce",
        "kimura-3.2",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    let failing: Vec<&str> = rows
        .iter()
        .filter(|r| r["verdict"] != "holds")
        .map(|r| r["subject"].as_str().unwrap())
        .collect();
    assert_eq!(failing, ["B=12 D=6"]);
    assert!(rows.iter().all(|r| r["fidelity"] == "faithful"));
    for ext in ["md", "json", "html"] {
        assert!(dir.join(format!("kimura-3.2.{ext}")).exists(), "{ext}");
    }
    let html = std::fs::read_to_string(dir.join("kimura-3.2.html")).unwrap();
    assert!(html.contains("<td class=\"n\">2985984</td>"), "{html}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Engine names are checked against the registry before anything runs.
#[test]
fn unknown_engines_are_refused() {
    let out = rtbench(&[
        "reproduce",
        "spd-stats",
        "--engines",
        "bogus",
        "--out",
        "/nonexistent/x",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("unknown engine 'bogus'") && err.lines().count() == 1,
        "{err}"
    );
}

/// Options that leave nothing to run, or name what does not exist, are refused
/// before anything is measured (they used to give an empty table and exit 0).
#[test]
fn options_that_leave_nothing_to_run_are_refused() {
    for (args, needle) in [
        (
            &["nakamaru-3.2", "--quick", "--max-sf", "0"][..],
            "leaves no size factor to run",
        ),
        (&["nakamaru-3.2", "--max-sf", "bogus=3"][..], "does not run"),
        (
            &["nakamaru-3.2", "--engines", "bogus"][..],
            "option 'engines' does not apply",
        ),
        (
            &["kimura-3.3", "--engines", "bogus"][..],
            "option 'engines' does not apply",
        ),
        (&["spd-stats", "--threads", "0"][..], "'0' for '--threads"),
        (&["yamauchi-static-lb", "--size", "0"][..], "size '0'"),
    ] {
        let out = rtbench(&[&["reproduce"][..], args, &["--out", "/nonexistent/x"][..]].concat());
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(needle) && err.lines().count() == 1,
            "{args:?}: {err}"
        );
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}
