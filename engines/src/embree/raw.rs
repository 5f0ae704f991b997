//! Thin owners of Embree handles (device, scene, geometry), made with embree4-sys directly.
//!
//! ABI note: embree4-sys 0.0.10 is generated from Embree 4.2's headers, and the library is 4.4.
//! The API is the same, but since 4.3 `RTCHit` ends with `instPrimID[RTC_MAX_INSTANCE_LEVEL_COUNT]`
//! (instance arrays, on in default builds), so the C `RTCRayHit` is 96 bytes where the bindings'
//! is 80. Embree writes that field on every hit: [`RayHit`] gives it room. `RTCRayQueryContext`
//! grew the same way, so we never allocate one (null arguments: Embree uses its own), and the
//! callbacks read only its first field (`instID[0]`, where it always was).

use super::api as sys;
use std::collections::HashMap;
use std::ffi::{c_char, c_void, CStr, CString};
use std::ptr::null_mut;
use std::sync::atomic::{AtomicI64, Ordering};
use std::sync::{Mutex, OnceLock};

/// What Embree's callbacks on a device record: memory in use and its peak (from the memory
/// monitor), and the last error message (from the error callback).
#[derive(Default)]
pub struct DeviceState {
    pub bytes: AtomicI64,
    pub peak_bytes: AtomicI64,
    pub last_error: Mutex<Option<String>>,
    /// Held by a build from before its scene is made until it is committed, and by an engine
    /// releasing its scene: the memory monitor's counts then change only for that scene, so a
    /// build reads its own bytes as a difference on a device that other scenes share.
    pub build: Mutex<()>,
}

/// Embree's memory monitor: `bytes` > 0 before an allocation, < 0 after a release. Called from
/// Embree's build threads, hence atomics.
unsafe extern "C" fn memory_monitor(ptr: *mut c_void, bytes: isize, _post: bool) -> bool {
    // SAFETY: `ptr` is the `DeviceState` registered with this callback in `Device::new`; it is
    // boxed (stable address) and outlives the device (see `Device`'s field order and Drop).
    let state = unsafe { &*(ptr as *const DeviceState) };
    let now = state.bytes.fetch_add(bytes as i64, Ordering::Relaxed) + bytes as i64;
    state.peak_bytes.fetch_max(now, Ordering::Relaxed);
    true
}

unsafe extern "C" fn error_callback(ptr: *mut c_void, code: sys::RTCError, msg: *const c_char) {
    // SAFETY: as in `memory_monitor`, `ptr` is the device's live, boxed `DeviceState`.
    let state = unsafe { &*(ptr as *const DeviceState) };
    let text = if msg.is_null() {
        String::new()
    } else {
        // SAFETY: Embree passes a NUL-terminated string valid for the duration of the call.
        unsafe { CStr::from_ptr(msg) }
            .to_string_lossy()
            .into_owned()
    };
    if let Ok(mut e) = state.last_error.lock() {
        *e = Some(format!("{code:?}: {text}"));
    }
}

/// An Embree device with its callbacks' state. Dropping releases the device; `state` is freed
/// only after that (field order), and every scene made on the device must be released first
/// (Embree would otherwise call the monitor later): [`super::engine::EmbreeEngine`] declares its
/// scene before its device.
pub struct Device {
    pub handle: sys::RTCDevice,
    pub state: Box<DeviceState>,
}

impl Device {
    /// A device with configuration `config` (e.g. `threads=1,verbose=0`), with a memory monitor
    /// and an error callback installed.
    pub fn new(config: &str) -> Result<Device, String> {
        let c = CString::new(config)
            .map_err(|_| "the Embree configuration contains a NUL byte".to_string())?;
        // Embree is opened when the first device is made, not when the process starts.
        sys::load()?;
        // SAFETY: `c` is a valid NUL-terminated string that outlives the call; Embree copies
        // what it needs from it.
        let handle = unsafe { sys::rtcNewDevice(c.as_ptr()) };
        if handle.is_null() {
            // SAFETY: a null device asks for the thread's last device-creation error.
            let code = unsafe { sys::rtcGetDeviceError(null_mut()) };
            return Err(format!("rtcNewDevice(\"{config}\") failed: {code:?}"));
        }
        let state = Box::<DeviceState>::default();
        let ptr = &*state as *const DeviceState as *mut c_void;
        // SAFETY: `handle` is a live device. `ptr` points into a Box that `Device` owns and
        // frees only after releasing the device; the callbacks only read it through shared
        // references to atomics and a mutex.
        unsafe {
            sys::rtcSetDeviceMemoryMonitorFunction(handle, Some(memory_monitor), ptr);
            sys::rtcSetDeviceErrorFunction(handle, Some(error_callback), ptr);
        }
        Ok(Device { handle, state })
    }

