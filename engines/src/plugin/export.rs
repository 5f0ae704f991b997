//! The other side of the ABI: any Rust [`Engine`] exported as a plugin (a `cdylib`), with
//! [`crate::export_plugin!`]. examples/rust-plugin uses it; so can an engine crate kept out of
//! rtbench's tree.
//!
//! The plugin's build gets the arrays of `rtb_scene` back as a [`BuildInput`] (one scene object
//! per primitive, so hit ids are primitive ids), builds the engine with the settings rtbench
//! passed on, and answers queries by calling the engine directly on the ray and hit arrays (the
//! layouts are the same). Counters go out as `nodes_visited`, `box_tests`, `primitive_tests`,
//! `primitive_hits`.

use super::{RtbPlugin, RtbScene, ABI_VERSION, PRIM_CONES, PRIM_SPHERES, PRIM_TRIANGLES};
use crate::engine::{BuildInput, Counters, Engine, EngineError, Settings};
use crate::geometry::{Geometry, Prim};
use crate::ray::{Hit, Ray};
use glam::Vec3;
use rtbench_scenes::{Object, Scene, Shape};
use std::ffi::{c_char, c_void, CStr};
use std::sync::{Arc, OnceLock};

/// How the exported engine is built: the same signature as a registry entry's.
pub type Build = fn(&BuildInput, Settings) -> Result<Box<dyn Engine>, EngineError>;

/// The function table, shareable between threads (it holds only static pointers).
pub struct Table(RtbPlugin);
// SAFETY: the pointers are to static strings and functions.
unsafe impl Sync for Table {}
unsafe impl Send for Table {}

impl Table {
    pub fn as_ptr(&self) -> *const RtbPlugin {
        &self.0
    }
}

static BUILD: OnceLock<(Build, &'static str)> = OnceLock::new();

const COUNTERS: [&CStr; 4] = [
    c"nodes_visited",
    c"box_tests",
    c"primitive_tests",
    c"primitive_hits",
];

struct Names([*const c_char; 4]);
// SAFETY: pointers to static C strings.
unsafe impl Sync for Names {}
static NAMES: Names = Names([
    COUNTERS[0].as_ptr(),
    COUNTERS[1].as_ptr(),
    COUNTERS[2].as_ptr(),
    COUNTERS[3].as_ptr(),
]);

/// The table of a plugin named `name` (NUL-terminated), built by `build`. Called once by
/// [`crate::export_plugin!`].
/// `kinds`: the `RTB_PRIM_*` bits the engine takes (triangles are added).
pub fn table(name: &'static CStr, version: &'static CStr, kinds: u32, build: Build) -> Table {
    let _ = BUILD.set((build, name.to_str().unwrap_or("rust-plugin")));
    Table(RtbPlugin {
        abi_version: ABI_VERSION,
        name: name.as_ptr(),
        version: version.as_ptr(),
        prim_kinds: PRIM_TRIANGLES | (kinds & (PRIM_SPHERES | PRIM_CONES)),
        counter_count: 4,
        counter_names: NAMES.0.as_ptr(),
        build: Some(ffi_build),
        intersect: Some(ffi_intersect),
        occluded: Some(ffi_occluded),
        structure_bytes: Some(ffi_bytes),
        destroy: Some(ffi_destroy),
    })
}

fn write_error(buf: *mut c_char, len: usize, msg: &str) {
    if buf.is_null() || len == 0 {
        return;
    }
    let n = msg.len().min(len - 1);
    // SAFETY: the caller gave len writable bytes.
    unsafe {
        std::ptr::copy_nonoverlapping(msg.as_ptr() as *const c_char, buf, n);
        *buf.add(n) = 0;
    }
}

/// The arrays of `rtb_scene` as rtbench's own input: one object per primitive, in id order.
///
/// # Safety
/// `s` points to a valid `rtb_scene` whose arrays hold the counts it states.
pub unsafe fn input_of(s: &RtbScene) -> BuildInput {
    let slice = |p: *const f32, n: usize| -> &[f32] {
        if n == 0 || p.is_null() {
            &[]
        } else {
            // SAFETY: the ABI: `n` floats at `p`, valid during build.
            unsafe { std::slice::from_raw_parts(p, n) }
        }
    };
    let tris = slice(s.triangles, 9 * s.triangle_count as usize);
    let sph = slice(s.spheres, 4 * s.sphere_count as usize);
    let cones = slice(s.cones, 8 * s.cone_count as usize);
    let v = |a: &[f32]| Vec3::new(a[0], a[1], a[2]);
    let mut g = Geometry::default();
    let mut scene = Scene::default();
    let mut push = |p: Prim, shape: Shape, g: &mut Geometry| {
        g.prim_object.push(g.prims.len() as u32);
        g.prims.push(p);
        scene.objects.push(Object { shape, material: 0 });
    };
    for t in tris.chunks_exact(9) {
        let (a, b, c) = (v(&t[0..3]), v(&t[3..6]), v(&t[6..9]));
        let shape = Shape::Polygon(vec![a.as_dvec3(), b.as_dvec3(), c.as_dvec3()]);
        push(Prim::Triangle([a, b, c]), shape, &mut g);
    }
    for q in sph.chunks_exact(4) {
        let (center, radius) = (v(&q[0..3]), q[3]);
        let shape = Shape::Sphere {
            center: center.as_dvec3(),
            radius: radius as f64,
        };
        push(Prim::Sphere { center, radius }, shape, &mut g);
    }
    for c in cones.chunks_exact(8) {
        let (base, base_radius, apex, apex_radius) = (v(&c[0..3]), c[3], v(&c[4..7]), c[7]);
        let shape = Shape::Cone {
            base: base.as_dvec3(),
            base_radius: base_radius as f64,
            apex: apex.as_dvec3(),
            apex_radius: apex_radius as f64,
        };
        let p = Prim::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
        };
        push(p, shape, &mut g);
    }
    g.bounds_min = Vec3::from_array(s.bounds_min);
    g.bounds_max = Vec3::from_array(s.bounds_max);
    BuildInput {
        scene: Arc::new(scene),
        geometry: Arc::new(g),
    }
}

