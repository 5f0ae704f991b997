//! Geometry shared by all engines: the ray–primitive kernels (once, in `kernels.rs`) and the
//! prepared `f32` primitives every engine builds from.
//!
//! Preparation keeps spheres and cones as they are (engines intersect them exactly) and cuts
//! polygons into triangles by ear clipping (gears' faces are concave 144-gons: a fan would fill
//! the gaps between the teeth). Patches are triangles already. Each prepared primitive keeps the
//! index of its scene object, so hits name the NFF record.

pub mod aabb;
pub mod dda;
pub mod kernels;
pub mod lanes;
pub mod triangle_simd;

use crate::ray::Ray;
use glam::Vec3;
use kernels::f32 as k;
use rtbench_scenes::{triangulate, Scene, ShapeRef};
use serde::Serialize;
use std::str::FromStr;

/// The ray–triangle test an engine that uses the shared kernels should call.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub enum TriangleTest {
    /// Woop, Benthin and Wald 2013: no gaps or double hits along shared edges.
    #[default]
    Watertight,
    /// Möller and Trumbore 1997: the classic, a little faster.
    Moller,
}

impl FromStr for TriangleTest {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "watertight" => Ok(TriangleTest::Watertight),
            "moller" | "moller-trumbore" => Ok(TriangleTest::Moller),
            _ => Err("expected watertight or moller".into()),
        }
    }
}

/// One prepared primitive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Prim {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    Cone {
        base: Vec3,
        base_radius: f32,
        apex: Vec3,
        apex_radius: f32,
    },
    Triangle([Vec3; 3]),
}

impl Prim {
    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match *self {
            Prim::Sphere { center, radius } => {
                (center - Vec3::splat(radius), center + Vec3::splat(radius))
            }
            Prim::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => {
                let axis = (apex - base).normalize_or_zero();
                let e = (Vec3::ONE - axis * axis).max(Vec3::ZERO);
                let e = Vec3::new(e.x.sqrt(), e.y.sqrt(), e.z.sqrt());
                let (b0, b1) = (base - e * base_radius, base + e * base_radius);
                let (a0, a1) = (apex - e * apex_radius, apex + e * apex_radius);
                (b0.min(a0), b1.max(a1))
            }
            Prim::Triangle([a, b, c]) => (a.min(b).min(c), a.max(b).max(c)),
        }
    }

    pub fn centroid(&self) -> Vec3 {
        let (lo, hi) = self.bounds();
        (lo + hi) * 0.5
    }

    /// The shared kernel for this primitive: (t, u, v) of the nearest hit in (tmin, tmax).
    /// `wt` is the ray's watertight set-up, made once per ray by the caller.
    ///
    /// Always inlined: left to itself the compiler keeps this one out of line, so a traversal
    /// loop compiled for AVX2 (bvh8) called an SSE2 copy through a call; inlined, bvh8 traces
    /// the tessellated scenes 7–10% faster.
    #[inline(always)]
    pub fn intersect(
        &self,
        ray: &Ray,
        test: TriangleTest,
        wt: &k::WatertightRay,
    ) -> Option<(f32, f32, f32)> {
        match *self {
            Prim::Sphere { center, radius } => {
                k::sphere(ray.origin, ray.dir, ray.tmin, ray.tmax, center, radius)
                    .map(|t| (t, 0.0, 0.0))
            }
            Prim::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => k::cone(
                ray.origin,
                ray.dir,
                ray.tmin,
                ray.tmax,
                base,
                base_radius,
                apex,
                apex_radius,
            )
            .map(|t| (t, 0.0, 0.0)),
            Prim::Triangle([a, b, c]) => match test {
                TriangleTest::Watertight => {
                    k::triangle_watertight(ray.origin, wt, ray.tmin, ray.tmax, a, b, c)
                }
                TriangleTest::Moller => {
                    k::triangle_moller(ray.origin, ray.dir, ray.tmin, ray.tmax, a, b, c)
                }
            },
        }
    }
}

/// The prepared scene: primitives in `f32`, each with its scene object.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    pub prims: Vec<Prim>,
    /// `prim_object[i]`: index in `Scene::objects` of the object `prims[i]` came from.
    pub prim_object: Vec<u32>,
    pub bounds_min: Vec3,
    pub bounds_max: Vec3,
}

impl Geometry {
    pub fn from_scene(scene: &Scene) -> Geometry {
        let mut g = Geometry::default();
        let mut prims = Vec::new();
        let mut tris = Vec::new();
        for (i, o) in scene.objects.iter().enumerate() {
            prims.clear();
            prims_of(o.shape.as_ref(), &mut prims, &mut tris);
            for p in &prims {
                g.push(*p, i as u32);
            }
        }
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for p in &g.prims {
            let (a, b) = p.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        g.bounds_min = lo;
        g.bounds_max = hi;
        g
    }

    fn push(&mut self, p: Prim, object: u32) {
        self.prims.push(p);
        self.prim_object.push(object);
    }

    /// Bytes the prepared primitives take (shared by all engines).
    pub fn bytes(&self) -> u64 {
        (self.prims.len() * (std::mem::size_of::<Prim>() + 4)) as u64
    }
}

/// The prepared primitives of one scene object, appended to `out`: spheres and cones as they
/// are, a three-vertex patch as one triangle, other polygons and patches cut into triangles by
/// ear clipping. `tris` is scratch space. One function, so that every engine (and the on-disk
/// store of [`crate::store`]) prepares an object the same way.
pub fn prims_of(shape: ShapeRef<'_>, out: &mut Vec<Prim>, tris: &mut Vec<[usize; 3]>) {
    match shape {
        ShapeRef::Sphere { center, radius } => out.push(Prim::Sphere {
            center: center.as_vec3(),
            radius: radius as f32,
        }),
        ShapeRef::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
        } => out.push(Prim::Cone {
            base: base.as_vec3(),
            base_radius: base_radius as f32,
            apex: apex.as_vec3(),
            apex_radius: apex_radius as f32,
        }),
        ShapeRef::Patch { vertices, .. } if vertices.len() == 3 => out.push(Prim::Triangle([
            vertices[0].as_vec3(),
            vertices[1].as_vec3(),
            vertices[2].as_vec3(),
        ])),
        ShapeRef::Polygon(v) | ShapeRef::Patch { vertices: v, .. } => {
            tris.clear();
            triangulate::triangulate(v, tris);
            for t in tris.iter() {
                out.push(Prim::Triangle([
                    v[t[0]].as_vec3(),
                    v[t[1]].as_vec3(),
                    v[t[2]].as_vec3(),
                ]));
            }
        }
    }
}
