//! Mesh files wherever an SPD program goes: `run`, `report`, `compare`, `sweep` and nightly suites
//! take OBJ, PLY and glTF paths; a run is keyed by the file's name and content hash, so a changed
//! file is never compared as the same scene; bad paths and files are one line and exit 2.

mod common;

use common::{expect_input_error, rtbench, Dir};
use serde_json::Value;
use std::path::Path;

/// An octahedron: 6 vertices, 8 faces (1-based, as OBJ counts).
const VERTS: [[f32; 3]; 6] = [
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
];
const FACES: [[u16; 3]; 8] = [
    [1, 3, 5],
    [3, 2, 5],
    [2, 4, 5],
    [4, 1, 5],
    [3, 1, 6],
    [2, 3, 6],
    [4, 2, 6],
    [1, 4, 6],
];

fn obj() -> String {
    let mut s = String::new();
    for v in VERTS {
        s.push_str(&format!("v {} {} {}\n", v[0], v[1], v[2]));
    }
    for f in FACES {
        s.push_str(&format!("f {} {} {}\n", f[0], f[1], f[2]));
    }
    s
}

fn ply() -> String {
    let mut s = String::from(
        "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n\
         property float z\nelement face 8\nproperty list uchar int vertex_indices\nend_header\n",
    );
    for v in VERTS {
        s.push_str(&format!("{} {} {}\n", v[0], v[1], v[2]));
    }
    for f in FACES {
        s.push_str(&format!("3 {} {} {}\n", f[0] - 1, f[1] - 1, f[2] - 1));
    }
    s
}