unsafe extern "C" fn ffi_build(s: *const RtbScene, err: *mut c_char, len: usize) -> *mut c_void {
    let Some((build, name)) = BUILD.get() else {
        write_error(err, len, "plugin table not initialised");
        return std::ptr::null_mut();
    };
    if s.is_null() {
        write_error(err, len, "no scene");
        return std::ptr::null_mut();
    }
    // SAFETY: the ABI: a valid scene during build.
    let s = unsafe { &*s };
    let mut pairs = Vec::new();
    for i in 0..s.setting_count as usize {
        // SAFETY: setting_count settings of NUL-terminated strings.
        let st = unsafe { &*s.settings.add(i) };
        let k = unsafe { CStr::from_ptr(st.key) }
            .to_string_lossy()
            .into_owned();
        let v = unsafe { CStr::from_ptr(st.value) }
            .to_string_lossy()
            .into_owned();
        pairs.push((k, v));
    }
    // SAFETY: as above.
    let input = unsafe { input_of(s) };
    let r = std::panic::catch_unwind(|| build(&input, Settings::new(name, pairs)));
    match r {
        Ok(Ok(engine)) => Box::into_raw(Box::new(engine)) as *mut c_void,
        Ok(Err(e)) => {
            write_error(err, len, &e.to_string());
            std::ptr::null_mut()
        }
        Err(_) => {
            write_error(err, len, "the engine panicked while building");
            std::ptr::null_mut()
        }
    }
}

fn out_counters(c: &Counters, out: *mut u64) {
    if out.is_null() {
        return;
    }
    let v = [
        c.nodes_visited,
        c.box_tests,
        c.primitive_tests,
        c.primitive_hits,
    ];
    for (i, x) in v.iter().enumerate() {
        // SAFETY: the ABI: counter_count (4) counters.
        unsafe { *out.add(i) += x };
    }
}

unsafe extern "C" fn ffi_intersect(
    e: *const c_void,
    rays: *const Ray,
    hits: *mut Hit,
    n: usize,
    counters: *mut u64,
) {
    if n == 0 {
        return;
    }
    // SAFETY: e came from ffi_build; n rays and hits (rtb_ray/rtb_hit are Ray/Hit).
    let (engine, rays, hits) = unsafe {
        (
            &*(e as *const Box<dyn Engine>),
            std::slice::from_raw_parts(rays, n),
            std::slice::from_raw_parts_mut(hits, n),
        )
    };
    let mut c = Counters::default();
    engine.intersect(rays, hits, &mut c);
    out_counters(&c, counters);
}

unsafe extern "C" fn ffi_occluded(
    e: *const c_void,
    rays: *const Ray,
    occ: *mut u8,
    n: usize,
    counters: *mut u64,
) {
    if n == 0 {
        return;
    }
    // SAFETY: as in ffi_intersect; occ holds n bytes.
    let (engine, rays, occ) = unsafe {
        (
            &*(e as *const Box<dyn Engine>),
            std::slice::from_raw_parts(rays, n),
            std::slice::from_raw_parts_mut(occ, n),
        )
    };
    let mut b = vec![false; n];
    let mut c = Counters::default();
    engine.occluded(rays, &mut b, &mut c);
    for (o, x) in occ.iter_mut().zip(b) {
        *o = x as u8;
    }
    out_counters(&c, counters);
}

unsafe extern "C" fn ffi_bytes(e: *const c_void) -> u64 {
    // SAFETY: e came from ffi_build.
    unsafe { &*(e as *const Box<dyn Engine>) }.structure_bytes()
}

unsafe extern "C" fn ffi_destroy(e: *mut c_void) {
    if !e.is_null() {
        // SAFETY: e came from ffi_build and is destroyed once.
        drop(unsafe { Box::from_raw(e as *mut Box<dyn Engine>) });
    }
}

/// Exports a Rust engine as an rtbench plugin: put it in a `cdylib` crate.
///
/// ```ignore
/// // name, version, primitive kinds (RTB_PRIM_* bits), build function
/// rtbench_engines::export_plugin!(c"my-bvh", c"0.1", rtbench_engines::plugin::PRIM_TRIANGLES, my_crate::build);
/// ```
#[macro_export]
macro_rules! export_plugin {
    ($name:expr, $version:expr, $kinds:expr, $build:expr) => {
        #[no_mangle]
        pub extern "C" fn rtbench_engine_abi_version() -> u32 {
            $crate::plugin::ABI_VERSION
        }
        #[no_mangle]
        pub extern "C" fn rtbench_engine_plugin() -> *const $crate::plugin::RtbPlugin {
            static TABLE: ::std::sync::OnceLock<$crate::plugin::export::Table> =
                ::std::sync::OnceLock::new();
            TABLE
                .get_or_init(|| $crate::plugin::export::table($name, $version, $kinds, $build))
                .as_ptr()
        }
    };
}
