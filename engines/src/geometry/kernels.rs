//! The ray–primitive kernels, written once and instantiated for `f32` (every engine) and `f64`
//! (the reference engine): sphere, open cone/cylinder, triangle (watertight and
//! Möller–Trumbore), and the polygon normal. Polygons are cut into triangles
//! (`rtbench_scenes::triangulate`) and meet rays through the watertight triangle test, in f32
//! and in f64 alike: a crossing-number polygon test is not consistent along edges shared with
//! neighbouring polygons.
//!
//! Every kernel returns the nearest intersection with `tmin < t < tmax`, or `None`. Rays may
//! start inside a sphere or cone (refraction rays do): both surfaces count.

macro_rules! kernels {
    ($T:ty, $V:ty) => {
        use $V as V;
        type T = $T;

        /// Ray–sphere. The discriminant is computed as r² − |oc − (b/a)·d|² (Ray Tracing Gems,
        /// ch. 7), which keeps its precision for rays from far away and for small spheres.
        #[inline]
        pub fn sphere(o: V, d: V, tmin: T, tmax: T, center: V, radius: T) -> Option<T> {
            let oc = o - center;
            let a = d.dot(d);
            let b = oc.dot(d);
            let c = oc.dot(oc) - radius * radius;
            let h = oc - d * (b / a);
            let disc = radius * radius - h.dot(h);
            if disc < 0.0 {
                return None;
            }
            let q = -b - (a * disc).sqrt().copysign(b);
            if q == 0.0 {
                return None;
            }
            let (mut t0, mut t1) = (c / q, q / a);
            if t0 > t1 {
                std::mem::swap(&mut t0, &mut t1);
            }
            if t0 > tmin && t0 < tmax {
                Some(t0)
            } else if t1 > tmin && t1 < tmax {
                Some(t1)
            } else {
                None
            }
        }

        /// Outward unit normal of a sphere at `p`.
        #[inline]
        pub fn sphere_normal(p: V, center: V, radius: T) -> V {
            (p - center) / radius.abs()
        }

        /// Ray–open cone (or cylinder when the radii are equal): the lateral surface between
        /// the base disc (centre `base`, radius `rb`) and the apex disc (`apex`, `ra`), no caps.
        /// Solves |q⊥ + t·d⊥|² = (rb + k·(q·w + t·d·w))² with w the unit axis, k the slope.
        #[inline]
        #[allow(clippy::too_many_arguments)]
        pub fn cone(o: V, d: V, tmin: T, tmax: T, base: V, rb: T, apex: V, ra: T) -> Option<T> {
            // Solve from the ray's point nearest the cone's centre, not from its far-away origin:
            // the quadratic's coefficients then carry no large, cancelling terms (in f32 this
            // took the 99th percentile of the t error on rings and tree from 2e-5 to the level
            // of the other kernels).
            let mid = (base + apex) * 0.5;
            let shift = (mid - o).dot(d) / d.dot(d);
            let o = o + d * shift;
            cone_from(o, d, tmin - shift, tmax - shift, base, rb, apex, ra).map(|t| t + shift)
        }

        #[inline]
        #[allow(clippy::too_many_arguments)]
        fn cone_from(o: V, d: V, tmin: T, tmax: T, base: V, rb: T, apex: V, ra: T) -> Option<T> {
            let axis = apex - base;
            let height = axis.length();
            if height == 0.0 {
                return None;
            }
            let w = axis / height;
            let k = (ra - rb) / height;
            let q0 = o - base;
            let qw = q0.dot(w);
            let dw = d.dot(w);
            let qp = q0 - w * qw;
            let dp = d - w * dw;
            let r0 = rb + k * qw;
            let a = dp.dot(dp) - k * k * dw * dw;
            let b = 2.0 * (qp.dot(dp) - k * r0 * dw);
            let c = qp.dot(qp) - r0 * r0;
            let (t0, t1) = if a.abs() < T::EPSILON * dp.dot(dp).max(1e-30) {
                // Degenerate (ray parallel to a cone generator): one root.
                if b == 0.0 {
                    return None;
                }
                let t = -c / b;
                (t, t)
            } else {
                let disc = b * b - 4.0 * a * c;
                if disc < 0.0 {
                    return None;
                }
                let q = -0.5 * (b + disc.sqrt().copysign(b));
                let (x, y) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
                if x < y {
                    (x, y)
                } else {
                    (y, x)
                }
            };
            for t in [t0, t1] {
                if t > tmin && t < tmax {
                    let y = qw + t * dw;
                    // Inside the segment, and on the nappe whose radius is not negative.
                    if y >= 0.0 && y <= height && rb + k * y >= 0.0 {
                        return Some(t);
                    }
                }
            }
            None
        }

        /// Outward unit normal of an open cone at `p` (gradient of |q⊥|² − r(y)²).
        #[inline]
        pub fn cone_normal(p: V, base: V, rb: T, apex: V, ra: T) -> V {
            let axis = apex - base;
            let height = axis.length();
            let w = axis / height;
            let k = (ra - rb) / height;
            let q = p - base;
            let y = q.dot(w);
            let qp = q - w * y;
            let r = rb + k * y;
            (qp - w * (r * k)).normalize()
        }

        /// Möller–Trumbore 1997. Returns (t, u, v), u and v the barycentrics of v1 and v2.
        #[inline]
        pub fn triangle_moller(
            o: V,
            d: V,
            tmin: T,
            tmax: T,
            v0: V,
            v1: V,
            v2: V,
        ) -> Option<(T, T, T)> {
            let e1 = v1 - v0;
            let e2 = v2 - v0;
            let p = d.cross(e2);
            let det = e1.dot(p);
            if det == 0.0 {
                return None;
            }
            let inv = 1.0 / det;
            let s = o - v0;
            let u = s.dot(p) * inv;
            if !(0.0..=1.0).contains(&u) {
                return None;
            }
            let q = s.cross(e1);
            let v = d.dot(q) * inv;
            if v < 0.0 || u + v > 1.0 {
                return None;
            }
            let t = e2.dot(q) * inv;
            if t > tmin && t < tmax {
                Some((t, u, v))
            } else {
                None
            }
        }

        /// The per-ray set-up of the watertight test: the axis along which `d` is largest
        /// becomes z, and the shear that maps `d` to +z.
        #[derive(Clone, Copy, Debug)]
        pub struct WatertightRay {
            pub kx: usize,
            pub ky: usize,
            pub kz: usize,
            pub sx: T,
            pub sy: T,
            pub sz: T,
        }

        impl WatertightRay {
            #[inline]
            pub fn new(d: V) -> WatertightRay {
                let a = d.abs();
                let kz = if a.x > a.y {
                    if a.x > a.z {
                        0
                    } else {
                        2
                    }
                } else if a.y > a.z {
                    1
                } else {
                    2
                };
                let mut kx = (kz + 1) % 3;
                let mut ky = (kx + 1) % 3;
                if d[kz] < 0.0 {
                    std::mem::swap(&mut kx, &mut ky);
                }
                WatertightRay {
                    kx,
                    ky,
                    kz,
                    sx: d[kx] / d[kz],
                    sy: d[ky] / d[kz],
                    sz: 1.0 / d[kz],
                }
            }
        }

        /// Woop, Benthin and Wald 2013, "Watertight Ray/Triangle Intersection": edges shared by
        /// two triangles are never missed and never hit twice. Returns (t, u, v) as Möller's.
        ///
        /// Always inlined: left to itself the compiler kept it out of line in the grid's walks,
        /// a call per test with the triangle copied to the stack for it.
        ///
        /// The ray's axis order is one of six; the test is written once per order with constant
        /// axes ([`triangle_watertight_axes`]) and chosen by one branch, which follows the ray
        /// and so is predicted. Picking each of the nine vertex coordinates by the ray's axis
        /// indices at run time was a select of up to three values each. Both do the same
        /// arithmetic, so the answers are the same to the bit.
        #[inline(always)]
        pub fn triangle_watertight(
            o: V,
            w: &WatertightRay,
            tmin: T,
            tmax: T,
            v0: V,
            v1: V,
            v2: V,
        ) -> Option<(T, T, T)> {
            match (w.kz, w.kx) {
                (2, 0) => triangle_watertight_axes::<0, 1, 2>(o, w, tmin, tmax, v0, v1, v2),
                (2, _) => triangle_watertight_axes::<1, 0, 2>(o, w, tmin, tmax, v0, v1, v2),
                (0, 1) => triangle_watertight_axes::<1, 2, 0>(o, w, tmin, tmax, v0, v1, v2),
                (0, _) => triangle_watertight_axes::<2, 1, 0>(o, w, tmin, tmax, v0, v1, v2),
                (_, 2) => triangle_watertight_axes::<2, 0, 1>(o, w, tmin, tmax, v0, v1, v2),
                _ => triangle_watertight_axes::<0, 2, 1>(o, w, tmin, tmax, v0, v1, v2),
            }
        }

        /// [`triangle_watertight`] for the ray whose axes are `(KX, KY, KZ)` (`w.kx`, `w.ky`,
        /// `w.kz`; the shear `w.sx`, `w.sy`, `w.sz` is read from `w`).
        #[inline(always)]
        pub fn triangle_watertight_axes<const KX: usize, const KY: usize, const KZ: usize>(
            o: V,
            w: &WatertightRay,
            tmin: T,
            tmax: T,
            v0: V,
            v1: V,
            v2: V,
        ) -> Option<(T, T, T)> {
            debug_assert_eq!((w.kx, w.ky, w.kz), (KX, KY, KZ));
            let a = v0 - o;
            let b = v1 - o;
            let c = v2 - o;
            let ax = a[KX] - w.sx * a[KZ];
            let ay = a[KY] - w.sy * a[KZ];
            let bx = b[KX] - w.sx * b[KZ];
            let by = b[KY] - w.sy * b[KZ];
            let cx = c[KX] - w.sx * c[KZ];
            let cy = c[KY] - w.sy * c[KZ];
            let mut u = cx * by - cy * bx;
            let mut v = ax * cy - ay * cx;
            let mut ww = bx * ay - by * ax;
            if u == 0.0 || v == 0.0 || ww == 0.0 {
                // Fall back to double precision on the edge, as the paper does.
                let (cxd, cyd, bxd, byd, axd, ayd) = (
                    cx as f64, cy as f64, bx as f64, by as f64, ax as f64, ay as f64,
                );
                u = (cxd * byd - cyd * bxd) as T;
                v = (axd * cyd - ayd * cxd) as T;
                ww = (bxd * ayd - byd * axd) as T;
            }
            if (u < 0.0 || v < 0.0 || ww < 0.0) && (u > 0.0 || v > 0.0 || ww > 0.0) {
                return None;
            }
            let det = u + v + ww;
            if det == 0.0 {
                return None;
            }
            let az = w.sz * a[KZ];
            let bz = w.sz * b[KZ];
            let cz = w.sz * c[KZ];
            let t = u * az + v * bz + ww * cz;
            let inv = 1.0 / det;
            let t = t * inv;
            if t > tmin && t < tmax {
                // u, v, ww weigh v0, v1, v2.
                Some((t, v * inv, ww * inv))
            } else {
                None
            }
        }

        /// Unit normal of the plane of a polygon by Newell's method (robust for concave and
        /// slightly non-planar polygons), in the winding order of the vertices.
        pub fn polygon_normal(verts: &[V]) -> V {
            let mut n = V::ZERO;
            for i in 0..verts.len() {
                let a = verts[i];
                let b = verts[(i + 1) % verts.len()];
                n.x += (a.y - b.y) * (a.z + b.z);
                n.y += (a.z - b.z) * (a.x + b.x);
                n.z += (a.x - b.x) * (a.y + b.y);
            }
            n.normalize_or_zero()
        }
    };
}

