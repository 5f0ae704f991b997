//! Helpers shared by the CLI tests.

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
