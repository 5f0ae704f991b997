//! The SPD workload for a scene store, never holding the scene (seed 000 §3.4, Algorithm 3.6,
//! with the improved method's lazy geometry loading, §4.2.2 "G"): the breadth-first engine
//! answers each generation streamed from a spill file, and shading reads the geometry file
//! forward only.
//!
//! Per generation:
//! 1. The generation's rays (ray, corner, weight, depth, medium) are in a spill file, in the order
//!    the in-memory tracer makes them.
//! 2. The engine reads them sequentially and gives hit records (ray id, object, t, u, v) in the
//!    order rays finish; they are spilled into one file per group of ray ids (a one-pass bucket
//!    sort: the thesis's sort by ray id), each group's then filed by id. A group is as many rays
//!    as the engine holds in memory at once ([`shade_group`]), at least [`MIN_GROUP`].
//! 3. Shading takes the rays group by group, read sequentially; each group's hits
//!    are sorted by object id and the bounding-box and geometry files read forward only (the
//!    split layout seeks to each object hit, Algorithm 4.4), loading just the objects hit (Algorithm 3.6, "join" of hit records and scene). What
//!    shading emits is put back in ray order before it is written (the thesis's second sort),
//!    so the next generation's file, the shadow rays and the image's sums come in the same order
//!    as in memory, and the image is the in-memory tracer's to the bit.
//! 4. Shadow rays go to their own spill file, are answered by the engine (one byte per ray), and
//!    their gains added in order.
//!
//! What is held: the image (12 bytes per pixel corner), one byte per shadow ray, a group of rays
//! and their hit records, one small buffer per hit-record file, and the engine within its budget.

use super::camera::Camera;
use super::trace::{shade_hit, GenerationStats, Path, RayStats, Render, MAX_DEPTH};
use glam::Vec3;
use rtbench_engines::breadth_first::spill::SpillDir;
use rtbench_engines::breadth_first::BreadthFirst;
use rtbench_engines::store::{Codec, IoCounters, IoFile, ObjectRecord, SceneReader};
use rtbench_engines::{Counters, Hit, Ray};
use std::io;
use std::path::{Path as FsPath, PathBuf};
use std::time::Instant;

/// The fewest rays shaded per group: below it the hit-record files (one per group, each with
/// its buffer) would outnumber what the group saves.
pub const MIN_GROUP: usize = 1 << 14;

/// What a shading group may hold, on top of the engine's budget (whose rays the engine keeps
/// between generations): with the image and the process itself, a run stays within the
/// engine's budget + 64 MiB (Table 4.1's bound: 320 MiB at 256 MiB).
pub const SHADE_BYTES: usize = 24 << 20;

/// Bytes a shading group holds per ray with `lights` lights: the ray and its path, its term,
/// hit and place in the object order, and what shading may emit for it (a reflected and a
/// refracted ray, one shadow ray per light).
pub fn shade_bytes_per_ray(lights: usize) -> usize {
    use std::mem::size_of;
    size_of::<(Ray, Path)>()
        + size_of::<Vec3>()
        + size_of::<Hit>()
        + size_of::<u32>()
        + 2 * size_of::<(u32, Ray, Path)>()
        + lights * size_of::<(u32, Ray, u32, Vec3)>()
}

/// Rays shaded per group: Algorithm 3.6's "while memory not full of rays", the rays the engine
/// holds in memory at once within its budget, as far as [`SHADE_BYTES`] holds them, and at least
/// [`MIN_GROUP`]. The basic layout reads the store forward once per group up to the last object
/// hit, so at 10^9 objects (rings368's 35 GB store: 284 s a read, measured) the group's size
/// sets the shading time: a fixed 16,384 makes the 263,169 eye rays of a 512² image 17 sweeps,
/// rings368's 41,213 rays a pass 7. Without the byte cap, gears18's and rings94's peak RSS
/// passed the 320 MiB bound (331.5 and 358.2 MiB, measured).
pub fn shade_group(engine: &BreadthFirst, lights: usize) -> usize {
    engine
        .ray_capacity()
        .min(SHADE_BYTES / shade_bytes_per_ray(lights))
        .max(MIN_GROUP)
}

