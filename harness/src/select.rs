//! Choosing what to run, once for every command: the engine list (`--engines` / `--engine`) and the
//! median the measurements report.

use crate::error::{input, Result};

/// One entry of an engine list: the engine's name and the settings after its colons
/// (`bvh4:simd=off:leaf=1`).
pub type Entry = (String, Vec<(String, String)>);

/// Parses an engine list: `all` (or no list) is every engine available here but `reference` (brute
/// force: hours on the standard scenes), `plugin` and the test-only ones; otherwise comma-separated
/// entries, each a registered engine that can run here, with optional `:key=value` settings.
/// `plugin:PATH[:key=value…]` is the engine `plugin` with the setting `path=PATH` first.
/// The engines a command runs when none are named: every registered engine that can run here,
/// but never `plugin` (a library must be named: `plugin:PATH`) nor the test-only ones, and
/// `reference` (brute force) only when `with_reference`.
pub fn default_engines(with_reference: bool) -> Vec<String> {
    rtbench_engines::registry()
        .iter()
        .filter(|e| e.name != "plugin" && !e.name.starts_with("test-"))
        .filter(|e| with_reference || e.name != "reference")
        .filter(|e| (e.available)().is_ok())
        .map(|e| e.name.to_string())
        .collect()
}

pub fn engines(list: Option<&str>, flag: &str) -> Result<Vec<Entry>> {
    let registry = rtbench_engines::registry();
    let list = list.map(str::trim).filter(|l| *l != "all");
    let Some(list) = list else {
        return Ok(default_engines(false)
            .into_iter()
            .map(|e| (e, Vec::new()))
            .collect());
    };
    let mut out = Vec::new();
    for entry in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let mut parts = entry.split(':');
        let name = parts.next().unwrap_or_default().trim();
        let mut settings = Vec::new();
        if name == "plugin" {
            // plugin:PATH[:key=value…]: the library, checked to exist here (its ABI is checked
            // when the run builds it, so a bad plugin fails its runs, not the whole command).
            let spec = parts.next().map(str::trim).unwrap_or_default();
            if spec.is_empty() || spec.contains('=') {
                return Err(input(format!(
                    "{flag} '{entry}': expected plugin:PATH[:key=value…]"
                )));
            }
            rtbench_engines::plugin::resolve(spec).map_err(|e| input(format!("{flag}: {e}")))?;
            settings.push(("path".to_string(), spec.to_string()));
        }
        let info = registry.iter().find(|e| e.name == name).ok_or_else(|| {
            let known: Vec<&str> = registry.iter().map(|e| e.name).collect();
            input(format!(
                "{flag}: unknown engine '{name}' (known: {})",
                known.join(", ")
            ))
        })?;
        (info.available)()
            .map_err(|r| input(format!("{flag}: engine '{name}' is not available: {r}")))?;
        for kv in parts {
            let (k, v) = kv
                .split_once('=')
                .filter(|(k, _)| !k.trim().is_empty())
                .ok_or_else(|| input(format!("{flag} '{entry}': expected engine:key=value")))?;
            settings.push((k.trim().to_string(), v.trim().to_string()));
        }
        out.push((name.to_string(), settings));
    }
    if out.is_empty() {
        return Err(input(format!("{flag} '{list}': no engine named")));
    }
    Ok(out)
}

/// Engine names only: an entry with settings is refused where a command takes plain names.
pub fn engine_names(list: Option<&str>, flag: &str) -> Result<Vec<String>> {
    engines(list, flag)?
        .into_iter()
        .map(|(name, settings)| {
            if settings.is_empty() {
                Ok(name)
            } else {
                Err(input(format!("{flag}: '{name}' takes no settings here")))
            }
        })
        .collect()
}

/// The median of `v` (sorted in place; NaN sorts last); NaN for an empty slice.
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => v[n / 2],
        _ => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_even_and_empty() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn engine_lists() {
        assert!(engines(Some("bogus"), "--engines").is_err());
        assert!(engines(Some(" , "), "--engines").is_err());
        assert!(engines(Some("grid:leaf"), "--engines").is_err());
        let e = engines(Some("grid:mailbox=off,bvh4"), "--engines").unwrap();
        assert_eq!(
            e[0],
            ("grid".into(), vec![("mailbox".into(), "off".into())])
        );
        assert!(engine_names(Some("grid:mailbox=off"), "--engine").is_err());
        let all = engines(None, "--engines").unwrap();
        assert!(all.iter().all(|(n, _)| n != "reference"));
    }

    /// No default list holds an engine that cannot be built without more to say (`plugin`
    /// needs its library): `check --suite hard` without `--engine` builds every one.
    #[test]
    fn default_lists_build_as_they_come() {
        let probe = crate::suite::probe_input();
        for with_reference in [false, true] {
            let list = default_engines(with_reference);
            assert!(list.iter().any(|e| e == "bvh4"), "{list:?}");
            assert_eq!(list.iter().any(|e| e == "reference"), with_reference);
            for e in &list {
                rtbench_engines::build_engine(e, &probe, vec![])
                    .unwrap_or_else(|err| panic!("{e}: {err}"));
            }
        }
        assert_eq!(crate::suite::engines(None).unwrap(), default_engines(true));
    }
}
