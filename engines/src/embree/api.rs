//! Embree's C API, loaded when the `embree` engine is first asked for instead of when the
//! process starts: embree4-sys's types and constants as they are, and the functions this engine
//! calls, by the same names and signatures, through pointers looked up once in the library.
//!
//! Why (peak RSS ≤ 3 × structure bytes + 16 MiB): linked, the loader
//! mapped and relocated Embree, its TBB and libstdc++ in every rtbench process, and they were
//! 3.1 MiB of the resident set of a bvh8 render that never calls them (gears4 at 512²,
//! `/proc/PID/smaps`: Embree 1.35 MiB, libstdc++ 1.43, TBB 0.29). No function of
//! embree4-sys is referenced any more, so the linker (`--as-needed`) leaves the library out of
//! the binary's dependencies; the library opened is the one the build found (`build.rs`), then
//! `libembree4.so` on the system's search path.

pub use embree4_sys::*;
use std::ffi::{c_char, c_int, c_uint, c_void};
use std::sync::OnceLock;

/// The library file the build linked against (`build.rs`: `RTBENCH_EMBREE_LIB_DIR`).
const BUILT: &str = env!("RTBENCH_EMBREE_LIB");

/// The functions of Embree this engine calls: each line a name and its C signature, as in
/// embree4-sys. Makes the table of pointers, its loading, and one `unsafe fn` per name that
/// calls through it (shadowing the glob import above).
macro_rules! embree_api {
    ($( fn $name:ident ( $($arg:ident : $ty:ty),* ) $(-> $ret:ty)? ; )*) => {
        #[allow(non_snake_case)]
        struct Api {
            $( $name: unsafe extern "C" fn($($ty),*) $(-> $ret)?, )*
            /// Kept open for the process's life (the pointers above point into it).
            _lib: libloading::Library,
        }

        impl Api {
            /// SAFETY: `lib` must be Embree 4, whose functions have the signatures above.
            #[allow(non_snake_case)]
            unsafe fn from(lib: libloading::Library) -> Result<Api, String> {
                $(
                    // SAFETY: the symbol is Embree's function of this signature (caller).
                    let $name = unsafe {
                        *lib.get::<unsafe extern "C" fn($($ty),*) $(-> $ret)?>(
                            concat!(stringify!($name), "\0").as_bytes(),
                        )
                        .map_err(|e| format!("{}: {e}", stringify!($name)))?
                    };
                )*
                Ok(Api { $( $name, )* _lib: lib })
            }
        }

        $(
            /// Embree's function of this name (see the module).
            ///
            /// # Safety
            /// As Embree's C function; callable only once [`load`] has succeeded.
            #[allow(non_snake_case)]
            #[inline]
            pub unsafe fn $name($($arg: $ty),*) $(-> $ret)? {
                // SAFETY: the caller keeps Embree's contract for this call.
                unsafe { (api().$name)($($arg),*) }
            }
        )*
    };
}

embree_api! {
    fn rtcNewDevice(config: *const c_char) -> RTCDevice;
    fn rtcGetDeviceError(device: RTCDevice) -> RTCError;
    fn rtcReleaseDevice(device: RTCDevice);
    fn rtcSetDeviceErrorFunction(device: RTCDevice, error: RTCErrorFunction, user: *mut c_void);
    fn rtcSetDeviceMemoryMonitorFunction(
        device: RTCDevice,
        monitor: RTCMemoryMonitorFunction,
        user: *mut c_void
    );
    fn rtcGetDeviceProperty(device: RTCDevice, prop: RTCDeviceProperty) -> isize;
    fn rtcNewScene(device: RTCDevice) -> RTCScene;
    fn rtcSetSceneFlags(scene: RTCScene, flags: RTCSceneFlags);
    fn rtcSetSceneBuildQuality(scene: RTCScene, quality: RTCBuildQuality);
    fn rtcCommitScene(scene: RTCScene);
    fn rtcReleaseScene(scene: RTCScene);
    fn rtcNewGeometry(device: RTCDevice, kind: RTCGeometryType) -> RTCGeometry;
    fn rtcSetNewGeometryBuffer(
        geometry: RTCGeometry,
        kind: RTCBufferType,
        slot: c_uint,
        format: RTCFormat,
        stride: usize,
        count: usize
    ) -> *mut c_void;
    fn rtcCommitGeometry(geometry: RTCGeometry);
    fn rtcAttachGeometryByID(scene: RTCScene, geometry: RTCGeometry, id: c_uint);
    fn rtcReleaseGeometry(geometry: RTCGeometry);
    fn rtcSetGeometryUserPrimitiveCount(geometry: RTCGeometry, count: c_uint);
    fn rtcSetGeometryUserData(geometry: RTCGeometry, ptr: *mut c_void);
    fn rtcSetGeometryBoundsFunction(geometry: RTCGeometry, f: RTCBoundsFunction, user: *mut c_void);
    fn rtcSetGeometryIntersectFunction(geometry: RTCGeometry, f: RTCIntersectFunctionN);
    fn rtcSetGeometryOccludedFunction(geometry: RTCGeometry, f: RTCOccludedFunctionN);
    fn rtcIntersect1(scene: RTCScene, rayhit: *mut RTCRayHit, args: *mut RTCIntersectArguments);
    fn rtcOccluded1(scene: RTCScene, ray: *mut RTCRay, args: *mut RTCOccludedArguments);
    fn rtcIntersect8(
        valid: *const c_int,
        scene: RTCScene,
        rayhit: *mut RTCRayHit8,
        args: *mut RTCIntersectArguments
    );
    fn rtcOccluded8(
        valid: *const c_int,
        scene: RTCScene,
        ray: *mut RTCRay8,
        args: *mut RTCOccludedArguments
    );
    fn rtcIntersect16(
        valid: *const c_int,
        scene: RTCScene,
        rayhit: *mut RTCRayHit16,
        args: *mut RTCIntersectArguments
    );
    fn rtcOccluded16(
        valid: *const c_int,
        scene: RTCScene,
        ray: *mut RTCRay16,
        args: *mut RTCOccludedArguments
    );
}

static API: OnceLock<Result<Api, String>> = OnceLock::new();

/// Opens Embree (once per process): the library the build found, else `libembree4.so` on the
/// system's search path. The error says both reasons.
pub fn load() -> Result<(), String> {
    API.get_or_init(|| {
        let open = |name: &str| {
            // SAFETY: opening Embree runs its and TBB's initialisers, which have no
            // preconditions; the library is kept open for the process's life.
            unsafe { libloading::Library::new(name) }.map_err(|e| e.to_string())
        };
        let lib = open(BUILT).or_else(|built| {
            open("libembree4.so").map_err(|system| {
                format!("cannot load Embree: {BUILT}: {built}; libembree4.so: {system}")
            })
        })?;
        // SAFETY: the library is Embree 4 (its name; a missing function is an error).
        unsafe { Api::from(lib) }
    })
    .as_ref()
    .map(|_| ())
    .map_err(Clone::clone)
}

/// The loaded functions. Every call of Embree is made on a device, and a device is only made
/// after [`load`] succeeded (`raw::Device::new`), so the table is there.
fn api() -> &'static Api {
    match API.get() {
        Some(Ok(api)) => api,
        _ => unreachable!("an Embree function was called before Embree was loaded"),
    }
}
