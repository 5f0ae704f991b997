//! What shading needs of one scene object at a hit: its shading and geometric normals. Kept
//! beside the store because the out-of-core workload reads it from the geometry file, and the
//! in-memory workload builds the same values from the scene: one definition, equal images.

use crate::geometry::kernels::f32 as k;
use crate::ray::Hit;
use glam::Vec3;
use rtbench_scenes::ShapeRef;

/// The surface of one object, in `f32`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Surface {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    Cone {
        base: Vec3,
        rb: f32,
        apex: Vec3,
        ra: f32,
    },
    Flat {
        normal: Vec3,
    },
    /// A triangle patch: vertex normals interpolated with the hit's barycentrics.
    Smooth {
        normals: [Vec3; 3],
        flat: Vec3,
    },
}

impl Surface {
    pub fn of(shape: ShapeRef<'_>) -> Surface {
        match shape {
            ShapeRef::Sphere { center, radius } => Surface::Sphere {
                center: center.as_vec3(),
                radius: radius as f32,
            },
            ShapeRef::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => Surface::Cone {
                base: base.as_vec3(),
                rb: base_radius as f32,
                apex: apex.as_vec3(),
                ra: apex_radius as f32,
            },
            ShapeRef::Polygon(v) => {
                let v: Vec<Vec3> = v.iter().map(|p| p.as_vec3()).collect();
                Surface::Flat {
                    normal: k::polygon_normal(&v),
                }
            }
            ShapeRef::Patch { vertices, normals } => {
                let v: Vec<Vec3> = vertices.iter().map(|p| p.as_vec3()).collect();
                let flat = k::polygon_normal(&v);
                if normals.len() == 3 {
                    Surface::Smooth {
                        normals: [
                            normals[0].as_vec3(),
                            normals[1].as_vec3(),
                            normals[2].as_vec3(),
                        ],
                        flat,
                    }
                } else {
                    Surface::Flat { normal: flat }
                }
            }
        }
    }

    /// (shading normal, geometric normal) at point `p` of the hit, both unit length, oriented as
    /// the primitive defines them (outward for spheres and cones, by winding for polygons).
    pub fn normals(&self, hit: &Hit, p: Vec3) -> (Vec3, Vec3) {
        match *self {
            Surface::Sphere { center, radius } => {
                let n = k::sphere_normal(p, center, radius).normalize();
                (n, n)
            }
            Surface::Cone { base, rb, apex, ra } => {
                let n = k::cone_normal(p, base, rb, apex, ra);
                (n, n)
            }
            Surface::Flat { normal } => (normal, normal),
            Surface::Smooth { normals, flat } => {
                let w = 1.0 - hit.u - hit.v;
                let n =
                    (normals[0] * w + normals[1] * hit.u + normals[2] * hit.v).normalize_or_zero();
                (if n == Vec3::ZERO { flat } else { n }, flat)
            }
        }
    }
}
