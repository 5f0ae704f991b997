//! The SPD workload, traced as wavefront generations (docs/concepts.md, "The SPD
//! workload"): all rays of one depth are answered as batches by the engine before shading makes
//! the next generation. One shading code path serves every engine, so images and ray statistics
//! agree across engines.
//!
//! Rules implemented: rays through the (size+1)² pixel corners; maximum ray-tree depth 5 (the eye
//! ray is depth 1); a reflection ray from every hit on a reflective (Ks > 0) or transmitting
//! surface; a refraction ray from every hit on a transmitting surface (Snell's law) unless under
//! total internal reflection; shadow rays only towards lights the shading normal faces (also on
//! transmitters); positional lights; NFF Phong with an ambient term; patches smooth-shaded.
//!
//! Policies this file states:
//! - Sides: every surface is shaded as seen (normals are turned to face the ray). This makes the
//!   teapot double-sided as the SPD asks; the other scenes are closed, or their backs unseen.
//! - Media: each ray knows whether it travels inside a transmitting object; a refraction ray
//!   entering uses 1/ior, one leaving uses ior. This does not depend on polygon winding.
//! - Self-intersection: a secondary ray starts at the hit point moved off the surface along the
//!   geometric normal by `OFFSET_REL` × the largest coordinate of the point (so the offset grows
//!   with the rounding error of the point, about 2^-23 of it), with tmin = 0.

use super::camera::Camera;
use super::surface::Surfaces;
use crate::measure::span::{Sample, Span, Workers};
use glam::Vec3;
use rayon::prelude::*;
use rtbench_engines::{Counters, Engine, Hit, Ray};
use rtbench_scenes::{Material, Scene};
use serde::Serialize;
use std::sync::{Mutex, TryLockError};
use std::time::Instant;

/// Maximum ray-tree depth (SPD procedure item 7).
pub const MAX_DEPTH: u8 = 5;
/// Offset of secondary ray origins, relative to the magnitude of the hit point: 2^-15, about
/// 256 times f32's unit roundoff.
pub const OFFSET_REL: f32 = 1.0 / 32768.0;
/// Floor of the offset, for hit points at the origin.
const OFFSET_MIN: f32 = 1e-7;

/// What one ray of a generation carries besides the ray.
#[derive(Clone, Copy)]
pub(crate) struct Path {
    pub corner: u32,
    pub weight: Vec3,
    pub depth: u8,
    pub inside: bool,
}

/// Ray counts of one generation.
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize, PartialEq)]
pub struct GenerationStats {
    pub generation: u32,
    pub rays: u64,
    pub hits: u64,
    pub shadow: u64,
    pub shadow_blocked: u64,
    pub reflect: u64,
    pub refract: u64,
    /// Hits on transmitting surfaces that spawned no refraction ray: total internal reflection.
    pub total_internal_reflections: u64,
}

/// Ray statistics of a whole render (the columns of the SPD table).
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize, PartialEq)]
pub struct RayStats {
    pub eye: u64,
    pub eye_hit: u64,
    pub shadow: u64,
    pub shadow_blocked: u64,
    pub reflect: u64,
    pub refract: u64,
    pub total: u64,
    pub generations: Vec<GenerationStats>,
}

impl RayStats {
    /// Adds another part of the same render's (tiles of one image): every count, generation by
    /// generation.
    pub fn add(&mut self, o: &RayStats) {
        self.eye += o.eye;
        self.eye_hit += o.eye_hit;
        self.shadow += o.shadow;
        self.shadow_blocked += o.shadow_blocked;
        self.reflect += o.reflect;
        self.refract += o.refract;
        self.total += o.total;
        for g in &o.generations {
            match self
                .generations
                .iter_mut()
                .find(|x| x.generation == g.generation)
            {
                Some(x) => {
                    x.rays += g.rays;
                    x.hits += g.hits;
                    x.shadow += g.shadow;
                    x.shadow_blocked += g.shadow_blocked;
                    x.reflect += g.reflect;
                    x.refract += g.refract;
                    x.total_internal_reflections += g.total_internal_reflections;
                }
                None => self.generations.push(g.clone()),
            }
        }
        self.generations.sort_by_key(|g| g.generation);
    }
}

