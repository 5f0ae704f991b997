//! `rtbench scene store` and the out-of-core render: a store traced by the
//! breadth-first engine gives Embree's in-memory image; bad stores, engines and spill
//! directories are input errors (exit 2, one line) that leave nothing behind.

mod common;

use common::{expect_input_error, json, rtbench, store_scene, Dir};
use serde_json::Value;

#[test]
fn a_store_renders_out_of_core_as_embree_renders_in_memory() {
    let d = Dir::new("store-cli", "render");
    let store = d.join("rings2");
    let s = json(&[
        "scene", "store", "rings", "--sf", "2", "-o", &store, "--json",
    ]);
    let stats = json(&["scene", "stats", "rings", "--sf", "2", "--json"]);
    assert_eq!(s["objects"], stats["objects"]);
    // A small budget: a few hundred rays in memory, many passes and refills.
    let ooc = json(&[
        "render",
        "--scene",
        &store,
        "--engine",
        "breadth-first",
        "--size",
        "64",
        "--set",
        "memory=1MiB",
        "--json",
    ]);
    let mem = json(&[
        "render",
        "--scene",
        "rings",
        "--sf",
        "2",
        "--engine",
        "breadth-first",
        "--size",
        "64",
        "--json",
    ]);
    assert_eq!(ooc["image"]["sha256"], mem["image"]["sha256"]);
    assert_eq!(ooc["rays"], mem["rays"]);
    assert!(ooc["counters"]["extra"]["bf_passes"].as_u64().unwrap() > 5);
    assert!(ooc["io"]["workload"]["bytes_written"].as_u64().unwrap() > 0);
    assert!(ooc["build_stats"]["rays_in_memory"].as_f64().unwrap() < 4000.0);
    // The spill files are gone.
    let left: Vec<_> = std::fs::read_dir(&d.0).unwrap().collect();
    assert_eq!(left.len(), 1, "{left:?}");
}

/// Shading groups are as many rays as the engine holds in memory (at least 16,384, at most what
/// the workload's shading bytes hold): at 160²
/// (25,921 eye rays) a 1 MiB budget shades the eye rays in 2 groups, a 64 MiB one in 1, and
/// the image is the in-memory tracer's either way.
#[test]
fn shading_groups_follow_the_memory_budget_and_leave_the_image_unchanged() {
    let d = Dir::new("store-cli", "groups");
    let store = d.join("rings2");
    json(&[
        "scene", "store", "rings", "--sf", "2", "-o", &store, "--json",
    ]);
    let ooc = |memory: &str| {
        json(&[
            "render",
            "--scene",
            &store,
            "--engine",
            "breadth-first",
            "--size",
            "160",
            "--set",
            memory,
            "--json",
        ])
    };
    let (small, large) = (ooc("memory=1MiB"), ooc("memory=64MiB"));
    let mem = json(&[
        "render",
        "--scene",
        "rings",
        "--sf",
        "2",
        "--engine",
        "breadth-first",
        "--size",
        "160",
        "--json",
    ]);
    let group = |v: &Value| v["shading"]["group_rays"].as_u64().unwrap();
    let in_memory = |v: &Value| v["build_stats"]["rays_in_memory"].as_f64().unwrap() as u64;
    assert_eq!(group(&small), 16_384, "{}", small["shading"]);
    assert!(in_memory(&small) < 16_384);
    // The engine's rays, as far as the shading bytes (`SHADE_BYTES`) hold them.
    let cap = large["shading"]["cap_rays"].as_u64().unwrap();
    assert_eq!(
        group(&large),
        in_memory(&large).min(cap),
        "{}",
        large["shading"]
    );
    assert!(group(&large) > 161 * 161, "{}", large["shading"]);
    // Generation 1 alone takes 2 sweeps in the small budget's groups, 1 in the large one's.
    let gens = small["rays"]["generations"].as_array().unwrap().len() as u64;
    assert!(small["shading"]["store_sweeps"].as_u64().unwrap() > gens);
    assert!(large["shading"]["store_sweeps"].as_u64().unwrap() <= gens);
    for v in [&small, &large] {
        assert_eq!(v["image"]["sha256"], mem["image"]["sha256"]);
        assert_eq!(v["rays"], mem["rays"]);
    }
}

