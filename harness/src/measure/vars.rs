//! Every `RTBENCH_*` environment variable rtbench reads at run time: read once, here, when the
//! process starts ([`load`]); a malformed value is one line naming the accepted forms and exit 2,
//! never silently ignored. `rtbench env` lists them ([`VARS`]); `--help` names them.
//!
//! The engines crate reads its own four (`RTBENCH_BUILD_PHASES`, `RTBENCH_PLUGIN_DIR`,
//! `RTBENCH_TEST_ENGINES`, `RTBENCH_TEST_SLOWDOWN`): it cannot depend on the harness. They are
//! checked here all the same, so a bad value stops the command before any engine sees it.

use crate::error::{input, Result};
use std::sync::OnceLock;

/// One variable: its name, the forms it accepts, what it does, and its check.
pub struct Var {
    pub name: &'static str,
    pub forms: &'static str,
    pub about: &'static str,
    check: fn(&str) -> bool,
}

impl Var {
    /// Whether `value` is one of the accepted forms.
    pub fn accepts(&self, value: &str) -> bool {
        (self.check)(value.trim())
    }
}

fn flag(v: &str) -> bool {
    v == "1" || v == "0"
}

fn count(v: &str) -> bool {
    v.parse::<usize>()
        .is_ok_and(|n| (1..=MOST_THREADS).contains(&n))
}

fn non_negative(v: &str) -> bool {
    v.parse::<f64>().is_ok_and(|x| x.is_finite() && x >= 0.0)
}

/// Whether every `;`-separated plant of `spec` is well formed (`RTBENCH_PLANT`, read by `runs/plant.rs`).
fn plant(spec: &str) -> bool {
    spec.split(';').all(|one| {
        let parts: Vec<&str> = one.trim().split(':').collect();
        match parts.as_slice() {
            ["work", e, s, f] => {
                !e.is_empty()
                    && !s.is_empty()
                    && f.parse::<f64>().is_ok_and(|f| f.is_finite() && f > 0.0)
            }
            ["time", e, s, f] => {
                !e.is_empty()
                    && !s.is_empty()
                    && f.parse::<f64>()
                        .is_ok_and(|f| f.is_finite() && f > 0.0 && f <= 10.0)
            }
            ["counter", e, s] => !e.is_empty() && !s.is_empty(),
            _ => false,
        }
    })
}

fn any(v: &str) -> bool {
    !v.is_empty()
}

/// The most threads [`Values::max_threads`] may raise the limit to.
pub const MOST_THREADS: usize = 64;

/// Every variable, in the order `rtbench env` lists them.
pub const VARS: &[Var] = &[
    Var {
        name: "RTBENCH_MAX_THREADS",
        forms: "a count from 1 to 64",
        about: "raises the most threads --threads takes above the machine's (instruction counts \
                and tests of a two-thread trace on one core; not for time figures)",
        check: count,
    },
    Var {
        name: "RTBENCH_PIN_THREADS",
        forms: "1 (on) or 0 (off)",
        about: "pins each pool thread to one CPU the process may run on, round robin",
        check: flag,
    },
    Var {
        name: "RTBENCH_SCHED",
        forms: "1 (per thread and per CPU) or bands (also per band)",
        about: "prints the scheduler's accounting of every render's pool threads on stderr",
        check: |v| v == "1" || v == "bands",
    },
    Var {
        name: "RTBENCH_BANDS",
        forms: "1 (on) or 0 (off)",
        about: "times every band of a render on its own (render --json: the bands' seconds)",
        check: flag,
    },
    Var {
        name: "RTBENCH_MEMORY_PHASES",
        forms: "1 (on) or 0 (off)",
        about: "prints the process's memory after each phase of rtbench render on stderr",
        check: flag,
    },
    Var {
        name: "RTBENCH_PLANT",
        forms:
            "work:ENGINE:SCENE:FRACTION, time:ENGINE:SCENE:FRACTION or counter:ENGINE:SCENE, \
                several joined by ';' (SCENE a program or *; FRACTION above 0, for time at most 10)",
        about: "plants a regression in an engine, to measure whether compare and the nightly \
                find it",
        check: plant,
    },
    Var {
        name: "RTBENCH_BUILD_PHASES",
        forms: "1 (on) or 0 (off)",
        about: "prints the seconds of each phase of a BVH build on stderr (engines)",
        check: flag,
    },
    Var {
        name: "RTBENCH_PLUGIN_DIR",
        forms: "a directory",
        about: "where plugin:NAME engines are looked for (default ./plugins) (engines)",
        check: any,
    },
    Var {
        name: "RTBENCH_TEST_ENGINES",
        forms: "1 (on) or 0 (off)",
        about: "registers the test-only engines (test-slow, test-panic …) (engines)",
        check: flag,
    },
    Var {
        name: "RTBENCH_TEST_SLOWDOWN",
        forms: "a fraction ≥ 0 (0.2: 20 % more)",
        about: "the fraction of each batch's time the test-slow engine adds (engines)",
        check: non_negative,
    },
];