/// Every query of a render with its answer, for cross-checking another engine on the same rays.
#[derive(Default)]
pub struct Recording {
    pub closest: Vec<(Ray, Hit)>,
    pub any: Vec<(Ray, bool)>,
    /// The pixel corner each query belongs to (its ray tree), for `closest` and `any`.
    pub closest_corner: Vec<u32>,
    pub any_corner: Vec<u32>,
}

pub struct Render {
    /// Colour at each of the (size+1)² corners, row by row from the top; empty unless asked for
    /// ([`render_chunked`]'s `keep_corners`; the out-of-core tracer always keeps them).
    pub corners: Vec<Vec3>,
    /// The image ([`pixels_of`] of the corners), made band by band as the chunks finish.
    pub pixels: Vec<u8>,
    pub stats: RayStats,
    pub counters: Counters,
    pub intersect_s: f64,
    pub shade_s: f64,
    pub trace_s: f64,
    /// CPU seconds the trace used on our threads (the render's and the pool's).
    pub trace_cpu_s: f64,
    /// The trace as its span measured it (`trace_s` and `trace_cpu_s` are its wall and worker
    /// CPU seconds).
    pub sample: Sample,
}

impl Render {
    /// The image: each pixel the average of its four corners, 8-bit sRGB-less RGB.
    pub fn pixels(&self) -> &[u8] {
        &self.pixels
    }
}

/// The image of `size`² pixels from its (size+1)² corner colours: each pixel the average of its
/// four corners, 8-bit RGB.
pub fn pixels_of(size: u32, corners: &[Vec3]) -> Vec<u8> {
    let n = size as usize;
    let w = n + 1;
    let mut out = vec![0; n * n * 3];
    for (j, row) in out.chunks_exact_mut(n * 3).enumerate() {
        pixel_row(
            &corners[j * w..(j + 1) * w],
            &corners[(j + 1) * w..(j + 2) * w],
            row,
        );
    }
    out
}