/// Kernels in single precision, for every engine.
pub mod f32 {
    kernels!(f32, glam::Vec3);
}

/// Kernels in double precision, for the reference engine.
pub mod f64 {
    kernels!(f64, glam::DVec3);
}

#[cfg(test)]
mod tests {
    use glam::{DVec3, Vec3};

    #[test]
    fn sphere_from_outside_and_inside() {
        let t = super::f64::sphere(
            DVec3::new(0.0, 0.0, -5.0),
            DVec3::Z,
            0.0,
            1e30,
            DVec3::ZERO,
            1.0,
        );
        assert!((t.unwrap() - 4.0).abs() < 1e-12);
        let t = super::f64::sphere(DVec3::ZERO, DVec3::Z, 1e-9, 1e30, DVec3::ZERO, 1.0);
        assert!((t.unwrap() - 1.0).abs() < 1e-12);
        assert!(super::f64::sphere(
            DVec3::new(0.0, 2.0, -5.0),
            DVec3::Z,
            0.0,
            1e30,
            DVec3::ZERO,
            1.0
        )
        .is_none());
    }

    #[test]
    fn cylinder_and_cone_are_open() {
        // Cylinder along z from 0 to 2, radius 1: a ray along x through z = 1 hits at x = −1.
        let (b, a) = (DVec3::ZERO, DVec3::new(0.0, 0.0, 2.0));
        let t = super::f64::cone(
            DVec3::new(-5.0, 0.0, 1.0),
            DVec3::X,
            0.0,
            1e30,
            b,
            1.0,
            a,
            1.0,
        );
        assert!((t.unwrap() - 4.0).abs() < 1e-12);
        // Down the axis: no caps, so no hit.
        assert!(super::f64::cone(
            DVec3::new(0.0, 0.0, -5.0),
            DVec3::Z,
            0.0,
            1e30,
            b,
            1.0,
            a,
            1.0
        )
        .is_none());
        // Cone radius 1 at z=0 to 0 at z=2: at z = 1 the radius is 0.5.
        let t = super::f64::cone(
            DVec3::new(-5.0, 0.0, 1.0),
            DVec3::X,
            0.0,
            1e30,
            b,
            1.0,
            a,
            0.0,
        );
        assert!((t.unwrap() - 4.5).abs() < 1e-12);
        // Above the apex nothing.
        assert!(super::f64::cone(
            DVec3::new(-5.0, 0.0, 2.5),
            DVec3::X,
            0.0,
            1e30,
            b,
            1.0,
            a,
            0.0
        )
        .is_none());
    }

