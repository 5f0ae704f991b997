//! The built `embree` engine: set-up with a few raw calls, tracing with raw `rtcIntersect1` /
//! `rtcOccluded1` (no error check per ray).

use super::api as sys;
use super::config::{Api, EmbreeConfig, Quality};
use super::raw::{self, Device, Geometry, RayHit, Scene};
use super::user::{self, UserPrims};
use crate::engine::{BuildInput, Counters, Engine, EngineError};
use crate::geometry::Prim;
use crate::ray::{Hit, Ray};
use std::collections::BTreeMap;
use std::ffi::c_void;
use std::ptr::null_mut;
use std::time::Instant;

/// geomID of the triangle geometry and of the user geometry (spheres, cones).
const TRIANGLES: u32 = 0;
const USER: u32 = 1;

/// The `embree` engine. The scene is released first (in `Drop`, under the device's build lock:
/// Embree then frees the BVH and reports it to the monitor), then the user primitives the
/// scene's callbacks read. The device is the process's shared one of this configuration
/// ([`Device::shared`]), never released.
pub struct EmbreeEngine {
    scene: Scene,
    _user: Box<UserPrims>,
    device: &'static Device,
    /// primID → scene object, per geomID (`objects[TRIANGLES]`, `objects[USER]`).
    objects: [Vec<u32>; 2],
    stats: BTreeMap<String, f64>,
    structure_bytes: u64,
    api: Api,
}

// SAFETY: after `build` nothing mutates the scene, the device or the user primitives. Embree
// documents `rtcIntersect1`/`rtcOccluded1` on a committed scene as safe to call from any number of
// threads at once; the callbacks read the user primitives only, count into thread-locals, and the
// device's callback state is atomics and a mutex. Moving the handles between threads is allowed
// by Embree (they are plain reference-counted pointers).
unsafe impl Send for EmbreeEngine {}
// SAFETY: see `Send`: every `&self` method only traces rays on the committed scene.
unsafe impl Sync for EmbreeEngine {}

fn build_err(reason: String) -> EngineError {
    EngineError::Build {
        engine: "embree".into(),
        reason,
    }
}

