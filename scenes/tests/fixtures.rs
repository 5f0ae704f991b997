//! Every fixture in tests/fixtures/spd/ (output of the SPD 3.14 C programs; provenance in its README) against our
//! generators, record by record and number by number: numbers equal within 1e-5 relative or
//! 1e-6 absolute (docs/concepts.md).
//!
//! `SPD_FIXTURE=balls` limits the run to fixtures whose name contains that text.

use flate2::read::GzDecoder;
use rtbench_scenes::nff::NffWriter;
use rtbench_scenes::spd::{self, MountHash, Options, Program};
use std::io::Read;
use std::path::PathBuf;

fn fixtures_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/spd")
}

/// `<program>[-jenkins]-sf<N>[-tess].nff.gz` → what to generate.
fn parse_name(name: &str) -> (Program, Options) {
    let stem = name
        .strip_suffix(".nff.gz")
        .expect("fixture name ends .nff.gz");
    let mut parts: Vec<&str> = stem.split('-').collect();
    let tess = parts.last() == Some(&"tess");
    if tess {
        parts.pop();
    }
    let sf: u32 = parts
        .pop()
        .and_then(|s| s.strip_prefix("sf"))
        .expect("sfN")
        .parse()
        .unwrap();
    let hash = if parts.last() == Some(&"jenkins") {
        parts.pop();
        MountHash::Jenkins
    } else {
        MountHash::Original
    };
    assert_eq!(parts.len(), 1, "fixture name {name}");
    let program: Program = parts[0].parse().unwrap();
    let tessellate = if tess {
        Some(spd::DEFAULT_RESOLUTION)
    } else {
        None
    };
    (
        program,
        Options {
            size_factor: sf,
            tessellate,
            hash,
        },
    )
}

fn numbers_equal(a: f64, b: f64) -> bool {
    let d = (a - b).abs();
    d <= 1e-6 || d <= 1e-5 * a.abs().max(b.abs())
}

/// Compares two NFF texts; returns the first few differences (line numbers are 1-based).
pub fn compare_nff(want: &str, got: &str) -> Vec<String> {
    let mut diffs = Vec::new();
    let wl: Vec<&str> = want.lines().collect();
    let gl: Vec<&str> = got.lines().collect();
    if wl.len() != gl.len() {
        diffs.push(format!("line count: want {}, got {}", wl.len(), gl.len()));
    }
    for (i, (w, g)) in wl.iter().zip(&gl).enumerate() {
        let wt: Vec<&str> = w.split_whitespace().collect();
        let gt: Vec<&str> = g.split_whitespace().collect();
        let same = wt.len() == gt.len()
            && wt
                .iter()
                .zip(&gt)
                .all(|(a, b)| match (a.parse::<f64>(), b.parse::<f64>()) {
                    (Ok(x), Ok(y)) => numbers_equal(x, y),
                    _ => a == b,
                });
        if !same {
            diffs.push(format!("line {}: want '{}', got '{}'", i + 1, w, g));
            if diffs.len() >= 5 {
                break;
            }
        }
    }
    diffs
}

#[test]
fn generators_match_every_spd_fixture() {
    let dir = fixtures_dir();
    let filter = std::env::var("SPD_FIXTURE").unwrap_or_default();
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("fixtures at {}: {e}", dir.display()))
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".nff.gz") && n.contains(&filter))
        .collect();
    names.sort();
    assert!(
        filter.is_empty() || !names.is_empty(),
        "no fixture matches {filter}"
    );
    if filter.is_empty() {
        assert!(
            names.len() >= 32,
            "expected the 32 SPD fixtures, found {}",
            names.len()
        );
    }
    let mut failures = Vec::new();
    for name in &names {
        let mut want = String::new();
        GzDecoder::new(std::fs::File::open(dir.join(name)).unwrap())
            .read_to_string(&mut want)
            .unwrap();
        let (program, opts) = parse_name(name);
        let mut w = NffWriter::new(Vec::new());
        spd::generate(program, &opts, &mut w).unwrap();
        let got = String::from_utf8(w.finish().unwrap()).unwrap();
        let diffs = compare_nff(&want, &got);
        if diffs.is_empty() {
            eprintln!("ok   {name} ({} lines)", want.lines().count());
        } else {
            eprintln!("FAIL {name}:\n  {}", diffs.join("\n  "));
            failures.push(name.clone());
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} fixtures differ: {failures:?}",
        failures.len(),
        names.len()
    );
}
