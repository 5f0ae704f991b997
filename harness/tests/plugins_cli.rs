//! Engine plugins (include/rtbench_engine.h): the example C plugin, compiled here with the `cc`
//! crate, runs beside the built-in engines and agrees with Embree; its faulty variants (a crash,
//! a NaN t, an id out of range, a t outside the interval, a wrong ABI version) fail their own
//! runs with a one-line reason while the other runs go on.

mod common;

use common::{expect_input_error, rtbench};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

/// Compiles examples/c-bvh/bvh.c with `defines` into `dir/libc_bvh<tag>.so`.
fn compile(dir: &Path, tag: &str, define: Option<&str>) -> PathBuf {
    let target = env!("RTBENCH_BUILD_TARGET");
    let root = workspace();
    let compiler = cc::Build::new()
        .cargo_metadata(false)
        .cargo_warnings(false)
        .target(target)
        .host(target)
        .opt_level(2)
        .out_dir(dir)
        .get_compiler();
    let out = dir.join(format!("libc_bvh{tag}.so"));
    let mut cmd = compiler.to_command();
    cmd.args(["-shared", "-fPIC", "-std=c99", "-Wall", "-Werror"]);
    cmd.arg(format!("-I{}", root.join("include").display()));
    if let Some(d) = define {
        cmd.arg(format!("-D{d}"));
    }
    cmd.arg(root.join("examples/c-bvh/bvh.c"))
        .arg("-o")
        .arg(&out)
        .arg("-lm");
    let status = cmd.status().expect("the C compiler runs");
    assert!(status.success(), "compiling the C plugin ({tag}) failed");
    out
}

/// The plugin and its faulty variants, compiled once for all tests of this file.
fn plugins() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("rtbench-plugins-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        compile(&dir, "", None);
        for (tag, d) in [
            ("_segv", "RTB_FAULT_SEGV"),
            ("_nan", "RTB_FAULT_NAN"),
            ("_id", "RTB_FAULT_ID"),
            ("_t", "RTB_FAULT_T"),
            ("_abi", "RTB_FAULT_ABI"),
            ("_bary", "RTB_FAULT_BARY"),
            ("_prim0", "RTB_FAULT_PRIM0"),
            ("_stdout", "RTB_FAULT_STDOUT"),
            ("_esc", "RTB_FAULT_ESC"),
        ] {
            compile(&dir, tag, Some(d));
        }
        dir
    })
}

fn plugin(tag: &str) -> String {
    plugins()
        .join(format!("libc_bvh{tag}.so"))
        .display()
        .to_string()
}

