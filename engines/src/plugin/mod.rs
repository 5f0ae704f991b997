//! Engines from shared libraries: the C ABI of `include/rtbench_engine.h`, loaded with
//! `libloading` (`--engines plugin:PATH[:key=value…]`).
//!
//! The `plugin` engine reads the settings rtbench itself uses (`path`, `tess`, `tessellate`,
//! `abi_timing`) and hands every other one to the library's `build`, which rejects what it does
//! not know. It checks the ABI version before it touches the function table, passes the prepared
//! geometry as arrays (curved primitives the plugin does not take are tessellated here, with
//! their geometric error in the build stats), and checks every answer: a NaN or out-of-interval
//! t, or a primitive id out of range, fails the run (`Engine::failure`) instead of reaching the
//! results. A plugin that crashes takes its run's child process with it, nothing else.

pub mod export;
pub mod tess;

use crate::engine::{BuildInput, Counters, Engine, EngineError, EngineInfo, Settings};
use crate::geometry::Prim;
use crate::ray::{Hit, Ray};
use std::collections::BTreeMap;
use std::ffi::{c_char, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// The version of `include/rtbench_engine.h` this rtbench speaks.
pub const ABI_VERSION: u32 = 1;
pub const PRIM_TRIANGLES: u32 = 1;
pub const PRIM_SPHERES: u32 = 2;
pub const PRIM_CONES: u32 = 4;
pub const MISS: u32 = u32::MAX;
/// How far outside [0, 1] a triangle's barycentrics may fall (f32 rounding at an edge).
const BARY_SLACK: f32 = 1e-3;

/// `rtb_ray` and `rtb_hit` are rtbench's own [`Ray`] and [`Hit`]: batches cross without a copy.
const _: () = assert!(std::mem::size_of::<Ray>() == 32 && std::mem::size_of::<Hit>() == 16);

/// `rtb_setting`.
#[repr(C)]
pub struct RtbSetting {
    pub key: *const c_char,
    pub value: *const c_char,
}

/// `rtb_scene`.
#[repr(C)]
pub struct RtbScene {
    pub triangle_count: u32,
    pub triangles: *const f32,
    pub sphere_count: u32,
    pub spheres: *const f32,
    pub cone_count: u32,
    pub cones: *const f32,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    pub setting_count: u32,
    pub settings: *const RtbSetting,
}

pub type BuildFn = unsafe extern "C" fn(*const RtbScene, *mut c_char, usize) -> *mut c_void;
pub type IntersectFn = unsafe extern "C" fn(*const c_void, *const Ray, *mut Hit, usize, *mut u64);
pub type OccludedFn = unsafe extern "C" fn(*const c_void, *const Ray, *mut u8, usize, *mut u64);

/// `rtb_plugin`: the function table.
#[repr(C)]
pub struct RtbPlugin {
    pub abi_version: u32,
    pub name: *const c_char,
    pub version: *const c_char,
    pub prim_kinds: u32,
    pub counter_count: u32,
    pub counter_names: *const *const c_char,
    pub build: Option<BuildFn>,
    pub intersect: Option<IntersectFn>,
    pub occluded: Option<OccludedFn>,
    pub structure_bytes: Option<unsafe extern "C" fn(*const c_void) -> u64>,
    pub destroy: Option<unsafe extern "C" fn(*mut c_void)>,
}

pub fn info() -> EngineInfo {
    EngineInfo {
        name: "plugin",
        description: "an engine from a shared library (C ABI include/rtbench_engine.h): plugin:PATH[:key=value…]",
        available: || Ok(()),
        build,
    }
}

/// Where `plugin:NAME` looks when NAME is not a path: `$RTBENCH_PLUGIN_DIR`, else `./plugins`.
pub fn plugin_dir() -> PathBuf {
    std::env::var_os("RTBENCH_PLUGIN_DIR")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("plugins"))
}