#[test]
fn bad_stores_engines_and_spill_directories_exit_2() {
    let d = Dir::new("store-cli", "errors");
    let store = d.join("tetra1");
    json(&[
        "scene", "store", "tetra", "--sf", "1", "-o", &store, "--json",
    ]);
    expect_input_error(
        &["scene", "store", "tetra", "--sf", "1", "-o", &store],
        "exists and is not an empty directory",
    );
    expect_input_error(
        &["render", "--scene", &store, "--engine", "grid"],
        "breadth-first engine only",
    );
    expect_input_error(
        &[
            "render",
            "--scene",
            &store,
            "--sf",
            "2",
            "--engine",
            "breadth-first",
        ],
        "a scene store is fixed",
    );
    // A spill directory that cannot be created (its parent is a file): in-memory and store.
    let file = d.join("a-file");
    std::fs::write(&file, b"x").unwrap();
    let spill = format!("spill={file}/sub");
    for scene in ["tetra", store.as_str()] {
        expect_input_error(
            &[
                "render",
                "--scene",
                scene,
                "--engine",
                "breadth-first",
                "--size",
                "16",
                "--set",
                &spill,
            ],
            "spill directory",
        );
    }
    expect_input_error(
        &[
            "render",
            "--scene",
            "tetra",
            "--engine",
            "breadth-first",
            "--set",
            "memory=0",
        ],
        "memory",
    );
    // A store written nowhere leaves nothing behind.
    expect_input_error(
        &[
            "scene",
            "store",
            "tetra",
            "--sf",
            "1",
            "-o",
            &format!("{file}/x"),
        ],
        "cannot write",
    );
    let left: Vec<_> = std::fs::read_dir(&d.0)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "{left:?}");
}

/// Seed 000's basic layout (one file of box + object records, read whole every sweep and in
/// shading) renders the split layout's image to the bit; a store of the other layout, or
/// `lazy=on` with the basic layout, is refused (exit 2, one line).
#[test]
fn basic_and_split_layouts_render_the_same_image() {
    let d = Dir::new("store-cli", "layouts");
    let (split, basic) = (d.join("split"), d.join("basic"));
    json(&[
        "scene", "store", "rings", "--sf", "2", "-o", &split, "--json",
    ]);
    let b = json(&[
        "scene", "store", "rings", "--sf", "2", "-o", &basic, "--layout", "basic", "--json",
    ]);
    assert_eq!(b["layout"], "basic");
    let render = |store: &str, layout: &str| {
        json(&[
            "render",
            "--scene",
            store,
            "--engine",
            "breadth-first",
            "--size",
            "48",
            "--set",
            &format!("layout={layout}"),
            "--set",
            "memory=1MiB",
            "--json",
        ])
    };
    let (s, b) = (render(&split, "split"), render(&basic, "basic"));
    assert_eq!(s["image"]["sha256"], b["image"]["sha256"]);
    let reads = |v: &Value| {
        v["counters"]["extra"]["bf_geometry_records_read"]
            .as_u64()
            .unwrap()
    };
    assert!(reads(&b) > reads(&s), "{} {}", reads(&b), reads(&s));
    expect_input_error(
        &[
            "render",
            "--scene",
            &basic,
            "--engine",
            "breadth-first",
            "--size",
            "16",
        ],
        "basic layout",
    );
    expect_input_error(
        &[
            "render",
            "--scene",
            &split,
            "--engine",
            "breadth-first",
            "--size",
            "16",
            "--set",
            "layout=basic",
        ],
        "split layout",
    );
    expect_input_error(
        &[
            "render",
            "--scene",
            &basic,
            "--engine",
            "breadth-first",
            "--size",
            "16",
            "--set",
            "layout=basic",
            "--set",
            "lazy=on",
        ],
        "lazy",
    );
    expect_input_error(
        &[
            "scene",
            "store",
            "tetra",
            "-o",
            &d.join("x"),
            "--layout",
            "packed",
        ],
        "--layout",
    );
}

