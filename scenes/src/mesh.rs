//! Scenes from the mesh files users have: Wavefront OBJ (`tobj`), PLY (`ply-rs-bw`, ASCII and
//! binary) and glTF 2.0 (`gltf`, `.gltf` with external or data-URI buffers, and `.glb`).
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
use glam::{DMat4, DVec3};
use std::path::Path;

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

fn read_obj(path: &Path) -> Result<Mesh, String> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) = tobj::load_obj(path, &opts).map_err(|e| format!("OBJ: {e}"))?;
    let mut mesh = Mesh::default();
    for m in models {
        let p = &m.mesh.positions;
        let nrm = &m.mesh.normals;
        let mut one = Mesh {
            positions: p
                .chunks_exact(3)
                .map(|c| DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64))
                .collect(),
            ..Default::default()
        };
        if nrm.len() == p.len() {
            one.normals = nrm
                .chunks_exact(3)
                .map(|c| DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64))
                .collect();
        }
        one.triangles = m
            .mesh
            .indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        one.check().map_err(|e| format!("OBJ: {e}"))?;
        mesh.append(one);
    }
    Ok(mesh)
}

fn read_ply(path: &Path) -> Result<Mesh, String> {
    use ply_rs_bw::ply::{DefaultElement, Property};
    let f = std::fs::File::open(path).map_err(|e| format!("cannot read: {e}"))?;
    let mut r = std::io::BufReader::new(f);
    let parser = ply_rs_bw::parser::Parser::<DefaultElement>::new();
    let ply = parser.read_ply(&mut r).map_err(|e| {
        let s = e.to_string();
        format!("PLY: {}", s.lines().next().unwrap_or("unreadable"))
    })?;
    let scalar = |p: &Property| -> Option<f64> {
        Some(match *p {
            Property::Char(v) => v as f64,
            Property::UChar(v) => v as f64,
            Property::Short(v) => v as f64,
            Property::UShort(v) => v as f64,
            Property::Int(v) => v as f64,
            Property::UInt(v) => v as f64,
            Property::Float(v) => v as f64,
            Property::Double(v) => v,
            _ => return None,
        })
    };
    let list = |p: &Property| -> Option<Vec<u32>> {
        let v: Vec<i64> = match p {
            Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
            _ => return None,
        };
        v.into_iter().map(|x| u32::try_from(x).ok()).collect()
    };
    let verts = ply
        .payload
        .get("vertex")
        .ok_or("PLY: no 'vertex' element")?;
    let mut mesh = Mesh::default();
    let mut normals = Vec::new();
    for (i, v) in verts.iter().enumerate() {
        let get = |k: &str| v.get(k).and_then(scalar);
        let (Some(x), Some(y), Some(z)) = (get("x"), get("y"), get("z")) else {
            return Err(format!("PLY: vertex {i} lacks a numeric x, y or z"));
        };
        mesh.positions.push(DVec3::new(x, y, z));
        if let (Some(a), Some(b), Some(c)) = (get("nx"), get("ny"), get("nz")) {
            normals.push(DVec3::new(a, b, c));
        }
    }
    if normals.len() == mesh.positions.len() {
        mesh.normals = normals;
    }
    let faces = ply.payload.get("face").ok_or("PLY: no 'face' element")?;
    for (i, f) in faces.iter().enumerate() {
        let idx = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(list)
            .ok_or_else(|| format!("PLY: face {i} has no vertex_indices list"))?;
        fan(&idx, &mut mesh.triangles);
    }
    mesh.check().map_err(|e| format!("PLY: {e}"))?;
    Ok(mesh)
}

