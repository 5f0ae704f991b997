//! How rtbench fails: every error is one line on stderr and an exit status
//! (docs/concepts.md): 1 for a failed check, 2 for bad usage or bad input.

use std::fmt;

#[derive(Debug)]
pub enum Failure {
    /// Bad usage or bad input (exit 2): names the problem and the input.
    Input(String),
    /// A check that ran and did not pass (exit 1).
    Check(String),
}

impl Failure {
    pub fn exit_code(&self) -> i32 {
        match self {
            Failure::Input(_) => 2,
            Failure::Check(_) => 1,
        }
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Failure::Input(m) | Failure::Check(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for Failure {}

/// Shorthand for an input error.
pub fn input(msg: impl Into<String>) -> Failure {
    Failure::Input(msg.into())
}

impl From<rtbench_scenes::spd::SpdError> for Failure {
    fn from(e: rtbench_scenes::spd::SpdError) -> Self {
        Failure::Input(e.to_string())
    }
}

impl From<rtbench_scenes::nff::NffError> for Failure {
    fn from(e: rtbench_scenes::nff::NffError) -> Self {
        Failure::Input(e.to_string())
    }
}

impl From<rtbench_engines::EngineError> for Failure {
    fn from(e: rtbench_engines::EngineError) -> Self {
        Failure::Input(e.to_string())
    }
}

pub type Result<T> = std::result::Result<T, Failure>;