/// One row of pixels from the corner rows above (`top`) and below it: each pixel the average
/// of its four corners. Never inlined, like [`trace_chunk`] (once per row).
#[inline(never)]
fn pixel_row(top: &[Vec3], bottom: &[Vec3], out: &mut [u8]) {
    for (i, px) in out.chunks_exact_mut(3).enumerate() {
        let c = (top[i] + top[i + 1] + bottom[i] + bottom[i + 1]) * 0.25;
        for (o, x) in px.iter_mut().zip([c.x, c.y, c.z]) {
            *o = (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        }
    }
}

/// Answers a batch of queries (`engine.intersect` or `engine.occluded`) split into chunks of
/// `batch` rays (the engine's [`Engine::batch_hint`]; `None`: all in one call, for engines that
/// answer a whole generation at once) over the pool's threads, each chunk with its own
/// counters, summed into `counters`. `out` is resized to the batch and filled with `fill` first.
pub(crate) fn query_all<T: Clone + Send>(
    batch: Option<usize>,
    rays: &[Ray],
    out: &mut Vec<T>,
    fill: T,
    counters: &mut Counters,
    query: impl Fn(&[Ray], &mut [T], &mut Counters) + Sync,
) {
    out.clear();
    out.resize(rays.len(), fill);
    let chunk = batch.unwrap_or(rays.len()).max(1);
    let sums: Vec<Counters> = rays
        .par_chunks(chunk)
        .zip(out.par_chunks_mut(chunk))
        .map(|(r, o)| {
            let mut c = Counters::default();
            query(r, o, &mut c);
            c
        })
        .collect();
    for c in &sums {
        counters.add(c);
    }
}

/// A secondary ray's origin: `p` moved off the surface along `n` (the self-intersection policy).
/// Each light's position and colour, scaled by SPD's light scale for renderers that do not scale:
/// 1/sqrt(number of lights).
pub(crate) fn scaled_lights(lights: &[rtbench_scenes::Light]) -> Vec<(Vec3, Vec3)> {
    let i = 1.0 / (lights.len() as f32).sqrt();
    lights
        .iter()
        .map(|l| {
            (
                l.position.as_vec3(),
                l.color.map(|c| c.as_vec3()).unwrap_or(Vec3::ONE) * i,
            )
        })
        .collect()
}

pub(crate) fn offset_origin(p: Vec3, n: Vec3) -> Vec3 {
    let scale = p.abs().max_element().max(OFFSET_MIN / OFFSET_REL) * OFFSET_REL;
    p + n * scale
}

/// Shades one hit (NFF Phong, SPD spawning rules; see the module's policies): returns the
/// ambient term for the ray's corner, emits a shadow ray with its gain per light the shading
/// normal faces, and the reflection and refraction rays of the next generation. Shared by the
/// in-memory tracer and the out-of-core one (`super::out_of_core`), so images agree.
#[allow(clippy::too_many_arguments)]
pub(crate) fn shade_hit(
    ray: &Ray,
    hit: &Hit,
    path: &Path,
    m: &Material,
    normals: (Vec3, Vec3),
    lights: &[(Vec3, Vec3)],
    g: &mut GenerationStats,
    shadow: &mut dyn FnMut(Ray, u32, Vec3),
    next: &mut dyn FnMut(Ray, Path),
) -> Vec3 {
    let color = m.color.as_vec3();
    let d = ray.dir;
    let p = ray.at(hit.t);
    let (mut ns, mut ng) = normals;
    if ng.dot(d) > 0.0 {
        ng = -ng;
        ns = -ns;
    }
    if ns.dot(d) > 0.0 {
        // A smooth normal turned away from the viewer: fall back to the facing flat one.
        ns = ng;
    }
    let above = offset_origin(p, ng);
    for (lp, lc) in lights {
        let to_light = *lp - p;
        if ns.dot(to_light) <= 0.0 {
            continue;
        }
        let dist = to_light.length();
        let l = to_light / dist;
        let diffuse = color * (m.kd as f32 * ns.dot(l));
        let h = (l - d).normalize_or_zero();
        let spec = if m.ks > 0.0 {
            m.ks as f32 * ns.dot(h).max(0.0).powf(m.shine as f32)
        } else {
            0.0
        };
        let gain = path.weight * *lc * (diffuse + Vec3::splat(spec));
        let o = above;
        shadow(
            Ray::new(o, l, 0.0, (*lp - o).length() * (1.0 - 1e-6)),
            path.corner,
            gain,
        );
    }
    // Ambient term for every object.
    let ambient = path.weight * color * 0.1;
    if path.depth >= MAX_DEPTH {
        return ambient;
    }
    let (ks, kt) = (m.ks as f32, m.t as f32);
    if ks > 0.0 || kt > 0.0 {
        let r = (d - ns * (2.0 * d.dot(ns))).normalize();
        let wr = if ks > 0.0 { ks } else { kt };
        next(
            Ray::new(above, r, 0.0, f32::INFINITY),
            Path {
                corner: path.corner,
                weight: path.weight * wr,
                depth: path.depth + 1,
                inside: path.inside,
            },
        );
        g.reflect += 1;
    }
    if kt > 0.0 {
        let ior = m.ior as f32;
        let inside = path.inside;
        let eta = if inside { ior } else { 1.0 / ior };
        let cos_i = -d.dot(ns);
        let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
        if k >= 0.0 {
            let t = (d * eta + ns * (eta * cos_i - k.sqrt())).normalize();
            next(
                Ray::new(offset_origin(p, -ng), t, 0.0, f32::INFINITY),
                Path {
                    corner: path.corner,
                    weight: path.weight * kt * color,
                    depth: path.depth + 1,
                    inside: !inside,
                },
            );
            g.refract += 1;
        } else {
            g.total_internal_reflections += 1;
        }
    }
    ambient
}

/// Pixel corners (rounded down to whole rows, at least one) whose ray trees one band of the
/// wavefront traces to the end before its thread starts another ([`render_chunked`]): one engine
/// batch ([`rtbench_engines::engine::DEFAULT_BATCH`]) of eye rays, so a band's generations hold
/// about 1 MB (rays, paths, hits, shadow rays) where a whole 512² generation held 32–96 MB.
pub const DEFAULT_CHUNK: usize = 4096;

/// Traces the SPD workload of `scene` with `engine` at `size`×`size` pixels, in chunks of
/// [`DEFAULT_CHUNK`] corners. With `record`, every query and its answer is kept.
pub fn render(
    scene: &Scene,
    engine: &dyn Engine,
    size: u32,
    record: Option<&mut Recording>,
) -> Render {
    render_chunked(scene, engine, size, DEFAULT_CHUNK, false, record)
}

// `RTBENCH_BANDS` (read once, in `measure::vars`) makes [`render_chunked`] print one line per
// band on stderr (its rows, thread, rays, engine counters and the thread's CPU seconds): how the
// trace's work is spread over bands and threads.

/// The buffers of one chunk's generations, reused from chunk to chunk on a thread.
#[derive(Default)]
struct Wavefront {
    /// The colours of the band's corners.
    corners: Vec<Vec3>,
    rays: Vec<Ray>,
    paths: Vec<Path>,
    hits: Vec<Hit>,
    blocked: Vec<bool>,
    shadow_rays: Vec<Ray>,
    shadow_gain: Vec<(u32, Vec3)>,
    next_rays: Vec<Ray>,
    next_paths: Vec<Path>,
}

/// What one chunk measured.
#[derive(Default)]
struct Part {
    stats: RayStats,
    counters: Counters,
    intersect_s: f64,
    shade_s: f64,
    /// Wall seconds of the whole chunk (to share the render's wall time among the phases when
    /// chunks run on several threads).
    wall_s: f64,
    record: Option<Recording>,
    /// The band's corner colours, when kept.
    corners: Vec<Vec3>,
}

/// The pixel row between two bands: made from the last corner row of the band above and the
/// first of the band below, each held here only until the other band finishes.
struct Seam<'a> {
    out: &'a mut [u8],
    above: Option<Vec<Vec3>>,
    below: Option<Vec<Vec3>>,
}