/// Bytes of one ray record of a generation file, and of a shadow record.
const RAY_RECORD: usize = 52;
const SHADOW_RECORD: usize = 48;
const HIT_RECORD: usize = 20;
/// Buffer of each hit-record file (one per group of the generation).
const HIT_BUFFER: usize = 16 << 10;

fn encode_hit(id: u32, h: &Hit) -> [u8; HIT_RECORD] {
    let mut b = [0u8; HIT_RECORD];
    b[..4].copy_from_slice(&id.to_le_bytes());
    b[4..8].copy_from_slice(&h.t.to_le_bytes());
    b[8..12].copy_from_slice(&h.object.to_le_bytes());
    b[12..16].copy_from_slice(&h.u.to_le_bytes());
    b[16..].copy_from_slice(&h.v.to_le_bytes());
    b
}

fn decode_hit(b: &[u8]) -> (u32, Hit) {
    let u = |i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap());
    (
        u(0),
        Hit {
            t: f32::from_bits(u(4)),
            object: u(8),
            u: f32::from_bits(u(12)),
            v: f32::from_bits(u(16)),
        },
    )
}

pub struct OutOfCoreRender {
    pub render: Render,
    /// The workload's own spill and shading I/O (the engine's is in `render.counters`).
    pub io: IoCounters,
    /// Rays per shading group ([`shade_group`]), and the groups shaded that had a hit: each is
    /// one forward read of the store (the basic layout reads every object up to the last hit).
    pub shade_group: usize,
    pub shade_sweeps: u64,
    /// The most rays [`SHADE_BYTES`] holds in a group with this scene's lights.
    pub shade_cap: usize,
}

fn put_ray(b: &mut Vec<u8>, r: &Ray) {
    for x in [
        r.origin.x, r.origin.y, r.origin.z, r.tmin, r.dir.x, r.dir.y, r.dir.z, r.tmax,
    ] {
        b.extend_from_slice(&x.to_le_bytes());
    }
}

fn get_f32(b: &[u8], i: usize) -> f32 {
    f32::from_le_bytes(b[4 * i..4 * i + 4].try_into().unwrap())
}

fn get_ray(b: &[u8]) -> Ray {
    let f = |i| get_f32(b, i);
    Ray::new(
        Vec3::new(f(0), f(1), f(2)),
        Vec3::new(f(4), f(5), f(6)),
        f(3),
        f(7),
    )
}

fn encode_path(r: &Ray, p: &Path) -> [u8; RAY_RECORD] {
    let mut b = Vec::with_capacity(RAY_RECORD);
    put_ray(&mut b, r);
    b.extend_from_slice(&p.corner.to_le_bytes());
    for x in p.weight.to_array() {
        b.extend_from_slice(&x.to_le_bytes());
    }
    b.extend_from_slice(&[p.depth, p.inside as u8, 0, 0]);
    b.try_into().unwrap()
}

fn decode_path(b: &[u8]) -> (Ray, Path) {
    let corner = u32::from_le_bytes(b[32..36].try_into().unwrap());
    let f = |i| get_f32(b, i);
    (
        get_ray(b),
        Path {
            corner,
            weight: Vec3::new(f(9), f(10), f(11)),
            depth: b[48],
            inside: b[49] != 0,
        },
    )
}

fn encode_shadow(r: &Ray, corner: u32, gain: Vec3) -> [u8; SHADOW_RECORD] {
    let mut b = Vec::with_capacity(SHADOW_RECORD);
    put_ray(&mut b, r);
    b.extend_from_slice(&corner.to_le_bytes());
    for x in gain.to_array() {
        b.extend_from_slice(&x.to_le_bytes());
    }
    b.try_into().unwrap()
}

/// A spill file of fixed-size records: written once, then read forward (twice).
struct Records {
    path: PathBuf,
    len: u64,
    buffer: usize,
    codec: Codec,
    writer: Option<IoFile>,
    io: IoCounters,
}

impl Records {
    fn create(dir: &FsPath, name: &str, buffer: usize, codec: Codec) -> io::Result<Records> {
        let path = dir.join(name);
        Ok(Records {
            writer: Some(IoFile::create_codec(&path, buffer, codec)?),
            path,
            len: 0,
            buffer,
            codec,
            io: IoCounters::default(),
        })
    }

    fn push(&mut self, rec: &[u8]) -> io::Result<()> {
        self.len += 1;
        self.writer
            .as_mut()
            .expect("written before reading")
            .write_all(rec)
    }