impl EmbreeEngine {
    pub fn build(input: &BuildInput, config: &EmbreeConfig) -> Result<EmbreeEngine, EngineError> {
        let t0 = Instant::now();
        let geo = &input.geometry;
        let device = Device::shared(&config.device_config()).map_err(build_err)?;
        // Until the commit, the monitor counts this scene only: its bytes are the difference.
        let _building = device.state.build.lock().unwrap_or_else(|e| e.into_inner());
        let (bytes_before, _) = device.memory();
        device
            .state
            .peak_bytes
            .store(bytes_before, std::sync::atomic::Ordering::Relaxed);

        // Split the prepared primitives: triangles for Embree, the rest for the user geometry.
        let mut tri_object = Vec::new();
        let mut user_object = Vec::new();
        let mut user_prims = Vec::new();
        let ntri = geo
            .prims
            .iter()
            .filter(|p| matches!(p, Prim::Triangle(_)))
            .count();
        if ntri > (u32::MAX / 3) as usize {
            return Err(build_err(format!(
                "{ntri} triangles: more than Embree's 32-bit indices can address"
            )));
        }
        tri_object.reserve_exact(ntri);

        // SAFETY: `device.handle` is a live device.
        let scene = Scene(unsafe { sys::rtcNewScene(device.handle) });
        device.check("rtcNewScene").map_err(build_err)?;
        let mut flags = sys::RTCSceneFlags::NONE;
        if config.robust {
            flags |= sys::RTCSceneFlags::ROBUST;
        }
        if config.compact {
            flags |= sys::RTCSceneFlags::COMPACT;
        }
        let quality = match config.quality {
            Quality::Low => sys::RTCBuildQuality::LOW,
            Quality::Medium => sys::RTCBuildQuality::MEDIUM,
            Quality::High => sys::RTCBuildQuality::HIGH,
        };
        // SAFETY: `scene.0` is a live scene not yet committed.
        unsafe {
            sys::rtcSetSceneFlags(scene.0, flags);
            sys::rtcSetSceneBuildQuality(scene.0, quality);
        }
        device.check("scene set-up").map_err(build_err)?;

        let mut buffer_bytes = 0u64;
        if ntri > 0 {
            // SAFETY: `device.handle` is a live device.
            let g = Geometry(unsafe {
                sys::rtcNewGeometry(device.handle, sys::RTCGeometryType::TRIANGLE)
            });
            device
                .check("rtcNewGeometry(TRIANGLE)")
                .map_err(build_err)?;
            // SAFETY: `g.0` is a live geometry; Embree returns buffers of the requested item count
            // and stride (or null on failure, checked before use).
            let (vb, ib) = unsafe {
                let vb = sys::rtcSetNewGeometryBuffer(
                    g.0,
                    sys::RTCBufferType::VERTEX,
                    0,
                    sys::RTCFormat::FLOAT3,
                    12,
                    3 * ntri,
                ) as *mut f32;
                let ib = sys::rtcSetNewGeometryBuffer(
                    g.0,
                    sys::RTCBufferType::INDEX,
                    0,
                    sys::RTCFormat::UINT3,
                    12,
                    ntri,
                ) as *mut u32;
                (vb, ib)
            };
            device.check("rtcSetNewGeometryBuffer").map_err(build_err)?;
            if vb.is_null() || ib.is_null() {
                return Err(build_err("Embree gave no triangle buffers".into()));
            }
            // SAFETY: non-null buffers of 3·ntri FLOAT3 vertices and ntri UINT3 triangles, 4-byte
            // aligned (Embree aligns to 16), owned by the geometry and written only here.
            let (verts, idx) = unsafe {
                (
                    std::slice::from_raw_parts_mut(vb, 9 * ntri),
                    std::slice::from_raw_parts_mut(ib, 3 * ntri),
                )
            };
            let mut t = 0usize;
            for (p, &obj) in geo.prims.iter().zip(&geo.prim_object) {
                if let Prim::Triangle(vs) = p {
                    for (j, v) in vs.iter().enumerate() {
                        verts[9 * t + 3 * j..9 * t + 3 * j + 3].copy_from_slice(&v.to_array());
                        idx[3 * t + j] = (3 * t + j) as u32;
                    }
                    tri_object.push(obj);
                    t += 1;
                }
            }
            buffer_bytes += (9 * ntri * 4 + 3 * ntri * 4) as u64;
            // SAFETY: live geometry and scene, on the same device; the scene retains the geometry.
            unsafe {
                sys::rtcCommitGeometry(g.0);
                sys::rtcAttachGeometryByID(scene.0, g.0, TRIANGLES);
            }
            device.check("triangle geometry").map_err(build_err)?;
        }

        for (p, &obj) in geo.prims.iter().zip(&geo.prim_object) {
            if !matches!(p, Prim::Triangle(_)) {
                user_prims.push(*p);
                user_object.push(obj);
            }
        }
        let user = Box::new(UserPrims { prims: user_prims });
        if !user.prims.is_empty() {
            let ptr = &*user as *const UserPrims as *mut c_void;
            // SAFETY: `device.handle` is live. `ptr` points into a Box the engine keeps, unchanged,
            // until after the scene is released (field order); the callbacks only read it.
            unsafe {
                let g = Geometry(sys::rtcNewGeometry(
                    device.handle,
                    sys::RTCGeometryType::USER,
                ));
                device.check("rtcNewGeometry(USER)").map_err(build_err)?;
                sys::rtcSetGeometryUserPrimitiveCount(g.0, user.prims.len() as u32);
                sys::rtcSetGeometryUserData(g.0, ptr);
                sys::rtcSetGeometryBoundsFunction(g.0, Some(user::bounds), ptr);
                sys::rtcSetGeometryIntersectFunction(g.0, Some(user::intersect));
                sys::rtcSetGeometryOccludedFunction(g.0, Some(user::occluded));
                sys::rtcCommitGeometry(g.0);
                sys::rtcAttachGeometryByID(scene.0, g.0, USER);
            }
            device.check("user geometry").map_err(build_err)?;
        }
        let setup_seconds = t0.elapsed().as_secs_f64();

        let t1 = Instant::now();
        // SAFETY: a live scene whose geometries are committed and whose user data is alive.
        unsafe { sys::rtcCommitScene(scene.0) };
        let commit_seconds = t1.elapsed().as_secs_f64();
        device.check("rtcCommitScene").map_err(build_err)?;

        let (bytes_now, peak_now) = device.memory();
        let (embree_bytes, embree_peak) = (bytes_now - bytes_before, peak_now - bytes_before);
        let own_bytes = (tri_object.capacity() + user_object.capacity()) * 4
            + user.prims.capacity() * std::mem::size_of::<Prim>();
        let structure_bytes = embree_bytes.max(0) as u64 + own_bytes as u64;
        let mut stats = BTreeMap::new();
        stats.insert("setup_seconds".into(), setup_seconds);
        stats.insert("commit_seconds".into(), commit_seconds);
        stats.insert("triangles".into(), ntri as f64);
        stats.insert("user_primitives".into(), user.prims.len() as f64);
        stats.insert("embree_bytes".into(), embree_bytes as f64);
        stats.insert("embree_peak_bytes".into(), embree_peak as f64);
        stats.insert("embree_buffer_bytes".into(), buffer_bytes as f64);
        stats.insert("own_bytes".into(), own_bytes as f64);
        stats.insert("threads".into(), config.threads as f64);
        stats.insert(
            "packet_width".into(),
            match config.api {
                Api::Single => 1.0,
                Api::Packet8 => 8.0,
                Api::Packet16 => 16.0,
            },
        );
        stats.insert(
            "embree_version".into(),
            device.property(sys::RTCDeviceProperty::VERSION) as f64,
        );
        Ok(EmbreeEngine {
            scene,
            _user: user,
            device,
            objects: [tri_object, user_object],
            stats,
            structure_bytes,
            api: config.api,
        })
    }

