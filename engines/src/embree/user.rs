//! Spheres and open cones/cylinders as one Embree user geometry whose callbacks call the shared
//! kernels, so Embree answers on exactly the primitives the other engines see.
//!
//! The callbacks get ray packets in SoA layout (`RTCRayHitN` / `RTCRayN`: field k of ray i at
//! float k·N + i, the hit's fields after the ray's 12). `rtcIntersect1` calls them with N = 1.
//! They must not unwind (they are `extern "C"`): they use no panicking indexing.

use super::api as sys;
use crate::geometry::kernels::f32 as k;
use crate::geometry::Prim;
use glam::Vec3;
use std::cell::Cell;

/// The primitives of the user geometry, indexed by Embree's primID.
pub struct UserPrims {
    pub prims: Vec<Prim>,
}

thread_local! {
    /// Ray–primitive tests and hits the callbacks made on this thread (read and reset by the
    /// engine after each batch, so no atomics in the callbacks).
    pub static TESTS: Cell<u64> = const { Cell::new(0) };
    pub static HITS: Cell<u64> = const { Cell::new(0) };
}

#[inline(always)]
fn test(p: &Prim, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<f32> {
    TESTS.with(|c| c.set(c.get() + 1));
    let t = match *p {
        Prim::Sphere { center, radius } => k::sphere(o, d, tmin, tmax, center, radius),
        Prim::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
        } => k::cone(o, d, tmin, tmax, base, base_radius, apex, apex_radius),
        // Triangles go to Embree's own triangle geometry, never here.
        Prim::Triangle(_) => None,
    };
    if t.is_some() {
        HITS.with(|c| c.set(c.get() + 1));
    }
    t
}

pub unsafe extern "C" fn bounds(args: *const sys::RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes valid arguments for the duration of the call; `geometryUserPtr` is
    // the `UserPrims` registered with `rtcSetGeometryUserData`, which the engine keeps alive
    // (boxed, unchanged) for as long as the scene exists.
    let (args, data) = unsafe {
        let a = &*args;
        (a, &*(a.geometryUserPtr as *const UserPrims))
    };
    let Some(p) = data.prims.get(args.primID as usize) else {
        return;
    };
    let (lo, hi) = p.bounds();
    // SAFETY: `bounds_o` points to one writable `RTCBounds` (Embree's contract).
    unsafe {
        *args.bounds_o = sys::RTCBounds {
            lower_x: lo.x,
            lower_y: lo.y,
            lower_z: lo.z,
            align0: 0.0,
            upper_x: hi.x,
            upper_y: hi.y,
            upper_z: hi.z,
            align1: 0.0,
        };
    }
}

pub unsafe extern "C" fn intersect(args: *const sys::RTCIntersectFunctionNArguments) {
    // SAFETY: as in `bounds`: valid arguments, and the user pointer is the live `UserPrims`.
    let (a, data) = unsafe {
        let a = &*args;
        (a, &*(a.geometryUserPtr as *const UserPrims))
    };
    let Some(p) = data.prims.get(a.primID as usize) else {
        return;
    };
    let n = a.N as usize;
    let f = a.rayhit as *mut f32;
    for i in 0..n {
        // SAFETY: `valid` holds N ints, `rayhit` an RTCRayHitN of N rays (12·N floats of ray,
        // then the hit: Ng 3·N, u, v, primID, geomID, instID[0] N each, all in bounds for any
        // Embree 4 layout); `context` is a live RTCRayQueryContext whose first field is instID[0].
        unsafe {
            if *a.valid.add(i) == 0 {
                continue;
            }
            let at = |field: usize| *f.add(field * n + i);
            let o = Vec3::new(at(0), at(1), at(2));
            let d = Vec3::new(at(4), at(5), at(6));
            if let Some(t) = test(p, o, d, at(3), at(8)) {
                *f.add(8 * n + i) = t; // tfar
                let h = f.add(12 * n);
                // The geometric normal is not written: rtbench's `Hit` does not carry it and
                // nothing reads it (no filter functions).
                *h.add(3 * n + i) = 0.0; // u
                *h.add(4 * n + i) = 0.0; // v
                *(h.add(5 * n + i) as *mut u32) = a.primID;
                *(h.add(6 * n + i) as *mut u32) = a.geomID;
                *(h.add(7 * n + i) as *mut u32) = (*a.context).instID[0];
            }
        }
    }
}

pub unsafe extern "C" fn occluded(args: *const sys::RTCOccludedFunctionNArguments) {
    // SAFETY: as in `bounds`: valid arguments, and the user pointer is the live `UserPrims`.
    let (a, data) = unsafe {
        let a = &*args;
        (a, &*(a.geometryUserPtr as *const UserPrims))
    };
    let Some(p) = data.prims.get(a.primID as usize) else {
        return;
    };
    let n = a.N as usize;
    let f = a.ray as *mut f32;
    for i in 0..n {
        // SAFETY: `valid` holds N ints and `ray` an RTCRayN of N rays (12·N floats).
        unsafe {
            if *a.valid.add(i) == 0 {
                continue;
            }
            let at = |field: usize| *f.add(field * n + i);
            let o = Vec3::new(at(0), at(1), at(2));
            let d = Vec3::new(at(4), at(5), at(6));
            if test(p, o, d, at(3), at(8)).is_some() {
                // Embree's "occluded" mark.
                *f.add(8 * n + i) = f32::NEG_INFINITY;
            }
        }
    }
}
