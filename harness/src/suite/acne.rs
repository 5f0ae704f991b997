//! Self-intersection ("acne") under the workload's policy (`trace.rs`: secondary rays start at
//! the hit point moved off the surface along the geometric normal by `OFFSET_REL` × its largest
//! coordinate, tmin = 0).
//!
//! From every hit an engine gives on the primary rays, the secondary rays the workload would
//! spawn are made from the origins `trace.rs` gives them — a reflection ray from above the
//! surface, a transmitted ray (the same direction) from below it, and a shadow ray to every light
//! the surface faces — whatever the material, and traced with the same engine. Directions come
//! from the geometric normal (a smooth patch normal may send a reflection under the flat
//! triangle, which would be the shading's fault, not the offset's). A secondary ray is
//! acne when it hits the surface it starts from: for a flat primitive any hit on it (a ray off a
//! plane cannot meet that plane again), for a sphere or cone a hit on it closer than 1e-4 of its
//! size (a legitimate second hit, e.g. through a sphere, is much further away).
//!
//! The offset grows with the hit point's magnitude, so far from the origin it can outgrow the
//! objects: a ray that starts further off its surface than 1% of the surface's size is counted
//! as *displaced* (its shadow or reflection may skip what lies next to the surface).

use crate::workload::surface::Surfaces;
use crate::workload::trace::{self, offset_origin};
use glam::Vec3;
use rtbench_engines::{Counters, Engine, Hit, Ray};
use rtbench_scenes::{Scene, Shape};
use serde_json::{json, Value};

/// Fraction of a curved primitive's size under which a hit on itself is acne.
const NEAR: f32 = 1e-4;
/// Offset, as a fraction of the object's size, beyond which a secondary ray is displaced.
const DISPLACED: f32 = 1e-2;

#[derive(Clone, Copy, Debug, Default)]
pub struct Acne {
    pub secondary: u64,
    pub acne: u64,
    pub displaced: u64,
}

impl Acne {
    pub fn add(&mut self, o: &Acne) {
        self.secondary += o.secondary;
        self.acne += o.acne;
        self.displaced += o.displaced;
    }
    pub fn rate(&self) -> f64 {
        self.acne as f64 / self.secondary.max(1) as f64
    }
    pub fn to_json(self) -> Value {
        json!({"secondary": self.secondary, "acne": self.acne, "rate": self.rate(),
            "displaced": self.displaced})
    }
}

/// Acne of the secondary rays spawned from `engine`'s hits on `primary`.
pub fn measure(scene: &Scene, engine: &dyn Engine, primary: &[Ray]) -> Acne {
    let surfaces = Surfaces::new(scene);
    // Per object: its size, and whether it is flat.
    let size: Vec<f32> = scene
        .objects
        .iter()
        .map(|o| o.shape.bounds().extent().length() as f32)
        .collect();
    // Per object: flat, or the size under which a hit on itself is acne.
    let near: Vec<Option<f32>> = scene
        .objects
        .iter()
        .zip(&size)
        .map(|(o, s)| match &o.shape {
            Shape::Polygon(_) | Shape::Patch { .. } => None,
            _ => Some(s * NEAR),
        })
        .collect();
    let mut displaced = 0u64;
    let mut counters = Counters::default();
    let mut hits = Vec::new();
    trace::query_all(
        engine.batch_hint(),
        primary,
        &mut hits,
        Hit::MISS,
        &mut counters,
        |r, h, c| engine.intersect(r, h, c),
    );
    let lights: Vec<Vec3> = scene.lights.iter().map(|l| l.position.as_vec3()).collect();
    let (mut rays, mut from) = (Vec::new(), Vec::new());
    for (ray, hit) in primary.iter().zip(&hits) {
        if !hit.is_hit() || !hit.t.is_finite() || hit.object as usize >= near.len() {
            continue;
        }
        let d = ray.dir;
        let p = ray.at(hit.t);
        let (_, mut ng) = surfaces.normals(hit, p);
        if !ng.is_finite() || ng == Vec3::ZERO {
            continue;
        }
        if ng.dot(d) > 0.0 {
            ng = -ng;
        }
        let above = offset_origin(p, ng);
        if (above - p).length() > DISPLACED * size[hit.object as usize] {
            // Every secondary ray of this hit starts that far off.
            displaced += 2 + lights.iter().filter(|lp| ng.dot(**lp - p) > 0.0).count() as u64;
        }
        let r = (d - ng * (2.0 * d.dot(ng))).normalize();
        rays.push(Ray::new(above, r, 0.0, f32::INFINITY));
        rays.push(Ray::new(offset_origin(p, -ng), d, 0.0, f32::INFINITY));
        from.extend([hit.object, hit.object]);
        for lp in &lights {
            if ng.dot(*lp - p) > 0.0 {
                let l = (*lp - p).normalize();
                rays.push(Ray::new(
                    above,
                    l,
                    0.0,
                    (*lp - above).length() * (1.0 - 1e-6),
                ));
                from.push(hit.object);
            }
        }
    }
    let mut second = Vec::new();
    trace::query_all(
        engine.batch_hint(),
        &rays,
        &mut second,
        Hit::MISS,
        &mut counters,
        |r, h, c| engine.intersect(r, h, c),
    );
    let acne = second
        .iter()
        .zip(&from)
        .filter(|(h, &o)| {
            h.is_hit()
                && h.object == o
                && match near[o as usize] {
                    None => true,
                    Some(size) => h.t < size,
                }
        })
        .count();
    Acne {
        secondary: rays.len() as u64,
        acne: acne as u64,
        displaced,
    }
}
