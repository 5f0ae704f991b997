//! Wavefront OBJ through `tobj`. Materials mean nothing to the SPD workload, so an `mtllib` line
//! is never followed: the file named there is not opened at all.

use super::Mesh;
use glam::DVec3;
use std::path::Path;

pub(super) fn read(bytes: &[u8]) -> Result<Mesh, String> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let no_materials = |_: &Path| Err(tobj::LoadError::OpenFileFailed);
    let (models, _materials) = tobj::load_obj_buf(&mut &bytes[..], &opts, no_materials)
        .map_err(|e| format!("OBJ: {e}"))?;
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