impl Seam<'_> {
    fn set_above(&mut self, row: &[Vec3]) {
        match self.below.take() {
            Some(below) => pixel_row(row, &below, self.out),
            None => self.above = Some(row.to_vec()),
        }
    }

    fn set_below(&mut self, row: &[Vec3]) {
        match self.above.take() {
            Some(above) => pixel_row(&above, row, self.out),
            None => self.below = Some(row.to_vec()),
        }
    }
}

/// What every chunk of one render reads.
struct Setup<'a> {
    scene: &'a Scene,
    engine: &'a dyn Engine,
    camera: Camera,
    surfaces: Surfaces,
    lights: Vec<(Vec3, Vec3)>,
    background: Vec3,
    size: u32,
    batch: Option<usize>,
}

/// Traces the SPD workload like [`render`], in bands of whole rows of pixel corners of about
/// `chunk` corners (at least one row; 0: all rows at once, whole generations as the SPD
/// procedure reads). A band's ray trees are traced generation by generation to the end, so only
/// one band's generations are held per thread, and its rows of pixels are made as it finishes;
/// bands run on the pool's threads. Engines that answer whole generations at once
/// ([`Engine::batch_hint`] `None`, the breadth-first engine with `batch=generation`) always get
/// whole generations. The
/// corner colours are kept (3.2 MB at 512²) only with `keep_corners`.
///
/// Chunking changes no answer and no colour: a corner's colour is the sum of its own ray tree's
/// terms, added in the same order (generation by generation, shading before shadows) whatever
/// else is traced, and the per-ray counters add up to the same totals. What can change is a
/// counter of state an engine keeps per batch (the grid's shadow cache starts empty in every
/// batch, and batches of later generations now start at band boundaries).
pub fn render_chunked(
    scene: &Scene,
    engine: &dyn Engine,
    size: u32,
    chunk: usize,
    keep_corners: bool,
    mut record: Option<&mut Recording>,
) -> Render {
    let span = Span::start(Workers::Pool);
    let batch = engine.batch_hint();
    let n = size as usize;
    let w = n + 1;
    let band_rows = match (batch, chunk) {
        (None, _) | (_, 0) => w,
        (_, c) => (c / w).clamp(1, w),
    };
    let setup = Setup {
        scene,
        engine,
        camera: Camera::new(&scene.view),
        surfaces: Surfaces::new(scene),
        lights: scaled_lights(&scene.lights),
        background: scene.background.as_vec3(),
        size,
        batch,
    };
    // Each band writes the pixel rows between its own corner rows; the row between two bands
    // (the seam) is made from the last corner row of the band above and the first of the band
    // below by whichever of the two finishes second, so only the edge rows of bands whose
    // neighbour is not yet done are held (on one thread: one row; all bands' edge rows were
    // 0.9 MiB at 512²).
    let mut pixels = vec![0u8; n * n * 3];
    let mut slices = Vec::new();
    let mut seams = Vec::new();
    let mut rest = pixels.as_mut_slice();
    for j0 in (0..w).step_by(band_rows) {
        let rows = band_rows.min(n.saturating_sub(j0));
        let (mine, more) = rest.split_at_mut(rows * n * 3);
        rest = more;
        // The band's last pixel row lies between its last corner row and the next band's first.
        let (inner, seam) = if j0 + band_rows < w && rows > 0 {
            mine.split_at_mut((rows - 1) * n * 3)
        } else {
            (mine, &mut [][..])
        };
        slices.push((slices.len(), j0, inner));
        if !seam.is_empty() {
            seams.push(Seam {
                out: seam,
                above: None,
                below: None,
            });
        }
    }
    let seams = Mutex::new(seams);
    let recording = record.is_some();
    let vars = crate::measure::vars::values();
    let bands = vars.bands;
    let sched = vars.sched;
    let sched_on = sched.is_some();
    // With RTBENCH_SCHED: each pool thread's scheduler counts before the region, and every
    // band's (thread, start, end) seconds from the region's start.
    let sched_start = Instant::now();
    let cpus_before = sched_on.then(crate::measure::sched::read_cpus);
    let process_before = sched_on.then(crate::measure::sched::process_threads);
    let sched_before = sched_on.then(|| rayon::broadcast(|_| crate::measure::sched::read_self()));
    // With RTBENCH_SCHED=bands also every band's line: its thread, the CPU it started and
    // ended on, and its start and end.
    let sched_bands = sched == Some(true);
    let band_times: Mutex<Vec<(usize, f64, f64)>> = Mutex::new(Vec::new());
    // One wavefront per pool thread, reused from band to band. A thread that runs a second band
    // while its first waits inside the engine's batches (rayon's join lets it) gets a fresh one.
    let threads = rayon::current_num_threads().max(1);
    let wavefronts: Vec<Mutex<Wavefront>> = (0..threads).map(|_| Mutex::default()).collect();
    let t = Instant::now();
    let parts: Vec<Part> = slices
        .into_par_iter()
        // One band per job. Left to itself rayon cuts an indexed iterator into about two
        // pieces per thread and splits a piece further only when another thread steals it, so
        // a piece's bands run in order on one thread and a thread that finished early could
        // take only pieces still queued, never bands of the piece being traced. The bands' work
        // is uneven (gears4 bvh8 at 512², one thread's CPU seconds per band: the first half of
        // the bands 39 % of the trace, one band up to 5.9 %): split in two halves, two threads
        // are bound at 1.65×; bands taken one by one as threads free up, at 1.99× (a
        // model from the per-band seconds). The order bands are traced in changes no answer.
        .with_max_len(1)
        .map(|(k, j0, out)| {
            let slot = rayon::current_thread_index().unwrap_or(0) % threads;
            let mut guard = match wavefronts[slot].try_lock() {
                Ok(g) => Some(g),
                Err(TryLockError::Poisoned(p)) => Some(p.into_inner()),
                Err(TryLockError::WouldBlock) => None,
            };
            let mut own = None;
            let wf: &mut Wavefront = match guard.as_deref_mut() {
                Some(wf) => wf,
                None => own.insert(Wavefront::default()),
            };
            let rows = band_rows.min(w - j0);
            let cpu = bands.then(crate::measure::clock::thread_cpu_seconds);
            let band_start = sched_on.then(|| (t.elapsed().as_secs_f64(), crate::measure::sched::cpu()));
            let mut part = trace_chunk(&setup, (j0 * w) as u32, rows * w, wf, recording);
            if let Some((s, cpu0)) = band_start {
                let e = t.elapsed().as_secs_f64();
                let i = rayon::current_thread_index().unwrap_or(usize::MAX);
                if sched_bands {
                    eprintln!(
                        "sched band {k} thread {i} cpu {cpu0} {} start_s {s:.6} end_s {e:.6}",
                        crate::measure::sched::cpu()
                    );
                }
                band_times
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push((i, s, e));
            }
            if let Some(cpu) = cpu {
                let c = &part.counters;
                eprintln!(
                    "band {k} rows {j0}+{rows} thread {} rays {} nodes {} boxes {} prims {} cells {} cpu_s {:.6}",
                    rayon::current_thread_index().unwrap_or(usize::MAX),
                    part.stats.total,
                    c.nodes_visited,
                    c.box_tests,
                    c.primitive_tests,
                    c.cells_visited,
                    crate::measure::clock::thread_cpu_seconds() - cpu
                );
            }
            for (j, row) in out.chunks_exact_mut(n * 3).take(rows - 1).enumerate() {
                pixel_row(
                    &wf.corners[j * w..(j + 1) * w],
                    &wf.corners[(j + 1) * w..(j + 2) * w],
                    row,
                );
            }
            let mut seams = seams.lock().unwrap_or_else(|e| e.into_inner());
            if k > 0 {
                seams[k - 1].set_below(&wf.corners[..w]);
            }
            if let Some(seam) = seams.get_mut(k) {
                seam.set_above(&wf.corners[(rows - 1) * w..rows * w]);
            }
            drop(seams);
            if keep_corners {
                part.corners = wf.corners.clone();
            }
            part
        })
        .collect();
    let region_s = t.elapsed().as_secs_f64();
    if let (Some(before), Some(cpus), Some(process)) = (sched_before, cpus_before, process_before) {
        print_sched(
            &before,
            &cpus,
            &process,
            sched_start,
            &band_times.into_inner().unwrap_or_default(),
        );
    }
    debug_assert!(seams
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .iter()
        .all(|s| s.above.is_none() && s.below.is_none()));

    let mut stats = RayStats::default();
    let mut counters = Counters::default();
    let mut corners = Vec::new();
    let (mut intersect_s, mut shade_s, mut chunks_s) = (0.0, 0.0, 0.0);
    for p in parts {
        stats.add(&p.stats);
        counters.add(&p.counters);
        intersect_s += p.intersect_s;
        shade_s += p.shade_s;
        chunks_s += p.wall_s;
        corners.extend(p.corners);
        if let (Some(rec), Some(r)) = (record.as_deref_mut(), p.record) {
            rec.closest.extend(r.closest);
            rec.any.extend(r.any);
            rec.closest_corner.extend(r.closest_corner);
            rec.any_corner.extend(r.any_corner);
        }
    }
    // Bands on several threads overlap: their phases' seconds are shared out of the wall time
    // in proportion (one thread: the sum of the bands' seconds fits the wall time already).
    let share = if chunks_s > region_s {
        region_s / chunks_s
    } else {
        1.0
    };
    let sample = span.stop();
    Render {
        corners,
        pixels,
        stats,
        counters,
        intersect_s: intersect_s * share,
        shade_s: shade_s * share,
        trace_s: sample.wall_s,
        trace_cpu_s: sample.thread_cpu_s,
        sample,
    }
}

