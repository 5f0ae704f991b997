//! Scenes from the mesh files users have: Wavefront OBJ (`obj.rs`), PLY (`ply.rs`, ASCII and
//! binary) and glTF 2.0 (`gltf.rs`, `.gltf` with external or data-URI buffers, and `.glb`). A mesh
//! never makes rtbench read outside its own folder (`folder.rs`).
//!
//! A mesh file carries triangles, not a scene: no camera, no lights, no materials that mean
//! anything to the SPD workload. So every file becomes the same kind of scene (docs/guides/meshes.md):
//! - every face as a triangle patch with vertex normals (the file's, or area-weighted normals
//!   computed from the faces when it has none); polygons are fanned; zero-area triangles are
//!   dropped;
//! - one material: grey, Kd 0.7, Ks 0.3, Phong exponent 20, opaque (eye rays, shadow rays and
//!   reflection rays in the SPD workload);
//! - a camera that frames the model: looking at the centre of its bounds from the direction
//!   (1, 0.6, 1.6) (Y up), far enough for the bounding sphere to fill a 40° view;
//! - one white key light above, left and in front of the camera, and a dark blue background.

use crate::model::{Light, Material, ShapeRef, View};
use crate::sink::Sink;
use glam::DVec3;
use std::path::Path;

mod folder;
mod gltf;
mod obj;
mod ply;

/// Why a mesh file could not be read: `file: message`, one line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}: {message}")]
pub struct MeshError {
    pub file: String,
    pub message: String,
}

/// The mesh formats rtbench reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Obj,
    Ply,
    Gltf,
}

impl Format {
    /// By the file's extension (`.obj`, `.ply`, `.gltf`, `.glb`; any case).
    pub fn of(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Format::Obj),
            "ply" => Some(Format::Ply),
            "gltf" | "glb" => Some(Format::Gltf),
            _ => None,
        }
    }
}

/// An indexed triangle mesh.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<DVec3>,
    /// One per position, or empty.
    pub normals: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    fn append(&mut self, o: Mesh) {
        let base = self.positions.len() as u32;
        // Normals stay per vertex only if both have them.
        if self.normals.len() == self.positions.len() && o.normals.len() == o.positions.len() {
            self.normals.extend(o.normals);
        } else {
            self.normals.clear();
        }
        self.positions.extend(o.positions);
        self.triangles.extend(
            o.triangles
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }

    /// Area-weighted vertex normals, when the file gave none.
    fn compute_normals(&mut self) {
        let mut n = vec![DVec3::ZERO; self.positions.len()];
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let f = (b - a).cross(c - a);
            for &i in t {
                n[i as usize] += f;
            }
        }
        self.normals = n;
    }

    fn check(&self) -> Result<(), String> {
        let n = self.positions.len();
        if let Some(t) = self
            .triangles
            .iter()
            .find(|t| t.iter().any(|&i| i as usize >= n))
        {
            return Err(format!(
                "face ({} {} {}) names a vertex past the {n} the file has",
                t[0], t[1], t[2]
            ));
        }
        if let Some(p) = self.positions.iter().find(|p| !p.is_finite()) {
            return Err(format!("vertex ({} {} {}) is not finite", p.x, p.y, p.z));
        }
        Ok(())
    }
}

fn fan(face: &[u32], out: &mut Vec<[u32; 3]>) {
    for i in 1..face.len().saturating_sub(1) {
        out.push([face[0], face[i], face[i + 1]]);
    }
}

/// Reads a mesh file into an indexed mesh.
pub fn read_mesh(path: &Path) -> Result<Mesh, MeshError> {
    let file = path.display().to_string();
    let e = |message: String| MeshError {
        file: file.clone(),
        message,
    };
    let format =
        Format::of(path).ok_or_else(|| e("not a .obj, .ply, .gltf or .glb file".into()))?;
    match std::fs::metadata(path) {
        Err(err) => return Err(e(format!("cannot read: {err}"))),
        Ok(m) if !m.is_file() => return Err(e("not a regular file".into())),
        Ok(_) => {}
    }
    let bytes = std::fs::read(path).map_err(|err| e(format!("cannot read: {err}")))?;
    // Validation comes first in every reader; catching a panic is only the last line, should a
    // third-party parser still find one.
    let read = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match format {
        Format::Obj => obj::read(&bytes),
        Format::Ply => ply::read(&bytes),
        Format::Gltf => gltf::read(path, &bytes),
    }));
    let mut mesh = match read {
        Ok(r) => r.map_err(e)?,
        Err(_) => return Err(e("the file's parser failed on it (malformed file)".into())),
    };
    if mesh.triangles.is_empty() {
        return Err(e("no triangles".into()));
    }
    if mesh.normals.len() != mesh.positions.len() {
        mesh.compute_normals();
    }
    Ok(mesh)
}