fn base64(s: &str) -> Result<Vec<u8>, String> {
    let val = |c: u8| -> Result<u32, String> {
        Ok(match c {
            b'A'..=b'Z' => (c - b'A') as u32,
            b'a'..=b'z' => (c - b'a' + 26) as u32,
            b'0'..=b'9' => (c - b'0' + 52) as u32,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return Err("bad base64 in a data URI".into()),
        })
    };
    let bytes: Vec<u8> = s
        .bytes()
        .filter(|&b| b != b'=' && !b.is_ascii_whitespace())
        .collect();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    for chunk in bytes.chunks(4) {
        let mut acc = 0u32;
        for (i, &c) in chunk.iter().enumerate() {
            acc |= val(c)? << (18 - 6 * i);
        }
        let n = chunk.len().saturating_sub(1);
        out.extend_from_slice(&acc.to_be_bytes()[1..1 + n]);
    }
    Ok(out)
}

fn read_gltf(path: &Path) -> Result<Mesh, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    let g = gltf::Gltf::from_slice(&bytes).map_err(|e| format!("glTF: {e}"))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut buffers = Vec::new();
    for b in g.document.buffers() {
        let data = match b.source() {
            gltf::buffer::Source::Bin => g.blob.clone().ok_or("glTF: no binary chunk")?,
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (_, b64) = rest
                        .split_once(";base64,")
                        .ok_or("glTF: a data URI that is not base64")?;
                    base64(b64).map_err(|e| format!("glTF: {e}"))?
                } else {
                    let p = dir.join(uri);
                    std::fs::read(&p).map_err(|e| format!("glTF: buffer {}: {e}", p.display()))?
                }
            }
        };
        if data.len() < b.length() {
            return Err(format!(
                "glTF: buffer {} holds {} bytes, {} declared",
                b.index(),
                data.len(),
                b.length()
            ));
        }
        buffers.push(data);
    }
    let mut mesh = Mesh::default();
    let add = |m: gltf::Mesh<'_>, xf: DMat4, mesh: &mut Mesh| -> Result<(), String> {
        let nxf = xf.inverse().transpose();
        for p in m.primitives() {
            if p.mode() != gltf::mesh::Mode::Triangles {
                continue;
            }
            let reader = p.reader(|b| buffers.get(b.index()).map(|v| v.as_slice()));
            let Some(pos) = reader.read_positions() else {
                continue;
            };
            let mut one = Mesh {
                positions: pos
                    .map(|q| xf.transform_point3(DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64)))
                    .collect(),
                ..Default::default()
            };
            if let Some(n) = reader.read_normals() {
                one.normals = n
                    .map(|q| {
                        nxf.transform_vector3(DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64))
                    })
                    .collect();
            }
            let idx: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..one.positions.len() as u32).collect(),
            };
            one.triangles = idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            one.check().map_err(|e| format!("glTF: {e}"))?;
            mesh.append(one);
        }
        Ok(())
    };
    let scene = g
        .document
        .default_scene()
        .or_else(|| g.document.scenes().next());
    match scene {
        Some(s) => {
            let mut stack: Vec<(gltf::Node<'_>, DMat4)> =
                s.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
            let mut visited = 0usize;
            while let Some((node, parent)) = stack.pop() {
                visited += 1;
                if visited > 1_000_000 {
                    return Err("glTF: the node graph does not end (a cycle?)".into());
                }
                let m = node.transform().matrix();
                let local = DMat4::from_cols_array_2d(&m.map(|c| c.map(|x| x as f64)));
                let xf = parent * local;
                if let Some(m) = node.mesh() {
                    add(m, xf, &mut mesh)?;
                }
                stack.extend(node.children().map(|c| (c, xf)));
            }
        }
        None => {
            for m in g.document.meshes() {
                add(m, DMat4::IDENTITY, &mut mesh)?;
            }
        }
    }
    Ok(mesh)
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
    if let Err(err) = std::fs::metadata(path) {
        return Err(e(format!("cannot read: {err}")));
    }
    let mut mesh = match format {
        Format::Obj => read_obj(path),
        Format::Ply => read_ply(path),
        Format::Gltf => read_gltf(path),
    }
    .map_err(e)?;
    if mesh.triangles.is_empty() {
        return Err(e("no triangles".into()));
    }
    if mesh.normals.len() != mesh.positions.len() {
        mesh.compute_normals();
    }
    Ok(mesh)
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
}
