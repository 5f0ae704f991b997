//! 003's own ray-tracing pass on the object-space machine (Yamauchi 1997, §2.4.2): one primary
//! ray through each pixel centre, at most 3 reflections (transmission traced as specular, as
//! 003 does, and counted with them), no shadow rays, and at every hit an intensity packet added
//! into the frame buffer. Nothing flows back along the ray tree: a secondary ray carries its
//! weight (the product of the reflection coefficients on its way) as its history.
//!
//! 003 takes the diffuse term G from its radiosity pass: given a radiosity solution (per scene
//! object, `diffuse`), a hit's intensity is the patch's radiosity (times the image's exposure),
//! and specular elements add only what their reflections bring (I = G + k_s S). Without one (the
//! SPD scenes, which have no emitters), the intensity of a hit is the NFF ambient and unshadowed
//! diffuse and specular terms, which is what a packet carries and what the image shows (an
//! image of its own, not the SPD's).
//!
//! The rays are executed on the engine for real, generation by generation (in parallel, in
//! fixed chunks, so the record is the same on any number of threads), and recorded as a
//! [`Trace`] for the timing simulation, parents before children.

use crate::workload::camera::Camera;
use crate::workload::surface::Surfaces;
use crate::workload::trace::offset_origin;
use glam::Vec3;
use rayon::prelude::*;
use rtbench_engines::object_space::trace::{Segment, Trace, TracedRay, NO_PIXEL};
use rtbench_engines::object_space::ObjectSpace;
use rtbench_engines::{Counters, Hit, Ray};
use rtbench_scenes::Scene;

/// Reflections (and refractions) after the primary ray: 003's Table 6.
pub const MAX_REFLECTIONS: u8 = 3;
const CHUNK: usize = 2048;

/// One chunk of a generation, executed: its segments, each ray's hit and segment count, and the
/// engine's counters.
type Executed = (Vec<Segment>, Vec<(Hit, u32)>, Counters);

/// 003's pass, traced: the record, the image it accumulates, and ray counts.
pub struct Pass {
    pub size: u32,
    pub trace: Trace,
    /// Intensity per pixel, row by row from the top.
    pub image: Vec<Vec3>,
    pub primary: u64,
    pub secondary: u64,
    pub intensity_packets: u64,
    pub counters: Counters,
}

impl Pass {
    /// A pass of no rays (stands for the radiosity pass, which has no fixed record).
    pub fn empty(size: u32) -> Pass {
        Pass {
            size,
            trace: Trace::default(),
            image: Vec::new(),
            primary: 0,
            secondary: 0,
            intensity_packets: 0,
            counters: Counters::default(),
        }
    }

    /// 8-bit RGB.
    pub fn pixels(&self) -> Vec<u8> {
        self.image
            .iter()
            .flat_map(|c| [c.x, c.y, c.z])
            .map(|x| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8)
            .collect()
    }
}

#[derive(Clone, Copy)]
struct Path {
    pixel: u32,
    weight: Vec3,
    reflections: u8,
    inside: bool,
}