    fn close(&mut self) -> io::Result<()> {
        if let Some(w) = self.writer.take() {
            let io = w.finish()?;
            self.io.add(&io);
        }
        Ok(())
    }

    fn reader(&mut self) -> io::Result<IoFile> {
        self.close()?;
        IoFile::open_codec(&self.path, self.buffer, self.codec)
    }

    fn remove(mut self) -> io::Result<IoCounters> {
        self.close()?;
        std::fs::remove_file(&self.path)?;
        Ok(self.io)
    }
}

/// Streams a record file's rays into the engine, keeping the first read error.
fn ray_stream<'a>(
    file: &'a mut IoFile,
    n: u64,
    record: usize,
    error: &'a mut Option<io::Error>,
) -> impl Iterator<Item = (u32, Ray)> + 'a {
    let mut buf = vec![0u8; record];
    (0..n).map_while(move |id| match file.read_exact(&mut buf) {
        Ok(()) => Some((id as u32, get_ray(&buf))),
        Err(e) => {
            *error = Some(e);
            None
        }
    })
}

/// Traces the SPD workload of the engine's store at `size`×`size` pixels.
pub fn render(engine: &BreadthFirst, size: u32) -> io::Result<OutOfCoreRender> {
    render_tile(engine, size, None)
}

/// The same for the ray trees of one tile set's pixel corners only ([`super::tiles`]); the
/// other corners stay black. `None`: the whole image.
pub fn render_tile(
    engine: &BreadthFirst,
    size: u32,
    tile: Option<crate::shard::ShardSpec>,
) -> io::Result<OutOfCoreRender> {
    render_view(engine, size, tile, None)
}

