//! The bounding-box hierarchy from the command line (seed 000 §4.2.2 "B"):
//! `scene store --hierarchy`, `hierarchy=on` giving the image without it (and the in-memory scene's), a damaged
//! hierarchy refused (exit 2, one line), and `reproduce nakamaru-4.1` on one tiny row.

mod common;

use common::{expect_input_error, json, render_breadth_first, rtbench, store_scene, Dir};
use serde_json::Value;

#[test]
fn hierarchy_renders_the_same_image_and_skips() {
    let d = Dir::new("bh-cli", "render");
    let store = d.join("mount5");
    let s = store_scene("mount", "5", &store, &["--hierarchy"]);
    assert!(!s["hierarchy_levels"].as_array().unwrap().is_empty());
    let sg = render_breadth_first(&store, &["memory=2MiB"]);
    let sgb = render_breadth_first(&store, &["memory=2MiB", "hierarchy=on", "cache=cold"]);
    let in_memory = json(&[
        "render",
        "--scene",
        "mount",
        "--sf",
        "5",
        "--engine",
        "breadth-first",
        "--size",
        "48",
        "--json",
    ]);
    assert_eq!(sg["image"]["sha256"], sgb["image"]["sha256"]);
    assert_eq!(sg["image"]["sha256"], in_memory["image"]["sha256"]);
    let x = &sgb["counters"]["extra"];
    assert!(x["bh_objects_skipped"].as_u64().unwrap() > 0, "{x}");
    assert_eq!(
        sgb["build_stats"]["bh_build_s"].as_f64(),
        Some(0.0),
        "built by scene store"
    );
    // Other constants: rebuilt at preprocessing, same image.
    let other = render_breadth_first(&store, &["memory=2MiB", "hierarchy=on", "bh_s=1.5"]);
    assert!(other["build_stats"]["bh_build_s"].as_f64().unwrap() > 0.0);
    assert_eq!(other["image"]["sha256"], sg["image"]["sha256"]);
}

#[test]
fn a_damaged_hierarchy_exits_2() {
    let d = Dir::new("bh-cli", "bad");
    let store = d.join("tetra4");
    store_scene("tetra", "4", &store, &["--hierarchy"]);
    let args = |set: &'static str| -> Vec<String> {
        [
            "render",
            "--scene",
            &store,
            "--engine",
            "breadth-first",
            "--size",
            "16",
            "--set",
            "hierarchy=on",
            "--set",
            set,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let run = |set: &'static str, needle: &str| {
        let a = args(set);
        let a: Vec<&str> = a.iter().map(|s| s.as_str()).collect();
        expect_input_error(&a, needle);
    };
    let l1 = std::path::Path::new(&store).join("bbox-1.bin");
    let good = std::fs::read(&l1).unwrap();
    // Truncated level file.
    std::fs::write(&l1, &good[..good.len() - 5]).unwrap();
    run("verify=records", "bytes");
    // A flipped byte in a box: the full check (the default) reads every record.
    let mut bad = good.clone();
    bad[20] ^= 0x40;
    std::fs::write(&l1, &bad).unwrap();
    run("verify=full", "checksum");
    std::fs::write(&l1, &good).unwrap();
    // hierarchy=on with a basic store is refused.
    let basic = d.join("basic");
    json(&[
        "scene", "store", "tetra", "--sf", "2", "-o", &basic, "--layout", "basic", "--json",
    ]);
    expect_input_error(
        &[
            "render",
            "--scene",
            &basic,
            "--engine",
            "breadth-first",
            "--set",
            "layout=basic",
            "--set",
            "hierarchy=on",
        ],
        "hierarchy",
    );
    expect_input_error(
        &[
            "scene",
            "store",
            "tetra",
            "--sf",
            "1",
            "-o",
            &d.join("x"),
            "--layout",
            "basic",
            "--hierarchy",
        ],
        "--hierarchy",
    );
    assert!(!std::path::Path::new(&d.join("x")).exists());
}

#[test]
fn nakamaru_4_1_one_tiny_row() {
    let d = Dir::new("bh-cli", "repro");
    let out = d.join("out");
    let r = rtbench(&[
        "reproduce",
        "nakamaru-4.1",
        "--out",
        &out,
        "--set",
        "rows=tetra4",
        "--set",
        "size=16",
        "--set",
        "cache=warm",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let v: Value = serde_json::from_slice(
        &std::fs::read(std::path::Path::new(&out).join("nakamaru-4.1.json")).unwrap(),
    )
    .unwrap();
    let rows = v["rows"].as_array().unwrap();
    let image = rows.iter().find(|r| r["claim"] == "image-equal").unwrap();
    assert_eq!(image["verdict"], "holds", "{image}");
    assert!(rows.iter().all(|r| r["fidelity"].is_string()));
    expect_input_error(
        &[
            "reproduce",
            "nakamaru-4.1",
            "--out",
            &out,
            "--set",
            "rows=cube4",
        ],
        "scenes are",
    );
}