    /// The process's one device of configuration `config`, made on first use and never released.
    /// Embree configures TBB's thread count once per device: a device
    /// of `threads=1` installs a `tbb::global_control` of one thread, and releasing the last
    /// device (or making another) destroys it. With that limit lifted oneTBB woke a worker
    /// thread that then spun in `sched_yield` for the rest of the process (a whole CPU of system
    /// time, from the first Embree engine dropped on), and on two cores the scheduler stacked the
    /// two trace threads on the other CPU for a fifth to a third of a two-thread trace
    /// (`RTBENCH_SCHED=1` shows it). One device per configuration for the process's life
    /// keeps the limit in place: no worker is ever started for `threads=1`.
    pub fn shared(config: &str) -> Result<&'static Device, String> {
        static DEVICES: OnceLock<Mutex<HashMap<String, &'static Device>>> = OnceLock::new();
        let mut map = DEVICES
            .get_or_init(Mutex::default)
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        if let Some(d) = map.get(config) {
            return Ok(*d);
        }
        let d: &'static Device = Box::leak(Box::new(Device::new(config)?));
        map.insert(config.to_string(), d);
        Ok(d)
    }

    /// `Err` with Embree's code and last message if the device has an error pending (clears it).
    pub fn check(&self, what: &str) -> Result<(), String> {
        // SAFETY: `self.handle` is a live device.
        let code = unsafe { sys::rtcGetDeviceError(self.handle) };
        if code == sys::RTCError::NONE {
            return Ok(());
        }
        let msg = self
            .state
            .last_error
            .lock()
            .ok()
            .and_then(|mut e| e.take())
            .unwrap_or_default();
        Err(format!("{what} failed: {code:?} ({msg})"))
    }

    pub fn property(&self, p: sys::RTCDeviceProperty) -> isize {
        // SAFETY: `self.handle` is a live device; reading a property has no other requirement.
        unsafe { sys::rtcGetDeviceProperty(self.handle, p) }
    }

    pub fn version(&self) -> String {
        format!(
            "{}.{}.{}",
            self.property(sys::RTCDeviceProperty::VERSION_MAJOR),
            self.property(sys::RTCDeviceProperty::VERSION_MINOR),
            self.property(sys::RTCDeviceProperty::VERSION_PATCH)
        )
    }

    /// Bytes Embree holds on this device now, and their peak so far.
    pub fn memory(&self) -> (i64, i64) {
        (
            self.state.bytes.load(Ordering::Relaxed),
            self.state.peak_bytes.load(Ordering::Relaxed),
        )
    }
}

// SAFETY: an Embree device handle may be used from any thread (Embree's API is thread-safe for
// the calls made here: making scenes and geometries, reading properties and errors); the state
// is atomics and mutexes.
unsafe impl Send for Device {}
// SAFETY: see `Send`.
unsafe impl Sync for Device {}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: we own one reference to the device; `state` is still alive here (fields are
        // dropped after `drop`), so callbacks fired by the release find it.
        unsafe { sys::rtcReleaseDevice(self.handle) }
    }
}

/// An owned `RTCScene`.
pub struct Scene(pub sys::RTCScene);

impl Drop for Scene {
    fn drop(&mut self) {
        if self.0.is_null() {
            return;
        }
        // SAFETY: we own one reference to the scene, which is not used after this.
        unsafe { sys::rtcReleaseScene(self.0) }
    }
}

/// An owned `RTCGeometry` (released once attached: the scene keeps its own reference).
pub struct Geometry(pub sys::RTCGeometry);

