//! The `tinybvh` engine as scripts see it: listed by `rtbench engines` with its layouts, and
//! cross-checked against Embree by `rtbench check` in every layout, on tessellated SPD scenes
//! (triangles only, so the same surfaces) as the other engines are.

mod common;

use common::rtbench;
use serde_json::Value;
use std::path::Path;
use std::sync::OnceLock;

/// Builds the plugin where the engine looks (examples/tinybvh/build.sh) unless it is there.
fn ensure_built() {
    static BUILT: OnceLock<()> = OnceLock::new();
    BUILT.get_or_init(|| {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/tinybvh/build.sh");
        let status = std::process::Command::new("bash")
            .arg(&script)
            .status()
            .expect("bash runs");
        assert!(status.success(), "examples/tinybvh/build.sh failed");
    });
}

#[test]
fn engines_lists_tinybvh_with_its_layouts() {
    ensure_built();
    let out = rtbench(&["engines", "--json"]);
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let e = v
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["name"] == "tinybvh")
        .expect("tinybvh is listed");
    assert_eq!(e["available"], true, "{e}");
    let d = e["description"].as_str().unwrap();
    assert!(d.contains("layout=bvh8_cpu|bvh4_cpu|cwbvh|bvh"), "{d}");
}

#[test]
fn every_layout_agrees_with_embree_on_tessellated_scenes() {
    ensure_built();
    for (scene, sf) in [("gears", "1"), ("tetra", "3"), ("balls", "1")] {
        for layout in ["bvh8_cpu", "bvh4_cpu", "cwbvh", "bvh"] {
            let set = format!("layout={layout}");
            let out = rtbench(&[
                "check",
                "--scene",
                scene,
                "--sf",
                sf,
                "--tessellate",
                "--engine",
                "tinybvh",
                "--set",
                &set,
                "--size",
                "128",
                "--json",
            ]);
            let v: Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|_| {
                panic!("{scene}/{layout}: {}", String::from_utf8_lossy(&out.stderr))
            });
            let agreement = v["hit_agreement"].as_f64().unwrap();
            assert!(
                agreement >= 0.9999,
                "{scene}{sf}/{layout}: agreement {agreement}: {v}"
            );
            assert!(out.status.success(), "{scene}/{layout}: {v}");
        }
    }
}
