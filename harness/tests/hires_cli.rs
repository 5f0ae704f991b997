//! The high-resolution grid from the command line (seed 000 §4.3): `grid=single` and
//! `grid=two-level` give the image of the basic grid, a truncated on-disk grid is refused (exit 2,
//! one line, no temporary left), and `reproduce nakamaru-4.2` / `nakamaru-fig4.4` on tiny rows.

mod common;

use common::{expect_input_error, json, render_breadth_first, rtbench, Dir};
use serde_json::Value;
use std::path::Path;

#[test]
fn every_grid_renders_the_same_image_and_a_truncated_grid_exits_2() {
    let d = Dir::new("hr-cli", "img");
    let store = d.join("mount5");
    json(&[
        "scene", "store", "mount", "--sf", "5", "-o", &store, "--json",
    ]);
    let base = render_breadth_first(&store, &[]);
    let sha = &base["image"]["sha256"];
    for sets in [
        vec!["grid=single", "cap=8"],
        vec!["grid=two-level"],
        vec![
            "grid=two-level",
            "upper=4",
            "lower=4",
            "pool=3",
            "hierarchy=on",
        ],
    ] {
        let v = render_breadth_first(&store, &sets);
        assert_eq!(&v["image"]["sha256"], sha, "{sets:?}");
        if sets[0] == "grid=two-level" {
            assert!(v["counters"]["extra"]["hr_blocks_read"].as_u64().unwrap() > 0);
        }
    }
    // The last run left its grid in the store; truncated, it is refused when reused.
    let grid = Path::new(&store).join("hrgrid.bin");
    let good = std::fs::read(&grid).unwrap();
    std::fs::write(&grid, &good[..good.len() - 3]).unwrap();
    let args = [
        "render",
        "--scene",
        &store,
        "--engine",
        "breadth-first",
        "--size",
        "16",
        "--set",
        "grid=two-level",
        "--set",
        "upper=4",
        "--set",
        "lower=4",
        "--set",
        "hrgrid=reuse",
    ];
    expect_input_error(&args, "truncated");
    assert!(!Path::new(&store).join("hrgrid.bin.tmp").exists());
    // Rebuilt (the default), it renders again.
    let v = render_breadth_first(&store, &["grid=two-level", "upper=4", "lower=4"]);
    assert_eq!(&v["image"]["sha256"], sha);
    assert_eq!(std::fs::read(&grid).unwrap(), good);
}

#[test]
fn nakamaru_4_2_and_fig4_4_on_tiny_rows() {
    let d = Dir::new("hr-cli", "repro");
    let out = d.join("out");
    for (id, sets) in [
        (
            "nakamaru-4.2",
            vec!["rows=tetra5", "cap=8", "size=16", "cache=warm"],
        ),
        (
            "nakamaru-fig4.4",
            vec!["sizes=tetra:3,4", "cap=4", "size=16", "cache=warm"],
        ),
    ] {
        let mut args = vec!["reproduce", id, "--out", &out];
        for s in &sets {
            args.push("--set");
            args.push(s);
        }
        let r = rtbench(&args);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let v: Value = serde_json::from_slice(
            &std::fs::read(Path::new(&out).join(format!("{id}.json"))).unwrap(),
        )
        .unwrap();
        let rows = v["rows"].as_array().unwrap();
        assert!(rows
            .iter()
            .filter(|r| r["claim"] == "image-equal")
            .all(|r| r["verdict"] == "holds"));
        assert!(rows.iter().all(|r| r["fidelity"].is_string()));
    }
    assert!(Path::new(&out)
        .join("plots/nakamaru-fig4.4-tetra.svg")
        .exists());
    expect_input_error(
        &[
            "reproduce",
            "nakamaru-4.2",
            "--out",
            &out,
            "--set",
            "rows=cube4",
        ],
        "scenes are",
    );
}