/// The library file of `plugin:SPEC`: SPEC itself when it names a file (or holds a `/`), else
/// NAME, libNAME.so or NAME.so in [`plugin_dir`].
pub fn resolve(spec: &str) -> Result<PathBuf, String> {
    let p = Path::new(spec);
    if spec.contains('/') || p.is_file() {
        return if p.is_file() {
            Ok(p.to_path_buf())
        } else {
            Err(format!("plugin '{spec}': no such file"))
        };
    }
    let dir = plugin_dir();
    for cand in [
        spec.to_string(),
        format!("lib{spec}.so"),
        format!("{spec}.so"),
    ] {
        let c = dir.join(&cand);
        if c.is_file() {
            return Ok(c);
        }
    }
    Err(format!(
        "plugin '{spec}': not a file, nor {spec}, lib{spec}.so or {spec}.so in {}",
        dir.display()
    ))
}

fn err(path: &str, reason: impl Into<String>) -> EngineError {
    EngineError::Build {
        engine: format!("plugin:{path}"),
        reason: reason.into(),
    }
}

/// A string from the plugin, with control characters (terminal escapes among them) shown
/// escaped rather than sent to the user's terminal.
fn cstr(p: *const c_char) -> String {
    if p.is_null() {
        return String::new();
    }
    // SAFETY: the ABI requires NUL-terminated static strings; null was handled.
    let s = unsafe { CStr::from_ptr(p) }.to_string_lossy();
    printable(&s)
}

/// `s` with every control character but the newline escaped (`\u{1b}`).
fn printable(s: &str) -> String {
    s.chars()
        .flat_map(|c| {
            let escaped: Vec<char> = if c.is_control() && c != '\n' {
                c.escape_unicode().collect()
            } else {
                vec![c]
            };
            escaped
        })
        .collect()
}

/// While any plugin function runs, file descriptor 1 points at stderr, so that what a plugin
/// prints cannot reach rtbench's own output on stdout (`render --json`). C stdio buffers are
/// flushed before the descriptor is given back. Calls may overlap (threads): the first in
/// redirects, the last out restores.
mod quiet_stdout {
    use std::io::Write;
    use std::sync::Mutex;

    /// Calls under way, and the saved descriptor of the real stdout.
    static STATE: Mutex<(usize, i32)> = Mutex::new((0, -1));

    pub struct Guard;

    pub fn enter() -> Guard {
        let mut s = STATE.lock().unwrap_or_else(|p| p.into_inner());
        if s.0 == 0 {
            let _ = std::io::stdout().flush();
            // SAFETY: plain descriptor calls; a failed dup leaves stdout as it was.
            unsafe {
                libc::fflush(std::ptr::null_mut());
                let saved = libc::dup(1);
                if saved >= 0 && libc::dup2(2, 1) >= 0 {
                    s.1 = saved;
                } else if saved >= 0 {
                    libc::close(saved);
                }
            }
        }
        s.0 += 1;
        Guard
    }

    impl Drop for Guard {
        fn drop(&mut self) {
            let mut s = STATE.lock().unwrap_or_else(|p| p.into_inner());
            s.0 -= 1;
            if s.0 == 0 && s.1 >= 0 {
                // SAFETY: `s.1` is the descriptor saved by `enter`, still open.
                unsafe {
                    libc::fflush(std::ptr::null_mut());
                    libc::dup2(s.1, 1);
                    libc::close(s.1);
                }
                s.1 = -1;
            }
        }
    }
}

/// Where a plugin counter goes.
#[derive(Clone, Debug)]
enum Slot {
    NodesVisited,
    BoxTests,
    PrimitiveTests,
    PrimitiveHits,
    Extra(String),
}

/// A loaded library and the function table it exported, version-checked.
pub struct Library {
    /// Kept loaded while the table is used (PluginEngine's `destroy` runs before it drops).
    _lib: libloading::Library,
    table: *const RtbPlugin,
    pub name: String,
    pub version: String,
    pub prim_kinds: u32,
}

// SAFETY: the table is immutable static data of the library, which stays loaded.
unsafe impl Send for Library {}
unsafe impl Sync for Library {}

