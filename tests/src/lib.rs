//! Cross-crate tests live in tests/tests/ (the CLI tests, which need the binary, in harness/tests/).

pub mod fuzz;
