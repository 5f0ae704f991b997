//! tetra, ported from SPD 3.14's tetra.c: a Sierpinski tetrahedron of 4^SF triangles (the scene
//! of Glassner and of Kay & Kajiya), one light.

use super::vec::{Coord3, Coord4};
use super::Output;

/// Triangles in the output: 4^SF.
pub fn object_count(size_factor: u64) -> Option<u64> {
    let exp = u32::try_from(size_factor).ok()?;
    4u64.checked_pow(exp)
}

/// The C `main` after option parsing.
pub fn generate(out: &mut Output<'_>, size_factor: u32) {
    out.background([0.078, 0.361, 0.753]);
    out.viewpoint(
        [1.022846, -3.177154, -2.174512],
        [-0.004103, -0.004103, 0.216539],
        [-0.816497, -0.816497, 0.816497],
        45.0,
        1.0,
        1.0,
        512,
        512,
    );
    out.light([2.0, -18.0, -5.0, 1.0]);
    // Red.
    out.color([1.0, 0.2, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    create_tetra(out, size_factor, [0.0, 0.0, 0.0, 1.0]);
}

/// tetra.c `create_tetra`: at depth 1 (or below: SF 1 goes straight here) the four faces of the
/// tetrahedron inscribed in the cube `center ± center[3]`; otherwise four half-size copies at
/// the alternate cube corners.
fn create_tetra(out: &mut Output<'_>, depth: u32, center: Coord4) {
    // Corners of the cube with x*y*z == 1, in the C loop order (x, then y, then z).
    const DIRS: [[f64; 3]; 4] = [
        [-1.0, -1.0, 1.0],
        [-1.0, 1.0, -1.0],
        [1.0, -1.0, -1.0],
        [1.0, 1.0, 1.0],
    ];
    if depth <= 1 {
        let mut obj_pt: [Coord3; 4] = [[0.0; 3]; 4];
        for (p, d) in obj_pt.iter_mut().zip(DIRS.iter()) {
            *p = [
                center[0] + d[0] * center[3],
                center[1] + d[1] * center[3],
                center[2] + d[2] * center[3],
            ];
        }
        // Faces: 0 1 2, 3 2 1, 2 3 0, 1 0 3 (odd faces reversed).
        for num_face in 0..4 {
            let mut ord = [num_face % 4, (num_face + 1) % 4, (num_face + 2) % 4];
            if num_face % 2 == 1 {
                ord.swap(0, 2);
            }
            let face_pt = [obj_pt[ord[0]], obj_pt[ord[1]], obj_pt[ord[2]]];
            out.polygon(&face_pt);
        }
    } else {
        for d in DIRS.iter() {
            let sub_center = [
                center[0] + d[0] * center[3] / 2.0,
                center[1] + d[1] * center[3] / 2.0,
                center[2] + d[2] * center[3] / 2.0,
                center[3] / 2.0,
            ];
            create_tetra(out, depth - 1, sub_center);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::CountingSink;
    use crate::spd::{CurveFormat, Output};

    #[test]
    fn object_counts() {
        assert_eq!(object_count(1), Some(4));
        assert_eq!(object_count(6), Some(4_096));
        assert_eq!(object_count(31), Some(1 << 62));
        assert_eq!(object_count(32), None);
    }

    #[test]
    fn generated_count_matches() {
        let mut sink = CountingSink::default();
        generate(&mut Output::new(&mut sink, CurveFormat::Curves, 3), 4);
        assert_eq!(sink.counts.polygon, object_count(4).unwrap());
    }
}