impl Library {
    /// Loads the library, checks `rtbench_engine_abi_version()` and then the table.
    pub fn open(path: &Path) -> Result<Library, String> {
        let _quiet = quiet_stdout::enter();
        // SAFETY: loading runs the library's initialisers: that is what a plugin is.
        let lib = unsafe { libloading::Library::new(path) }.map_err(|e| e.to_string())?;
        // SAFETY: the symbols' types are those of include/rtbench_engine.h.
        let version = unsafe {
            let f = lib
                .get::<unsafe extern "C" fn() -> u32>(b"rtbench_engine_abi_version\0")
                .map_err(|_| "exports no rtbench_engine_abi_version: not an rtbench plugin")?;
            f()
        };
        if version != ABI_VERSION {
            return Err(format!(
                "ABI version {version}, but this rtbench speaks version {ABI_VERSION} (include/rtbench_engine.h)"
            ));
        }
        // SAFETY: as above.
        let table = unsafe {
            let f = lib
                .get::<unsafe extern "C" fn() -> *const RtbPlugin>(b"rtbench_engine_plugin\0")
                .map_err(|_| "exports no rtbench_engine_plugin")?;
            f()
        };
        if table.is_null() {
            return Err("rtbench_engine_plugin() returned NULL".into());
        }
        // SAFETY: non-null, and the ABI says it points to a table valid while loaded.
        let t = unsafe { &*table };
        if t.abi_version != ABI_VERSION {
            return Err(format!(
                "function table of ABI version {}, but this rtbench speaks version {ABI_VERSION}",
                t.abi_version
            ));
        }
        if t.build.is_none()
            || t.intersect.is_none()
            || t.occluded.is_none()
            || t.structure_bytes.is_none()
            || t.destroy.is_none()
        {
            return Err("function table has a NULL function".into());
        }
        if t.prim_kinds & PRIM_TRIANGLES == 0 {
            return Err("does not take triangles (RTB_PRIM_TRIANGLES is mandatory)".into());
        }
        if t.counter_count > 0 && t.counter_names.is_null() {
            return Err("counter_count > 0 but counter_names is NULL".into());
        }
        Ok(Library {
            name: cstr(t.name),
            version: cstr(t.version),
            prim_kinds: t.prim_kinds,
            _lib: lib,
            table,
        })
    }

    fn table(&self) -> &RtbPlugin {
        // SAFETY: checked non-null in `open`; valid while `lib` is loaded.
        unsafe { &*self.table }
    }
}

/// A plugin's built engine.
pub struct PluginEngine {
    engine: *mut c_void,
    intersect_fn: IntersectFn,
    occluded_fn: OccludedFn,
    /// Scene object of each plugin primitive id.
    prim_object: Vec<u32>,
    slots: Vec<Slot>,
    failure: Mutex<Option<String>>,
    timing: bool,
    stats: BTreeMap<String, f64>,
    label: String,
    lib: Library,
}

// SAFETY: the ABI requires intersect/occluded to be callable from several threads at once;
// build and destroy run with exclusive access (`&mut`/drop).
unsafe impl Send for PluginEngine {}
unsafe impl Sync for PluginEngine {}

impl Drop for PluginEngine {
    fn drop(&mut self) {
        if let Some(d) = self.lib.table().destroy {
            // SAFETY: the engine came from this table's build and is destroyed once.
            unsafe { d(self.engine) }
        }
    }
}

/// What the plugin is given: the arrays and, per primitive id, the scene object.
#[derive(Default)]
struct Arrays {
    triangles: Vec<f32>,
    spheres: Vec<f32>,
    cones: Vec<f32>,
    tri_object: Vec<u32>,
    sphere_object: Vec<u32>,
    cone_object: Vec<u32>,
    tessellated_spheres: u64,
    tessellated_cones: u64,
    tess_triangles: u64,
    error: tess::TessError,
}

