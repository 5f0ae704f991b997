//! glTF 2.0 (`.gltf` with external or data-URI buffers, and `.glb`), read on the JSON schema of
//! the `gltf` crate but checked here against the spec before a byte is used: every index names
//! something that exists, POSITION and NORMAL are VEC3 of FLOAT, indices are SCALAR of an
//! unsigned integer type, strides hold their element, and every accessor lies inside its view
//! and every view inside its buffer. A malformed file is a one-line error, never a panic inside
//! a crate nor a silently different mesh. Buffers come only from the GLB binary chunk, data URIs
//! or files inside the mesh's folder (`folder.rs`).

use super::folder;
use super::Mesh;
use glam::{DMat4, DQuat, DVec3};
use gltf::json::accessor::{ComponentType, GenericComponentType, Type};
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked;
use gltf::json::Root;
use std::borrow::Cow;
use std::path::Path;

/// Triangles a file may instance through its node graph: a few kilobytes of JSON could
/// otherwise instance one mesh a million times.
const MAX_TRIANGLES: usize = 1 << 27;

const GLB_JSON: u32 = 0x4E4F_534A;
const GLB_BIN: u32 = 0x004E_4942;

/// The JSON and binary chunks of a GLB container (glTF 2.0 spec, section 4.4).
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let u32_at = |b: &[u8], o: usize| {
        b.get(o..o + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    let (Some(version), Some(total)) = (u32_at(bytes, 4), u32_at(bytes, 8)) else {
        return Err("GLB: shorter than its 12-byte header".into());
    };
    if version != 2 {
        return Err(format!("GLB: version {version}; only 2 is read"));
    }
    let total = total as usize;
    if total < 12 || total > bytes.len() {
        return Err(format!(
            "GLB: the header declares {total} bytes, the file holds {}",
            bytes.len()
        ));
    }
    let body = &bytes[..total];
    let (mut at, mut json, mut bin) = (12usize, None, None);
    while at < body.len() {
        let (Some(len), Some(kind)) = (u32_at(body, at), u32_at(body, at + 4)) else {
            return Err("GLB: a chunk header runs past the end of the file".into());
        };
        let start = at + 8;
        let end = start
            .checked_add(len as usize)
            .filter(|&e| e <= body.len())
            .ok_or("GLB: a chunk runs past the end of the file")?;
        match kind {
            GLB_JSON if json.is_none() => json = Some(&body[start..end]),
            GLB_BIN if bin.is_none() && json.is_some() => bin = Some(&body[start..end]),
            // Chunks of unknown type are skipped, as the spec asks.
            _ => {}
        }
        at = end;
    }
    Ok((json.ok_or("GLB: no JSON chunk")?, bin))
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

/// Every buffer, each exactly its declared length.
fn load_buffers<'a>(
    root: &Root,
    bin: Option<&'a [u8]>,
    dir: &Path,
) -> Result<Vec<Cow<'a, [u8]>>, String> {
    let mut out = Vec::with_capacity(root.buffers.len());
    for (i, b) in root.buffers.iter().enumerate() {
        let len = b.byte_length.0;
        let short = |have: usize| format!("glTF: buffer {i} holds {have} bytes, {len} declared");
        let data: Cow<'a, [u8]> = match &b.uri {
            None => {
                let bin = bin.filter(|_| i == 0).ok_or_else(|| {
                    format!("glTF: buffer {i} has no uri and no GLB binary chunk")
                })?;
                if (bin.len() as u64) < len {
                    return Err(short(bin.len()));
                }
                Cow::Borrowed(&bin[..len as usize])
            }
            Some(uri) if uri.starts_with("data:") => {
                let (_, b64) = uri
                    .split_once(";base64,")
                    .ok_or("glTF: a data URI that is not base64")?;
                let mut v = base64(b64).map_err(|e| format!("glTF: {e}"))?;
                if (v.len() as u64) < len {
                    return Err(short(v.len()));
                }
                v.truncate(len as usize);
                Cow::Owned(v)
            }
            Some(uri) => {
                let p = folder::resolve(dir, uri).map_err(|e| format!("glTF: {e}"))?;
                Cow::Owned(
                    folder::read_exact_len(&p, len)
                        .map_err(|e| format!("glTF: buffer {i}: {e}"))?,
                )
            }
        };
        out.push(data);
    }
    Ok(out)
}