/// The `sched` lines of `RTBENCH_SCHED`: each pool thread's scheduler counts over
/// the parallel region (`before`: read by each thread at the region's start, in thread order,
/// after `start`; the wall seconds are from `start` to when every thread has read its counts
/// again) and its bands' wall seconds (`band_times`: thread, start, end).
fn print_sched(
    before: &[Option<crate::measure::sched::ThreadSched>],
    cpus: &[(usize, [u64; 8])],
    process: &[(i64, u64)],
    start: Instant,
    band_times: &[(usize, f64, f64)],
) {
    let after = rayon::broadcast(|_| crate::measure::sched::read_self());
    let region_s = start.elapsed().as_secs_f64();
    let pool: Vec<i64> = after.iter().flatten().map(|t| t.tid).collect();
    eprintln!(
        "{}",
        crate::measure::sched::process_line(
            process,
            &crate::measure::sched::process_threads(),
            &pool
        )
    );
    for l in crate::measure::sched::cpu_lines(cpus, &crate::measure::sched::read_cpus()) {
        eprintln!("{l}");
    }
    for (i, (b, a)) in before.iter().zip(&after).enumerate() {
        let (Some(b), Some(a)) = (b, a) else {
            eprintln!("sched thread {i} unavailable (no /proc/thread-self/schedstat)");
            continue;
        };
        let mine: Vec<(f64, f64)> = band_times
            .iter()
            .filter(|x| x.0 == i)
            .map(|x| (x.1, x.2))
            .collect();
        let last = mine.iter().map(|x| x.1).fold(0.0, f64::max);
        eprintln!(
            "{}",
            crate::measure::sched::line(
                i,
                region_s,
                &a.since(b),
                mine.len(),
                crate::measure::sched::covered_seconds(&mine),
                last
            )
        );
    }
}

