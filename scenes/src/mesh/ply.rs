//! PLY through `ply-rs-bw` (ASCII and binary). The header's counts are held against the data:
//! a file whose data runs out early is refused by the parser, one whose data goes on past the
//! last declared element is refused here, and so is a face of fewer than three vertices (what
//! a shifted binary payload reads as), so a wrong count never silently drops faces.

use super::{fan, Mesh};
use glam::DVec3;
use ply_rs_bw::ply::{DefaultElement, Encoding, Property};
use std::io::BufRead;

/// The header's counts against the bytes of data that follow it, before anything is read: an
/// element of no properties, or more elements than the data could hold even at their smallest
/// (a scalar's bytes, a list's count; a line each in ASCII), would have the parser make billions
/// of empty elements out of a few bytes.
fn check_counts(h: &ply_rs_bw::ply::Header, data: usize) -> Result<(), String> {
    use ply_rs_bw::ply::{PropertyType, ScalarType};
    let size = |t: &ScalarType| match t {
        ScalarType::Char | ScalarType::UChar => 1u64,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    };
    let mut need = 0u64;
    for e in h.elements.values() {
        if e.count > 0 && e.properties.is_empty() {
            return Err(format!(
                "PLY: element '{}' has {} entries and no properties",
                e.name, e.count
            ));
        }
        let least = match h.encoding {
            // A value and its separator, or the line's end.
            Encoding::Ascii => 2 * e.properties.len() as u64,
            _ => e
                .properties
                .values()
                .map(|p| match &p.data_type {
                    PropertyType::Scalar(t) => size(t),
                    PropertyType::List(count, _) => size(count),
                })
                .sum(),
        };
        need = need.saturating_add((e.count as u64).saturating_mul(least));
    }
    if need > data as u64 {
        return Err(format!(
            "PLY: the header's counts need at least {need} bytes of data, the file has {data}"
        ));
    }
    Ok(())
}

fn first_line(e: impl std::fmt::Display) -> String {
    let s = e.to_string();
    format!("PLY: {}", s.lines().next().unwrap_or("unreadable"))
}

pub(super) fn read(bytes: &[u8]) -> Result<Mesh, String> {
    let mut r = ply_rs_bw::parser::Reader::new(bytes);
    let parser = ply_rs_bw::parser::Parser::<DefaultElement>::new();
    let header = parser.read_header(&mut r).map_err(first_line)?;
    check_counts(&header, r.get_ref().len())?;
    let payload = parser.read_payload(&mut r, &header).map_err(first_line)?;
    let rest = r.get_mut().fill_buf().map_err(|e| format!("PLY: {e}"))?;
    let trailing = match header.encoding {
        Encoding::Ascii => rest.iter().any(|b| !b.is_ascii_whitespace()),
        _ => !rest.is_empty(),
    };
    if trailing {
        return Err(
            "PLY: data goes on past the elements the header declares (a wrong count?)".into(),
        );
    }
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
    let verts = payload.get("vertex").ok_or("PLY: no 'vertex' element")?;
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
    let faces = payload.get("face").ok_or("PLY: no 'face' element")?;
    for (i, f) in faces.iter().enumerate() {
        let idx = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(list)
            .ok_or_else(|| format!("PLY: face {i} has no vertex_indices list"))?;
        if idx.len() < 3 {
            return Err(format!(
                "PLY: face {i} has {} vertices (a wrong count in the header?)",
                idx.len()
            ));
        }
        fan(&idx, &mut mesh.triangles);
    }
    mesh.check().map_err(|e| format!("PLY: {e}"))?;
    Ok(mesh)
}