    /// Adds the user-geometry callbacks' counts of this thread to `counters` and resets them.
    fn collect_user_counts(counters: &mut Counters) {
        let tests = user::TESTS.with(|c| c.replace(0));
        let hits = user::HITS.with(|c| c.replace(0));
        if tests > 0 {
            *counters
                .extra
                .entry("user_primitive_tests".into())
                .or_insert(0) += tests;
            *counters
                .extra
                .entry("user_primitive_hits".into())
                .or_insert(0) += hits;
        }
    }
}

impl Drop for EmbreeEngine {
    fn drop(&mut self) {
        // Released under the build lock, so that a build on another thread reads only its own
        // scene's bytes; the user primitives (a later field) are still alive for Embree here.
        let _releasing = self
            .device
            .state
            .build
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        drop(std::mem::replace(&mut self.scene, Scene(null_mut())));
    }
}

/// A packet's valid mask: Embree reads it with aligned vector loads (64 bytes covers 16 lanes).
#[repr(C, align(64))]
struct Valid<const N: usize>([i32; N]);

/// Packet forms of `intersect` and `occluded`: consecutive rays N at a time through
/// `rtcIntersectN` / `rtcOccludedN`, a short last packet masked by `valid`.
macro_rules! packet_queries {
    ($closest:ident, $any:ident, $n:literal, $rh:ty, $fill:path, $isect:path, $occl:path) => {
        fn $closest(&self, rays: &[Ray], hits: &mut [Hit]) {
            let mut p = <$rh>::new();
            let mut valid = Valid([0i32; $n]);
            for (rs, hs) in rays.chunks($n).zip(hits.chunks_mut($n)) {
                $fill(rs, &mut p.rh.ray, &mut valid.0);
                p.rh.hit.geomID = [sys::RTC_INVALID_GEOMETRY_ID; $n];
                p.rh.hit.primID = [sys::RTC_INVALID_GEOMETRY_ID; $n];
                // SAFETY: committed, unchanging scene (see `Sync`); `p` is an aligned SoA packet
                // with room for the hit fields newer Embree versions append; `valid` has N
                // lanes; null arguments select Embree's defaults.
                unsafe { $isect(valid.0.as_ptr(), self.scene.0, &mut p.rh, null_mut()) };
                let hit = &p.rh.hit;
                for (i, h) in hs.iter_mut().enumerate() {
                    *h = match self
                        .objects
                        .get(hit.geomID[i] as usize)
                        .and_then(|m| m.get(hit.primID[i] as usize))
                    {
                        Some(&object) => Hit {
                            t: p.rh.ray.tfar[i],
                            object,
                            u: hit.u[i],
                            v: hit.v[i],
                        },
                        None => Hit::MISS,
                    };
                }
            }
        }

        fn $any(&self, rays: &[Ray], occluded: &mut [bool]) {
            let mut p = <$rh>::new();
            let mut valid = Valid([0i32; $n]);
            for (rs, os) in rays.chunks($n).zip(occluded.chunks_mut($n)) {
                $fill(rs, &mut p.rh.ray, &mut valid.0);
                // SAFETY: as for the closest-hit packet; only the ray part is passed.
                unsafe { $occl(valid.0.as_ptr(), self.scene.0, &mut p.rh.ray, null_mut()) };
                for (i, o) in os.iter_mut().enumerate() {
                    *o = p.rh.ray.tfar[i] == f32::NEG_INFINITY;
                }
            }
        }
    };
}