/// The same through another camera than the store's (`None`: the store's): a view the seed
/// names but the scene's generator does not make, such as seed 000's rings368m (§4.4).
pub fn render_view(
    engine: &BreadthFirst,
    size: u32,
    tile: Option<crate::shard::ShardSpec>,
    view: Option<&rtbench_scenes::View>,
) -> io::Result<OutOfCoreRender> {
    // One thread does all the work here.
    let span = crate::measure::span::Span::start(crate::measure::span::Workers::Caller);
    let h = engine.header();
    let config = engine.config();
    let buffer = config.buffer as usize;
    let spill = SpillDir::create(config.spill.as_deref()).map_err(io::Error::other)?;
    let camera = Camera::new(view.unwrap_or(&h.view));
    let w = size + 1;
    let n_corners = (w as usize) * (w as usize);
    let mut corners = vec![Vec3::ZERO; n_corners];
    let background = h.background.as_vec3();
    let lights = super::trace::scaled_lights(&h.lights);
    let mut io_total = IoCounters::default();
    // The engine's layout and `lazy`: the basic layout (or `lazy=off`) reads every object up to
    // the last one hit (Algorithm 3.6), the split one only the objects hit (§4.2.2).
    let mut scene = SceneReader::open(h, buffer, config.lazy)?;

    let codec = config.spill_codec;
    let mut rays = Records::create(spill.path(), "rays-1", buffer, codec)?;
    for j in 0..w {
        if tile.is_some_and(|t| !super::tiles::owns_row(t, j)) {
            continue;
        }
        for i in 0..w {
            let path = Path {
                corner: j * w + i,
                weight: Vec3::ONE,
                depth: 1,
                inside: false,
            };
            rays.push(&encode_path(&camera.corner_ray(i, j, size), &path))?;
        }
    }

    let mut stats = RayStats::default();
    let mut counters = Counters::default();
    let (mut intersect_s, mut shade_s) = (0.0, 0.0);
    let mut generation = 0u32;
    let mut record = ObjectRecord::default();
    let group_len = shade_group(engine, lights.len());
    let mut shade_sweeps = 0u64;
    while rays.len > 0 {
        generation += 1;
        let n = rays.len;
        let mut g = GenerationStats {
            generation,
            rays: n,
            ..Default::default()
        };
        // Intersection: hit records spilled into one file per group of ray ids.
        let t0 = Instant::now();
        let groups = n.div_ceil(group_len as u64) as usize;
        let mut buckets = (0..groups)
            .map(|b| {
                Records::create(
                    spill.path(),
                    &format!("hits-{generation}-{b}"),
                    HIT_BUFFER,
                    codec,
                )
            })
            .collect::<io::Result<Vec<_>>>()?;
        let mut file = rays.reader()?;
        let (mut error, mut write_error) = (None, None);
        engine.trace_stream(
            &mut ray_stream(&mut file, n, RAY_RECORD, &mut error),
            false,
            &mut |id, hit| {
                if write_error.is_none() {
                    let r = buckets[id as usize / group_len].push(&encode_hit(id, &hit));
                    write_error = r.err();
                }
            },
            &mut counters,
        )?;
        if let Some(e) = error.or(write_error) {
            return Err(e);
        }
        io_total.add(&file.io);
        intersect_s += t0.elapsed().as_secs_f64();

        // Shading, group by group, in object order; emitted records put back in ray order.
        let t1 = Instant::now();
        let mut next = Records::create(
            spill.path(),
            &format!("rays-{}", generation + 1),
            buffer,
            codec,
        )?;
        let mut shadows = Records::create(
            spill.path(),
            &format!("shadows-{generation}"),
            buffer,
            codec,
        )?;
        let mut file = rays.reader()?;
        // A generation smaller than a group holds only its own rays.
        let held = group_len.min(n as usize);
        let mut group: Vec<(Ray, Path)> = Vec::with_capacity(held);
        let mut order: Vec<u32> = Vec::with_capacity(held);
        let mut term = vec![Vec3::ZERO; held];
        // Reserved once at the most a group can emit (pages count only once written), so that
        // growing them never copies the group's emissions.
        let mut out_next: Vec<(u32, Ray, Path)> = Vec::with_capacity(2 * held);
        let mut out_shadow: Vec<(u32, Ray, u32, Vec3)> = Vec::with_capacity(held * lights.len());
        let mut buf = [0u8; RAY_RECORD];
        let mut hb = [0u8; HIT_RECORD];
        let mut hits = vec![Hit::MISS; held];
        let mut first = 0u64;
        for mut bucket in buckets {
            let count = (n - first).min(group_len as u64) as usize;
            group.clear();
            for _ in 0..count {
                file.read_exact(&mut buf)?;
                group.push(decode_path(&buf));
            }
            // This group's hit records, filed by ray id.
            let mut hfile = bucket.reader()?;
            for _ in 0..bucket.len {
                hfile.read_exact(&mut hb)?;
                let (id, hit) = decode_hit(&hb);
                hits[(id as u64 - first) as usize] = hit;
            }
            io_total.add(&hfile.io);
            drop(hfile);
            io_total.add(&bucket.remove()?);
            order.clear();
            for k in 0..count {
                let hit = &hits[k];
                if hit.is_hit() {
                    order.push(k as u32);
                } else {
                    term[k] = group[k].1.weight * background;
                }
            }
            order.sort_by_key(|&k| (hits[k as usize].object, k));
            shade_sweeps += u64::from(!order.is_empty());
            scene.rewind()?;
            let mut loaded = u32::MAX;
            out_next.clear();
            out_shadow.clear();
            for &k in &order {
                let hit = hits[k as usize];
                if hit.object != loaded {
                    // Forward through the store to the object: the basic layout reads the
                    // objects before it (Algorithm 3.6: "while current object ID < hit's object
                    // ID: read next object"), the split one seeks to its box (Algorithm 4.4).
                    scene.skip_to(hit.object, &mut record)?;
                    match scene.next(&mut record)? {
                        Some((id, b, read)) if id == hit.object => {
                            if !read {
                                scene.load(&b, &mut record)?;
                            }
                        }
                        _ => return Err(io::Error::other("hit names no object")),
                    }
                    loaded = hit.object;
                }
                let (ray, path) = &group[k as usize];
                let surface = record
                    .surface
                    .ok_or_else(|| io::Error::other("record without a surface"))?;
                let p = ray.at(hit.t);
                let m = h.materials.get(record.material as usize).ok_or_else(|| {
                    io::Error::new(
                        io::ErrorKind::InvalidData,
                        format!(
                            "object {} names material {} of {} in header.json",
                            hit.object,
                            record.material,
                            h.materials.len()
                        ),
                    )
                })?;
                g.hits += 1;
                term[k as usize] = shade_hit(
                    ray,
                    &hit,
                    path,
                    m,
                    surface.normals(&hit, p),
                    &lights,
                    &mut g,
                    &mut |r, corner, gain| out_shadow.push((k, r, corner, gain)),
                    &mut |r, p| out_next.push((k, r, p)),
                );
            }
            // Back to ray order (stable: a ray's own emissions keep their order).
            out_next.sort_by_key(|e| e.0);
            out_shadow.sort_by_key(|e| e.0);
            for (k, (_, path)) in group.iter().enumerate() {
                corners[path.corner as usize] += term[k];
            }
            // Eye and shadow rays only (`secondary=off`): no next generation.
            for (_, r, p) in out_next.iter().filter(|_| config.secondary) {
                next.push(&encode_path(r, p))?;
            }
            for (_, r, corner, gain) in &out_shadow {
                shadows.push(&encode_shadow(r, *corner, *gain))?;
            }
            first += count as u64;
        }
        io_total.add(&file.io);
        drop(file);
        io_total.add(&rays.remove()?);
        shade_s += t1.elapsed().as_secs_f64();

        // Shadow rays: any hit, one byte per ray, then the gains in order.
        let t2 = Instant::now();
        let ns = shadows.len;
        let mut blocked = vec![false; ns as usize];
        let mut file = shadows.reader()?;
        let mut error = None;
        engine.trace_stream(
            &mut ray_stream(&mut file, ns, SHADOW_RECORD, &mut error),
            true,
            &mut |id, hit| blocked[id as usize] = hit.is_hit(),
            &mut counters,
        )?;
        if let Some(e) = error {
            return Err(e);
        }
        io_total.add(&file.io);
        intersect_s += t2.elapsed().as_secs_f64();
        let t3 = Instant::now();
        let mut file = shadows.reader()?;
        let mut sb = [0u8; SHADOW_RECORD];
        for b in &blocked {
            file.read_exact(&mut sb)?;
            if *b {
                g.shadow_blocked += 1;
            } else {
                let corner = u32::from_le_bytes(sb[32..36].try_into().unwrap());
                corners[corner as usize] +=
                    Vec3::new(get_f32(&sb, 9), get_f32(&sb, 10), get_f32(&sb, 11));
            }
        }
        io_total.add(&file.io);
        drop(file);
        io_total.add(&shadows.remove()?);
        g.shadow = ns;
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
        debug_assert!(generation <= MAX_DEPTH as u32);
        rays = next;
    }
    io_total.add(&rays.remove()?);
    io_total.add(&scene.io());
    let sample = span.stop();
    Ok(OutOfCoreRender {
        render: Render {
            pixels: super::trace::pixels_of(size, &corners),
            corners,
            stats,
            counters,
            intersect_s,
            shade_s,
            trace_s: sample.wall_s,
            trace_cpu_s: sample.thread_cpu_s,
            sample,
        },
        io: io_total,
        shade_group: group_len,
        shade_sweeps,
        shade_cap: SHADE_BYTES / shade_bytes_per_ray(lights.len()),
    })
}

