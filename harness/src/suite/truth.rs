//! The right answer of a case, in f64: brute force over the scene's original primitives with the
//! f64 kernels, on the very `f32` ray the engines get. Two rules the reference engine does not
//! state: objects without a surface (zero area, zero radius, zero height) are never hit, and
//! among hits at the same distance (coplanar overlaps) the lowest object id is the answer.
//!
//! A ray has a known right answer only where the answer does not hang on the last bit: a ray
//! through a sphere's silhouette, along a face or through the rim of a box face is a hit or a
//! miss depending on rounding that neither f32 nor f64 settles. So the answer is also computed for
//! eight copies of the ray moved sideways (along two perpendiculars of its direction and the
//! diagonals between them: a ray along an edge of a box face stays on one of the face's planes
//! when moved along an axis only) by a few f32 units in the last place of its origin; when
//! one of them hits something else (or nothing, or something where the ray does not), the ray is
//! *ambiguous* and scored for validity and leaks only.

use rtbench_engines::geometry::kernels::f64 as k;
use rtbench_engines::Ray;
use rtbench_scenes::{triangulate, triangulate::newell_normal, Scene, Shape};

/// Relative distance within which two hits are the same point (a tie).
const TIE: f64 = 1e-9;

/// Sideways shift of the copies, in units of the ray origin's largest coordinate: 4 f32 ulps.
const SHIFT_REL: f64 = 4.0 * f32::EPSILON as f64;

/// The nearest hit in f64: (object, t), and whether it is stable under a tiny sideways shift.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth {
    pub hit: Option<(u32, f64)>,
    pub stable: bool,
}

/// Whether a primitive has no surface at all.
pub fn is_degenerate(shape: &Shape) -> bool {
    match shape {
        Shape::Sphere { radius, .. } => *radius <= 0.0,
        Shape::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
        } => (*apex - *base).length() == 0.0 || (*base_radius <= 0.0 && *apex_radius <= 0.0),
        Shape::Polygon(v) | Shape::Patch { vertices: v, .. } => newell_normal(v).length() == 0.0,
    }
}

/// A primitive ready for the f64 tests: polygons as their triangles (empty for other shapes).
type Prepared<'a> = Option<(&'a Shape, Vec<[glam::DVec3; 3]>)>;

/// The right answers for `rays` in `scene`.
pub fn answers(scene: &Scene, rays: &[Ray]) -> Vec<Truth> {
    use rayon::prelude::*;
    // Polygons as their triangles (the same ear clipping as every engine's), tested watertight.
    let shapes: Vec<Prepared> = scene
        .objects
        .iter()
        .map(|o| match &o.shape {
            s if is_degenerate(s) => None,
            s @ (Shape::Polygon(v) | Shape::Patch { vertices: v, .. }) => {
                let mut idx = Vec::new();
                triangulate::triangulate(v, &mut idx);
                Some((s, idx.iter().map(|t| [v[t[0]], v[t[1]], v[t[2]]]).collect()))
            }
            s => Some((s, Vec::new())),
        })
        .collect();
    let nearest = |o: glam::DVec3, d: glam::DVec3, tmin: f64, tmax: f64| {
        let wt = k::WatertightRay::new(d);
        let mut best: Option<(u32, f64)> = None;
        for (i, s) in shapes.iter().enumerate() {
            let Some((shape, tris)) = s else { continue };
            let t = match shape {
                Shape::Sphere { center, radius } => k::sphere(o, d, tmin, tmax, *center, *radius),
                Shape::Cone {
                    base,
                    base_radius,
                    apex,
                    apex_radius,
                } => k::cone(o, d, tmin, tmax, *base, *base_radius, *apex, *apex_radius),
                Shape::Polygon(_) | Shape::Patch { .. } => tris
                    .iter()
                    .filter_map(|[a, b, c]| {
                        k::triangle_watertight(o, &wt, tmin, tmax, *a, *b, *c).map(|h| h.0)
                    })
                    .min_by(f64::total_cmp),
            };
            if let Some(t) = t {
                match best {
                    // A tie keeps the lower id (found first); the nearer t is kept.
                    Some((_, bt)) if t >= bt * (1.0 - TIE) => {
                        if t < bt {
                            best = best.map(|(id, _)| (id, t));
                        }
                    }
                    _ => best = Some((i as u32, t)),
                }
            }
        }
        best
    };
    rays.par_iter()
        .map(|r| {
            let o = r.origin.as_dvec3();
            let d = r.dir.as_dvec3();
            let (tmin, tmax) = (r.tmin as f64, r.tmax as f64);
            let hit = nearest(o, d, tmin, tmax);
            let shift = SHIFT_REL * o.abs().max_element().max(1e-30);
            let u = d.any_orthonormal_vector();
            let w = d.normalize().cross(u);
            let (p, q) = ((u + w) * 0.5f64.sqrt(), (u - w) * 0.5f64.sqrt());
            let stable = [u, -u, w, -w, p, -p, q, -q].iter().all(|s| {
                let other = nearest(o + *s * shift, d, tmin, tmax);
                match (hit, other) {
                    (None, None) => true,
                    (Some((a, ta)), Some((b, tb))) => a == b || (ta - tb).abs() <= 1e-5 * ta,
                    _ => false,
                }
            });
            Truth { hit, stable }
        })
        .collect()
}
