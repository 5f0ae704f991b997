//! gears: SF³ interlocking gears over a reflective ground square (SPD 3.14 `gears.c`, Eric
//! Haines). Each gear is a concave 144-gon top, 144 side rectangles and a 144-gon bottom; every
//! fifth gear (by position) is glass. Five lights.
//!
//! Only polygons are emitted, so the tessellated (`-t`) output is the same as the curved one.

use super::vec::{self, Coord3, Coord4, PI, Z_AXIS};
use super::Output;

/// `TEETH`: teeth per gear (the C requires a multiple of 4).
const TEETH: usize = 36;
/// Vertices of a gear face: four per tooth.
const FACE_VERTS: usize = 4 * TEETH;
/// `OUTER_EDGE_RATIO`: the tooth tips stop short of the full radius so that meshing gears never
/// share a surface.
const OUTER_EDGE_RATIO: f64 = 0.995;
/// `INNER_EDGE_RATIO` and `EDGE_DIFF = 1 - INNER_EDGE_RATIO` (as the C macro computes it).
const INNER_EDGE_RATIO: f64 = 0.9;
const EDGE_DIFF: f64 = 1.0 - INNER_EDGE_RATIO;
/// `DEPTH_RATIO`: gear thickness relative to its width.
const DEPTH_RATIO: f64 = 0.1;

/// def.h's `FRACTION(A)`: `A - (int)A` (truncation toward zero).
fn fraction(a: f64) -> f64 {
    a - a.trunc()
}

/// `create_tooth`: the four face vertices of one tooth, rotated about Z around `center`.
fn create_tooth(
    gear_angle: f64,
    tooth_angle: f64,
    center: &Coord3,
    outer_pt: &Coord3,
    inner_pt: &Coord3,
    edge_pts: &mut [Coord3],
) {
    let corners = [
        (gear_angle - 0.19 * tooth_angle, outer_pt),
        (gear_angle + 0.19 * tooth_angle, outer_pt),
        (gear_angle + 0.3 * tooth_angle, inner_pt),
        (gear_angle + 0.7 * tooth_angle, inner_pt),
    ];
    for (edge, (angle, pt)) in edge_pts.iter_mut().zip(corners) {
        let mx = vec::rotate_matrix(Z_AXIS, angle);
        *edge = vec::add3(&vec::transform_vector(pt, &mx), center);
    }
}

/// `create_gear`: top face, the side rectangles, bottom face (the bottom winds the other way).
fn create_gear(
    out: &mut Output<'_>,
    center: &Coord3,
    offset_angle: f64,
    outer_radius: f64,
    inner_radius: f64,
    thickness: f64,
    gear_pts: &mut [Coord3; FACE_VERTS],
) {
    let mut outer_pt = [outer_radius, 0.0, 0.0];
    let mut inner_pt = [inner_radius, 0.0, 0.0];
    let tooth_angle = 2.0 * PI / TEETH as f64;

    // gear top
    for num_teeth in 0..TEETH {
        let gear_angle = offset_angle + 2.0 * PI * num_teeth as f64 / TEETH as f64;
        let pts = &mut gear_pts[num_teeth * 4..num_teeth * 4 + 4];
        create_tooth(gear_angle, tooth_angle, center, &outer_pt, &inner_pt, pts);
    }
    out.polygon(&gear_pts[..]);

    // teeth sides: one rectangle per face edge, extruded down by the thickness
    for num_side in 0..FACE_VERTS {
        let next_side = (num_side + 1) % FACE_VERTS;
        let a = gear_pts[num_side];
        let b = gear_pts[next_side];
        let side_pts = [
            a,
            [a[0], a[1], a[2] - thickness],
            [b[0], b[1], b[2] - thickness],
            b,
        ];
        out.polygon(&side_pts);
    }

    // gear bottom
    outer_pt[2] = -thickness;
    inner_pt[2] = -thickness;
    for num_teeth in 0..TEETH {
        let gear_angle = offset_angle - 2.0 * PI * num_teeth as f64 / TEETH as f64;
        let pts = &mut gear_pts[num_teeth * 4..num_teeth * 4 + 4];
        create_tooth(gear_angle, -tooth_angle, center, &outer_pt, &inner_pt, pts);
    }
    out.polygon(&gear_pts[..]);
}