fn arrays(input: &BuildInput, kinds: u32, res: u32) -> Arrays {
    let mut a = Arrays::default();
    let mut tris = Vec::new();
    let push_tri = |a: &mut Arrays, t: &[glam::Vec3; 3], o: u32| {
        for p in t {
            a.triangles.extend_from_slice(&p.to_array());
        }
        a.tri_object.push(o);
    };
    let g = &input.geometry;
    for (p, &o) in g.prims.iter().zip(&g.prim_object) {
        match *p {
            Prim::Triangle(t) => push_tri(&mut a, &t, o),
            Prim::Sphere { center, radius } if kinds & PRIM_SPHERES != 0 => {
                a.spheres.extend_from_slice(&center.to_array());
                a.spheres.push(radius);
                a.sphere_object.push(o);
            }
            Prim::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } if kinds & PRIM_CONES != 0 => {
                a.cones.extend_from_slice(&base.to_array());
                a.cones.push(base_radius);
                a.cones.extend_from_slice(&apex.to_array());
                a.cones.push(apex_radius);
                a.cone_object.push(o);
            }
            Prim::Sphere { center, radius } => {
                tris.clear();
                a.error.merge(tess::sphere(center, radius, res, &mut tris));
                a.tessellated_spheres += 1;
                a.tess_triangles += tris.len() as u64;
                for t in &tris {
                    push_tri(&mut a, t, o);
                }
            }
            Prim::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => {
                tris.clear();
                a.error.merge(tess::cone(
                    base,
                    base_radius,
                    apex,
                    apex_radius,
                    res,
                    &mut tris,
                ));
                a.tessellated_cones += 1;
                a.tess_triangles += tris.len() as u64;
                for t in &tris {
                    push_tri(&mut a, t, o);
                }
            }
        }
    }
    a
}

