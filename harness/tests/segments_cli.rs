//! Seed 000 Table 4.3's groundwork from the command line: a store written in segments
//! across runs (`scene store --segment N --max-seconds S`, then `--resume`) renders as the store
//! written at once; the rings368m view file counts objects in view; and `reproduce nakamaru-4.3`
//! stops at a checkpoint under a time budget and finishes when resumed.

mod common;

use common::{expect_input_error, json, render_breadth_first, rtbench, Dir};
use serde_json::Value;
use sha2::Digest;
use std::path::Path;

const VIEW: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../data/views/rings368m.json");

#[test]
fn a_store_written_in_segments_across_runs_renders_as_one_written_at_once() {
    let d = Dir::new("seg-cli", "store");
    let once = d.join("once");
    let seg = d.join("seg");
    json(&[
        "scene",
        "store",
        "rings",
        "--sf",
        "2",
        "-o",
        &once,
        "--layout",
        "basic",
        "--compress",
        "gzip:1",
        "--json",
    ]);
    let args = |resume: bool| {
        let mut a = vec![
            "scene",
            "store",
            "rings",
            "--sf",
            "2",
            "-o",
            &seg,
            "--layout",
            "basic",
            "--compress",
            "gzip:1",
            "--segment",
            "100",
            "--max-seconds",
            "0.000001",
            "--json",
        ];
        if resume {
            a.push("--resume");
        }
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let run = |resume| {
        let a = args(resume);
        json(&a.iter().map(|s| s.as_str()).collect::<Vec<_>>())
    };
    let first = run(false);
    assert_eq!(first["finished"], false);
    assert_eq!(first["objects_on_disk"], 100);
    // Not resumed: refused, the partial store kept.
    let a = args(false);
    expect_input_error(
        &a.iter().map(|s| s.as_str()).collect::<Vec<_>>(),
        "--resume",
    );
    // 301 objects in segments of 100: runs 2 and 3 stop after 200 and 300, run 4 finishes.
    let mut runs = vec![first];
    while runs.last().unwrap()["finished"] == false {
        runs.push(run(true));
        assert!(runs.len() <= 4, "{runs:?}");
    }
    assert_eq!(runs.len(), 4);
    assert_eq!(runs[3]["objects_on_disk"], 301);
    assert_eq!(runs[3]["this_run"]["skipped_objects"], 300);
    let a = render_breadth_first(&once, &["layout=basic"]);
    let b = render_breadth_first(&seg, &["layout=basic"]);
    assert_eq!(a["image"]["sha256"], b["image"]["sha256"]);
    expect_input_error(
        &[
            "scene",
            "store",
            "rings",
            "--sf",
            "2",
            "-o",
            &d.join("x"),
            "--segment",
            "10",
            "--hierarchy",
        ],
        "--hierarchy",
    );
}

#[test]
fn the_rings368m_view_sees_a_small_share_of_rings() {
    let whole = json(&["scene", "stats", "rings", "--sf", "6", "--json"]);
    let v = json(&[
        "scene", "stats", "rings", "--sf", "6", "--view", VIEW, "--json",
    ]);
    assert_eq!(v["objects"], whole["objects"]);
    let n = v["objects_in_view"].as_u64().unwrap();
    assert!(n > 0 && n < v["objects"].as_u64().unwrap() / 10, "{v}");
    let d = Dir::new("seg-cli", "view");
    let bad = d.join("bad.json");
    std::fs::write(
        &bad,
        r#"{"view": {"from": [0,0,0], "at": [0,0,0], "up": [0,0,1], "angle": 10}}"#,
    )
    .unwrap();
    expect_input_error(
        &["scene", "stats", "rings", "--sf", "2", "--view", &bad],
        "from ≠ at",
    );
}

#[test]
fn nakamaru_4_3_stops_at_a_checkpoint_and_finishes_resumed() {
    let d = Dir::new("seg-cli", "repro");
    let out = d.join("out");
    let sets = [
        "rows=mount4,rings2m",
        "size=16",
        "segment=100",
        "cache=warm",
    ];
    let run = |extra: &[&str], resume: bool| -> Value {
        let mut args = vec!["reproduce", "nakamaru-4.3", "--out", &out];
        if resume {
            args.push("--resume");
        }
        for s in sets.iter().chain(extra) {
            args.push("--set");
            args.push(s);
        }
        let r = rtbench(&args);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        serde_json::from_slice(&std::fs::read(Path::new(&out).join("nakamaru-4.3.json")).unwrap())
            .unwrap()
    };
    let partial = run(&["max-seconds=0.000001"], false);
    assert_eq!(partial["finished"], false, "{partial}");
    let done = run(&["basic-fraction=2"], true);
    assert_eq!(done["finished"], true);
    let rows = done["rows"].as_array().unwrap();
    assert!(rows.iter().all(|r| r["fidelity"].is_string()));
    let image: Vec<&Value> = rows
        .iter()
        .filter(|r| r["claim"] == "image-equal")
        .collect();
    assert_eq!(image.len(), 2);
    assert!(image.iter().all(|r| r["verdict"] == "holds"), "{image:?}");
    let m = &done["measured"];
    assert!(m[1]["objects_in_view"].as_u64().unwrap() > 0);
    // The basic method was traced on half the bands of rows and extrapolated: a model.
    let basic = &m[0]["basic"];
    assert!(basic["scale"].as_f64().unwrap() > 1.0, "{basic}");
    assert!(rows
        .iter()
        .any(|r| r["claim"] == "basic-model" && r["fidelity"] == "model"));
    assert!(!Path::new(&out)
        .join(".partial/nakamaru-4.3/stores")
        .exists());
}

/// rings368 and rings368m share their stores. Both basic runs come before the split store is
/// written, so the basic store (~47 GB) is gone before the split store (~24 GB) is written: the
/// disk holds them only one after the other. The second row takes the first's stores as they
/// are, without streaming the scene again.
#[test]
fn nakamaru_4_3_runs_a_scenes_basic_rows_before_its_split_store() {
    let d = Dir::new("seg-cli", "order");
    let out = d.join("out");
    let r = rtbench(&[
        "reproduce",
        "nakamaru-4.3",
        "--out",
        &out,
        "--set",
        "rows=rings2,rings2m",
        "--set",
        "size=16",
        "--set",
        "segment=100",
        "--set",
        "cache=warm",
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    let at = |s: &str| err.find(s).unwrap_or_else(|| panic!("no {s:?} in {err}"));
    assert!(at("rings2m: basic …") < at("rings2: split store"), "{err}");
    assert_eq!(err.matches("basic store").count(), 1, "{err}");
    assert_eq!(err.matches("split store").count(), 1, "{err}");
    let v: Value =
        serde_json::from_slice(&std::fs::read(Path::new(&out).join("nakamaru-4.3.json")).unwrap())
            .unwrap();
    let m = &v["measured"];
    assert_eq!(m[0]["basic_store"], m[1]["basic_store"]);
    assert_eq!(m[0]["split_store"], m[1]["split_store"]);
    assert!(m[1]["objects"].as_u64().unwrap() > 0);
    assert_eq!(v["finished"], true);
    // `progress=on`: one stderr line per pass of every run (basic, S+G and S+G+B of both rows).
    let passes: u64 = (0..2)
        .flat_map(|i| ["basic", "sg", "sgb"].map(|k| m[i][k]["passes"].as_u64().unwrap()))
        .sum();
    assert!(passes >= 6, "{passes}");
    assert_eq!(
        err.matches("breadth-first: pass ").count() as u64,
        passes,
        "{err}"
    );
    // Each row's S+G+B image, kept across invocations in the checkpoint and written beside the
    // report: the pixels whose sha256 the row states.
    for (i, row) in ["rings2", "rings2m"].iter().enumerate() {
        let png = Path::new(&out).join(format!("images/nakamaru-4.3-{row}.png"));
        let img = image::open(&png).unwrap_or_else(|e| panic!("{}: {e}", png.display()));
        assert_eq!((img.width(), img.height()), (16, 16));
        let sha = sha2::Sha256::digest(img.to_rgb8().as_raw());
        let hex: String = sha.iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(m[i]["sgb"]["sha256"].as_str().unwrap(), hex, "{row}");
    }
}

/// `methods` measures a row one method an invocation (a 10^9-object row takes more than a
/// invocation per method): S+G+B first with no basic store written, then the capped basic run,
/// whose pass model takes its totals from the S+G+B run saved before, then S+G (its split store
/// written again when the disk no longer holds it), which finishes the rows and removes their
/// stores.
#[test]
fn nakamaru_4_3_measures_one_method_an_invocation() {
    let d = Dir::new("seg-cli", "methods");
    let out = d.join("out");
    let run = |extra: &[&str]| -> (Value, String) {
        let mut args = vec!["reproduce", "nakamaru-4.3", "--out", &out, "--resume"];
        for s in [
            "rows=rings2,rings2m",
            "size=16",
            "segment=100",
            "cache=warm",
        ]
        .iter()
        .chain(extra)
        {
            args.push("--set");
            args.push(s);
        }
        let r = rtbench(&args);
        let err = String::from_utf8_lossy(&r.stderr).to_string();
        assert!(r.status.success(), "{err}");
        let v = serde_json::from_slice(
            &std::fs::read(Path::new(&out).join("nakamaru-4.3.json")).unwrap(),
        )
        .unwrap();
        (v, err)
    };
    let (v, err) = run(&["methods=sgb"]);
    assert_eq!(v["finished"], false);
    assert!(!err.contains("basic store"), "{err}");
    assert!(!err.contains("S+G …"), "{err}");
    for i in 0..2 {
        let m = &v["measured"][i];
        assert!(m["sgb"]["passes"].as_u64().unwrap() > 0, "{m}");
        assert!(m["basic"].is_null() && m["sg"].is_null(), "{m}");
    }
    let (v, err) = run(&["methods=basic", "basic-passes=1"]);
    assert_eq!(v["finished"], false);
    assert!(
        !err.contains("S+G+B …") && !err.contains("split store"),
        "{err}"
    );
    for i in 0..2 {
        let m = &v["measured"][i];
        let b = &m["basic"];
        assert_eq!(b["capped"], true, "{b}");
        // The S+G+B run's streams at the basic run's rays a pass (the same passes here: both
        // hold every stream in one pass).
        let from = b["passes_from"].as_str().unwrap();
        assert!(
            from.starts_with("S+G+B's streams at the basic run's"),
            "{b}"
        );
        assert_eq!(b["passes_total"], m["sgb"]["passes"], "{m}");
        assert!(b["sweeps_total"].as_u64().unwrap() > 0, "{b}");
        assert!(m["sg"].is_null(), "{m}");
    }
    // The stores gone (another machine): the split store the steps name is written again.
    let stores = Path::new(&out).join(".partial/nakamaru-4.3/stores");
    std::fs::remove_dir_all(&stores).unwrap();
    let (v, err) = run(&["methods=sg,basic"]);
    assert!(
        err.contains("rings2: the store saved steps name is not at"),
        "{err}"
    );
    assert_eq!(err.matches("split store (in segments)").count(), 1, "{err}");
    assert_eq!(v["finished"], true);
    assert!(v["measured"][1]["sg"]["passes"].as_u64().unwrap() > 0);
    assert!(!Path::new(&out)
        .join(".partial/nakamaru-4.3/stores")
        .exists());
    expect_input_error(
        &[
            "reproduce",
            "nakamaru-4.3",
            "--out",
            &out,
            "--set",
            "methods=sgb,fast",
        ],
        "methods 'fast'",
    );
    expect_input_error(
        &[
            "reproduce",
            "nakamaru-4.3",
            "--out",
            &out,
            "--set",
            "basic-subspaces=2",
        ],
        "basic-subspaces needs basic-passes",
    );
}
