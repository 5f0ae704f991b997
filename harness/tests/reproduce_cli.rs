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
    let _ = std::fs::remove_dir_all(&dir);
}