pub fn trace_pass(os: &ObjectSpace, scene: &Scene, size: u32, diffuse: Option<&[Vec3]>) -> Pass {
    let camera = Camera::new(&scene.view);
    let surfaces = Surfaces::new(scene);
    let lights = crate::workload::trace::scaled_lights(&scene.lights);
    let mut rays = camera.pixel_centre_rays(size, size);
    let mut paths: Vec<Path> = (0..rays.len() as u32)
        .map(|pixel| Path {
            pixel,
            weight: Vec3::ONE,
            reflections: 0,
            inside: false,
        })
        .collect();
    let mut pass = Pass {
        size,
        trace: Trace::default(),
        image: vec![Vec3::ZERO; rays.len()],
        primary: rays.len() as u64,
        secondary: 0,
        intensity_packets: 0,
        counters: Counters::default(),
    };
    let mut root = true;
    while !rays.is_empty() {
        // Execute the generation: per chunk, its segments and each ray's (hit, segment count).
        let chunks: Vec<Executed> = rays
            .par_chunks(CHUNK)
            .map(|chunk| {
                let (mut segs, mut out, mut c) = (Vec::new(), Vec::new(), Counters::default());
                for r in chunk {
                    let n = segs.len();
                    let h = os.execute(r, false, &mut segs, &mut c);
                    out.push((h, (segs.len() - n) as u32));
                }
                (segs, out, c)
            })
            .collect();
        let base = pass.trace.rays.len() as u32;
        let next_base = base + rays.len() as u32;
        let mut next_rays = Vec::new();
        let mut next_paths = Vec::new();
        let mut i = 0;
        for (segs, out, c) in chunks {
            pass.counters.add(&c);
            let mut seg_start = pass.trace.segs.len() as u32;
            pass.trace.segs.extend_from_slice(&segs);
            for (hit, seg_count) in out {
                let (ray, path) = (rays[i], paths[i]);
                i += 1;
                let first_child = next_base + next_rays.len() as u32;
                let mut traced = TracedRay {
                    seg_start,
                    seg_count,
                    first_child,
                    children: 0,
                    pixel: NO_PIXEL,
                    root,
                    initial: root,
                    hit: hit.is_hit(),
                };
                seg_start += seg_count;
                if hit.is_hit() {
                    traced.pixel = path.pixel;
                    pass.intensity_packets += 1;
                    let children = shade(
                        &surfaces,
                        scene,
                        &lights,
                        diffuse,
                        &ray,
                        &hit,
                        &path,
                        &mut pass.image,
                        &mut next_rays,
                        &mut next_paths,
                    );
                    traced.children = children;
                }
                pass.trace.rays.push(traced);
            }
        }
        debug_assert_eq!(pass.trace.rays.len() as u32, next_base);
        pass.secondary += next_rays.len() as u64;
        rays = next_rays;
        paths = next_paths;
        root = false;
    }
    pass
}

/// The ICU and the SRGU at one hit: adds the intensity to the pixel, pushes the reflection and
/// refraction rays, and says how many it made.
#[allow(clippy::too_many_arguments)]
fn shade(
    surfaces: &Surfaces,
    scene: &Scene,
    lights: &[(Vec3, Vec3)],
    diffuse: Option<&[Vec3]>,
    ray: &Ray,
    hit: &Hit,
    path: &Path,
    image: &mut [Vec3],
    next_rays: &mut Vec<Ray>,
    next_paths: &mut Vec<Path>,
) -> u32 {
    let m = &scene.materials[surfaces.material[hit.object as usize] as usize];
    let color = m.color.as_vec3();
    let d = ray.dir;
    let p = ray.at(hit.t);
    let (mut ns, mut ng) = surfaces.normals(hit, p);
    if ng.dot(d) > 0.0 {
        ng = -ng;
        ns = -ns;
    }
    if ns.dot(d) > 0.0 {
        ns = ng;
    }
    let mut intensity = color * 0.1;
    if let Some(g) = diffuse {
        intensity = g[hit.object as usize];
    }
    for (lp, lc) in lights.iter().filter(|_| diffuse.is_none()) {
        let l = (*lp - p).normalize_or_zero();
        let cos = ns.dot(l);
        if cos <= 0.0 {
            continue;
        }
        let h = (l - d).normalize_or_zero();
        let spec = if m.ks > 0.0 {
            m.ks as f32 * ns.dot(h).max(0.0).powf(m.shine as f32)
        } else {
            0.0
        };
        intensity += *lc * (color * (m.kd as f32 * cos) + Vec3::splat(spec));
    }
    image[path.pixel as usize] += path.weight * intensity;
    if path.reflections >= MAX_REFLECTIONS {
        return 0;
    }
    let (ks, kt) = (m.ks as f32, m.t as f32);
    let mut made = 0;
    let above = offset_origin(p, ng);
    if ks > 0.0 || kt > 0.0 {
        let r = (d - ns * (2.0 * d.dot(ns))).normalize();
        next_rays.push(Ray::new(above, r, 0.0, f32::INFINITY));
        next_paths.push(Path {
            weight: path.weight * if ks > 0.0 { ks } else { kt },
            reflections: path.reflections + 1,
            ..*path
        });
        made += 1;
    }
    if kt > 0.0 {
        let eta = if path.inside {
            m.ior as f32
        } else {
            1.0 / m.ior as f32
        };
        let cos_i = -d.dot(ns);
        let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
        if k >= 0.0 {
            let t = (d * eta + ns * (eta * cos_i - k.sqrt())).normalize();
            next_rays.push(Ray::new(offset_origin(p, -ng), t, 0.0, f32::INFINITY));
            next_paths.push(Path {
                weight: path.weight * kt * color,
                reflections: path.reflections + 1,
                inside: !path.inside,
                ..*path
            });
            made += 1;
        }
    }
    made
}
