//! A reproduction's options: a typed parameter bag read like engine settings. Every table declares the
//! keys it takes ([`super::Table::params`]); a key it does not take is refused with one line (exit 2),
//! and so is a value that does not parse. The historic flags (`--engines`, `--threads`, `--max-sf`,
//! `--fault-ms`, `--size`, `--max-pes`, `--scenes`) are a contract and arrive here as keys of the same
//! names; `--set key=value` reaches every other key.

use crate::error::{input, Result};
use crate::measure::threads::Threads;
use std::collections::BTreeMap;
use std::str::FromStr;

/// One key a table can take: its name and a line of help for `reproduce list`.
#[derive(Clone, Copy, Debug)]
pub struct Param {
    pub key: &'static str,
    pub help: &'static str,
}

pub const ENGINES: Param = Param {
    key: "engines",
    help: "engines, comma-separated (default: every available engine but reference)",
};
pub const THREADS: Param = Param {
    key: "threads",
    help: "worker threads: a count or all (default 1)",
};
pub const SIZE: Param = Param {
    key: "size",
    help: "image size in pixels",
};
pub const SCENES: Param = Param {
    key: "scenes",
    help: "SPD scenes, comma-separated (standard size factors)",
};
pub const MAX_PES: Param = Param {
    key: "max-pes",
    help: "the largest PE count simulated",
};

/// The options given to one table, checked against what it takes.
#[derive(Debug, Default)]
pub struct Params {
    id: String,
    pairs: BTreeMap<String, String>,
}

impl Params {
    /// `pairs` from the flags and `--set`; a key given twice, or one the table does not take, is refused.
    pub fn new(id: &str, pairs: Vec<(String, String)>, takes: &[Param]) -> Result<Params> {
        let mut map = BTreeMap::new();
        for (k, v) in pairs {
            if !takes.iter().any(|p| p.key == k) {
                let known: Vec<&str> = takes.iter().map(|p| p.key).collect();
                return Err(input(format!(
                    "{id}: option '{k}' does not apply (it takes: {})",
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                )));
            }
            if map.insert(k.clone(), v).is_some() {
                return Err(input(format!("{id}: option '{k}' given twice")));
            }
        }
        Ok(Params {
            id: id.to_string(),
            pairs: map,
        })
    }

    pub fn raw(&self, key: &str) -> Option<&str> {
        self.pairs.get(key).map(String::as_str)
    }

    /// A byte size as the engines take it (`256MiB`), `default` when absent; checked here, before
    /// anything is written, not when the first engine is built.
    pub fn bytes(&self, key: &str, default: &str) -> Result<String> {
        let v = self.raw(key).unwrap_or(default);
        v.trim()
            .parse::<rtbench_engines::breadth_first::config::Bytes>()
            .map_err(|e| input(format!("{}: {key} '{v}': {e}", self.id)))?;
        Ok(v.trim().to_string())
    }

    /// A number, or `None` when absent; a value that does not parse, or is below `min`, is refused.
    pub fn number<T: FromStr + PartialOrd + std::fmt::Display + Copy>(
        &self,
        key: &str,
        min: T,
    ) -> Result<Option<T>> {
        let Some(v) = self.raw(key) else {
            return Ok(None);
        };
        match v.trim().parse::<T>() {
            Ok(x) if x >= min => Ok(Some(x)),
            _ => Err(input(format!(
                "{}: {key} '{v}': expected a number of at least {min}",
                self.id
            ))),
        }
    }

    /// A comma-separated list, or `None` when absent; an empty list is refused.
    pub fn list(&self, key: &str) -> Result<Option<Vec<String>>> {
        let Some(v) = self.raw(key) else {
            return Ok(None);
        };
        let items: Vec<String> = v
            .split(',')
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .collect();
        if items.is_empty() {
            return Err(input(format!("{}: {key} '{v}': empty list", self.id)));
        }
        Ok(Some(items))
    }

    /// `threads`: a count or `all` ([`Threads`]'s one spelling and default; the pool refuses more
    /// than it can start). `None`: all cores.
    pub fn threads(&self) -> Result<Option<usize>> {
        match self.raw(THREADS.key) {
            None => Ok(Threads::DEFAULT.count()),
            Some(v) => v
                .parse::<Threads>()
                .map(Threads::count)
                .map_err(|e| input(format!("{}: {e}", self.id))),
        }
    }

    /// `engines`: each a registered engine that can run here; default every available engine but
    /// `reference` (brute force: hours on the standard scenes).
    pub fn engines(&self) -> Result<Vec<String>> {
        crate::select::engine_names(self.raw(ENGINES.key), &format!("{}: engines", self.id))
    }

    /// `scenes`: each an SPD program name; `None` when absent.
    pub fn scenes(&self) -> Result<Option<Vec<String>>> {
        let Some(names) = self.list(SCENES.key)? else {
            return Ok(None);
        };
        for n in &names {
            if n.parse::<rtbench_scenes::spd::Program>().is_err() {
                return Err(input(format!("{}: unknown scene '{n}'", self.id)));
            }
        }
        Ok(Some(names))
    }
}

/// `--set key=value` arguments as pairs.
pub fn parse_set(id: &str, set: &[String]) -> Result<Vec<(String, String)>> {
    set.iter()
        .map(|kv| {
            let (k, v) = kv
                .split_once('=')
                .ok_or_else(|| input(format!("{id}: --set '{kv}': expected key=value")))?;
            Ok((k.trim().to_string(), v.trim().to_string()))
        })
        .collect()
}

/// A process's peak resident set as the memory rows show it beside the thesis's machines, which
/// were sized in MB: `peak RSS 15.2 MiB (16 MB)`.
pub fn peak_rss_text(peak: u64) -> String {
    format!(
        "peak RSS {:.1} MiB ({:.0} MB)",
        peak as f64 / 1048576.0,
        peak as f64 / 1e6
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pairs(kv: &[(&str, &str)]) -> Vec<(String, String)> {
        kv.iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect()
    }

    #[test]
    fn keys_a_table_does_not_take_are_refused() {
        let e = Params::new("t", pairs(&[("size", "4")]), &[THREADS]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "t: option 'size' does not apply (it takes: threads)"
        );
        let e = Params::new("t", pairs(&[("size", "4")]), &[]).unwrap_err();
        assert!(e.to_string().ends_with("(it takes: none)"));
    }

    #[test]
    fn values_are_checked() {
        let p = Params::new(
            "t",
            pairs(&[("size", "0"), ("threads", "x")]),
            &[SIZE, THREADS],
        )
        .unwrap();
        assert!(p.number::<u32>("size", 1).is_err());
        assert!(p.threads().is_err());
        let p = Params::new("t", pairs(&[("size", "64")]), &[SIZE]).unwrap();
        assert_eq!(p.number::<u32>("size", 1).unwrap(), Some(64));
        assert_eq!(p.threads().unwrap(), Some(1));
    }

    #[test]
    fn unknown_engines_and_scenes_are_refused() {
        let p = Params::new(
            "t",
            pairs(&[("engines", "bogus"), ("scenes", "balls,nope")]),
            &[ENGINES, SCENES],
        )
        .unwrap();
        assert!(p
            .engines()
            .unwrap_err()
            .to_string()
            .contains("unknown engine 'bogus'"));
        assert!(p
            .scenes()
            .unwrap_err()
            .to_string()
            .contains("unknown scene 'nope'"));
    }
}