    #[test]
    fn triangle_tests_agree_and_watertight_shares_edges() {
        let (v0, v1, v2) = (
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        );
        let o = Vec3::new(0.25, 0.25, -1.0);
        let m = super::f32::triangle_moller(o, Vec3::Z, 0.0, 10.0, v0, v1, v2).unwrap();
        let w = super::f32::triangle_watertight(
            o,
            &super::f32::WatertightRay::new(Vec3::Z),
            0.0,
            10.0,
            v0,
            v1,
            v2,
        )
        .unwrap();
        assert!((m.0 - 1.0).abs() < 1e-6 && (w.0 - 1.0).abs() < 1e-6);
        assert!((m.1 - w.1).abs() < 1e-6 && (m.2 - w.2).abs() < 1e-6);
        // A ray exactly through the shared diagonal of a quad hits exactly one of its halves or
        // both (never neither).
        let v3 = Vec3::new(1.0, 1.0, 0.0);
        let o = Vec3::new(0.5, 0.5, -1.0);
        let wr = super::f32::WatertightRay::new(Vec3::Z);
        let h1 = super::f32::triangle_watertight(o, &wr, 0.0, 10.0, v1, v3, v2).is_some();
        let h2 = super::f32::triangle_watertight(o, &wr, 0.0, 10.0, v0, v1, v2).is_some();
        assert!(h1 || h2);
    }

    #[test]
    fn polygon_normal_follows_the_winding() {
        // An L shape, counter-clockwise seen from +z.
        let l: Vec<DVec3> = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
        assert!((super::f64::polygon_normal(&l) - DVec3::Z).length() < 1e-12);
        let rev: Vec<DVec3> = l.iter().rev().copied().collect();
        assert!((super::f64::polygon_normal(&rev) + DVec3::Z).length() < 1e-12);
    }
}
