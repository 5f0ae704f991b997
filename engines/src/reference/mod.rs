//! `reference`: brute force in double precision on the scene's original primitives. Slow by
//! design: the ground truth for small scenes.
//!
//! Polygons are cut into triangles in f64 (the same ear clipping as the prepared geometry) and
//! tested with the watertight triangle test, so a ray through an edge shared by two polygons or
//! by two triangles of one polygon always finds one of them. (The crossing-number polygon test
//! used before was not consistent between neighbouring polygons, which project on different
//! planes and round the crossing differently: rays aimed at the shared edges of closed meshes
//! leaked through 39 times in 26 461 in `rtbench check --suite hard`.)

use crate::engine::{BuildInput, Counters, Engine, EngineError, EngineInfo, Settings};
use crate::geometry::kernels::f64 as k;
use crate::ray::{Hit, Ray};
use glam::DVec3;
use rtbench_scenes::{triangulate, Shape};

pub fn info() -> EngineInfo {
    EngineInfo {
        name: "reference",
        description:
            "brute force in f64 over the original primitives: ground truth for small scenes",
        available: || Ok(()),
        build,
    }
}

/// A primitive in f64, with what its test needs precomputed (polygon normals).
enum RefPrim {
    Sphere {
        center: DVec3,
        radius: f64,
    },
    Cone {
        base: DVec3,
        rb: f64,
        apex: DVec3,
        ra: f64,
    },
    /// A polygon's triangles; a hit names the polygon, with no barycentrics.
    Polygon(Vec<[DVec3; 3]>),
    Triangle([DVec3; 3]),
}

pub struct Reference {
    prims: Vec<RefPrim>,
}

fn build(input: &BuildInput, settings: Settings) -> Result<Box<dyn Engine>, EngineError> {
    settings.finish()?;
    let prims = input
        .scene
        .objects
        .iter()
        .map(|o| match &o.shape {
            Shape::Sphere { center, radius } => RefPrim::Sphere {
                center: *center,
                radius: *radius,
            },
            Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => RefPrim::Cone {
                base: *base,
                rb: *base_radius,
                apex: *apex,
                ra: *apex_radius,
            },
            Shape::Patch { vertices, .. } if vertices.len() == 3 => {
                RefPrim::Triangle([vertices[0], vertices[1], vertices[2]])
            }
            Shape::Polygon(v) | Shape::Patch { vertices: v, .. } => {
                let mut idx = Vec::new();
                triangulate::triangulate(v, &mut idx);
                RefPrim::Polygon(idx.iter().map(|t| [v[t[0]], v[t[1]], v[t[2]]]).collect())
            }
        })
        .collect();
    Ok(Box::new(Reference { prims }))
}

impl Reference {
    /// Nearest hit over all primitives; with `any`, the first found.
    fn trace(&self, ray: &Ray, any: bool, c: &mut Counters) -> Hit {
        let o = ray.origin.as_dvec3();
        let d = ray.dir.as_dvec3();
        let tmin = ray.tmin as f64;
        let mut tmax = ray.tmax as f64;
        let mut best = Hit::MISS;
        let wt = k::WatertightRay::new(d);
        c.rays += 1;
        for (i, p) in self.prims.iter().enumerate() {
            c.primitive_tests += 1;
            let h = match p {
                RefPrim::Sphere { center, radius } => {
                    k::sphere(o, d, tmin, tmax, *center, *radius).map(|t| (t, 0.0, 0.0))
                }
                RefPrim::Cone { base, rb, apex, ra } => {
                    k::cone(o, d, tmin, tmax, *base, *rb, *apex, *ra).map(|t| (t, 0.0, 0.0))
                }
                RefPrim::Polygon(tris) => {
                    let mut near = None;
                    let mut far = tmax;
                    for [a, b, cc] in tris {
                        if let Some((t, _, _)) =
                            k::triangle_watertight(o, &wt, tmin, far, *a, *b, *cc)
                        {
                            near = Some((t, 0.0, 0.0));
                            far = t;
                        }
                    }
                    near
                }
                RefPrim::Triangle([a, b, cc]) => {
                    k::triangle_watertight(o, &wt, tmin, tmax, *a, *b, *cc)
                }
            };
            if let Some((t, u, v)) = h {
                c.primitive_hits += 1;
                tmax = t;
                best = Hit {
                    t: t as f32,
                    object: i as u32,
                    u: u as f32,
                    v: v as f32,
                };
                if any {
                    break;
                }
            }
        }
        best
    }
}

impl Engine for Reference {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], c: &mut Counters) {
        for (r, h) in rays.iter().zip(hits.iter_mut()) {
            *h = self.trace(r, false, c);
        }
    }

    fn occluded(&self, rays: &[Ray], occluded: &mut [bool], c: &mut Counters) {
        for (r, o) in rays.iter().zip(occluded.iter_mut()) {
            *o = self.trace(r, true, c).is_hit();
        }
    }

    fn structure_bytes(&self) -> u64 {
        0
    }
}
