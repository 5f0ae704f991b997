//! rings: a pyramid of objects, each six pentagonal rings (spheres joined by cylinders) through
//! the edge midpoints of a dodecahedron, seen from its tip, with a wall behind for shadows
//! (SPD 3.14 `rings.c`, Eric Haines). Three lights.
//!
//! Layer `d` (1..=SF) is a d×d square of objects, each 30 cylinders and 30 spheres.

use super::vec::{self, Coord3, Coord4, PI, X_AXIS, Z_AXIS};
use super::Output;

/// `SPREAD_OUT`: if > 1, succeeding layers spread out more.
const SPREAD_OUT: f64 = 1.0;

/// `create_dodec`: the 30 points of the rings, in a sphere of radius 1 (ring tubes included).
///
/// C quirk: the C writes `vertex[i][W] = 1.0` into an array of `COORD3`, i.e. into the next
/// vertex's X; every such write is overwritten afterwards, so it has no effect and is left out.
fn create_dodec(minor_radius: f64) -> [Coord3; 30] {
    let mut vertex = [[0.0; 3]; 30];
    let scale = 1.0 / (1.0 + minor_radius);

    // one pentagon on the XY plane, starting along +X
    for (num_vertex, v) in vertex.iter_mut().take(5).enumerate() {
        let a = num_vertex as f64 * 2.0 * PI / 5.0;
        *v = [scale * a.cos(), scale * a.sin(), 0.0];
    }

    // the angle between two adjacent dodecahedron faces
    let x_rotation = 2.0 * ((PI / 3.0).cos() / (PI / 5.0).sin()).acos();
    let x_matrix = vec::rotate_matrix(X_AXIS, x_rotation);

    // the other five pentagons: rotate about X, then about Z by 1/10 + N/5 of a turn
    for num_pentagon in 1..6 {
        let z_rotation = PI * (2.0 * (num_pentagon - 1) as f64 + 1.0) / 5.0;
        let z_matrix = vec::rotate_matrix(Z_AXIS, z_rotation);
        for num_vertex in 0..5 {
            let temp = vec::transform_point(&vertex[num_vertex], &x_matrix);
            vertex[5 * num_pentagon + num_vertex] = vec::transform_point(&temp, &z_matrix);
        }
    }
    vertex
}

/// rings.c `main` after option parsing.
pub fn generate(out: &mut Output<'_>, size_factor: u32) {
    // cone and sphere radius
    let radius = 0.07412;

    // spread of the objects
    let spread = 1.0 / (PI / 8.0).sin();
    let (y_diff, xz_diff) = if SPREAD_OUT <= spread {
        (spread / SPREAD_OUT, 1.0)
    } else {
        (1.0, SPREAD_OUT / spread)
    };

    // UNC sky blue (never seen: the wall fills the view)
    out.background([0.078, 0.361, 0.753]);

    let from = [-1.0, -spread, 0.5];
    let at = [from[0], from[1] + 1.0, from[2]];
    out.viewpoint(from, at, [0.0, 0.0, 1.0], 45.0, 1.0, 1.0, 512, 512);

    // NFF lights are not scaled (lscale = 1 for OUTPUT_NFF).
    let lscale = 1.0;
    out.light([3.0, -spread, 3.0, lscale]);
    out.light([-4.0, -spread, 1.0, lscale]);
    out.light([2.0, -spread, -4.0, lscale]);

    // wall polygon - white; just spans the 45 degree view + 1%
    out.color([1.0, 1.0, 1.0], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    // `y_diff * (size_factor + 1)`: int addition first (no wrap for any SF the count allows)
    let wy = y_diff * (size_factor as f64 + 1.0);
    let wxz = 1.01 * (wy - from[1]) * (PI / 8.0).tan();
    let wall = [
        [wxz + from[0], wy, wxz + from[2]],
        [-wxz + from[0], wy, wxz + from[2]],
        [-wxz + from[0], wy, -wxz + from[2]],
        [wxz + from[0], wy, -wxz + from[2]],
    ];
    out.polygon(&wall);

    // ring colors - RGB and complements
    let ring_color: [Coord3; 6] = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 0.0],
    ];

    let dodec = create_dodec(radius);
    let n = size_factor as i64;
    for num_depth in 0..n {
        let oy = y_diff * (num_depth + 1) as f64;
        for num_objz in 0..=num_depth {
            let oz = xz_diff * (2 * num_objz - num_depth) as f64;
            for num_objx in 0..=num_depth {
                let ox = xz_diff * (2 * num_objx - num_depth) as f64;
                let offset = [ox, oy, oz];
                for num_elem in 0..30 {
                    let prev_elem = if num_elem % 5 == 0 {
                        // new ring beginning - output color
                        out.color(ring_color[num_elem / 5], 0.0, 0.5, 0.2, 0.3, 37.0, 0.0, 0.0);
                        num_elem + 4
                    } else {
                        num_elem - 1
                    };
                    let b = vec::add3(&dodec[num_elem], &offset);
                    let a = vec::add3(&dodec[prev_elem], &offset);
                    // radius of osculating cylinders and spheres (no derivation given)
                    let base_pt: Coord4 = [b[0], b[1], b[2], radius];
                    let apex_pt: Coord4 = [a[0], a[1], a[2], radius];
                    out.cylcone(base_pt, apex_pt);
                    out.sphere(base_pt);
                }
            }
        }
    }
}

/// 30 spheres and 30 cylinders per object, Σ d² = SF(SF+1)(2SF+1)/6 objects, plus the wall:
/// 10·SF(SF+1)(2SF+1) + 1.
pub fn object_count(size_factor: u64) -> Option<u64> {
    let sf = size_factor;
    sf.checked_mul(sf.checked_add(1)?)?
        .checked_mul(sf.checked_mul(2)?.checked_add(1)?)?
        .checked_mul(10)?
        .checked_add(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::CountingSink;
    use crate::spd::{CurveFormat, DEFAULT_RESOLUTION};

    fn count(sf: u32, format: CurveFormat) -> CountingSink {
        let mut sink = CountingSink::default();
        let mut out = Output::new(&mut sink, format, DEFAULT_RESOLUTION);
        generate(&mut out, sf);
        sink
    }

    #[test]
    fn object_count_standard() {
        assert_eq!(object_count(7), Some(8_401));
        assert_eq!(object_count(1), Some(61));
        assert_eq!(object_count(u64::MAX / 2), None);
    }

    #[test]
    fn stream_matches_object_count() {
        for sf in 1..=7 {
            let s = count(sf, CurveFormat::Curves);
            assert_eq!(
                s.counts.objects(),
                object_count(sf as u64).unwrap(),
                "sf {sf}"
            );
            let per_kind = 5 * (sf * (sf + 1) * (2 * sf + 1)) as u64;
            assert_eq!(s.counts.sphere, per_kind);
            assert_eq!(s.counts.cone, per_kind);
            assert_eq!(s.counts.polygon, 1);
        }
    }
}