fn stdout_json(args: &[&str]) -> serde_json::Value {
    let out = rtbench(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("json")
}

#[test]
fn c_plugin_agrees_with_embree_and_reports_tessellation() {
    let p = format!("plugin:{}", plugin(""));
    // balls: spheres the plugin takes, and the floor polygon as triangles.
    let v = stdout_json(&[
        "check", "--scene", "balls", "--sf", "2", "--engine", &p, "--size", "96", "--json",
    ]);
    assert_eq!(v["pass"], true, "{v}");
    assert!(v["hit_agreement"].as_f64().unwrap() >= 0.9999, "{v}");
    // rings: cones the plugin does not take are tessellated, and the render says so.
    let v = stdout_json(&[
        "render", "--scene", "rings", "--sf", "1", "--engine", &p, "--size", "32", "--json",
    ]);
    let s = &v["build_stats"];
    assert!(s["tessellated_cones"].as_f64().unwrap() > 0.0, "{v}");
    let rel = s["tessellation_max_rel_error"].as_f64().unwrap();
    assert!(rel > 0.0 && rel < 0.05, "{v}");
    // A finer tessellation on request: smaller error.
    let v = stdout_json(&[
        "render",
        "--scene",
        "rings",
        "--sf",
        "1",
        "--engine",
        &format!("{p}:tess=32"),
        "--size",
        "32",
        "--json",
    ]);
    assert!(
        v["build_stats"]["tessellation_max_rel_error"]
            .as_f64()
            .unwrap()
            < rel / 10.0
    );
}

#[test]
fn faulty_plugins_fail_their_runs_and_others_go_on() {
    let dir = std::env::temp_dir().join(format!("rtbench-plugin-runs-{}", std::process::id()));
    let engines = [
        "bvh4".to_string(),
        format!("plugin:{}", plugin("_segv")),
        format!("plugin:{}", plugin("_nan")),
        format!("plugin:{}", plugin("_id")),
        format!("plugin:{}", plugin("_t")),
        format!("plugin:{}", plugin("_abi")),
        format!("plugin:{}", plugin("")),
    ]
    .join(",");
    let out = rtbench(&[
        "run",
        "--engines",
        &engines,
        "--scenes",
        "balls",
        "--sf",
        "1",
        "--size",
        "48",
        "--repeat",
        "1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let text = std::fs::read_to_string(dir.join("results.jsonl")).expect("results");
    let recs: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(recs.len(), 7);
    let by_path = |tag: &str| {
        let path = plugin(tag);
        recs.iter()
            .find(|r| r["settings"]["path"].as_str() == Some(path.as_str()))
            .unwrap_or_else(|| panic!("no record for {tag}"))
            .clone()
    };
    for (tag, needle) in [
        ("_segv", "signal 11"),
        ("_nan", "t is NaN"),
        ("_id", "out of range"),
        ("_t", "outside the ray's interval"),
        ("_abi", "ABI version 99"),
    ] {
        let r = by_path(tag);
        assert_eq!(r["status"], "failed", "{tag}: {r}");
        let reason = r["reason"].as_str().unwrap();
        assert!(reason.contains(needle), "{tag}: {reason}");
        assert_eq!(reason.lines().count(), 1, "{tag}: {reason}");
        assert!(
            r["rays_total"].as_u64().unwrap_or(0) == 0,
            "{tag}: results kept"
        );
    }
    let good = by_path("");
    assert_eq!(good["status"], "ok", "{good}");
    let bvh4 = recs.iter().find(|r| r["engine"] == "bvh4").unwrap();
    assert_eq!(bvh4["status"], "ok");
    // The plugin's hits agree with Embree's.
    assert!(
        good["check"]["hit_agreement"].as_f64().unwrap() >= 0.9999,
        "{good}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_plugin_entries_exit_2() {
    expect_input_error(
        &[
            "render",
            "--scene",
            "balls",
            "--sf",
            "1",
            "--engine",
            "plugin:no/such/lib.so",
        ],
        "no such file",
    );
    expect_input_error(
        &[
            "run",
            "--engines",
            "plugin:",
            "--scenes",
            "balls",
            "--out",
            "x",
        ],
        "expected plugin:PATH",
    );
    let p = format!("plugin:{}:bogus=1", plugin(""));
    expect_input_error(
        &["render", "--scene", "balls", "--sf", "1", "--engine", &p],
        "unknown setting 'bogus'",
    );
    expect_input_error(
        &[
            "render",
            "--scene",
            "balls",
            "--sf",
            "1",
            "--engine",
            &format!("plugin:{}", plugin("_abi")),
        ],
        "ABI version",
    );
}

/// A plugin's answers are held to the ABI beyond t and ids: barycentrics finite and inside the
/// triangle; what it prints stays off rtbench's stdout; naming primitive 0 at the right
/// distance does not pass `check` on the tie rule; its messages reach the terminal escaped.
#[test]
fn plugin_answers_output_and_messages_are_held_to_the_abi() {
    let engine = |tag: &str| format!("plugin:{}", plugin(tag));
    let render = |e: &str| {
        rtbench(&[
            "render", "--scene", "balls", "--sf", "1", "--engine", e, "--size", "24", "--json",
        ])
    };
    let out = render(&engine("_bary"));
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("barycentrics"));
    let out = render(&engine("_stdout"));
    assert!(out.status.success(), "{out:?}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is the JSON");
    assert!(v["rays_total"].as_u64().unwrap_or(0) > 0 || v.is_object());
    assert!(String::from_utf8_lossy(&out.stderr).contains("c-bvh:"));
    let out = rtbench(&[
        "check",
        "--scene",
        "balls",
        "--sf",
        "1",
        "--engine",
        &engine("_prim0"),
        "--size",
        "24",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert!(v["hit_agreement"].as_f64().unwrap() > 0.99, "{v}");
    assert!(v["primitive_agreement"].as_f64().unwrap() < 0.99, "{v}");
    assert_eq!(v["pass"], false);
    let v = stdout_json(&[
        "check",
        "--scene",
        "balls",
        "--sf",
        "1",
        "--engine",
        &engine(""),
        "--size",
        "24",
        "--json",
    ]);
    assert!(v["primitive_agreement"].as_f64().unwrap() >= 0.99, "{v}");
    let out = render(&engine("_esc"));
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains('\u{1b}') && !err.contains('\u{7}'), "{err:?}");
    assert!(err.contains("\\u{1b}[31mred"), "{err}");
    expect_input_error(
        &[
            "render",
            "--scene",
            "balls",
            "--sf",
            "1",
            "--engine",
            &format!("{}:abi_timing=bogus", engine("")),
        ],
        "abi_timing",
    );
}