/// A binary glTF (GLB) of the octahedron: positions and 16-bit indices in its BIN chunk.
fn glb() -> Vec<u8> {
    let mut bin = Vec::new();
    for v in VERTS {
        for c in v {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in FACES {
        for i in f {
            bin.extend_from_slice(&(i - 1).to_le_bytes());
        }
    }
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"buffers":[{{"byteLength":{}}}],"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":72}},{{"buffer":0,"byteOffset":72,"byteLength":48}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":6,"type":"VEC3","min":[-1,-1,-1],"max":[1,1,1]}},{{"bufferView":1,"componentType":5123,"count":24,"type":"SCALAR"}}]}}"#,
        bin.len()
    );
    let mut json = json.into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    let total = 12 + 8 + json.len() + 8 + bin.len();
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

fn records(dir: &str) -> Vec<Value> {
    std::fs::read_to_string(Path::new(dir).join("results.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

fn ok(args: &[&str]) -> std::process::Output {
    let out = rtbench(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn run_mesh(file: &str, out: &str) {
    ok(&[
        "run",
        "--engines",
        "embree,bvh8",
        "--scenes",
        file,
        "--repeat",
        "2",
        "--size",
        "32",
        "--out",
        out,
    ]);
}

#[test]
fn obj_ply_and_glb_run_report_and_compare() {
    let d = Dir::new("mesh-runs", "formats");
    std::fs::write(d.join("octa.obj"), obj()).unwrap();
    std::fs::write(d.join("octa.ply"), ply()).unwrap();
    std::fs::write(d.join("octa.glb"), glb()).unwrap();
    for name in ["octa.obj", "octa.ply", "octa.glb"] {
        let file = d.join(name);
        let (a, b) = (d.join(&format!("{name}-a")), d.join(&format!("{name}-b")));
        run_mesh(&file, &a);
        let recs = records(&a);
        assert_eq!(recs.len(), 2, "{recs:?}");
        let sha = recs[0]["scene"]["sha256"].as_str().unwrap().to_string();
        assert_eq!(sha.len(), 64);
        let label = format!("{name}-{}", &sha[..12]);
        for r in &recs {
            assert_eq!(r["status"], "ok", "{r}");
            assert_eq!(r["scene"]["name"], label.as_str());
            assert_eq!(r["scene"]["file"], file.as_str());
            assert_eq!(r["scene"]["primitives"], 8, "{r}");
            assert!(r["key"].as_str().unwrap().contains(&label), "{r}");
        }
        let bvh8 = recs.iter().find(|r| r["engine"] == "bvh8").unwrap();
        assert_eq!(bvh8["check"]["hit_agreement"], 1.0, "{bvh8}");
        ok(&["report", &a]);
        let md = std::fs::read_to_string(Path::new(&a).join("report.md")).unwrap();
        assert!(md.contains(&format!("| {label} | bvh8 |")), "{md}");
        run_mesh(&file, &b);
        let out = ok(&["compare", &a, &b, "--threshold", "1000", "--json"]);
        let c: Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(c["matched"], 2, "{c}");
    }
}

#[test]
fn a_changed_file_is_another_scene() {
    let d = Dir::new("mesh-runs", "changed");
    let file = d.join("model.obj");
    std::fs::write(&file, obj()).unwrap();
    let (a, b) = (d.join("a"), d.join("b"));
    run_mesh(&file, &a);
    // One more vertex, used by no face: the same triangles, another file.
    std::fs::write(&file, obj() + "v 2 2 2\n").unwrap();
    run_mesh(&file, &b);
    let (ka, kb) = (records(&a)[0]["key"].clone(), records(&b)[0]["key"].clone());
    assert_ne!(ka, kb);
    expect_input_error(&["compare", &a, &b], "model.obj changed");
}

#[test]
fn sweep_runs_a_mesh_once_and_suites_take_mesh_paths() {
    let d = Dir::new("mesh-runs", "sweep");
    let file = d.join("octa.ply");
    std::fs::write(&file, ply()).unwrap();
    let out = d.join("s");
    ok(&[
        "sweep",
        "--engines",
        "embree",
        "--scenes",
        &format!("tetra,{file}"),
        "--sf-max",
        "2",
        "--size",
        "16",
        "--max-seconds",
        "60",
        "--out",
        &out,
    ]);
    let recs = records(&out);
    let names: Vec<&str> = recs
        .iter()
        .map(|r| r["scene"]["name"].as_str().unwrap())
        .collect();
    assert_eq!(names.len(), 3, "{names:?}");
    assert_eq!(
        names.iter().filter(|n| n.starts_with("octa.ply-")).count(),
        1
    );
    let suite = d.join("suite.toml");
    std::fs::write(
        &suite,
        format!(
            "engines = [\"embree\", \"bvh8\"]\nscenes = [\"tetra\", {file:?}]\nsf = [1]\nrepeats = 2\nsize = 16\ngate = [\"counters\"]\n"
        ),
    )
    .unwrap();
    let out = ok(&["plan", "--json", "nightly", "--suite", &suite]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.matches("/octa.ply-").count(), 2, "{text}");
    assert_eq!(text.matches("/tetra1@").count(), 2, "{text}");
}

#[test]
fn bad_mesh_paths_are_one_line_and_exit_2() {
    let d = Dir::new("mesh-runs", "bad");
    let out = d.join("x");
    let run = |scene: &str, needle: &str| {
        expect_input_error(
            &[
                "run",
                "--engines",
                "embree",
                "--scenes",
                scene,
                "--out",
                &out,
            ],
            needle,
        );
        assert!(!Path::new(&out).join("results.jsonl").exists());
    };
    run(&d.join("missing.obj"), "missing.obj");
    run(&d.0.display().to_string(), "a directory");
    std::fs::write(
        d.join("bad.ply"),
        "ply\nformat ascii 1.0\nelement vertex 1\n",
    )
    .unwrap();
    run(&d.join("bad.ply"), "bad.ply");
    // A glTF whose buffer lies outside its folder is never read.
    std::fs::create_dir_all(d.0.join("m")).unwrap();
    std::fs::write(d.join("secret.bin"), [0u8; 120]).unwrap();
    std::fs::write(
        d.join("m/out.gltf"),
        r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"../secret.bin","byteLength":120}]}"#,
    )
    .unwrap();
    run(&d.join("m/out.gltf"), "leaves the mesh's folder");
    let suite = d.join("suite.toml");
    std::fs::write(
        &suite,
        "engines = [\"embree\"]\nscenes = [\"nowhere.glb\"]\nsf = [1]\ngate = []\n",
    )
    .unwrap();
    expect_input_error(&["plan", "nightly", "--suite", &suite], "nowhere.glb");
}