fn type_name(t: Type) -> &'static str {
    match t {
        Type::Scalar => "SCALAR",
        Type::Vec2 => "VEC2",
        Type::Vec3 => "VEC3",
        Type::Vec4 => "VEC4",
        Type::Mat2 => "MAT2",
        Type::Mat3 => "MAT3",
        Type::Mat4 => "MAT4",
    }
}

fn component_size(c: ComponentType) -> usize {
    match c {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

/// The elements of one accessor, checked to lie inside its view.
struct Elements<'a> {
    view: &'a [u8],
    offset: usize,
    stride: usize,
    count: usize,
    component: ComponentType,
}

impl Elements<'_> {
    /// Component `k` of element `i` (in range by construction).
    fn get(&self, i: usize, k: usize) -> f64 {
        let size = component_size(self.component);
        let o = self.offset + i * self.stride + k * size;
        let b = &self.view[o..o + size];
        match self.component {
            ComponentType::I8 => b[0] as i8 as f64,
            ComponentType::U8 => b[0] as f64,
            ComponentType::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            ComponentType::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            ComponentType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            ComponentType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        }
    }

    fn vec3(&self, i: usize) -> DVec3 {
        DVec3::new(self.get(i, 0), self.get(i, 1), self.get(i, 2))
    }

    fn index(&self, i: usize) -> u32 {
        self.get(i, 0) as u32
    }
}

/// Accessor `index` used as `what`, which the spec allows only as `ty` of one of `components`.
fn accessor<'a>(
    root: &Root,
    buffers: &'a [Cow<'a, [u8]>],
    index: usize,
    what: &str,
    ty: Type,
    components: &[ComponentType],
) -> Result<Elements<'a>, String> {
    let a = root.accessors.get(index).ok_or_else(|| {
        format!(
            "{what} names accessor {index}; the file has {}",
            root.accessors.len()
        )
    })?;
    let (Checked::Valid(t), Checked::Valid(GenericComponentType(c))) = (a.type_, a.component_type)
    else {
        return Err(format!(
            "accessor {index} ({what}) has an unknown type or componentType"
        ));
    };
    if t != ty || !components.contains(&c) {
        let allowed: Vec<String> = components
            .iter()
            .map(|c| c.as_gl_enum().to_string())
            .collect();
        return Err(format!(
            "accessor {index} ({what}) is {} of componentType {}; the spec allows {} of {}",
            type_name(t),
            c.as_gl_enum(),
            type_name(ty),
            allowed.join(" or ")
        ));
    }
    if a.sparse.is_some() {
        return Err(format!("accessor {index} ({what}) is sparse; not read"));
    }
    let view_index = a
        .buffer_view
        .ok_or_else(|| format!("accessor {index} ({what}) has no bufferView"))?
        .value();
    let v = root.buffer_views.get(view_index).ok_or_else(|| {
        format!(
            "accessor {index} names bufferView {view_index}; the file has {}",
            root.buffer_views.len()
        )
    })?;
    let buffer = buffers.get(v.buffer.value()).ok_or_else(|| {
        format!(
            "bufferView {view_index} names buffer {}; the file has {}",
            v.buffer.value(),
            buffers.len()
        )
    })?;
    let view_off = v.byte_offset.map_or(0, |o| o.0);
    let view_len = v.byte_length.0;
    let view = view_off
        .checked_add(view_len)
        .filter(|&end| end <= buffer.len() as u64)
        .map(|end| &buffer[view_off as usize..end as usize])
        .ok_or_else(|| {
            format!(
                "bufferView {view_index} ({view_off}+{view_len} bytes) runs past its buffer of {}",
                buffer.len()
            )
        })?;
    let size = component_size(c);
    // Only SCALAR and VEC3 pass the check above.
    let elem = size * if ty == Type::Scalar { 1 } else { 3 };
    let stride = match v.byte_stride {
        Some(s) if s.0 < elem || s.0 > 252 || s.0 % size != 0 => {
            return Err(format!(
                "bufferView {view_index}: byteStride {} does not hold a {}-byte element",
                s.0, elem
            ))
        }
        Some(s) => s.0,
        None => elem,
    };
    let offset = a.byte_offset.map_or(0, |o| o.0);
    if offset % size as u64 != 0 {
        return Err(format!(
            "accessor {index}: byteOffset {offset} is not a multiple of its {size}-byte component"
        ));
    }
    let count = a.count.0;
    let need = if count == 0 {
        Some(0)
    } else {
        (count - 1)
            .checked_mul(stride as u64)
            .and_then(|x| x.checked_add(offset))
            .and_then(|x| x.checked_add(elem as u64))
    };
    match need {
        Some(n) if n <= view.len() as u64 => {}
        _ => {
            return Err(format!(
                "accessor {index} ({what}): {count} elements at offset {offset} overrun its bufferView of {} bytes",
                view.len()
            ))
        }
    }
    Ok(Elements {
        view,
        offset: offset as usize,
        stride,
        count: count as usize,
        component: c,
    })
}