/// Every file reading `path` opens, the mesh file first: what a scene's content hash must cover
/// (a glTF's external buffers are part of its scene). Never a file outside the mesh's folder.
pub fn files_read(path: &Path) -> Result<Vec<std::path::PathBuf>, MeshError> {
    let e = |message: String| MeshError {
        file: path.display().to_string(),
        message,
    };
    let mut out = vec![path.to_path_buf()];
    if Format::of(path) == Some(Format::Gltf) {
        let bytes = std::fs::read(path).map_err(|err| e(format!("cannot read: {err}")))?;
        let more = std::panic::catch_unwind(|| gltf::external_files(path, &bytes))
            .map_err(|_| e("the file's parser failed on it (malformed file)".into()))?
            .map_err(e)?;
        out.extend(more);
    }
    Ok(out)
}

/// The default view of a model with bounds `lo`…`hi` (module docs).
pub fn framing_view(lo: DVec3, hi: DVec3) -> View {
    let c = (lo + hi) * 0.5;
    let r = ((hi - lo).length() * 0.5).max(1e-6);
    let angle = 40.0f64;
    let dist = r / (angle.to_radians() * 0.5).sin() * 1.05;
    let dir = DVec3::new(1.0, 0.6, 1.6).normalize();
    View {
        from: c + dir * dist,
        at: c,
        up: DVec3::Y,
        angle,
        hither: dist * 1e-4,
        resolution: [512, 512],
    }
}

/// The key light of a model framed by `view` (module docs).
pub fn key_light(view: &View) -> Light {
    let fwd = (view.at - view.from).normalize();
    let right = fwd.cross(view.up).normalize();
    let dist = (view.at - view.from).length();
    Light {
        position: view.from - right * dist * 0.6 + view.up * dist * 0.8,
        color: None,
    }
}

/// The default material of mesh scenes (module docs).
pub fn default_material() -> Material {
    Material {
        color: DVec3::new(0.8, 0.8, 0.8),
        kd: 0.7,
        ks: 0.3,
        shine: 20.0,
        t: 0.0,
        ior: 1.0,
    }
}

