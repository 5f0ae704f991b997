//! The closed meshes of the watertightness cases, as polygons wound counter-clockwise seen from
//! outside (Newell normals point out): a regular tetrahedron, a UV-tessellated sphere, a capped
//! cone frustum, and a gear whose two faces are concave 144-gons (as SPD gears' are). Every
//! vertex is computed once and shared, so the meshes are closed exactly, in f64 and in f32.

use glam::{DVec2, DVec3};
use std::f64::consts::TAU;

/// A polygon list; orientation as above.
pub type Mesh = Vec<Vec<DVec3>>;

/// Regular tetrahedron with integer vertices (so edge midpoints are exact in f32).
pub fn tetrahedron() -> Mesh {
    let v = [
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ];
    let faces = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]];
    faces
        .iter()
        .map(|f| outward(f.iter().map(|&i| v[i]).collect(), DVec3::ZERO))
        .collect()
}

/// Unit sphere cut into `nlat` bands of `nlon` quads, triangles at the poles.
pub fn uv_sphere(nlat: usize, nlon: usize) -> Mesh {
    let ring = |j: usize| -> Vec<DVec3> {
        let th = std::f64::consts::PI * j as f64 / nlat as f64;
        (0..nlon)
            .map(|i| {
                let ph = TAU * i as f64 / nlon as f64;
                DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())
            })
            .collect()
    };
    let rings: Vec<Vec<DVec3>> = (1..nlat).map(ring).collect();
    let (top, bottom) = (DVec3::Z, -DVec3::Z);
    let mut m = Vec::new();
    for i in 0..nlon {
        let k = (i + 1) % nlon;
        m.push(outward(vec![top, rings[0][i], rings[0][k]], DVec3::ZERO));
        for b in 0..rings.len() - 1 {
            let (r0, r1) = (&rings[b], &rings[b + 1]);
            m.push(outward(vec![r0[i], r1[i], r1[k], r0[k]], DVec3::ZERO));
        }
        let last = &rings[rings.len() - 1];
        m.push(outward(vec![bottom, last[k], last[i]], DVec3::ZERO));
    }
    m
}

/// A cone frustum with both caps: radius `rb` at z = −1, `rt` at z = 1, `n` sides.
pub fn capped_cone(n: usize, rb: f64, rt: f64) -> Mesh {
    let circle = |r: f64, z: f64| -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let a = TAU * i as f64 / n as f64;
                DVec3::new(r * a.cos(), r * a.sin(), z)
            })
            .collect()
    };
    loft(&circle(rb, -1.0), &circle(rt, 1.0))
}

/// A gear: `teeth` teeth of 4 outline vertices each (4·36 = 144, as SPD gears), radii 0.8 and
/// 1, thickness 0.3. Its two faces are concave.
pub fn gear(teeth: usize) -> Mesh {
    let mut outline = Vec::with_capacity(teeth * 4);
    let step = TAU / teeth as f64;
    for k in 0..teeth {
        let a = step * k as f64;
        for (f, r) in [(0.0, 0.8), (0.2, 1.0), (0.5, 1.0), (0.7, 0.8)] {
            let b = a + f * step;
            outline.push(DVec2::new(r * b.cos(), r * b.sin()));
        }
    }
    let lift = |z: f64| -> Vec<DVec3> { outline.iter().map(|p| p.extend(z)).collect() };
    loft(&lift(-0.15), &lift(0.15))
}

/// The closed solid between two loops (counter-clockwise seen from +z, `bottom` below `top`):
/// both loops as faces, and one quad per loop edge.
fn loft(bottom: &[DVec3], top: &[DVec3]) -> Mesh {
    let n = bottom.len();
    let mut m = vec![bottom.iter().rev().copied().collect(), top.to_vec()];
    for i in 0..n {
        let k = (i + 1) % n;
        m.push(vec![bottom[i], bottom[k], top[k], top[i]]);
    }
    m
}

/// `poly` wound so that its normal points away from `inside` (for convex solids).
fn outward(mut poly: Vec<DVec3>, inside: DVec3) -> Vec<DVec3> {
    let n = rtbench_scenes::triangulate::newell_normal(&poly);
    let c = poly.iter().copied().sum::<DVec3>() / poly.len() as f64;
    if n.dot(c - inside) < 0.0 {
        poly.reverse();
    }
    poly
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtbench_scenes::triangulate::newell_normal;

    /// Closed and consistently wound: every directed edge appears once, its reverse once too,
    /// and the signed volume (divergence theorem) is positive.
    fn check_closed(m: &Mesh) {
        let key = |p: DVec3| (p.x.to_bits(), p.y.to_bits(), p.z.to_bits());
        let mut edges = std::collections::HashMap::new();
        let mut volume = 0.0;
        for poly in m {
            for i in 0..poly.len() {
                let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
                *edges.entry((key(a), key(b))).or_insert(0) += 1;
            }
            let n = newell_normal(poly);
            volume += n.dot(poly[0]) / 6.0;
        }
        for ((a, b), c) in &edges {
            assert_eq!(*c, 1);
            assert_eq!(edges.get(&(*b, *a)), Some(&1), "edge without its twin");
        }
        assert!(volume > 0.0, "wound inwards");
    }

    #[test]
    fn meshes_are_closed_and_wound_outwards() {
        check_closed(&tetrahedron());
        check_closed(&uv_sphere(8, 16));
        check_closed(&capped_cone(24, 1.0, 0.4));
        let g = gear(36);
        assert_eq!(g[1].len(), 144);
        check_closed(&g);
    }
}
