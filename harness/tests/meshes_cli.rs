//! Mesh files as scenes (OBJ, PLY, glTF): stats, render and check like NFF files; malformed files
//! of each format are one-line errors with exit status 2.

mod common;

use common::{expect_input_error, rtbench};
use std::path::PathBuf;

fn tmp(name: &str, body: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtbench-meshes-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    std::fs::write(&p, body).unwrap();
    p
}

/// An octahedron: 6 vertices, 8 faces, no normals (computed).
const OCTA_OBJ: &str = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

#[test]
fn obj_and_ply_scenes_run_like_nff() {
    let obj = tmp("octa.obj", OCTA_OBJ);
    let mut ply = String::from("ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\nelement face 8\nproperty list uchar int vertex_indices\nend_header\n");
    ply.push_str("1 0 0\n-1 0 0\n0 1 0\n0 -1 0\n0 0 1\n0 0 -1\n");
    for f in OCTA_OBJ.lines().filter(|l| l.starts_with('f')) {
        let idx: Vec<u32> = f[2..]
            .split(' ')
            .map(|x| x.parse::<u32>().unwrap() - 1)
            .collect();
        ply.push_str(&format!("3 {} {} {}\n", idx[0], idx[1], idx[2]));
    }
    let ply = tmp("octa.ply", &ply);
    for p in [&obj, &ply] {
        let s = p.to_str().unwrap();
        let out = rtbench(&["scene", "stats", s, "--json"]);
        assert!(out.status.success(), "{out:?}");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["counts"]["patch"], 8, "{v}");
        assert_eq!(v["lights"], 1, "{v}");
        let out = rtbench(&[
            "check", "--scene", s, "--engine", "bvh4", "--size", "32", "--json",
        ]);
        assert!(out.status.success(), "{out:?}");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["pass"], true, "{v}");
        // The default camera frames the model: a good share of the eye rays hit it.
        let out = rtbench(&[
            "render", "--scene", s, "--engine", "bvh4", "--size", "32", "--json",
        ]);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let (hit, total) = (
            v["rays"]["eye_hit"].as_f64().unwrap(),
            v["rays"]["eye"].as_f64().unwrap(),
        );
        assert!(hit / total > 0.1 && hit / total < 0.9, "{v}");
    }
}

#[test]
fn malformed_mesh_files_exit_2() {
    let cases = [
        ("bad.obj", "v 0 0 0\nf 1 2 3\n", "bad.obj"),
        ("empty.obj", "# nothing\n", "no triangles"),
        (
            "bad.ply",
            "ply\nformat ascii 1.0\nelement vertex 1\nend_header\n",
            "bad.ply",
        ),
        ("bad.gltf", "{ not json", "glTF"),
        ("bad.glb", "glTF", "GLB"),
    ];
    for (name, body, needle) in cases {
        let p = tmp(name, body);
        expect_input_error(&["scene", "stats", p.to_str().unwrap()], needle);
        expect_input_error(
            &[
                "render",
                "--scene",
                p.to_str().unwrap(),
                "--engine",
                "bvh4",
                "--size",
                "8",
            ],
            needle,
        );
    }
}