/// Streams a mesh file into `sink` as a scene (module docs). Returns the triangles dropped for
/// zero area.
pub fn stream_mesh(path: &Path, sink: &mut dyn Sink) -> Result<u64, MeshError> {
    let mesh = read_mesh(path)?;
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for t in &mesh.triangles {
        for &i in t {
            lo = lo.min(mesh.positions[i as usize]);
            hi = hi.max(mesh.positions[i as usize]);
        }
    }
    let view = framing_view(lo, hi);
    sink.background(DVec3::new(0.05, 0.07, 0.15));
    sink.view(&view);
    sink.light(&key_light(&view));
    sink.material(&default_material());
    let mut dropped = 0;
    for t in &mesh.triangles {
        let v = t.map(|i| mesh.positions[i as usize]);
        if (v[1] - v[0]).cross(v[2] - v[0]).length_squared() == 0.0 {
            dropped += 1;
            continue;
        }
        let n = t.map(|i| {
            let n = mesh.normals[i as usize];
            if n.length_squared() > 0.0 && n.is_finite() {
                n.normalize()
            } else {
                (v[1] - v[0]).cross(v[2] - v[0]).normalize()
            }
        });
        sink.shape(ShapeRef::Patch {
            vertices: &v,
            normals: &n,
        });
    }
    Ok(dropped)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::SceneCollector;

    fn tmp(name: &str, body: &[u8]) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("rtbench-mesh-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let p = d.join(name);
        std::fs::write(&p, body).unwrap();
        p
    }

    const QUAD_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

    #[test]
    fn obj_ply_gltf_give_the_same_quad() {
        let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
        // Four vertices and six u16 indices in a data URI.
        let mut bin: Vec<u8> = Vec::new();
        for p in [[0f32, 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]] {
            for x in p {
                bin.extend_from_slice(&x.to_le_bytes());
            }
        }
        for i in [0u16, 1, 2, 0, 2, 3] {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        const T: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut b64 = String::new();
        for c in bin.chunks(3) {
            let v = (c[0] as u32) << 16
                | (*c.get(1).unwrap_or(&0) as u32) << 8
                | *c.get(2).unwrap_or(&0) as u32;
            for i in 0..=c.len() {
                b64.push(T[(v >> (18 - 6 * i) & 63) as usize] as char);
            }
        }
        while !b64.len().is_multiple_of(4) {
            b64.push('=');
        }
        let gltf = format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
            "buffers":[{{"byteLength":60,"uri":"data:application/octet-stream;base64,{b64}"}}],
            "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":12}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                         {{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}}]}}"#
        );
        for (name, body) in [
            ("q.obj", QUAD_OBJ.as_bytes()),
            ("q.ply", ply.as_bytes()),
            ("q.gltf", gltf.as_bytes()),
        ] {
            let p = tmp(name, body);
            let mut c = SceneCollector::default();
            let dropped = stream_mesh(&p, &mut c).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(dropped, 0);
            assert_eq!(c.scene.objects.len(), 2, "{name}");
            assert_eq!(c.scene.lights.len(), 1);
            let area: f64 = c
                .scene
                .objects
                .iter()
                .map(|o| match o.shape.as_ref() {
                    ShapeRef::Patch {
                        vertices: v,
                        normals: n,
                    } => {
                        assert!((n[0].z.abs() - 1.0).abs() < 1e-12, "{name}: {n:?}");
                        (v[1] - v[0]).cross(v[2] - v[0]).length() / 2.0
                    }
                    _ => panic!("{name}: not a patch"),
                })
                .sum();
            assert!((area - 1.0).abs() < 1e-12, "{name}: area {area}");
            // The camera sees the model's centre.
            assert!((c.scene.view.at - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-12);
        }
    }

    #[test]
    fn malformed_files_are_one_line_errors() {
        let cases: [(&str, &[u8]); 7] = [
            ("bad.obj", b"v 0 0 0\nf 1 2 3\n"),
            ("empty.obj", b"# nothing\n"),
            ("bad.ply", b"ply\nformat ascii 1.0\nelement vertex 1\nend_header\n"),
            ("trunc.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x00\x00"),
            ("bad.gltf", b"{ not json"),
            ("bad.glb", b"glTF\x02\x00\x00\x00"),
            ("q.stl", b"solid"),
        ];
        for (name, body) in cases {
            let p = tmp(name, body);
            let e = read_mesh(&p).expect_err(name).to_string();
            assert_eq!(e.lines().count(), 1, "{name}: {e}");
            assert!(e.contains(name), "{name}: {e}");
        }
    }

    fn b64(bin: &[u8]) -> String {
        const T: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut s = String::new();
        for c in bin.chunks(3) {
            let v = (c[0] as u32) << 16
                | (*c.get(1).unwrap_or(&0) as u32) << 8
                | *c.get(2).unwrap_or(&0) as u32;
            for i in 0..=c.len() {
                s.push(T[(v >> (18 - 6 * i) & 63) as usize] as char);
            }
        }
        s
    }

    /// Two triangles (a unit quad): 4 float VEC3 positions then 6 u16 indices, 60 bytes.
    fn quad_bin() -> Vec<u8> {
        let mut bin = Vec::new();
        for p in [[0f32, 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]] {
            for x in p {
                bin.extend_from_slice(&x.to_le_bytes());
            }
        }
        for i in [0u16, 1, 2, 0, 2, 3] {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        bin
    }

    /// A glTF document over `buffer` (a `buffers` entry) with the given views and accessors;
    /// the primitive reads accessor 0 as POSITION and accessor 1 as indices.
    fn gltf_doc(buffer: &str, views: &str, accessors: &str) -> String {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
            "buffers":[{buffer}],"bufferViews":[{views}],"accessors":[{accessors}]}}"#
        )
    }

    const VIEWS: &str = r#"{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12}"#;
    const POS: &str = r#"{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"}"#;
    const IDX: &str = r#"{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}"#;

    fn data_buffer() -> String {
        format!(
            r#"{{"byteLength":60,"uri":"data:application/octet-stream;base64,{}"}}"#,
            b64(&quad_bin())
        )
    }

    #[test]
    fn gltf_accessors_are_checked_against_the_spec() {
        let buf = data_buffer();
        let ok = gltf_doc(&buf, VIEWS, &format!("{POS},{IDX}"));
        let m = read_mesh(&tmp("ok.gltf", ok.as_bytes())).unwrap();
        assert_eq!(m.triangles.len(), 2);
        let pos_as = |ty: &str, ct: u32| {
            format!(r#"{{"bufferView":0,"componentType":{ct},"count":4,"type":"{ty}"}}"#)
        };
        let cases: Vec<(&str, String, &str)> = vec![
            ("no-accessors", gltf_doc(&buf, VIEWS, ""), "accessor 0"),
            ("idx-float", gltf_doc(&buf, VIEWS, &format!(r#"{POS},{{"bufferView":1,"componentType":5126,"count":3,"type":"SCALAR"}}"#)), "componentType 5126"),
            ("stride4", gltf_doc(&buf, r#"{"buffer":0,"byteLength":48,"byteStride":4},{"buffer":0,"byteOffset":48,"byteLength":12}"#, &format!("{POS},{IDX}")), "byteStride 4"),
            ("vec2", gltf_doc(&buf, VIEWS, &format!("{},{IDX}", pos_as("VEC2", 5126))), "VEC2"),
            ("vec4", gltf_doc(&buf, VIEWS, &format!("{},{IDX}", pos_as("VEC4", 5126))), "VEC4"),
            ("scalar", gltf_doc(&buf, VIEWS, &format!("{},{IDX}", pos_as("SCALAR", 5126))), "SCALAR"),
            ("mat4", gltf_doc(&buf, VIEWS, &format!("{},{IDX}", pos_as("MAT4", 5126))), "MAT4"),
            ("ubyte", gltf_doc(&buf, VIEWS, &format!("{},{IDX}", pos_as("VEC3", 5121))), "5121"),
            ("ushort", gltf_doc(&buf, VIEWS, &format!("{},{IDX}", pos_as("VEC3", 5123))), "5123"),
            ("idx-overrun", gltf_doc(&buf, VIEWS, &format!(r#"{POS},{{"bufferView":1,"componentType":5123,"count":9,"type":"SCALAR"}}"#)), "overrun"),
            ("pos-overrun", gltf_doc(&buf, VIEWS, &format!(r#"{{"bufferView":0,"byteOffset":4,"componentType":5126,"count":4,"type":"VEC3"}},{IDX}"#)), "overrun"),
            ("view-past-buffer", gltf_doc(&buf, r#"{"buffer":0,"byteOffset":40,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12}"#, &format!("{POS},{IDX}")), "runs past"),
            ("idx-range", gltf_doc(&buf, VIEWS, &format!(r#"{POS},{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR","byteOffset":0}}"#)).replace("\"count\":4,", "\"count\":2,"), "past the"),
            ("no-view", gltf_doc(&buf, "", &format!("{POS},{IDX}")), "bufferView 0"),
            ("bad-node", ok.replace(r#""nodes":[0]"#, r#""nodes":[7]"#), "node 7"),
            ("bad-mesh", ok.replace(r#""mesh":0"#, r#""mesh":3"#), "mesh 3"),
            ("cycle", ok.replace(r#""nodes":[{"mesh":0}]"#, r#""nodes":[{"mesh":0,"children":[0]}]"#), "reached twice"),
        ];
        for (name, doc, want) in cases {
            let e = read_mesh(&tmp(&format!("{name}.gltf"), doc.as_bytes()))
                .expect_err(name)
                .to_string();
            assert_eq!(e.lines().count(), 1, "{name}: {e}");
            assert!(e.contains(want), "{name}: {e}");
        }
    }

    #[test]
    fn gltf_buffers_stay_in_the_mesh_folder() {
        let root = std::env::temp_dir().join(format!("rtbench-meshdir-{}", std::process::id()));
        let dir = root.join("m");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("q.bin"), quad_bin()).unwrap();
        std::fs::write(root.join("outside.bin"), quad_bin()).unwrap();
        let doc = |uri: &str, len: usize| {
            gltf_doc(
                &format!(r#"{{"byteLength":{len},"uri":"{uri}"}}"#),
                VIEWS,
                &format!("{POS},{IDX}"),
            )
        };
        std::fs::write(dir.join("in.gltf"), doc("q.bin", 60)).unwrap();
        assert_eq!(read_mesh(&dir.join("in.gltf")).unwrap().triangles.len(), 2);
        let outside = root.join("outside.bin").display().to_string();
        for (name, uri, len) in [
            ("abs", outside.as_str(), 60),
            ("dotdot", "../outside.bin", 60),
            ("passwd", "/etc/passwd", 60),
            ("dev", "/dev/zero", 60),
            ("file", "file:///etc/passwd", 60),
            ("short", "q.bin", 61),
        ] {
            let p = dir.join(format!("{name}.gltf"));
            std::fs::write(&p, doc(uri, len)).unwrap();
            let e = read_mesh(&p).expect_err(name).to_string();
            assert_eq!(e.lines().count(), 1, "{name}: {e}");
            assert!(!e.contains("root:"), "{name}: {e}");
        }
        // A GLB with its binary chunk reads the same quad.
        let json = gltf_doc(r#"{"byteLength":60}"#, VIEWS, &format!("{POS},{IDX}"));
        let mut j = json.into_bytes();
        while !j.len().is_multiple_of(4) {
            j.push(b' ');
        }
        let bin = quad_bin();
        let total = 12 + 8 + j.len() + 8 + bin.len();
        let mut glb = b"glTF".to_vec();
        for w in [2u32, total as u32, j.len() as u32, 0x4E4F_534A] {
            glb.extend_from_slice(&w.to_le_bytes());
        }
        glb.extend_from_slice(&j);
        glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        glb.extend_from_slice(&0x004E_4942u32.to_le_bytes());
        glb.extend_from_slice(&bin);
        assert_eq!(read_mesh(&tmp("q.glb", &glb)).unwrap().triangles.len(), 2);
        for cut in [13, 30, total - 1] {
            let e = read_mesh(&tmp("cut.glb", &glb[..cut])).expect_err("cut");
            assert_eq!(e.to_string().lines().count(), 1);
        }
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn obj_never_opens_its_material_library() {
        let d = std::env::temp_dir().join(format!("rtbench-mtl-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        // A FIFO blocks whoever opens it: reading the OBJ returns only if mtllib is not followed.
        let fifo = d.join("m.mtl");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if !made.map(|s| s.success()).unwrap_or(false) {
            return;
        }
        let p = d.join("m.obj");
        std::fs::write(
            &p,
            format!("mtllib {}\nmtllib /dev/zero\n{QUAD_OBJ}", fifo.display()),
        )
        .unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || tx.send(read_mesh(&p).map(|m| m.triangles.len())));
        let got = rx.recv_timeout(std::time::Duration::from_secs(20));
        if got.is_err() {
            // Unblock the reader before failing.
            let _ = std::fs::OpenOptions::new().write(true).open(&fifo);
        }
        assert_eq!(got.expect("mtllib was opened").unwrap(), 2);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn ply_counts_are_held_against_the_data() {
        let bin_ply = |nv: usize| {
            let mut b = format!("ply\nformat binary_little_endian 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n").into_bytes();
            for p in [[0f32, 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]] {
                for x in p {
                    b.extend_from_slice(&x.to_le_bytes());
                }
            }
            for f in [[0i32, 1, 2], [0, 2, 3]] {
                b.push(3);
                for i in f {
                    b.extend_from_slice(&i.to_le_bytes());
                }
            }
            b
        };
        assert_eq!(
            read_mesh(&tmp("ok.ply", &bin_ply(4)))
                .unwrap()
                .triangles
                .len(),
            2
        );
        for (name, nv) in [("more.ply", 5), ("fewer.ply", 3)] {
            let e = read_mesh(&tmp(name, &bin_ply(nv)))
                .expect_err(name)
                .to_string();
            assert_eq!(e.lines().count(), 1, "{name}: {e}");
        }
        // Counts no data could hold: refused before the parser makes a single element.
        for (name, body) in [
            ("empty-elements.ply", &b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nend_header\n"[..]),
            ("huge.ply", &b"ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nend_header\n0\n"[..]),
        ] {
            let e = read_mesh(&tmp(name, body)).expect_err(name).to_string();
            assert!(e.contains("no properties") || e.contains("at least"), "{name}: {e}");
        }
        let mut trailing = bin_ply(4);
        trailing.extend_from_slice(&[0u8; 13]);
        assert!(read_mesh(&tmp("trail.ply", &trailing)).is_err());
    }

    #[test]
    fn devices_and_folders_are_not_meshes() {
        let d = std::env::temp_dir().join(format!("rtbench-dirmesh-{}.obj", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        assert!(read_mesh(&d)
            .unwrap_err()
            .to_string()
            .contains("not a regular file"));
        std::fs::remove_dir_all(&d).unwrap();
    }
}
