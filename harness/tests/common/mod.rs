//! Helpers shared by the CLI tests (each test binary uses some of them).
#![allow(dead_code)]

use std::process::{Command, Output};

/// Runs the rtbench binary built for these tests.
pub fn rtbench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rtbench"))
        .args(args)
        .output()
        .expect("rtbench runs")
}

/// Bad input: exit status 2, exactly one line on stderr mentioning `needle`, nothing on stdout,
/// no panic.
pub fn expect_input_error(args: &[&str], needle: &str) {
    let out = rtbench(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{args:?}: status {:?}, stderr {err}",
        out.status
    );
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{args:?}: not one line: {err}"
    );
    assert!(
        err.contains(needle),
        "{args:?}: '{err}' does not mention '{needle}'"
    );
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(out.stdout.is_empty(), "{args:?}: wrote to stdout");
}

/// A scratch directory under the system's temp dir, removed when dropped.
pub struct Dir(pub std::path::PathBuf);

impl Dir {
    /// `rtbench-{suite}-{tag}-{pid}`, emptied first.
    pub fn new(suite: &str, tag: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("rtbench-{suite}-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }
    pub fn join(&self, p: &str) -> String {
        self.0.join(p).to_str().unwrap().to_string()
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs rtbench, which must succeed, and parses its stdout as JSON.
pub fn json(args: &[&str]) -> serde_json::Value {
    let out = rtbench(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// `scene store SCENE --sf SF -o OUT EXTRA… --json`, which must succeed.
pub fn store_scene(scene: &str, sf: &str, out: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["scene", "store", scene, "--sf", sf, "-o", out];
    args.extend_from_slice(extra);
    args.push("--json");
    json(&args)
}

/// `render --scene STORE --engine breadth-first --size 48 --set S… --json`.
pub fn render_breadth_first(store: &str, sets: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "render",
        "--scene",
        store,
        "--engine",
        "breadth-first",
        "--size",
        "48",
    ];
    for s in sets {
        args.push("--set");
        args.push(s);
    }
    args.push("--json");
    json(&args)
}
