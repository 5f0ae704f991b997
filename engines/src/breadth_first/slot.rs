//! One ray in memory during the sweep ([`Slot`]), its box test ([`BoxRay`]) and its test of an
//! object's primitives, and what one sweep counts: the per-ray side of seed 000's Algorithm 3.5,
//! shared by the basic grid's registration (`intersect.rs`) and the high-resolution grid's
//! block-wise traversal (`hires/blocks.rs`).

use super::voxels::face_bit;
use crate::engine::Counters;
use crate::geometry::aabb::SlabRay;
use crate::geometry::dda::Dda;
use crate::geometry::kernels::f32::WatertightRay;
use crate::geometry::TriangleTest;
use crate::ray::{Hit, Ray};
use crate::store::ObjectRecord;
use glam::Vec3;

#[inline]
pub(super) fn face_bit_of(entered: u8) -> u8 {
    face_bit((entered / 2) as usize, entered % 2 == 1)
}

/// What one sweep counted.
#[derive(Default)]
pub struct Tally {
    pub prev_skips: u64,
    pub loads: u64,
    /// Geometry records read with their boxes (`lazy=off`, basic layout).
    pub records: u64,
}

/// One ray in memory (seed 000 §1.3's per-ray data).
///
/// Laid out for the sweep: the first 64 bytes (one cache line, the struct being aligned to one)
/// hold all that a visit of [`Work::object`] reads for a ray whose box test fails or is skipped
/// (the box ray, `best_t`, the mailbox, the previous voxel, the any-hit flag); the rest is read
/// only on a box hit or between passes. The size stays what it was with Rust's field order
/// (256 bytes), so the rays a memory budget holds, and with them the passes, do not change.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
pub struct Slot {
    pub(super) boxray: BoxRay,
    /// The t of the nearest hit so far (at first the segment's end): ends the segment still
    /// searched.
    pub(super) best_t: f32,
    /// Last object tested (the mailbox, on the ray's side).
    pub(super) mailbox: u32,
    /// The last voxel registered in the previous pass, and in this one (`[u32::MAX; 3]`: none).
    pub(super) prev: [u32; 3],
    /// `best.is_hit()`, kept beside the mailbox for the any-hit check of every visit.
    pub(super) has_hit: bool,
    /// The walk ended (left the grid or the segment) during registration.
    pub(super) exhausted: bool,
    pub(super) ray: Ray,
    /// Nearest hit so far.
    pub(super) best: Hit,
    /// The walk is swept up to here once this pass's sweep is done.
    pub(super) covered: f32,
    pub(super) id: u32,
    pub(super) last: [u32; 3],
    pub(super) wt: WatertightRay,
    pub(super) dda: Dda,
}

// The visit's fields fill the first cache line and no more; the slot keeps the 256 bytes the
// memory budget counted per ray before this layout.
const _: () = assert!(std::mem::offset_of!(Slot, ray) == 64);
const _: () = assert!(std::mem::size_of::<Slot>() == 256);

/// The ray as the sweep's box test reads it: [`SlabRay`]'s inverse direction and conservative
/// `origin × inverse` terms (the near plane picked by the sign of `rdir`, as `SlabRay::negative`
/// is), and the segment's start.
#[derive(Clone, Copy)]
pub struct BoxRay {
    rdir: [f32; 3],
    org_rdir_near: [f32; 3],
    org_rdir_far: [f32; 3],
    tmin: f32,
}

impl BoxRay {
    pub fn new(ray: &Ray, extent: f32) -> BoxRay {
        let s = SlabRay::new(ray, extent);
        BoxRay {
            rdir: s.rdir.to_array(),
            org_rdir_near: s.org_rdir_near.to_array(),
            org_rdir_far: s.org_rdir_far.to_array(),
            tmin: ray.tmin,
        }
    }

    /// A box's six planes in the order lo x, hi x, lo y, hi y, lo z, hi z: what
    /// [`BoxRay::hits`] takes, made once per box.
    #[inline(always)]
    pub fn planes(lo: Vec3, hi: Vec3) -> [f32; 6] {
        [lo.x, hi.x, lo.y, hi.y, lo.z, hi.z]
    }

    /// [`crate::geometry::aabb::Aabb::slab`]`(self, tmin, tmax).is_some()` for the box of
    /// `planes`: the same answer for every box and every traceable ray ([`Ray::is_traceable`]),
    /// without a NaN test per plane (the sweep makes this test once per ray and object it does not
    /// skip, seed 000 §3.3):
    /// - the near plane of an axis is the upper one where `rdir` is negative, as
    ///   `SlabRay::negative` says; `rdir` is never zero or NaN (`SlabRay::new` clamps tiny
    ///   components), so its sign bit says the same and indexes the plane without a branch;
    /// - each `if x > acc { x } else { acc }` keeps `acc` when `x` is NaN (an overflow's ∞ − ∞),
    ///   as `f32::max` ignores a NaN, and `acc`, starting at tmin or tmax (never NaN for a
    ///   traceable ray), never is one; so no NaN test is made per plane.
    #[inline(always)]
    pub fn hits(&self, planes: &[f32; 6], tmax: f32) -> bool {
        let (mut near, mut far) = (self.tmin, tmax);
        let mut axis = |i: usize| {
            let r = self.rdir[i];
            let n = 2 * i + (r.to_bits() >> 31) as usize;
            let tn = planes[n] * r - self.org_rdir_near[i];
            let tf = planes[n ^ 1] * r - self.org_rdir_far[i];
            near = if tn > near { tn } else { near };
            far = if tf < far { tf } else { far };
        };
        axis(0);
        axis(1);
        axis(2);
        near <= far
    }
}

/// Bytes one ray in memory takes (slot and its registrations), for the memory budget.
pub fn slot_bytes() -> u64 {
    std::mem::size_of::<Slot>() as u64
}

impl Slot {
    /// The ray against object `id`'s primitives, keeping the nearest hit (any hit: the first).
    /// Of two hits at the same t the object with the smaller id is kept, whichever is met
    /// first: which voxel and which pass a ray meets an object in depends on the grid, so
    /// keeping the first would make the image depend on the grid (rings118: one
    /// pixel between the capped and the high-resolution grid).
    #[inline(never)]
    pub(super) fn intersect(
        &mut self,
        id: u32,
        record: &ObjectRecord,
        any: bool,
        test: TriangleTest,
        c: &mut Counters,
    ) {
        let mut seg = self.ray;
        for prim in &record.prims {
            // A hit at exactly best_t is taken from an object of a smaller id: the next float
            // up as the (exclusive) limit. best_t is finite and positive once there is a hit.
            seg.tmax = if self.has_hit && id < self.best.object {
                f32::from_bits(self.best_t.to_bits() + 1)
            } else {
                self.best_t
            };
            c.primitive_tests += 1;
            if let Some((th, u, v)) = prim.intersect(&seg, test, &self.wt) {
                c.primitive_hits += 1;
                self.best_t = th;
                self.best = Hit {
                    t: th,
                    object: id,
                    u,
                    v,
                };
                self.has_hit = true;
                if any {
                    break;
                }
            }
        }
    }
}