impl EmbreeEngine {
    packet_queries!(
        intersect8,
        occluded8,
        8,
        raw::RayHit8,
        raw::fill_ray8,
        sys::rtcIntersect8,
        sys::rtcOccluded8
    );
    packet_queries!(
        intersect16,
        occluded16,
        16,
        raw::RayHit16,
        raw::fill_ray16,
        sys::rtcIntersect16,
        sys::rtcOccluded16
    );
}

impl Engine for EmbreeEngine {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], counters: &mut Counters) {
        assert_eq!(rays.len(), hits.len(), "one hit per ray");
        user::TESTS.with(|c| c.set(0));
        user::HITS.with(|c| c.set(0));
        match self.api {
            Api::Single => {}
            Api::Packet8 | Api::Packet16 => {
                if self.api == Api::Packet8 {
                    self.intersect8(rays, hits);
                } else {
                    self.intersect16(rays, hits);
                }
                counters.rays += rays.len() as u64;
                Self::collect_user_counts(counters);
                return;
            }
        }
        for (r, h) in rays.iter().zip(hits.iter_mut()) {
            let mut rh = RayHit::new(raw::rtc_ray(r));
            // SAFETY: the scene is committed and never changed (see `Sync`); `rh` is a properly
            // aligned RTCRayHit with room for the fields newer Embree versions append; null
            // arguments select Embree's defaults.
            unsafe { sys::rtcIntersect1(self.scene.0, &mut rh.rh, null_mut()) };
            let hit = &rh.rh.hit;
            *h = match self
                .objects
                .get(hit.geomID as usize)
                .and_then(|m| m.get(hit.primID as usize))
            {
                Some(&object) => Hit {
                    t: rh.rh.ray.tfar,
                    object,
                    u: hit.u,
                    v: hit.v,
                },
                None => Hit::MISS,
            };
        }
        counters.rays += rays.len() as u64;
        Self::collect_user_counts(counters);
    }

    fn occluded(&self, rays: &[Ray], occluded: &mut [bool], counters: &mut Counters) {
        assert_eq!(rays.len(), occluded.len(), "one answer per ray");
        user::TESTS.with(|c| c.set(0));
        user::HITS.with(|c| c.set(0));
        if self.api != Api::Single {
            if self.api == Api::Packet8 {
                self.occluded8(rays, occluded);
            } else {
                self.occluded16(rays, occluded);
            }
            counters.rays += rays.len() as u64;
            Self::collect_user_counts(counters);
            return;
        }
        for (r, o) in rays.iter().zip(occluded.iter_mut()) {
            let mut ray = raw::rtc_ray(r);
            // SAFETY: committed, unchanging scene; `ray` is a valid RTCRay (its layout is the same
            // in every Embree 4); null arguments select Embree's defaults.
            unsafe { sys::rtcOccluded1(self.scene.0, &mut ray, null_mut()) };
            *o = ray.tfar == f32::NEG_INFINITY;
        }
        counters.rays += rays.len() as u64;
        Self::collect_user_counts(counters);
    }

    fn structure_bytes(&self) -> u64 {
        self.structure_bytes
    }

    fn build_stats(&self) -> BTreeMap<String, f64> {
        self.stats.clone()
    }
}