impl Drop for Geometry {
    fn drop(&mut self) {
        // SAFETY: we own one reference to the geometry, which is not used after this.
        unsafe { sys::rtcReleaseGeometry(self.0) }
    }
}

/// `RTCRayHit` with room for the fields Embree ≥ 4.3 appends to `RTCHit` (see the module
/// notes): 32 spare bytes cover `instPrimID` for up to 8 instance levels.
#[repr(C, align(16))]
pub struct RayHit {
    pub rh: sys::RTCRayHit,
    _tail: [u32; 8],
}

impl RayHit {
    #[inline(always)]
    pub fn new(ray: sys::RTCRay) -> RayHit {
        RayHit {
            rh: sys::RTCRayHit {
                ray,
                hit: sys::RTCHit {
                    Ng_x: 0.0,
                    Ng_y: 0.0,
                    Ng_z: 0.0,
                    u: 0.0,
                    v: 0.0,
                    primID: sys::RTC_INVALID_GEOMETRY_ID,
                    geomID: sys::RTC_INVALID_GEOMETRY_ID,
                    instID: [sys::RTC_INVALID_GEOMETRY_ID],
                },
            },
            _tail: [sys::RTC_INVALID_GEOMETRY_ID; 8],
        }
    }
}

/// Our ray as Embree's: `tnear = tmin`, `tfar = tmax`, every mask bit, time 0.
#[inline(always)]
pub fn rtc_ray(r: &crate::ray::Ray) -> sys::RTCRay {
    sys::RTCRay {
        org_x: r.origin.x,
        org_y: r.origin.y,
        org_z: r.origin.z,
        tnear: r.tmin,
        dir_x: r.dir.x,
        dir_y: r.dir.y,
        dir_z: r.dir.z,
        time: 0.0,
        tfar: r.tmax,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

/// `RTCRayHit8` / `RTCRayHit16` with room for the `instPrimID[1][N]` row Embree ≥ 4.3 appends
/// to the hit (see the module notes; 4.2's bindings end the hit at `instID`).
#[repr(C, align(32))]
pub struct RayHit8 {
    pub rh: sys::RTCRayHit8,
    _tail: [u32; 8],
}

#[repr(C, align(64))]
pub struct RayHit16 {
    pub rh: sys::RTCRayHit16,
    _tail: [u32; 16],
}

macro_rules! packet_fill {
    ($name:ident, $rays:ty, $n:literal) => {
        /// Writes up to N rays into the SoA ray packet `p` and their `valid` mask (-1: live
        /// lane, 0: padding); lanes past `rays.len()` get an empty segment.
        #[inline(always)]
        pub fn $name(rays: &[crate::ray::Ray], p: &mut $rays, valid: &mut [i32; $n]) {
            for i in 0..$n {
                match rays.get(i) {
                    Some(r) => {
                        p.org_x[i] = r.origin.x;
                        p.org_y[i] = r.origin.y;
                        p.org_z[i] = r.origin.z;
                        p.tnear[i] = r.tmin;
                        p.dir_x[i] = r.dir.x;
                        p.dir_y[i] = r.dir.y;
                        p.dir_z[i] = r.dir.z;
                        p.tfar[i] = r.tmax;
                        valid[i] = -1;
                    }
                    None => {
                        p.tnear[i] = 0.0;
                        p.tfar[i] = -1.0;
                        valid[i] = 0;
                    }
                }
                p.time[i] = 0.0;
                p.mask[i] = u32::MAX;
                p.id[i] = 0;
                p.flags[i] = 0;
            }
        }
    };
}
packet_fill!(fill_ray8, sys::RTCRay8, 8);
packet_fill!(fill_ray16, sys::RTCRay16, 16);

impl RayHit8 {
    pub fn new() -> Box<RayHit8> {
        // SAFETY: every field is a plain f32/u32 array, for which all-zero bytes are valid.
        Box::new(unsafe { std::mem::zeroed() })
    }
}

impl RayHit16 {
    pub fn new() -> Box<RayHit16> {
        // SAFETY: as for `RayHit8`.
        Box::new(unsafe { std::mem::zeroed() })
    }
}
