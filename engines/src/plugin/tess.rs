//! Tessellation of the curved primitives a plugin does not take, with the geometric error of
//! each: a sphere as a latitude–longitude mesh (`res` bands, `2·res` sectors, triangle fans at
//! the poles), an open cone as `2·res` planar trapezoids cut into two triangles each.
//!
//! Every vertex lies on the true surface, so the mesh is inside it; the error is the largest
//! distance from a triangle to the surface:
//! - sphere: a triangle with circumradius ρ lies in a plane at distance √(r² − ρ²) from the
//!   centre, so no point of it is deeper than r − √(r² − ρ²) (exact when the circumcentre is
//!   inside the triangle, an upper bound otherwise);
//! - cone: each trapezoid is planar (a ruled surface's two generators), and the chord sags by
//!   r·(1 − cos(π/sectors)) at the larger radius r.

use glam::Vec3;
use std::f32::consts::PI;

/// Largest distance from a tessellated primitive to its surface, absolute and relative to the
/// primitive's (largest) radius.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TessError {
    pub max_abs: f64,
    pub max_rel: f64,
}

impl TessError {
    pub fn merge(&mut self, o: TessError) {
        self.max_abs = self.max_abs.max(o.max_abs);
        self.max_rel = self.max_rel.max(o.max_rel);
    }
}

fn circumradius(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    let (ab, ac) = (b - a, c - a);
    let n = ab.cross(ac);
    let n2 = n.length_squared();
    if n2 == 0.0 {
        return 0.0;
    }
    // |(|ac|² ab − |ab|² ac) × n| / (2 |n|²) … the circumcentre's offset from a.
    let off = (n.cross(ab) * ac.length_squared() + ac.cross(n) * ab.length_squared()) / (2.0 * n2);
    off.length()
}

/// Appends a sphere's triangles to `out`; returns its error.
pub fn sphere(center: Vec3, radius: f32, res: u32, out: &mut Vec<[Vec3; 3]>) -> TessError {
    let bands = res.max(2);
    let sectors = 2 * bands;
    let p = |i: u32, j: u32| -> Vec3 {
        let theta = PI * i as f32 / bands as f32;
        let phi = 2.0 * PI * (j % sectors) as f32 / sectors as f32;
        center
            + radius
                * Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                )
    };
    let r = radius as f64;
    let mut err = 0.0f64;
    let mut push = |t: [Vec3; 3], out: &mut Vec<[Vec3; 3]>| {
        let rho = circumradius(t[0], t[1], t[2]).min(r);
        err = err.max(r - (r * r - rho * rho).max(0.0).sqrt());
        out.push(t);
    };
    for i in 0..bands {
        for j in 0..sectors {
            let (a, b, c, d) = (p(i, j), p(i, j + 1), p(i + 1, j), p(i + 1, j + 1));
            if i == 0 {
                push([a, d, c], out);
            } else if i + 1 == bands {
                push([a, b, c], out);
            } else {
                push([a, b, d], out);
                push([a, d, c], out);
            }
        }
    }
    TessError {
        max_abs: err,
        max_rel: if r > 0.0 { err / r } else { 0.0 },
    }
}

/// Appends an open cone's triangles to `out`; returns its error.
pub fn cone(
    base: Vec3,
    base_radius: f32,
    apex: Vec3,
    apex_radius: f32,
    res: u32,
    out: &mut Vec<[Vec3; 3]>,
) -> TessError {
    let sectors = 2 * res.max(2);
    let axis = (apex - base).normalize_or_zero();
    let u = axis.any_orthonormal_vector();
    let v = axis.cross(u);
    let ring = |c: Vec3, r: f32, j: u32| {
        let phi = 2.0 * PI * (j % sectors) as f32 / sectors as f32;
        c + r * (phi.cos() * u + phi.sin() * v)
    };
    for j in 0..sectors {
        let (b0, b1) = (ring(base, base_radius, j), ring(base, base_radius, j + 1));
        let (a0, a1) = (ring(apex, apex_radius, j), ring(apex, apex_radius, j + 1));
        // A cone narrowing to a point has zero-area triangles at the apex: leave them out.
        if base_radius > 0.0 {
            out.push([b0, b1, a1]);
        }
        if apex_radius > 0.0 {
            out.push([b0, a1, a0]);
        }
    }
    let r = base_radius.max(apex_radius) as f64;
    let sag = r * (1.0 - (std::f64::consts::PI / sectors as f64).cos());
    TessError {
        max_abs: sag,
        max_rel: if r > 0.0 { sag / r } else { 0.0 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_vertices_on_surface_and_error_shrinks() {
        let mut out = Vec::new();
        let c = Vec3::new(1.0, 2.0, 3.0);
        let e8 = sphere(c, 2.0, 8, &mut out);
        assert_eq!(out.len(), 16 * 2 + 16 * 6 * 2);
        for t in &out {
            for p in t {
                assert!(((*p - c).length() - 2.0).abs() < 1e-5);
            }
        }
        let e32 = sphere(c, 2.0, 32, &mut Vec::new());
        assert!(e8.max_rel > 0.01 && e8.max_rel < 0.1, "{e8:?}");
        assert!(e32.max_rel < e8.max_rel / 10.0, "{e32:?} vs {e8:?}");
        // The centre of the largest triangle really is that deep (within the bound).
        let deepest = out
            .iter()
            .map(|t| 2.0 - ((t[0] + t[1] + t[2]) / 3.0 - c).length() as f64)
            .fold(0.0, f64::max);
        assert!(deepest <= e8.max_abs + 1e-6 && deepest > e8.max_abs * 0.5);
    }

    #[test]
    fn cone_sag() {
        let mut out = Vec::new();
        let e = cone(Vec3::ZERO, 1.0, Vec3::Y, 0.5, 4, &mut out);
        assert_eq!(out.len(), 16);
        assert!((e.max_abs - (1.0 - (std::f64::consts::PI / 8.0).cos())).abs() < 1e-9);
        let mut pointed = Vec::new();
        cone(Vec3::ZERO, 1.0, Vec3::Y, 0.0, 4, &mut pointed);
        assert_eq!(pointed.len(), 8);
    }
}
