//! balls ("sphereflake"), ported from SPD 3.14's balls.c: a sphere with nine spheres of a third
//! its radius around it, recursively, `size_factor` levels deep; a beige floor square and three
//! lights.
//!
//! Spheres: sum over k = 0..=SF of 9^k (SF 4: 7,381), plus the floor polygon. The C floor has
//! five vertices, the last repeating the first; `lib_output_polygon` merges them, so it prints
//! as `p 4`.

use super::vec::{self, Coord4, Matrix, Y_AXIS, Z_AXIS};
use super::Output;

/// Primitives in the curved output: the spheres plus the floor polygon.
pub fn object_count(size_factor: u64) -> Option<u64> {
    let mut total: u64 = 1;
    let mut level: u64 = 1;
    for _ in 0..=size_factor {
        total = total.checked_add(level)?;
        level = level.saturating_mul(9);
    }
    // `level` may saturate on the step after the last one added; only sums matter.
    Some(total)
}

/// The C `main` after option parsing.
pub fn generate(out: &mut Output<'_>, size_factor: u32) {
    let radius = 1.0;

    // UNC sky blue.
    out.background([0.078, 0.361, 0.753]);
    out.viewpoint(
        [2.1, 1.3, 1.7],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        0.01,
        512,
        512,
    );

    // NFF does not scale light intensity (lscale = 1).
    let lscale = 1.0;
    out.light([4.0, 3.0, 2.0, lscale]);
    out.light([1.0, -4.0, 4.0, lscale]);
    out.light([-3.0, 1.0, 5.0, lscale]);

    // Floor polygon, beige.
    out.color([1.0, 0.75, 0.33], 0.2, 0.8, 0.0, 0.0, 0.0, 0.0, 1.0);
    let bvec = [12.0 * radius, 12.0 * radius, -radius / 2.0];
    let backg = [
        [bvec[0], bvec[1], bvec[2]],
        [-bvec[0], bvec[1], bvec[2]],
        [-bvec[0], -bvec[1], bvec[2]],
        [bvec[0], -bvec[1], bvec[2]],
        [bvec[0], bvec[1], bvec[2]],
    ];
    out.polygon(&backg);

    // Mirrored spheres.
    out.color([1.0, 0.9, 0.7], 0.0, 0.5, 0.5, 0.5, 37.0, 0.0, 1.0);
    let objset = create_objset();
    let center_pt = [0.0, 0.0, 0.0, radius / 2.0];
    let direction = [0.0, 0.0, 1.0, 1.0 / 3.0];
    output_object(out, &objset, size_factor, center_pt, direction);
}

/// balls.c `output_object`: the sphere, then its nine children, depth first.
fn output_object(
    out: &mut Output<'_>,
    objset: &[Coord4; 9],
    depth: u32,
    center: Coord4,
    direction: Coord4,
) {
    out.sphere(center);
    if depth == 0 {
        return;
    }
    let depth = depth - 1;

    // Rotation taking +Z to `direction`; the 0.9999 tests allow for child directions slightly
    // shorter than 1.
    let mx: Matrix = if direction[2] >= 0.9999 {
        vec::identity_matrix()
    } else if direction[2] <= -0.9999 {
        vec::rotate_matrix(Y_AXIS, vec::PI)
    } else {
        let z_axis = [0.0, 0.0, 1.0];
        let mut axis = vec::cross(&z_axis, &direction);
        vec::normalize_vector(&mut axis);
        let angle = vec::dot(&z_axis, &direction).acos();
        vec::axis_rotate_matrix(&axis, angle)
    };

    let scale = center[3] * (1.0 + direction[3]);
    for set in objset {
        let mut child_pt = vec::transform_coord(set, &mx);
        child_pt[0] = child_pt[0] * scale + center[0];
        child_pt[1] = child_pt[1] * scale + center[1];
        child_pt[2] = child_pt[2] * scale + center[2];
        child_pt[3] = center[3] * direction[3];
        let d = vec::sub3(&child_pt, &center);
        let child_dir = [d[0] / scale, d[1] / scale, d[2] / scale, direction[3]];
        output_object(out, objset, depth, child_pt, child_dir);
    }
}

/// balls.c `create_objset`: the nine unit directions of the children (three trios rotated by
/// 120 degrees about Z).
fn create_objset() -> [Coord4; 9] {
    let dist = 1.0 / 2.0f64.sqrt();
    let mut trio_dir: [Coord4; 3] = [
        [dist, dist, 0.0, 0.0],
        [dist, 0.0, -dist, 0.0],
        [0.0, dist, -dist, 0.0],
    ];
    let mut axis = [1.0, -1.0, 0.0];
    vec::normalize_vector(&mut axis);
    let mx = vec::axis_rotate_matrix(&axis, (2.0 / 6.0f64.sqrt()).asin());
    for t in trio_dir.iter_mut() {
        *t = vec::transform_coord(t, &mx);
    }
    let mut objset = [[0.0; 4]; 9];
    for num_set in 0..3 {
        let mx = vec::rotate_matrix(Z_AXIS, num_set as f64 * 2.0 * vec::PI / 3.0);
        for (num_vert, t) in trio_dir.iter().enumerate() {
            objset[num_set * 3 + num_vert] = vec::transform_coord(t, &mx);
        }
    }
    objset
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::CountingSink;
    use crate::spd::{CurveFormat, Output};

    #[test]
    fn object_counts() {
        assert_eq!(object_count(1), Some(11));
        assert_eq!(object_count(2), Some(92));
        assert_eq!(object_count(4), Some(7_382));
        // The sum up to 9^20 (≈ 1.4e19) still fits 64 bits, the sum up to 9^21 does not.
        assert_eq!(
            object_count(20),
            Some((9u64.pow(20) - 1) / 8 + 9u64.pow(20) + 1)
        );
        assert_eq!(object_count(21), None);
    }

    #[test]
    fn curved_counts_match_object_count() {
        let mut sink = CountingSink::default();
        generate(&mut Output::new(&mut sink, CurveFormat::Curves, 3), 3);
        assert_eq!(sink.counts.sphere, 820);
        assert_eq!(sink.counts.polygon, 1);
        assert_eq!(sink.counts.objects(), object_count(3).unwrap());
    }

    #[test]
    fn tessellated_sf4_triangles() {
        let mut sink = CountingSink::default();
        generate(&mut Output::new(&mut sink, CurveFormat::Patches, 3), 4);
        // 7,381 spheres x 108 patches + the floor quad as 2 triangles.
        assert_eq!(sink.counts.patch, 797_148);
        assert_eq!(sink.counts.triangles, 797_150);
    }
}