/// Whether the breadth-first engine's pass cap stopped the run (`max_passes`).
pub fn pass_capped(c: &rtbench_engines::Counters) -> bool {
    c.extra
        .get(rtbench_engines::breadth_first::cap::CAP_REACHED)
        .is_some_and(|&n| n > 0)
}

/// `none`, `gzip`, `gzip:LEVEL` (1–9), `zstd` or `zstd:LEVEL` (1–19).
pub fn parse_codec(s: &str) -> std::result::Result<rtbench_engines::store::Codec, String> {
    let level = |p: &str| s.strip_prefix(p).map(str::parse::<u32>);
    match s {
        "none" => Ok(rtbench_engines::store::Codec::None),
        "gzip" => Ok(rtbench_engines::store::Codec::Gzip(6)),
        "zstd" => Ok(rtbench_engines::store::Codec::Zstd(3)),
        _ => match (level("gzip:"), level("zstd:")) {
            (Some(Ok(l)), _) if (1..=9).contains(&l) => Ok(rtbench_engines::store::Codec::Gzip(l)),
            (_, Some(Ok(l))) if (1..=19).contains(&l) => {
                Ok(rtbench_engines::store::Codec::Zstd(l as i32))
            }
            _ => Err("expected none, gzip, gzip:LEVEL (1-9), zstd or zstd:LEVEL (1-19)".into()),
        },
    }
}