/// One primitive's triangles, in model space.
fn primitive(
    root: &Root,
    buffers: &[Cow<'_, [u8]>],
    p: &gltf::json::mesh::Primitive,
) -> Result<Option<Mesh>, String> {
    match p.mode {
        Checked::Valid(Mode::Triangles) => {}
        Checked::Valid(_) => return Ok(None),
        Checked::Invalid => return Err("a primitive of unknown mode".into()),
    }
    let Some(pos) = p.attributes.get(&Checked::Valid(Semantic::Positions)) else {
        return Ok(None);
    };
    let pos = accessor(
        root,
        buffers,
        pos.value(),
        "POSITION",
        Type::Vec3,
        &[ComponentType::F32],
    )?;
    let mut one = Mesh {
        positions: (0..pos.count).map(|i| pos.vec3(i)).collect(),
        ..Default::default()
    };
    if let Some(n) = p.attributes.get(&Checked::Valid(Semantic::Normals)) {
        let n = accessor(
            root,
            buffers,
            n.value(),
            "NORMAL",
            Type::Vec3,
            &[ComponentType::F32],
        )?;
        if n.count != pos.count {
            return Err(format!(
                "NORMAL has {} elements, POSITION {}",
                n.count, pos.count
            ));
        }
        one.normals = (0..n.count).map(|i| n.vec3(i)).collect();
    }
    let idx: Vec<u32> = match p.indices {
        Some(i) => {
            let i = accessor(
                root,
                buffers,
                i.value(),
                "indices",
                Type::Scalar,
                &[ComponentType::U8, ComponentType::U16, ComponentType::U32],
            )?;
            (0..i.count).map(|k| i.index(k)).collect()
        }
        None => (0..one.positions.len() as u32).collect(),
    };
    if !idx.len().is_multiple_of(3) {
        return Err(format!(
            "a triangle list of {} indices (not a multiple of 3)",
            idx.len()
        ));
    }
    one.triangles = idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    one.check()?;
    Ok(Some(one))
}

/// A node's local transform: its matrix, or translation × rotation × scale.
fn local_transform(n: &gltf::json::Node) -> Result<DMat4, String> {
    let m = match n.matrix {
        Some(m) => DMat4::from_cols_array(&m.map(|x| x as f64)),
        None => {
            let t = n.translation.unwrap_or([0.0; 3]).map(|x| x as f64);
            let s = n.scale.unwrap_or([1.0; 3]).map(|x| x as f64);
            let r = n.rotation.as_ref().map_or([0.0, 0.0, 0.0, 1.0], |q| q.0);
            let q = DQuat::from_xyzw(r[0] as f64, r[1] as f64, r[2] as f64, r[3] as f64);
            let len = q.length();
            if !len.is_finite() || len < 1e-6 {
                return Err("a node's rotation is not a unit quaternion".into());
            }
            DMat4::from_scale_rotation_translation(s.into(), q / len, t.into())
        }
    };
    if !m.is_finite() {
        return Err("a node's transform is not finite".into());
    }
    Ok(m)
}

fn add_mesh(
    root: &Root,
    buffers: &[Cow<'_, [u8]>],
    index: usize,
    xf: DMat4,
    out: &mut Mesh,
) -> Result<(), String> {
    let m = root.meshes.get(index).ok_or_else(|| {
        format!(
            "a node names mesh {index}; the file has {}",
            root.meshes.len()
        )
    })?;
    let nxf = xf.inverse().transpose();
    for p in &m.primitives {
        let Some(mut one) = primitive(root, buffers, p)? else {
            continue;
        };
        if out.triangles.len() + one.triangles.len() > MAX_TRIANGLES {
            return Err(format!(
                "the node graph instances more than {MAX_TRIANGLES} triangles"
            ));
        }
        for q in &mut one.positions {
            *q = xf.transform_point3(*q);
        }
        for n in &mut one.normals {
            *n = nxf.transform_vector3(*n);
        }
        out.append(one);
    }
    Ok(())
}

/// The files besides `path` that reading it would open: its external buffers, each resolved
/// inside the mesh's folder as [`read`] resolves them (data URIs and the GLB chunk open none).
pub(super) fn external_files(path: &Path, bytes: &[u8]) -> Result<Vec<std::path::PathBuf>, String> {
    let json = if bytes.starts_with(b"glTF") {
        split_glb(bytes)?.0
    } else {
        bytes
    };
    let root = Root::from_slice(json).map_err(|e| format!("glTF: {e}"))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    root.buffers
        .iter()
        .filter_map(|b| b.uri.as_deref())
        .filter(|uri| !uri.starts_with("data:"))
        .map(|uri| folder::resolve(dir, uri).map_err(|e| format!("glTF: {e}")))
        .collect()
}

pub(super) fn read(path: &Path, bytes: &[u8]) -> Result<Mesh, String> {
    let (json, bin) = if bytes.starts_with(b"glTF") {
        split_glb(bytes)?
    } else {
        (bytes, None)
    };
    let root = Root::from_slice(json).map_err(|e| format!("glTF: {e}"))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let buffers = load_buffers(&root, bin, dir)?;
    let scene = match root.scene {
        Some(s) => Some(root.scenes.get(s.value()).ok_or_else(|| {
            format!(
                "glTF: scene {} named; the file has {}",
                s.value(),
                root.scenes.len()
            )
        })?),
        None => root.scenes.first(),
    };
    let mut mesh = Mesh::default();
    let g = |e: String| format!("glTF: {e}");
    match scene {
        Some(s) => {
            let mut stack: Vec<(usize, DMat4)> = s
                .nodes
                .iter()
                .map(|n| (n.value(), DMat4::IDENTITY))
                .collect();
            // The spec's node graph is a forest: a node reached twice is a cycle or a node with
            // two parents, either of which would instance its subtree again and again.
            let mut seen = vec![false; root.nodes.len()];
            while let Some((index, parent)) = stack.pop() {
                let node = root.nodes.get(index).ok_or_else(|| {
                    format!(
                        "glTF: node {index} named; the file has {}",
                        root.nodes.len()
                    )
                })?;
                if std::mem::replace(&mut seen[index], true) {
                    return Err(format!(
                        "glTF: node {index} is reached twice (a cycle, or two parents)"
                    ));
                }
                let xf = parent * local_transform(node).map_err(g)?;
                if let Some(m) = node.mesh {
                    add_mesh(&root, &buffers, m.value(), xf, &mut mesh).map_err(g)?;
                }
                if let Some(children) = &node.children {
                    stack.extend(children.iter().map(|c| (c.value(), xf)));
                }
            }
        }
        None => {
            for m in 0..root.meshes.len() {
                add_mesh(&root, &buffers, m, DMat4::IDENTITY, &mut mesh).map_err(g)?;
            }
        }
    }
    Ok(mesh)
}