/// The harness's variables, parsed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Values {
    pub max_threads: Option<usize>,
    pub pin_threads: bool,
    /// `Some(true)` for `bands`.
    pub sched: Option<bool>,
    pub bands: bool,
    pub memory_phases: bool,
    pub plant: Option<String>,
}

static VALUES: OnceLock<Values> = OnceLock::new();

/// Reads and checks every variable of [`VARS`] in `get` (the environment, or a test's map).
pub fn parse(get: impl Fn(&str) -> Option<String>) -> Result<Values> {
    for v in VARS {
        if let Some(value) = get(v.name) {
            if !v.accepts(&value) {
                return Err(input(format!("{}='{value}': expected {}", v.name, v.forms)));
            }
        }
    }
    let on = |name: &str| get(name).is_some_and(|v| v.trim() == "1");
    Ok(Values {
        max_threads: get("RTBENCH_MAX_THREADS").and_then(|v| v.trim().parse().ok()),
        pin_threads: on("RTBENCH_PIN_THREADS"),
        sched: get("RTBENCH_SCHED").map(|v| v.trim() == "bands"),
        bands: on("RTBENCH_BANDS"),
        memory_phases: on("RTBENCH_MEMORY_PHASES"),
        plant: get("RTBENCH_PLANT"),
    })
}

fn from_env(name: &str) -> Option<String> {
    std::env::var_os(name).map(|v| v.to_string_lossy().into_owned())
}

/// Reads the environment once, at the start of the process: a malformed value is an input error.
pub fn load() -> Result<&'static Values> {
    let v = parse(from_env)?;
    Ok(VALUES.get_or_init(|| v))
}

/// The values read at the start. Where [`load`] did not run (unit tests), the environment is read
/// now, and a malformed value counts as unset.
pub fn values() -> &'static Values {
    VALUES.get_or_init(|| parse(from_env).unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn parse_map(pairs: &[(&str, &str)]) -> Result<Values> {
        let m: BTreeMap<String, String> = pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        parse(|k| m.get(k).cloned())
    }

    #[test]
    fn good_values_are_read() {
        let v = parse_map(&[
            ("RTBENCH_MAX_THREADS", "2"),
            ("RTBENCH_PIN_THREADS", "1"),
            ("RTBENCH_SCHED", "bands"),
            ("RTBENCH_PLANT", "work:bvh8:*:0.1;counter:grid:tetra"),
        ])
        .unwrap();
        assert_eq!(v.max_threads, Some(2));
        assert!(v.pin_threads && !v.bands && !v.memory_phases);
        assert_eq!(v.sched, Some(true));
        assert_eq!(parse_map(&[]).unwrap(), Values::default());
        assert!(!parse_map(&[("RTBENCH_BANDS", "0")]).unwrap().bands);
    }

    #[test]
    fn a_bad_value_names_the_variable_and_the_accepted_forms() {
        for (name, bad) in [
            ("RTBENCH_MAX_THREADS", "abc"),
            ("RTBENCH_MAX_THREADS", "0"),
            ("RTBENCH_MAX_THREADS", "65"),
            ("RTBENCH_PIN_THREADS", "yes"),
            ("RTBENCH_SCHED", "band"),
            ("RTBENCH_PLANT", "work:bvh8:*:-1"),
            ("RTBENCH_PLANT", "slow:bvh8"),
            ("RTBENCH_TEST_SLOWDOWN", "fast"),
        ] {
            let e = parse_map(&[(name, bad)]).unwrap_err();
            let forms = VARS.iter().find(|v| v.name == name).unwrap().forms;
            assert_eq!(e.exit_code(), 2);
            assert_eq!(e.to_string(), format!("{name}='{bad}': expected {forms}"));
        }
    }

    #[test]
    fn every_variable_is_named_in_the_help() {
        for v in VARS {
            assert!(
                crate::cli::ENV_HELP.contains(v.name),
                "{} missing from --help",
                v.name
            );
        }
    }
}
