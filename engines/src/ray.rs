//! Rays and hits: plain `f32` structs, as every engine takes and gives them.

use glam::Vec3;

/// A ray segment: points `origin + t·dir` for `tmin < t < tmax`. `dir` need not be unit length
/// (the workload normalises it; t is then a distance).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Ray {
    pub origin: Vec3,
    pub tmin: f32,
    pub dir: Vec3,
    pub tmax: f32,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Ray {
        Ray {
            origin,
            tmin,
            dir,
            tmax,
        }
    }

    /// Origin and direction finite, tmin and tmax not NaN (tmax may be +∞). Engines answer any
    /// other ray as a miss (not occluded), never by indexing with what a NaN test let through.
    #[inline(always)]
    pub fn is_traceable(&self) -> bool {
        self.origin.is_finite()
            && self.dir.is_finite()
            && !self.tmin.is_nan()
            && !self.tmax.is_nan()
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// The closest hit of a ray. `object` indexes `Scene::objects` (the NFF record order); for
/// triangles (patches, and polygons cut into triangles) `u`, `v` are the barycentrics of the hit
/// with respect to the triangle's vertices 1 and 2, which for a patch are its own vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Hit {
    pub t: f32,
    pub object: u32,
    pub u: f32,
    pub v: f32,
}

impl Hit {
    pub const MISS: Hit = Hit {
        t: f32::INFINITY,
        object: u32::MAX,
        u: 0.0,
        v: 0.0,
    };

    pub fn is_hit(&self) -> bool {
        self.object != u32::MAX
    }
}

impl Default for Hit {
    fn default() -> Self {
        Hit::MISS
    }
}