/// Traces the ray trees of the corners `first..first + count` to the end, their colours into
/// `wf.corners`. Never inlined (once per band, so no cost): a profile then shows the bands'
/// work apart from the serial rest of [`render_chunked`].
#[inline(never)]
fn trace_chunk(s: &Setup, first: u32, count: usize, wf: &mut Wavefront, recording: bool) -> Part {
    let t_chunk = Instant::now();
    let w = s.size + 1;
    let mut part = Part {
        record: recording.then(Recording::default),
        ..Default::default()
    };
    wf.corners.clear();
    wf.corners.resize(count, Vec3::ZERO);
    let corners = &mut wf.corners;
    wf.rays.clear();
    wf.paths.clear();
    for corner in first..first + count as u32 {
        wf.rays
            .push(s.camera.corner_ray(corner % w, corner / w, s.size));
        wf.paths.push(Path {
            corner,
            weight: Vec3::ONE,
            depth: 1,
            inside: false,
        });
    }
    let stats = &mut part.stats;
    let counters = &mut part.counters;
    let mut generation = 0;
    while !wf.rays.is_empty() {
        generation += 1;
        let mut g = GenerationStats {
            generation,
            rays: wf.rays.len() as u64,
            ..Default::default()
        };
        let t0 = Instant::now();
        query_all(
            s.batch,
            &wf.rays,
            &mut wf.hits,
            Hit::MISS,
            counters,
            |r, h, c| s.engine.intersect(r, h, c),
        );
        part.intersect_s += t0.elapsed().as_secs_f64();
        if let Some(rec) = part.record.as_mut() {
            rec.closest
                .extend(wf.rays.iter().copied().zip(wf.hits.iter().copied()));
            rec.closest_corner.extend(wf.paths.iter().map(|p| p.corner));
        }

        let t1 = Instant::now();
        wf.shadow_rays.clear();
        wf.shadow_gain.clear();
        wf.next_rays.clear();
        wf.next_paths.clear();
        for ((ray, hit), path) in wf.rays.iter().zip(&wf.hits).zip(&wf.paths) {
            let at = (path.corner - first) as usize;
            if !hit.is_hit() {
                corners[at] += path.weight * s.background;
                continue;
            }
            g.hits += 1;
            let m = &s.scene.materials[s.surfaces.material[hit.object as usize] as usize];
            let p = ray.at(hit.t);
            let normals = s.surfaces.normals(hit, p);
            corners[at] += shade_hit(
                ray,
                hit,
                path,
                m,
                normals,
                &s.lights,
                &mut g,
                &mut |r, corner, gain| {
                    wf.shadow_rays.push(r);
                    wf.shadow_gain.push((corner, gain));
                },
                &mut |r, p| {
                    wf.next_rays.push(r);
                    wf.next_paths.push(p);
                },
            );
        }
        part.shade_s += t1.elapsed().as_secs_f64();

        let t2 = Instant::now();
        query_all(
            s.batch,
            &wf.shadow_rays,
            &mut wf.blocked,
            false,
            counters,
            |r, o, c| s.engine.occluded(r, o, c),
        );
        part.intersect_s += t2.elapsed().as_secs_f64();
        if let Some(rec) = part.record.as_mut() {
            rec.any.extend(
                wf.shadow_rays
                    .iter()
                    .copied()
                    .zip(wf.blocked.iter().copied()),
            );
            rec.any_corner
                .extend(wf.shadow_gain.iter().map(|(c, _)| *c));
        }
        let t3 = Instant::now();
        g.shadow = wf.shadow_rays.len() as u64;
        for ((corner, gain), b) in wf.shadow_gain.iter().zip(&wf.blocked) {
            if *b {
                g.shadow_blocked += 1;
            } else {
                corners[(*corner - first) as usize] += *gain;
            }
        }
        part.shade_s += t3.elapsed().as_secs_f64();

        if generation == 1 {
            stats.eye = g.rays;
            stats.eye_hit = g.hits;
        }
        stats.shadow += g.shadow;
        stats.shadow_blocked += g.shadow_blocked;
        stats.reflect += g.reflect;
        stats.refract += g.refract;
        stats.total += g.rays + g.shadow;
        stats.generations.push(g);
        std::mem::swap(&mut wf.rays, &mut wf.next_rays);
        std::mem::swap(&mut wf.paths, &mut wf.next_paths);
    }
    part.wall_s = t_chunk.elapsed().as_secs_f64();
    part
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtbench_engines::geometry::Geometry;
    use rtbench_engines::{build_engine, BuildInput};
    use rtbench_scenes::generate_scene;
    use rtbench_scenes::spd::{Options, Program};
    use std::sync::Arc;

    fn input(p: Program, sf: u32) -> BuildInput {
        let scene = generate_scene(
            p,
            &Options {
                size_factor: sf,
                ..Options::standard(p)
            },
        )
        .unwrap();
        BuildInput {
            geometry: Arc::new(Geometry::from_scene(&scene)),
            scene: Arc::new(scene),
        }
    }

    /// Bands of one row, of several rows with a short last band, and whole generations give the
    /// same image, corner colours to the bit, ray statistics and per-ray counters (balls: a
    /// reflective scene, so several generations per band).
    #[test]
    fn chunks_change_no_colour_and_no_count() {
        let inp = input(Program::Balls, 1);
        let e = build_engine("bvh8", &inp, vec![]).unwrap();
        let size = 40;
        let whole = render_chunked(&inp.scene, e.as_ref(), size, 0, true, None);
        assert_eq!(whole.pixels, pixels_of(size, &whole.corners));
        assert!(whole.stats.generations.len() > 2);
        for chunk in [1, 41, 3 * 41, 7 * 41 + 5, 100_000] {
            let r = render_chunked(&inp.scene, e.as_ref(), size, chunk, true, None);
            assert_eq!(r.corners, whole.corners, "chunk {chunk}");
            assert_eq!(r.pixels, whole.pixels, "chunk {chunk}");
            assert_eq!(r.stats, whole.stats, "chunk {chunk}");
            assert_eq!(r.counters, whole.counters, "chunk {chunk}");
        }
        let r = render(&inp.scene, e.as_ref(), size, None);
        assert!(r.corners.is_empty());
        assert_eq!(r.pixels, whole.pixels);
    }

    /// Bands traced on two threads (taken one by one, in whatever order the threads free up)
    /// give what one thread gives: corner colours, image, ray statistics, counters.
    #[test]
    fn threads_change_no_colour_and_no_count() {
        let inp = input(Program::Balls, 1);
        let e = build_engine("bvh8", &inp, vec![]).unwrap();
        let on = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| render_chunked(&inp.scene, e.as_ref(), 40, 41, true, None))
        };
        let (one, two) = (on(1), on(2));
        assert_eq!(one.corners, two.corners);
        assert_eq!(one.pixels, two.pixels);
        assert_eq!(one.stats, two.stats);
        assert_eq!(one.counters, two.counters);
    }

    /// A recording holds every query once, whatever the chunks.
    #[test]
    fn chunked_recording_holds_every_query() {
        let inp = input(Program::Tetra, 2);
        let e = build_engine("bvh4", &inp, vec![]).unwrap();
        let mut rec = Recording::default();
        let r = render_chunked(&inp.scene, e.as_ref(), 24, 50, false, Some(&mut rec));
        assert_eq!(rec.closest.len() as u64, r.stats.total - r.stats.shadow);
        assert_eq!(rec.any.len() as u64, r.stats.shadow);
        assert_eq!(rec.closest_corner.len(), rec.closest.len());
        assert_eq!(rec.any_corner.len(), rec.any.len());
    }
}