/// A gzip-compressed basic store (seed 000 Table 3.3) renders the plain store's image, with
/// gzip spill files too; the engine counts compressed and uncompressed bytes; a truncated or
/// corrupted compressed store, and compression with the split layout, exit 2 in one line.
#[test]
fn compressed_stores_render_the_plain_image_and_refuse_damage() {
    let d = Dir::new("store-cli", "gzip");
    let (plain, gz) = (d.join("plain"), d.join("gz"));
    let p = json(&[
        "scene", "store", "mount", "--sf", "3", "-o", &plain, "--layout", "basic", "--json",
    ]);
    let g = json(&[
        "scene",
        "store",
        "mount",
        "--sf",
        "3",
        "-o",
        &gz,
        "--layout",
        "basic",
        "--compress",
        "gzip",
        "--json",
    ]);
    assert_eq!(p["objects_bytes"], g["objects_bytes"]);
    assert!(g["stored_bytes"].as_u64() < p["stored_bytes"].as_u64());
    let render = |store: &str, spill: &str| {
        json(&[
            "render",
            "--scene",
            store,
            "--engine",
            "breadth-first",
            "--size",
            "32",
            "--set",
            "layout=basic",
            "--set",
            &format!("spill_codec={spill}"),
            "--set",
            "buffer=1KiB",
            "--json",
        ])
    };
    let (a, b) = (render(&plain, "none"), render(&gz, "gzip"));
    assert_eq!(a["image"]["sha256"], b["image"]["sha256"]);
    let extra = &b["counters"]["extra"];
    assert!(extra["io_codec_bytes"].as_u64().unwrap() > extra["io_bytes_read"].as_u64().unwrap());
    assert!(b["io"]["workload"]["codec_bytes"].as_u64().unwrap() > 0);
    expect_input_error(
        &[
            "scene",
            "store",
            "tetra",
            "-o",
            &d.join("x"),
            "--compress",
            "gzip",
        ],
        "--layout basic",
    );
    // Corrupted in the middle (size kept), then truncated.
    let f = format!("{gz}/objects.bin.gz");
    let bytes = std::fs::read(&f).unwrap();
    let mut bad = bytes.clone();
    let mid = bad.len() / 2;
    bad[mid] ^= 0xff;
    std::fs::write(&f, &bad).unwrap();
    let args = [
        "render",
        "--scene",
        &gz,
        "--engine",
        "breadth-first",
        "--size",
        "16",
        "--set",
        "layout=basic",
    ];
    let out = rtbench(&args);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&out.stderr).lines().count(), 1);
    std::fs::write(&f, &bytes[..bytes.len() - 100]).unwrap();
    expect_input_error(&args, "header.json says");
}

/// A zstd-compressed split store (blocks with an index) renders the plain split store's image
/// with S+G and S+G+B, smaller on disk; a flipped byte exits 2 in one line. A render stopped
/// by the pass cap claims no image.
#[test]
fn a_compressed_split_store_renders_the_plain_image_and_the_pass_cap_claims_none() {
    let d = Dir::new("store-cli", "split-zstd");
    let (plain, zst) = (d.join("plain"), d.join("zst"));
    let p = store_scene("mount", "5", &plain, &[]);
    let z = store_scene("mount", "5", &zst, &["--compress", "zstd"]);
    assert_eq!(p["objects_bytes"], z["objects_bytes"]);
    assert!(
        z["stored_bytes"].as_u64() < p["stored_bytes"].as_u64(),
        "{z}"
    );
    let render = |store: &str, extra: &[&str]| {
        let mut a = vec![
            "render",
            "--scene",
            store,
            "--engine",
            "breadth-first",
            "--size",
            "32",
            "--set",
            "rays=200",
            "--json",
        ];
        for s in extra {
            a.extend(["--set", *s]);
        }
        json(&a)
    };
    for sets in [&[][..], &["hierarchy=on"][..]] {
        let (a, b) = (render(&plain, sets), render(&zst, sets));
        assert_eq!(a["image"]["sha256"], b["image"]["sha256"], "{sets:?}");
        assert_eq!(
            a["counters"]["extra"]["bf_passes"],
            b["counters"]["extra"]["bf_passes"]
        );
        assert!(b["counters"]["extra"]["io_codec_bytes"].as_u64().unwrap() > 0);
    }
    // The pass cap: one pass, no image.
    let c = render(&zst, &["max_passes=1"]);
    assert_eq!(c["counters"]["extra"]["bf_passes"], 1);
    assert!(
        c["image"]["sha256"].is_null() && c["image"]["incomplete"] == true,
        "{c}"
    );
    // A flipped byte in the geometry blocks.
    let f = format!("{zst}/geometry.bin.zst");
    let mut bytes = std::fs::read(&f).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x40;
    std::fs::write(&f, &bytes).unwrap();
    let out = rtbench(&[
        "render",
        "--scene",
        &zst,
        "--engine",
        "breadth-first",
        "--size",
        "16",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&out.stderr).lines().count(), 1);
}