/// gears.c `main` after option parsing.
pub fn generate(out: &mut Output<'_>, size_factor: u32) {
    let sf = size_factor as f64;

    // UNC sky blue
    out.background([0.078, 0.361, 0.753]);
    out.viewpoint(
        [-1.1, -2.1, 2.6],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        1.0,
        512,
        512,
    );

    // NFF lights are not scaled (lscale = 1 for OUTPUT_NFF).
    let lscale = 1.0;
    let lights: [Coord4; 5] = [
        [2.0, 4.0, 4.0, lscale],
        [-2.0, 4.0, 3.0, lscale],
        [2.0, -2.5, 2.5, lscale],
        [-1.0, -4.0, 2.0, lscale],
        // just behind the eye
        [-1.111, -2.121, 2.626, lscale],
    ];
    for l in lights {
        out.light(l);
    }

    // ground polygon - off white
    out.color([1.0, 0.85, 0.7], 0.0, 0.3, 0.6, 0.3, 37.0, 0.0, 0.0);
    let ground = [
        [2.0, 2.0, 0.0],
        [-2.0, 2.0, 0.0],
        [-2.0, -2.0, 0.0],
        [2.0, -2.0, 0.0],
    ];
    out.polygon(&ground);

    // `(double)(size_factor-1)` in C: int arithmetic first (SF ≥ 1, so no wrap).
    let outer_radius = 1.0 / (sf - (size_factor as f64 - 1.0) * EDGE_DIFF / 2.0);
    let zero_pt = [-1.0 + outer_radius, -1.0 + outer_radius, 1.0];
    let offset_xy = outer_radius * (2.0 - EDGE_DIFF);
    let offset_z = -1.0 / sf;
    let thickness = f64::min(DEPTH_RATIO, 1.0 / (2.0 * sf));

    let mut gear_pts = [[0.0; 3]; FACE_VERTS];
    let n = size_factor as u64;
    for iz in 0..n {
        let cz = zero_pt[2] + iz as f64 * offset_z;
        for iy in 0..n {
            let cy = zero_pt[1] + iy as f64 * offset_xy;
            for ix in 0..n {
                let cx = zero_pt[0] + ix as f64 * offset_xy;
                let center = [cx, cy, cz];

                // pseudo-random gear color, scaled so its largest component is 1
                let mut gear_color = [
                    0.01 + fraction((ix * 3 + iy * 2 + iz + 1) as f64 * 5.0 / 7.0),
                    0.01 + fraction((iy * 3 + iz * 2 + ix + 1) as f64 * 3.0 / 7.0),
                    0.01 + fraction((iz * 3 + ix * 2 + iy + 1) as f64 * 2.0 / 7.0),
                ];
                // MAX(A,B) = A > B ? A : B
                let mut color_scale = if gear_color[0] > gear_color[1] {
                    gear_color[0]
                } else {
                    gear_color[1]
                };
                color_scale = if color_scale > gear_color[2] {
                    color_scale
                } else {
                    gear_color[2]
                };
                for c in &mut gear_color {
                    *c /= color_scale;
                }
                if (ix * 4 + iy * 2 + iz) % 5 == 0 {
                    out.color(gear_color, 0.0, 0.2, 0.0, 0.0, 0.0, 0.8, 1.1);
                } else {
                    out.color(gear_color, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
                }

                // neighbouring gears are turned half a tooth so that they mesh
                let angle = PI * ((ix + iy + iz) % 2) as f64 / TEETH as f64;
                create_gear(
                    out,
                    &center,
                    angle,
                    OUTER_EDGE_RATIO * outer_radius,
                    (1.0 - EDGE_DIFF) * outer_radius,
                    thickness,
                    &mut gear_pts,
                );
            }
        }
    }
}

/// One ground square plus, per gear, two faces and 144 side rectangles: 146·SF³ + 1.
pub fn object_count(size_factor: u64) -> Option<u64> {
    size_factor.checked_pow(3)?.checked_mul(146)?.checked_add(1)
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
        assert_eq!(object_count(4), Some(9_345));
        assert_eq!(object_count(1), Some(147));
        assert_eq!(object_count(u64::MAX), None);
    }

    #[test]
    fn stream_matches_object_count() {
        for sf in 1..=4 {
            let s = count(sf, CurveFormat::Curves);
            assert_eq!(
                s.counts.objects(),
                object_count(sf as u64).unwrap(),
                "sf {sf}"
            );
            assert_eq!(s.counts.polygon, s.counts.objects());
            assert_eq!(s.lights, 5);
            assert_eq!(s.materials, 1 + (sf as u64).pow(3));
        }
    }

    #[test]
    fn tessellated_triangles() {
        // ground (2) + 64 gears × (2 faces × 142 + 144 sides × 2)
        let s = count(4, CurveFormat::Patches);
        assert_eq!(s.counts.triangles, 36_610);
        assert_eq!(s.counts.objects(), 9_345);
    }
}
