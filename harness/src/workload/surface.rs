//! What shading needs at a hit, per scene object: the shading normal (sphere, cone, polygon,
//! smooth patch) and the material. Built once per scene in `f32`.

use glam::Vec3;
use rtbench_engines::geometry::kernels::f32 as k;
use rtbench_engines::Hit;
use rtbench_scenes::{Scene, Shape};

enum SurfaceShape {
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

pub struct Surfaces {
    shapes: Vec<SurfaceShape>,
    pub material: Vec<u32>,
}

impl Surfaces {
    pub fn new(scene: &Scene) -> Surfaces {
        let mut shapes = Vec::with_capacity(scene.objects.len());
        let mut material = Vec::with_capacity(scene.objects.len());
        for o in &scene.objects {
            material.push(o.material);
            shapes.push(match &o.shape {
                Shape::Sphere { center, radius } => SurfaceShape::Sphere {
                    center: center.as_vec3(),
                    radius: *radius as f32,
                },
                Shape::Cone {
                    base,
                    base_radius,
                    apex,
                    apex_radius,
                } => SurfaceShape::Cone {
                    base: base.as_vec3(),
                    rb: *base_radius as f32,
                    apex: apex.as_vec3(),
                    ra: *apex_radius as f32,
                },
                Shape::Polygon(v) => {
                    let v: Vec<Vec3> = v.iter().map(|p| p.as_vec3()).collect();
                    SurfaceShape::Flat {
                        normal: k::polygon_normal(&v),
                    }
                }
                Shape::Patch { vertices, normals } => {
                    let v: Vec<Vec3> = vertices.iter().map(|p| p.as_vec3()).collect();
                    let flat = k::polygon_normal(&v);
                    if normals.len() == 3 {
                        SurfaceShape::Smooth {
                            normals: [
                                normals[0].as_vec3(),
                                normals[1].as_vec3(),
                                normals[2].as_vec3(),
                            ],
                            flat,
                        }
                    } else {
                        SurfaceShape::Flat { normal: flat }
                    }
                }
            });
        }
        Surfaces { shapes, material }
    }

    /// (shading normal, geometric normal) at point `p` of the hit, both unit length, oriented as
    /// the primitive defines them (outward for spheres and cones, by winding for polygons).
    pub fn normals(&self, hit: &Hit, p: Vec3) -> (Vec3, Vec3) {
        match &self.shapes[hit.object as usize] {
            SurfaceShape::Sphere { center, radius } => {
                let n = k::sphere_normal(p, *center, *radius).normalize();
                (n, n)
            }
            SurfaceShape::Cone { base, rb, apex, ra } => {
                let n = k::cone_normal(p, *base, *rb, *apex, *ra);
                (n, n)
            }
            SurfaceShape::Flat { normal } => (*normal, *normal),
            SurfaceShape::Smooth { normals, flat } => {
                let w = 1.0 - hit.u - hit.v;
                let n =
                    (normals[0] * w + normals[1] * hit.u + normals[2] * hit.v).normalize_or_zero();
                (if n == Vec3::ZERO { *flat } else { n }, *flat)
            }
        }
    }
}