fn build(input: &BuildInput, mut s: Settings) -> Result<Box<dyn Engine>, EngineError> {
    let spec: String = s.get("path", String::new())?;
    if spec.is_empty() {
        return Err(err("?", "no library: use plugin:PATH"));
    }
    let res: u32 = s.get("tess", 8)?;
    if !(2..=256).contains(&res) {
        return Err(EngineError::BadValue {
            engine: "plugin".into(),
            key: "tess".into(),
            value: res.to_string(),
            reason: "expected 2…256".into(),
        });
    }
    let force: String = s.get("tessellate", "auto".to_string())?;
    let force = match force.as_str() {
        "auto" => false,
        "all" => true,
        _ => {
            return Err(EngineError::BadValue {
                engine: "plugin".into(),
                key: "tessellate".into(),
                value: force,
                reason: "expected auto or all".into(),
            })
        }
    };
    let timing: String = s.get("abi_timing", "off".to_string())?;
    let timing = match timing.as_str() {
        "on" => true,
        "off" => false,
        _ => {
            return Err(EngineError::BadValue {
                engine: "plugin".into(),
                key: "abi_timing".into(),
                value: timing,
                reason: "expected on or off".into(),
            })
        }
    };
    let rest = s.into_rest();
    let path = resolve(&spec).map_err(|e| err(&spec, e))?;
    let lib = Library::open(&path).map_err(|e| err(&spec, e))?;
    let kinds = if force {
        PRIM_TRIANGLES
    } else {
        lib.prim_kinds
    };
    let a = arrays(input, kinds, res);
    let n_prims = a.tri_object.len() + a.sphere_object.len() + a.cone_object.len();
    if n_prims >= MISS as usize {
        return Err(err(
            &spec,
            format!("{n_prims} primitives: more than ids hold"),
        ));
    }
    let ckeys: Vec<CString> = rest
        .iter()
        .map(|(k, _)| CString::new(k.as_str()).unwrap_or_default())
        .collect();
    let cvals: Vec<CString> = rest
        .iter()
        .map(|(_, v)| CString::new(v.as_str()).unwrap_or_default())
        .collect();
    let settings: Vec<RtbSetting> = ckeys
        .iter()
        .zip(&cvals)
        .map(|(k, v)| RtbSetting {
            key: k.as_ptr(),
            value: v.as_ptr(),
        })
        .collect();
    let g = &input.geometry;
    let scene = RtbScene {
        triangle_count: a.tri_object.len() as u32,
        triangles: a.triangles.as_ptr(),
        sphere_count: a.sphere_object.len() as u32,
        spheres: a.spheres.as_ptr(),
        cone_count: a.cone_object.len() as u32,
        cones: a.cones.as_ptr(),
        bounds_min: g.bounds_min.to_array(),
        bounds_max: g.bounds_max.to_array(),
        setting_count: settings.len() as u32,
        settings: settings.as_ptr(),
    };
    let t = lib.table();
    let mut msg = vec![0 as c_char; 512];
    let start = Instant::now();
    // SAFETY: `scene` and its arrays live across the call; msg has msg.len() bytes.
    let engine = {
        let _quiet = quiet_stdout::enter();
        unsafe { (t.build.expect("checked in open"))(&scene, msg.as_mut_ptr(), msg.len()) }
    };
    let build_s = start.elapsed().as_secs_f64();
    if engine.is_null() {
        msg[511] = 0;
        // The plugin's message: control characters shown escaped (cstr).
        let reason = cstr(msg.as_ptr());
        return Err(err(
            &spec,
            if reason.is_empty() {
                "build failed (no reason given)".to_string()
            } else {
                reason.lines().next().unwrap_or_default().to_string()
            },
        ));
    }
    let slots = (0..t.counter_count as usize)
        .map(|i| {
            // SAFETY: counter_names holds counter_count pointers (checked non-null in open).
            let name = cstr(unsafe { *t.counter_names.add(i) });
            match name.as_str() {
                "nodes_visited" => Slot::NodesVisited,
                "box_tests" => Slot::BoxTests,
                "primitive_tests" => Slot::PrimitiveTests,
                "primitive_hits" => Slot::PrimitiveHits,
                _ => Slot::Extra(name),
            }
        })
        .collect();
    let mut stats = BTreeMap::new();
    stats.insert("plugin_build_s".into(), build_s);
    stats.insert("plugin_abi_version".into(), ABI_VERSION as f64);
    stats.insert("plugin_triangles".into(), a.tri_object.len() as f64);
    stats.insert("plugin_spheres".into(), a.sphere_object.len() as f64);
    stats.insert("plugin_cones".into(), a.cone_object.len() as f64);
    if a.tessellated_spheres + a.tessellated_cones > 0 {
        stats.insert("tessellated_spheres".into(), a.tessellated_spheres as f64);
        stats.insert("tessellated_cones".into(), a.tessellated_cones as f64);
        stats.insert("tessellation_triangles".into(), a.tess_triangles as f64);
        stats.insert("tessellation_res".into(), res as f64);
        stats.insert("tessellation_max_error".into(), a.error.max_abs);
        stats.insert("tessellation_max_rel_error".into(), a.error.max_rel);
    }
    let mut prim_object = a.tri_object;
    prim_object.extend_from_slice(&a.sphere_object);
    prim_object.extend_from_slice(&a.cone_object);
    Ok(Box::new(PluginEngine {
        engine,
        intersect_fn: t.intersect.expect("checked in open"),
        occluded_fn: t.occluded.expect("checked in open"),
        prim_object,
        slots,
        failure: Mutex::new(None),
        timing,
        stats,
        label: format!("{} {} ({})", lib.name, lib.version, path.display()),
        lib,
    }))
}

impl PluginEngine {
    /// The plugin's name, version and file.
    pub fn label(&self) -> &str {
        &self.label
    }

    fn fail(&self, reason: String) {
        let mut f = self.failure.lock().unwrap_or_else(|p| p.into_inner());
        if f.is_none() {
            *f = Some(format!("plugin {}: {reason}", self.lib.name));
        }
    }

    fn failed(&self) -> bool {
        self.failure.lock().map(|f| f.is_some()).unwrap_or(true)
    }

    fn add_counters(&self, raw: &[u64], c: &mut Counters) {
        for (slot, &v) in self.slots.iter().zip(raw) {
            match slot {
                Slot::NodesVisited => c.nodes_visited += v,
                Slot::BoxTests => c.box_tests += v,
                Slot::PrimitiveTests => c.primitive_tests += v,
                Slot::PrimitiveHits => c.primitive_hits += v,
                Slot::Extra(n) => *c.extra.entry(n.clone()).or_insert(0) += v,
            }
        }
    }

