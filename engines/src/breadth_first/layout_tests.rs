//! The sweep's in-core layout changes no answer: the box ray's test answers as the shared slab
//! test for every box and traceable ray (NaN-making overflows included), the registrations
//! grouped by voxel come in the order of the linked lists they replaced, a ray that is not
//! traceable is a miss, and the slots grow once to the rays the budget holds.

use super::slot::{BoxRay, Slot};
use super::voxels::{push_within, Registrations};
use crate::geometry::aabb::{Aabb, SlabRay};
use crate::test_support::{kv, spd};
use crate::{build_engine, Counters, Hit, Ray};
use glam::Vec3;
use rtbench_scenes::spd::Program;

/// A value in [0, 1) from a seeded generator: the same boxes and rays every run.
fn next(s: &mut fastrand::Rng) -> f32 {
    s.f32()
}

#[test]
fn the_box_ray_answers_as_the_shared_slab_test() {
    let mut s = fastrand::Rng::with_seed(0x9e37_79b9_7f4a_7c15);
    let (mut hits, mut misses, mut nan_planes) = (0, 0, 0);
    for i in 0..200_000 {
        let u = &mut s;
        // Scales from a unit scene to coordinates whose products overflow f32 (1e20 · 1e18).
        let scale = [1.0f32, 1e3, 1e20, 1e30][i % 4];
        let mut v = || {
            Vec3::new(
                next(u) * 2.0 - 1.0,
                next(u) * 2.0 - 1.0,
                next(u) * 2.0 - 1.0,
            )
        };
        let lo = v() * scale;
        let mut hi = lo + (v() + Vec3::ONE) * 0.5 * scale;
        if i % 7 == 0 {
            hi.z = lo.z; // flat
        }
        if i % 11 == 0 {
            hi.x = lo.x - scale * 0.01; // empty
        }
        let origin = v() * scale * 2.0;
        let mut dir = (lo + hi) * 0.5 - origin + v() * scale * 0.3;
        // Axis-parallel and nearly so (the inverse is then clamped to ±1e18).
        match i % 5 {
            0 => dir.y = 0.0,
            1 => dir.x = -1e-20,
            _ => {}
        }
        let tmin = [0.0, 1e-4, -1.0][i % 3];
        let tmax = [f32::INFINITY, next(u) * 3.0, 0.5][(i / 3) % 3];
        let ray = Ray::new(origin, dir, tmin, tmax);
        assert!(ray.is_traceable());
        let extent = lo.abs().max(hi.abs()).max(origin.abs()).max_element();
        let slab = SlabRay::new(&ray, extent);
        for a in 0..3 {
            let near = lo[a] * slab.rdir[a] - slab.org_rdir_near[a];
            let far = hi[a] * slab.rdir[a] - slab.org_rdir_far[a];
            nan_planes += (near.is_nan() || far.is_nan()) as u32;
        }
        let want = Aabb::new(lo, hi).slab(&slab, tmin, tmax).is_some();
        let got = BoxRay::new(&ray, extent).hits(&BoxRay::planes(lo, hi), tmax);
        assert_eq!(got, want, "ray {ray:?}, box {lo} {hi}, extent {extent}");
        if want {
            hits += 1;
        } else {
            misses += 1;
        }
    }
    // Both answers, and planes whose distance is NaN (∞ − ∞), were met.
    assert!(
        hits > 20_000 && misses > 20_000,
        "{hits} hits, {misses} misses"
    );
    assert!(nan_planes > 100, "{nan_planes} NaN planes");
}

#[test]
fn registrations_come_grouped_by_voxel_latest_first() {
    let mut r = Registrations::new(5, 8);
    for _pass in 0..2 {
        for (voxel, slot) in [(3, 0), (1, 0), (3, 1), (0, 2), (3, 2), (1, 4)] {
            r.push(voxel, slot);
        }
        r.group();
        assert_eq!(r.count(), 6);
        // A voxel's rays latest first, as a list whose new nodes went in at its head.
        assert_eq!(r.run(3, 3), &[2, 1, 0]);
        assert_eq!(r.run(1, 1), &[4, 0]);
        assert_eq!(r.run(2, 2), &[] as &[u32]);
        assert_eq!(r.run(4, 4), &[] as &[u32]);
        // A run of voxels is their lists one after the other.
        assert_eq!(r.run(0, 4), &[2, 4, 0, 2, 1, 0]);
        r.clear();
        assert_eq!(r.count(), 0);
        assert_eq!(r.run(0, 4), &[] as &[u32]);
    }
}

#[test]
fn a_ray_that_is_not_traceable_is_a_miss() {
    let input = spd(Program::Tetra, 2);
    let e = build_engine("breadth-first", &input, kv(&[])).unwrap();
    let good = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z, 0.0, f32::INFINITY);
    let bad = [
        Ray::new(Vec3::new(f32::NAN, 0.0, 5.0), -Vec3::Z, 0.0, f32::INFINITY),
        Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z, f32::NAN, f32::INFINITY),
        Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z, 0.0, f32::NAN),
        Ray::new(
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::new(0.0, f32::INFINITY, -1.0),
            0.0,
            9.0,
        ),
    ];
    let mut rays = vec![good];
    rays.extend(bad);
    let mut hits = vec![Hit::MISS; rays.len()];
    let mut c = Counters::default();
    e.intersect(&rays, &mut hits, &mut c);
    assert!(hits[0].is_hit(), "the tetrahedron is below the eye");
    assert!(hits[1..].iter().all(|h| *h == Hit::MISS));
    let mut occ = vec![true; rays.len()];
    e.occluded(&rays, &mut occ, &mut c);
    assert_eq!(occ, [true, false, false, false, false]);
    assert_eq!(c.rays, 10);
}

/// The slots' array holds no more than the rays the budget gives it: past its first reservation
/// it grows once to that count (a doubling would copy the old block into one up to twice the
/// budget's, both held at once), and never past it.
#[test]
fn the_slots_grow_once_to_the_capacity_and_no_further() {
    let capacity = 1000;
    let slot = || std::mem::MaybeUninit::<Slot>::zeroed();
    let mut v: Vec<std::mem::MaybeUninit<Slot>> = Vec::with_capacity(64);
    let mut grew = 0;
    let mut cap = v.capacity();
    for _ in 0..capacity {
        push_within(&mut v, slot(), capacity);
        if v.capacity() != cap {
            grew += 1;
            cap = v.capacity();
        }
    }
    assert_eq!((grew, v.capacity()), (1, capacity));
    // Past the bound (no caller goes there) it still pushes, doubling as Vec does: a thousand
    // pushes more take a handful of reservations, not one each.
    for _ in 0..capacity {
        push_within(&mut v, slot(), capacity);
        if v.capacity() != cap {
            grew += 1;
            cap = v.capacity();
        }
    }
    assert_eq!(v.len(), 2 * capacity);
    assert!(grew <= 3, "{grew} reservations");
}
