//! The SPD workload, traced as wavefront generations (../shared/SPD.md, "The testing
//! procedure"): all rays of one depth are answered as batches by the engine before shading makes
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
use glam::Vec3;
use rayon::prelude::*;
use rtbench_engines::{Counters, Engine, Hit, Ray};
use rtbench_scenes::{Material, Scene};
use serde::Serialize;
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
    pub size: u32,
    /// Colour at each of the (size+1)² corners, row by row from the top.
    pub corners: Vec<Vec3>,
    pub stats: RayStats,
    pub counters: Counters,
    pub intersect_s: f64,
    pub shade_s: f64,
    pub trace_s: f64,
    /// CPU seconds the trace used on our threads (the render's and the pool's).
    pub trace_cpu_s: f64,
}

impl Render {
    /// The image: each pixel the average of its four corners, 8-bit sRGB-less RGB.
    pub fn pixels(&self) -> Vec<u8> {
        pixels_of(self.size, &self.corners)
    }
}

/// The image of `size`² pixels from its (size+1)² corner colours: each pixel the average of its
/// four corners, 8-bit RGB.
pub fn pixels_of(size: u32, corners: &[Vec3]) -> Vec<u8> {
    let n = size as usize;
    let w = n + 1;
    let mut out = Vec::with_capacity(n * n * 3);
    for j in 0..n {
        for i in 0..n {
            let c = (corners[j * w + i]
                + corners[j * w + i + 1]
                + corners[(j + 1) * w + i]
                + corners[(j + 1) * w + i + 1])
                * 0.25;
            for x in [c.x, c.y, c.z] {
                out.push((x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8);
            }
        }
    }
    out
}

/// CPU seconds spent by pool threads other than the render's own (whose time the render
/// measures as a whole), so nothing is counted twice.
fn other_thread_cpu(me: Option<usize>, work: impl FnOnce()) -> f64 {
    let c0 = super::thread_cpu_seconds();
    work();
    if rayon::current_thread_index() != me {
        super::thread_cpu_seconds() - c0
    } else {
        0.0
    }
}

/// Answers a batch of queries (`engine.intersect` or `engine.occluded`) split into chunks of
/// `batch` rays (the engine's [`Engine::batch_hint`]; `None`: all in one call, for engines that
/// answer a whole generation at once) over the pool's threads, each chunk with its own
/// counters, summed into `counters`. `out` is resized to the batch and filled with `fill` first.
/// Returns the CPU seconds used on threads other than the caller's.
pub(crate) fn query_all<T: Clone + Send>(
    batch: Option<usize>,
    rays: &[Ray],
    out: &mut Vec<T>,
    fill: T,
    counters: &mut Counters,
    query: impl Fn(&[Ray], &mut [T], &mut Counters) + Sync,
) -> f64 {
    out.clear();
    out.resize(rays.len(), fill);
    let me = rayon::current_thread_index();
    let chunk = batch.unwrap_or(rays.len()).max(1);
    let sums: Vec<(Counters, f64)> = rays
        .par_chunks(chunk)
        .zip(out.par_chunks_mut(chunk))
        .map(|(r, o)| {
            let mut c = Counters::default();
            let cpu = other_thread_cpu(me, || query(r, o, &mut c));
            (c, cpu)
        })
        .collect();
    let mut cpu = 0.0;
    for (c, t) in &sums {
        counters.add(c);
        cpu += t;
    }
    cpu
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

/// Traces the SPD workload of `scene` with `engine` at `size`×`size` pixels. With `record`,
/// every query and its answer is kept.
pub fn render(
    scene: &Scene,
    engine: &dyn Engine,
    size: u32,
    mut record: Option<&mut Recording>,
) -> Render {
    let start = Instant::now();
    let cpu_start = super::thread_cpu_seconds();
    let mut other_cpu = 0.0;
    let batch = engine.batch_hint();
    let camera = Camera::new(&scene.view);
    let surfaces = Surfaces::new(scene);
    let w = size + 1;
    let n_corners = (w as usize) * (w as usize);
    let mut corners = vec![Vec3::ZERO; n_corners];
    let background = scene.background.as_vec3();
    let lights = scaled_lights(&scene.lights);

    let mut rays: Vec<Ray> = Vec::with_capacity(n_corners);
    let mut paths: Vec<Path> = Vec::with_capacity(n_corners);
    for j in 0..w {
        for i in 0..w {
            rays.push(camera.corner_ray(i, j, size));
            paths.push(Path {
                corner: j * w + i,
                weight: Vec3::ONE,
                depth: 1,
                inside: false,
            });
        }
    }

    let mut stats = RayStats::default();
    let mut counters = Counters::default();
    let mut hits = Vec::new();
    let mut blocked = Vec::new();
    let mut shadow_rays: Vec<Ray> = Vec::new();
    let mut shadow_gain: Vec<(u32, Vec3)> = Vec::new();
    let mut next_rays = Vec::new();
    let mut next_paths = Vec::new();
    let (mut intersect_s, mut shade_s) = (0.0, 0.0);
    let mut generation = 0;

    while !rays.is_empty() {
        generation += 1;
        let mut g = GenerationStats {
            generation,
            rays: rays.len() as u64,
            ..Default::default()
        };
        let t0 = Instant::now();
        other_cpu += query_all(
            batch,
            &rays,
            &mut hits,
            Hit::MISS,
            &mut counters,
            |r, h, c| engine.intersect(r, h, c),
        );
        intersect_s += t0.elapsed().as_secs_f64();
        if let Some(rec) = record.as_deref_mut() {
            rec.closest
                .extend(rays.iter().copied().zip(hits.iter().copied()));
            rec.closest_corner.extend(paths.iter().map(|p| p.corner));
        }

        let t1 = Instant::now();
        shadow_rays.clear();
        shadow_gain.clear();
        next_rays.clear();
        next_paths.clear();
        for ((ray, hit), path) in rays.iter().zip(&hits).zip(&paths) {
            if !hit.is_hit() {
                corners[path.corner as usize] += path.weight * background;
                continue;
            }
            g.hits += 1;
            let m = &scene.materials[surfaces.material[hit.object as usize] as usize];
            let p = ray.at(hit.t);
            let normals = surfaces.normals(hit, p);
            corners[path.corner as usize] += shade_hit(
                ray,
                hit,
                path,
                m,
                normals,
                &lights,
                &mut g,
                &mut |r, corner, gain| {
                    shadow_rays.push(r);
                    shadow_gain.push((corner, gain));
                },
                &mut |r, p| {
                    next_rays.push(r);
                    next_paths.push(p);
                },
            );
        }
        shade_s += t1.elapsed().as_secs_f64();

        let t2 = Instant::now();
        other_cpu += query_all(
            batch,
            &shadow_rays,
            &mut blocked,
            false,
            &mut counters,
            |r, o, c| engine.occluded(r, o, c),
        );
        intersect_s += t2.elapsed().as_secs_f64();
        if let Some(rec) = record.as_deref_mut() {
            rec.any
                .extend(shadow_rays.iter().copied().zip(blocked.iter().copied()));
            rec.any_corner.extend(shadow_gain.iter().map(|(c, _)| *c));
        }
        let t3 = Instant::now();
        g.shadow = shadow_rays.len() as u64;
        for ((corner, gain), b) in shadow_gain.iter().zip(&blocked) {
            if *b {
                g.shadow_blocked += 1;
            } else {
                corners[*corner as usize] += *gain;
            }
        }
        shade_s += t3.elapsed().as_secs_f64();

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
        std::mem::swap(&mut rays, &mut next_rays);
        std::mem::swap(&mut paths, &mut next_paths);
    }

    Render {
        size,
        corners,
        stats,
        counters,
        intersect_s,
        shade_s,
        trace_s: start.elapsed().as_secs_f64(),
        trace_cpu_s: super::thread_cpu_seconds() - cpu_start + other_cpu,
    }
}