    fn time(&self, c: &mut Counters, key: &str, since: Instant) {
        if self.timing {
            *c.extra.entry(key.into()).or_insert(0) += since.elapsed().as_nanos() as u64;
        }
    }
}

impl Engine for PluginEngine {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], c: &mut Counters) {
        let n = rays.len().min(hits.len());
        c.rays += n as u64;
        if self.failed() {
            hits.fill(Hit::MISS);
            return;
        }
        let whole = Instant::now();
        let mut raw = vec![0u64; self.slots.len()];
        let call = Instant::now();
        let quiet = quiet_stdout::enter();
        // SAFETY: n rays in, n hits out, counter_count counters; the engine is live.
        unsafe {
            (self.intersect_fn)(
                self.engine,
                rays.as_ptr(),
                hits.as_mut_ptr(),
                n,
                raw.as_mut_ptr(),
            )
        };
        drop(quiet);
        self.time(c, "abi_inside_ns", call);
        self.add_counters(&raw, c);
        let np = self.prim_object.len() as u32;
        for (i, (h, r)) in hits[..n].iter_mut().zip(rays).enumerate() {
            if h.object == MISS {
                *h = Hit::MISS;
                continue;
            }
            let bad = if h.object >= np {
                Some(format!(
                    "ray {i}: primitive id {} out of range (0…{})",
                    h.object,
                    np.saturating_sub(1)
                ))
            } else if h.t.is_nan() {
                Some(format!("ray {i}: t is NaN"))
            } else if !(h.t > r.tmin && h.t < r.tmax) {
                Some(format!(
                    "ray {i}: t = {} outside the ray's interval ({}, {})",
                    h.t, r.tmin, r.tmax
                ))
            } else if !(h.u.is_finite() && h.v.is_finite()) {
                Some(format!(
                    "ray {i}: barycentrics ({}, {}) not finite",
                    h.u, h.v
                ))
            } else if !(h.u >= -BARY_SLACK && h.v >= -BARY_SLACK && h.u + h.v <= 1.0 + BARY_SLACK) {
                // Triangles' weights lie in the triangle; other kinds answer 0, 0.
                Some(format!(
                    "ray {i}: barycentrics ({}, {}) outside the triangle",
                    h.u, h.v
                ))
            } else {
                None
            };
            match bad {
                Some(reason) => {
                    self.fail(reason);
                    *h = Hit::MISS;
                }
                None => h.object = self.prim_object[h.object as usize],
            }
        }
        self.time(c, "abi_total_ns", whole);
    }

    fn occluded(&self, rays: &[Ray], occluded: &mut [bool], c: &mut Counters) {
        let n = rays.len().min(occluded.len());
        c.rays += n as u64;
        if self.failed() {
            occluded.fill(false);
            return;
        }
        let whole = Instant::now();
        let mut raw = vec![0u64; self.slots.len()];
        let mut out = vec![0u8; n];
        let call = Instant::now();
        let quiet = quiet_stdout::enter();
        // SAFETY: n rays in, n bytes out, counter_count counters; the engine is live.
        unsafe {
            (self.occluded_fn)(
                self.engine,
                rays.as_ptr(),
                out.as_mut_ptr(),
                n,
                raw.as_mut_ptr(),
            )
        };
        drop(quiet);
        self.time(c, "abi_inside_ns", call);
        self.add_counters(&raw, c);
        for (i, (o, &b)) in occluded[..n].iter_mut().zip(&out).enumerate() {
            if b > 1 {
                self.fail(format!("ray {i}: occluded = {b}, expected 0 or 1"));
                *o = false;
            } else {
                *o = b == 1;
            }
        }
        self.time(c, "abi_total_ns", whole);
    }

    fn structure_bytes(&self) -> u64 {
        match self.lib.table().structure_bytes {
            // SAFETY: the engine is live.
            Some(f) => unsafe { f(self.engine) },
            None => 0,
        }
    }

    fn failure(&self) -> Option<String> {
        self.failure.lock().ok().and_then(|f| f.clone())
    }

    fn build_stats(&self) -> BTreeMap<String, f64> {
        self.stats.clone()
    }
}
