//! `rtbench scene …` as scripts use it (docs/concepts.md): counts against the SPD formulas,
//! computed here independently of the generators, by streaming; bad input → exit 2, one line.

mod common;

use common::{expect_input_error, rtbench};
use serde_json::Value;

fn stats(program: &str, sf: u32, extra: &[&str]) -> Value {
    let sf = sf.to_string();
    let mut args = vec!["scene", "stats", program, "--sf", &sf, "--json"];
    args.extend_from_slice(extra);
    let out = rtbench(&args);
    assert!(
        out.status.success(),
        "{program} {sf}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON document on stdout")
}

/// The SPD count formulas (docs/concepts.md), as u128 so nothing here can overflow.
fn formula(program: &str, sf: u32) -> u128 {
    let s = sf as u128;
    match program {
        "balls" => (0..=sf).map(|k| 9u128.pow(k)).sum::<u128>() + 1,
        "gears" => 146 * s * s * s + 1,
        "mount" => 2 * 4u128.pow(sf) + 4,
        "rings" => 10 * s * (s + 1) * (2 * s + 1) + 1,
        "teapot" => 65 * s * s - 8 * s,
        "tetra" => 4u128.pow(sf),
        "tree" => 2u128.pow(sf + 2) - 1,
        _ => unreachable!(),
    }
}

#[test]
fn counts_equal_the_spd_formulas_by_streaming() {
    let ranges: &[(&str, std::ops::RangeInclusive<u32>)] = &[
        ("balls", 1..=7),
        ("gears", 1..=20),
        ("mount", 1..=10),
        ("rings", 1..=30),
        ("teapot", 1..=30),
        ("tetra", 1..=10),
        ("tree", 1..=18),
    ];
    for (program, sfs) in ranges {
        for sf in sfs.clone() {
            let v = stats(program, sf, &[]);
            let c = &v["counts"];
            let objects: u64 = ["sphere", "cone", "polygon", "patch"]
                .iter()
                .map(|k| c[k].as_u64().unwrap())
                .sum();
            assert_eq!(
                objects as u128,
                formula(program, sf),
                "{program} sf {sf}: {v}"
            );
            assert_eq!(v["objects"].as_u64().unwrap(), objects);
            assert_eq!(v["sf"].as_u64().unwrap(), sf as u64);
        }
    }
    // balls 7 has 5,380,841 spheres: held in memory they would take far more than 64 MiB.
    let v = stats("balls", 7, &[]);
    let rss = v["peak_rss_bytes"].as_u64().unwrap();
    assert!(rss < 64 << 20, "counting balls 7 streamed? peak RSS {rss}");
}

#[test]
fn spd_tessellated_triangle_counts() {
    for (program, sf, want) in [
        ("balls", 4, 797_150u64),
        ("gears", 4, 36_610),
        ("tree", 10, 270_206),
    ] {
        let v = stats(program, sf, &["--tessellate"]);
        assert_eq!(
            v["counts"]["triangles"].as_u64().unwrap(),
            want,
            "{program}{sf} tessellated"
        );
    }
}

#[test]
fn stats_json_has_the_contract_fields() {
    let v = stats("balls", 1, &[]);
    for k in ["program", "sf", "counts", "lights", "bounds"] {
        assert!(v.get(k).is_some(), "missing {k}");
    }
    for k in ["sphere", "cone", "polygon", "patch", "triangles"] {
        assert!(v["counts"].get(k).is_some(), "missing counts.{k}");
    }
    assert_eq!(v["lights"], 3);
    assert_eq!(v["bounds"][0].as_array().unwrap().len(), 3);
}

#[test]
fn bad_input_exits_2_with_one_line() {
    let dir = std::env::temp_dir().join(format!("rtbench-badnff-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        (
            "truncated.nff",
            "s 0 0 0 1\np 4\n0 0 0\n1 0 0\n1 1 0\n",
            "truncated.nff:5",
        ),
        ("word.nff", "s 0 0 zero 1\n", "'zero'"),
        ("nan.nff", "s 0 0 0 1\ns 0 NaN 0 1\n", "word.nff"),
        ("inf.nff", "s 0 0 0 1\n\ns inf 0 0 1\n", "inf.nff:3"),
        (
            "directive.nff",
            "s 0 0 0 1\nsphere 0 0 0 1\n",
            "unknown directive 'sphere'",
        ),
    ];
    for (name, text, needle) in cases {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let p = path.to_str().unwrap();
        let needle = if name == "nan.nff" {
            "nan.nff:2"
        } else {
            needle
        };
        expect_input_error(&["scene", "stats", p], needle);
    }
    let missing = dir.join("missing.nff");
    expect_input_error(
        &["scene", "stats", missing.to_str().unwrap()],
        "missing.nff",
    );
    expect_input_error(&["scene", "stats", "ballz"], "unknown SPD program 'ballz'");
    expect_input_error(
        &["scene", "gen", "balls", "--sf", "0"],
        "size factor must be at least 1",
    );
    expect_input_error(
        &["scene", "stats", "tetra", "--sf", "40"],
        "more than 2^64 objects",
    );
    expect_input_error(&["scene", "stats", "balls", "--sf", "-3"], "--sf");
    expect_input_error(&["scene", "stats", "balls", "--sf", "many"], "--sf");
    expect_input_error(
        &["scene", "gen", "tetra", "--hash", "jenkins"],
        "mount only",
    );
    expect_input_error(&["scene", "gen", "mount", "--hash", "md5"], "md5");
    // A failed write leaves no file behind.
    let out = dir.join("no-such-dir").join("x.nff");
    expect_input_error(
        &["scene", "gen", "tetra", "-o", out.to_str().unwrap()],
        "cannot write",
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn gen_writes_what_stats_reads_back() {
    let dir = std::env::temp_dir().join(format!("rtbench-gen-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("rings3.nff");
    let out = rtbench(&[
        "scene",
        "gen",
        "rings",
        "--sf",
        "3",
        "-o",
        f.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let from_file = rtbench(&["scene", "stats", f.to_str().unwrap(), "--json"]);
    let a: Value = serde_json::from_slice(&from_file.stdout).unwrap();
    let b = stats("rings", 3, &[]);
    assert_eq!(a["counts"], b["counts"]);
    assert_eq!(a["lights"], b["lights"]);
    // The file is the same text as stdout gives.
    let stdout = rtbench(&["scene", "gen", "rings", "--sf", "3"]).stdout;
    assert_eq!(std::fs::read(&f).unwrap(), stdout);
    std::fs::remove_dir_all(&dir).unwrap();
}
