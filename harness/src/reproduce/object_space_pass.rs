//! What the three `yamauchi-*` tables share: seed 003's own ray-tracing pass
//! ([`super::models::pass_003`]: one primary ray per pixel centre, ≤ 3 reflections, no shadow rays)
//! executed once per scene on the object-space engine, then timed on many (Mπ)² machine
//! configurations by the engine's event simulation; the options they take, the records they keep
//! of a pass and of a simulated run, and their plot helpers.

use super::models::pass_003;
use super::params::{Param, MAX_PES, SCENES, SIZE, THREADS};
use super::{Checkpoint, Ctx, Image};
use crate::error::{input, Result};
use crate::source::Source;
use crate::workload;
use rayon::prelude::*;
use rtbench_engines::object_space::config::{Costs, FrameBuffer, ObjectSpaceConfig};
use rtbench_engines::object_space::fbpath::FbPath;
use rtbench_engines::object_space::machine::{Allocation, Machine};
use rtbench_engines::object_space::radiosity::{self, Patches};
use rtbench_engines::object_space::sim::{simulate_path, SimResult};
use rtbench_engines::object_space::ObjectSpace;
use rtbench_reports::plot::{LegendAt, Panel, Point, Series, XyPanel};
use serde::Serialize;
use std::time::Instant;

/// The options every `yamauchi-*` table takes.
pub const PARAMS: &[Param] = &[THREADS, SIZE, MAX_PES, SCENES, ROOM, THRESHOLD];

pub const ROOM: Param = Param {
    key: "room",
    help: "the room's patches per metre (default 8: 18,910 patches; 2 with --quick)",
};
pub const THRESHOLD: Param = Param {
    key: "threshold",
    help: "radiosity shooting threshold on unshot radiosity, above 0 (default 0.05)",
};
/// The default threshold on unshot radiosity (the lights emit 12; see the document).
pub const DEFAULT_THRESHOLD: f32 = 0.05;

/// `threshold`, above 0.
pub fn threshold(ctx: &Ctx) -> Result<f32> {
    let t = match ctx.params.raw(THRESHOLD.key) {
        None => DEFAULT_THRESHOLD,
        Some(v) => v.trim().parse::<f32>().map_err(|_| {
            input(format!(
                "{}: threshold '{v}': expected a number above 0",
                ctx.id
            ))
        })?,
    };
    radiosity::check_threshold(t).map_err(|e| input(format!("{}: {e}", ctx.id)))?;
    Ok(t)
}

/// The radiosity pass of a scene with emitting patches (the room): its patches and threshold.
/// Its shots are executed as each simulated machine makes them ([`radiosity::simulate`]).
pub struct RadiosityPass {
    pub patches: Patches,
    pub threshold: f32,
}

/// One scene and one of 003's passes on it: the engine (its subspaces and primitives) and, for the
/// ray-tracing pass, the pass executed once; for the radiosity pass, its patches (`pass` then holds
/// no rays).
pub struct Traced {
    pub label: String,
    pub os: ObjectSpace,
    pub pass: pass_003::Pass,
    pub trace_s: f64,
    pub radiosity: Option<RadiosityPass>,
}

impl Traced {
    /// The ray-tracing pass's image, as `images/<scene>-yamauchi.png` (none for the radiosity
    /// pass).
    pub fn image(&self) -> Option<Image> {
        self.radiosity.is_none().then(|| Image {
            path: self.image_path(),
            pixels: self.pass.pixels(),
            size: self.pass.size,
        })
    }

    /// "radiosity" or "ray tracing".
    pub fn pass_name(&self) -> &'static str {
        if self.radiosity.is_some() {
            "radiosity"
        } else {
            "ray tracing"
        }
    }
    fn image_path(&self) -> String {
        format!("images/{}-yamauchi.png", self.label)
    }
    pub fn record(&self) -> PassRecord {
        PassRecord {
            scene: self.label.clone(),
            pass: self.pass_name(),
            threshold: self.radiosity.as_ref().map(|r| r.threshold),
            size: self.pass.size,
            primary: self.pass.primary,
            secondary: self.pass.secondary,
            intensity_packets: self.pass.intensity_packets,
            subspace_visits: self.pass.trace.segs.len(),
            primitive_tests: self.pass.counters.primitive_tests,
            trace_s: self.trace_s,
            image: self.image_path(),
        }
    }
}

/// What a pass did, as every `yamauchi-*` result records it.
#[derive(Serialize)]
pub struct PassRecord {
    pub scene: String,
    pub pass: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub threshold: Option<f32>,
    pub size: u32,
    pub primary: u64,
    pub secondary: u64,
    pub intensity_packets: u64,
    pub subspace_visits: usize,
    pub primitive_tests: u64,
    pub trace_s: f64,
    pub image: String,
}

/// One simulated run: clocks against a reference time `t1`, over `blocks` processing units.
#[derive(Serialize)]
pub struct SimRecord {
    pub clocks: u64,
    pub speedup: f64,
    pub efficiency: f64,
    pub utilisation: f64,
    pub imbalance: f64,
    pub frgu_clocks: u64,
    pub events: u64,
    pub packets: u64,
    pub hops: u64,
    pub frame_buffer: rtbench_engines::object_space::framebuffer::FrameBufferStats,
    pub wall_s: f64,
    pub events_per_s: f64,
}

impl SimRecord {
    pub fn new(r: &SimResult, t1: u64, blocks: u64, wall: f64) -> SimRecord {
        let speedup = t1 as f64 / r.clocks as f64;
        SimRecord {
            clocks: r.clocks,
            speedup,
            efficiency: speedup / blocks as f64,
            utilisation: r.utilisation(),
            imbalance: r.imbalance(),
            frgu_clocks: r.frgu_clocks,
            events: r.events,
            packets: r.packets,
            hops: r.hops,
            frame_buffer: r.frame_buffer.clone(),
            wall_s: wall,
            events_per_s: r.events as f64 / wall.max(1e-9),
        }
    }
}

/// What a table's heading says of a pass: the rays and subspace visits of a ray-tracing pass;
/// for the radiosity pass (which traces no eye rays) its threshold and the 1-PE machine's packet
/// events `t1`.
pub fn pass_summary(p: &PassRecord, t1: Option<&SimRecord>) -> String {
    if p.pass == "radiosity" {
        format!(
            "radiosity pass, τ = {}, {} packet events on 1 PE",
            p.threshold.map_or("–".into(), |t| format!("{t:.3}")),
            t1.map_or("–".into(), |s| s.events.to_string())
        )
    } else {
        format!(
            "{} rays, {} subspace visits",
            p.primary + p.secondary,
            p.subspace_visits
        )
    }
}

/// `size` (default 512, 128 with `--quick`).
pub fn size(ctx: &Ctx) -> Result<u32> {
    let size = ctx
        .params
        .number::<u32>(SIZE.key, 1)?
        .unwrap_or(if ctx.quick { 128 } else { 512 });
    workload::check_size(size)?;
    Ok(size)
}

/// `max-pes`, at least 1, or the default.
pub fn max_pes(ctx: &Ctx, default: u32) -> Result<u32> {
    Ok(ctx.params.number::<u32>(MAX_PES.key, 1)?.unwrap_or(default))
}

/// `scenes`, or the default list.
pub fn scenes(ctx: &Ctx, default: &[&str]) -> Result<Vec<String>> {
    Ok(ctx
        .params
        .scenes()?
        .unwrap_or_else(|| default.iter().map(|s| s.to_string()).collect()))
}

/// The suffix of a scene name that asks for the room as it is generated (y up, the eye along +z):
/// an extra orientation, reported under its own label beside 003's.
pub const Y_UP: &str = "-yup";

/// Rows on the room in another orientation than 003's (`roomN-yup`): shown beside 003's, never
/// judged, and saying which orientation they are.
pub fn mark_extra_orientation(rows: &mut [super::Row]) {
    for r in rows.iter_mut().filter(|r| r.subject.contains(Y_UP)) {
        if matches!(r.verdict, super::Verdict::Holds | super::Verdict::Fails) {
            r.verdict = super::Verdict::Shown;
        }
        r.note =
            "an extra orientation, the room y up as generated (not 003's, z up): shown, not judged"
                .into();
    }
}

/// 003's orientation of its room: z up. §3.3.2 designs the skewed allocation for objects coherent
/// along the vertical ("walls stand upright, as do pillars and trees") and shifts ownership along the
/// axis that has no PE dimension, which on the 2D machine of eq. (10), PE = ((X + Z) mod N_x,
/// Y mod N_y), is Z; with y up, every plane of fixed Y (the floor and the ceiling, 43% of the
/// room's patches) sits on one PE row. The room is generated y up ([`rtbench_scenes::room`]), and
/// its `turn` is its own inverse, so applying it once more gives the modelling frame: floor x-y,
/// z up, the eye looking along +y.
pub fn turn_room_z_up(scene: &mut rtbench_scenes::Scene) {
    use rtbench_scenes::room::turn;
    use rtbench_scenes::Shape;
    let dir = |v: glam::DVec3| glam::DVec3::new(-v.x, v.z, v.y);
    scene.view.from = turn(scene.view.from);
    scene.view.at = turn(scene.view.at);
    scene.view.up = dir(scene.view.up);
    for l in &mut scene.lights {
        l.position = turn(l.position);
    }
    for o in &mut scene.objects {
        match &mut o.shape {
            Shape::Sphere { center, .. } => *center = turn(*center),
            Shape::Cone { base, apex, .. } => {
                *base = turn(*base);
                *apex = turn(*apex);
            }
            Shape::Polygon(vs) => vs.iter_mut().for_each(|v| *v = turn(*v)),
            Shape::Patch { vertices, normals } => {
                vertices.iter_mut().for_each(|v| *v = turn(*v));
                normals.iter_mut().for_each(|n| *n = dir(*n));
            }
        }
    }
}

/// A scene of the load-balancing tables ready for the engine: the room in 003's orientation (z up;
/// `roomN-yup`: as generated, y up, labelled so), anything else as it is.
fn prepare_oriented(name: &str) -> Result<workload::Prepared> {
    let (base, y_up) = match name.strip_suffix(Y_UP) {
        Some(b) => (b, true),
        None => (name, false),
    };
    let src = Source::resolve(base, None, None, None)?;
    if !matches!(src, Source::Room(_)) {
        if y_up {
            return Err(input(format!("{name}: '{Y_UP}' applies to the room only")));
        }
        return workload::prepare(&src);
    }
    let mut scene = src.load()?;
    if y_up {
        scene.name = format!("{}{Y_UP}", src.label());
    } else {
        turn_room_z_up(&mut scene);
    }
    let geometry = rtbench_engines::geometry::Geometry::from_scene(&scene);
    Ok(workload::Prepared {
        input: rtbench_engines::BuildInput {
            scene: std::sync::Arc::new(scene),
            geometry: std::sync::Arc::new(geometry),
        },
        generate_s: 0.0,
        prepare_s: 0.0,
    })
}

/// The load-balancing tables' shared setting: image size, largest PE count (256 with `--quick`,
/// else 1,024), the room with both passes (003's setting: `room` patches per metre, 2 with
/// `--quick`, else 8; radiosity `threshold`), then the SPD scenes as a second set (tetra with
/// `--quick`, else balls, rings, tetra; ray-tracing pass only: they have no emitters), each traced
/// with 003's pass at default costs. `scenes` replaces the default list (`room`/`roomN` or SPD
/// names; `roomN-yup` adds the room as generated, y up, as extra rows). The room is traced in 003's
/// orientation, z up ([`turn_room_z_up`]). A `max-pes` below `min_pes` is refused before anything is
/// traced.
pub fn load_balancing_setting(ctx: &Ctx, min_pes: u32) -> Result<(u32, u32, Vec<Traced>)> {
    let size = size(ctx)?;
    let max_pes = max_pes(ctx, if ctx.quick { 256 } else { 1024 })?;
    if max_pes < min_pes {
        return Err(crate::error::input(format!(
            "{}: max-pes must be at least {min_pes}",
            ctx.id
        )));
    }
    let ppm = ctx
        .params
        .number::<u32>(ROOM.key, 0)?
        .unwrap_or(if ctx.quick { 2 } else { 8 });
    let threshold = threshold(ctx)?;
    let room = format!("room{ppm}");
    let default: Vec<&str> = if ctx.quick {
        vec![&room, "tetra"]
    } else {
        vec![&room, "balls", "rings", "tetra"]
    };
    let names = match ctx.params.list(SCENES.key)? {
        Some(v) => v,
        None => default.iter().map(|s| s.to_string()).collect(),
    };
    for n in &names {
        if !n.starts_with("room") && n.parse::<rtbench_scenes::spd::Program>().is_err() {
            return Err(input(format!("{}: unknown scene '{n}'", ctx.id)));
        }
    }
    let traced = trace_scenes(&names, size, Costs::default(), Some(threshold))?;
    Ok((size, max_pes, traced))
}

/// Builds the engine on each scene (with the given unit costs: the per-test clocks enter the
/// record) and traces 003's pass at `size`².
/// A scene of the room also gets its radiosity pass (first) when `radiosity` (the threshold) is
/// given.
pub fn trace_scenes(
    scenes: &[String],
    size: u32,
    costs: Costs,
    radiosity: Option<f32>,
) -> Result<Vec<Traced>> {
    let mut v = Vec::new();
    for s in scenes {
        let prepared = prepare_oriented(s)?;
        let is_room = s.starts_with("room");
        let label = prepared.input.scene.name.clone();
        let config = ObjectSpaceConfig {
            costs,
            ..ObjectSpaceConfig::default()
        };
        let os = ObjectSpace::build(&prepared.input, config.clone())
            .map_err(|e| input(e.to_string()))?;
        if let (Some(threshold), true) = (radiosity, is_room) {
            let scene = &prepared.input.scene;
            let em = rtbench_scenes::room::emission(&scene.materials);
            let patches = Patches::from_scene(scene, &prepared.input.geometry.prim_object, &em)
                .map_err(|e| input(format!("{label}: {e}")))?;
            v.push(Traced {
                label: format!("{label}-radiosity"),
                os: ObjectSpace::build(&prepared.input, config)
                    .map_err(|e| input(e.to_string()))?,
                pass: pass_003::Pass::empty(size),
                trace_s: 0.0,
                radiosity: Some(RadiosityPass { patches, threshold }),
            });
        }
        eprintln!("{label}: tracing 003's pass at {size}x{size} …");
        let t = Instant::now();
        let pass = pass_003::trace_pass(&os, &prepared.input.scene, size, None);
        let trace_s = t.elapsed().as_secs_f64();
        v.push(Traced {
            label,
            os,
            pass,
            trace_s,
            radiosity: None,
        });
    }
    Ok(v)
}

/// PEs per axis for `pes` (a power of two) on a `dims`-dimensional torus, as even as possible,
/// the larger counts first.
fn shape(pes: u32, dims: u8) -> [u32; 3] {
    let k = pes.trailing_zeros();
    let mut s = [1u32; 3];
    for i in 0..dims as u32 {
        let bits = k / dims as u32 + u32::from(i < k % dims as u32);
        s[i as usize] = 1 << bits;
    }
    s
}

pub fn machine(pes: u32, dims: u8, allocation: Allocation, rp_blocks: u32) -> Machine {
    Machine {
        pes: shape(pes, dims),
        dims,
        allocation,
        rp_blocks,
    }
}

/// Simulates each machine on `t` (in parallel over machines) with the given frame buffer (the
/// radiosity pass sends no intensity packets): each run's result and its wall time. Each finished
/// machine is saved in `checkpoint` and, resumed (`--resume`), loaded instead of simulated again,
/// so that the full room's machines (each up to 5 × 10⁸ packet events) run in pieces.
pub fn run_all(
    t: &Traced,
    machines: &[(Machine, FrameBuffer)],
    checkpoint: &Checkpoint,
) -> Result<Vec<(SimResult, f64)>> {
    let keys: Vec<String> = machines
        .iter()
        .map(|(m, fb)| machine_key(t, m, fb))
        .collect();
    let mut done: Vec<Option<(SimResult, f64)>> = Vec::with_capacity(machines.len());
    for k in &keys {
        done.push(checkpoint.load(k)?);
    }
    let todo: Vec<usize> = (0..machines.len()).filter(|&i| done[i].is_none()).collect();
    if todo.len() < machines.len() {
        eprintln!(
            "{}: {} of {} machines loaded from saved steps",
            t.label,
            machines.len() - todo.len(),
            machines.len()
        );
    }
    let fresh: Vec<(usize, Result<(SimResult, f64)>)> = todo
        .par_iter()
        .map(|&i| {
            let r = simulate_all(t, &machines[i..i + 1]).remove(0);
            let saved = checkpoint.save(&keys[i], &r);
            (i, saved.map(|_| r))
        })
        .collect();
    for (i, r) in fresh {
        done[i] = Some(r?);
    }
    Ok(done
        .into_iter()
        .map(|r| r.expect("every machine run"))
        .collect())
}

/// A saved machine's key: everything its run depends on (scene, pass, threshold, image size,
/// unit costs, the machine and its frame buffer). The costs enter as a stable hash of their
/// `Debug` text ([`stable_hash`]), so that a binary built by any Rust version finds the steps.
fn machine_key(t: &Traced, m: &Machine, fb: &FrameBuffer) -> String {
    let costs = stable_hash(format!("{:?}", t.os.config().costs).as_bytes());
    let fb = match fb {
        FrameBuffer::Direct => "direct".to_string(),
        FrameBuffer::Cached { m } => format!("cfbs{m}"),
        FrameBuffer::WriteBuffer { m } => format!("wb{m}"),
    };
    let threshold = t
        .radiosity
        .as_ref()
        .map(|r| format!("-t{}", r.threshold))
        .unwrap_or_default();
    format!(
        "{}{threshold}-s{}-f{costs:016x}-{}d-{}-{}-r{}-{fb}",
        t.label,
        t.pass.size,
        m.dims,
        m.allocation.name(),
        m.pes_label(),
        m.rp_blocks
    )
}

/// 64-bit FNV-1a of `bytes`: fixed by its definition, unlike std's `DefaultHasher` (whose
/// algorithm may change between Rust versions, which would orphan every saved step). Keys made
/// with it are marked `-f` where the `DefaultHasher` ones were marked `-c`.
pub fn stable_hash(bytes: &[u8]) -> u64 {
    use std::hash::Hasher;
    let mut h = fnv::FnvHasher::default();
    h.write(bytes);
    h.finish()
}

/// [`run_all`] without saving: every machine simulated.
fn simulate_all(t: &Traced, machines: &[(Machine, FrameBuffer)]) -> Vec<(SimResult, f64)> {
    let paths: Vec<(Machine, FbPath)> = machines
        .iter()
        .map(|&(m, kind)| {
            let queue = match kind {
                FrameBuffer::WriteBuffer { .. } => u32::MAX,
                _ => 0,
            };
            (m, FbPath { kind, queue })
        })
        .collect();
    run_all_path(t, &paths)
}

/// [`run_all`] with the frame-buffer path's queue capacities ([`FbPath`]; 0: unbounded).
pub fn run_all_path(t: &Traced, machines: &[(Machine, FbPath)]) -> Vec<(SimResult, f64)> {
    let s = t.os.config().subspaces;
    machines
        .par_iter()
        .map(|(m, fb)| {
            let start = Instant::now();
            if let Some(rad) = &t.radiosity {
                let r = radiosity::simulate(
                    &t.os,
                    &rad.patches,
                    m,
                    &m.owner_map(s),
                    &t.os.config().costs,
                    rad.threshold,
                );
                return (as_sim(&r), start.elapsed().as_secs_f64());
            }
            let r = simulate_path(
                &t.pass.trace,
                m,
                &m.owner_map(s),
                &t.os.config().costs,
                *fb,
                t.pass.size,
            );
            (r, start.elapsed().as_secs_f64())
        })
        .collect()
}

/// A radiosity run as a simulated run (no frame buffer).
pub fn as_sim(r: &radiosity::RadiosityRun) -> SimResult {
    SimResult {
        clocks: r.clocks,
        pe_clocks: r.clocks,
        busy: r.busy,
        busy_max_pe: r.busy_max_pe,
        pes: r.pes,
        rp_blocks: r.rp_blocks,
        events: r.events,
        packets: r.packets,
        hops: r.hops,
        ..Default::default()
    }
}

/// The powers of two up to `max` (at most 4096).
pub fn powers(max: u32) -> Vec<u32> {
    (0..=12).map(|k| 1u32 << k).filter(|&p| p <= max).collect()
}

/// A line panel with a logarithmic x axis.
pub fn panel(title: &str, x: &str, y: &str, series: Vec<Series>, legend: LegendAt) -> Panel {
    Panel::Xy(XyPanel {
        title: title.into(),
        x_label: x.into(),
        y_label: y.into(),
        x_log: true,
        y_log: false,
        x_ticks: Vec::new(),
        lines: true,
        legend,
        series,
    })
}

pub fn series(name: &str, color: usize, pts: &[(f64, f64)]) -> Series {
    Series {
        name: name.into(),
        color,
        points: pts
            .iter()
            .map(|&(x, y)| Point {
                x,
                y,
                y_range: None,
            })
            .collect(),
    }
}

/// "Source: document; sections. note" for a report's first paragraph.
pub fn source_line(s: &super::published::Source) -> String {
    format!("Source: {}. {}", s.cite(), s.note.as_deref().unwrap_or(""))
}

/// The published file of a `yamauchi-*` table: its source and its claims.
#[derive(serde::Deserialize)]
pub struct Published {
    pub source: super::published::Source,
    pub claims: Vec<PublishedClaim>,
}

/// A claim of 003 as transcribed, with its figure where the prose gives one.
#[derive(serde::Deserialize)]
pub struct PublishedClaim {
    pub id: String,
    pub value: Option<f64>,
}

impl Published {
    /// The figure of claim `id` (the files are compiled in: a missing one is a broken build,
    /// caught by the tests).
    pub fn value(&self, id: &str) -> f64 {
        self.claims
            .iter()
            .find(|c| c.id == id)
            .and_then(|c| c.value)
            .unwrap_or_else(|| panic!("published claim '{id}' has no value"))
    }
}

#[cfg(test)]
pub mod tests {
    use super::*;

    /// A pass record for tests of the pure analyses.
    pub fn pass(scene: &str) -> PassRecord {
        PassRecord {
            scene: scene.into(),
            pass: "ray tracing",
            threshold: None,
            size: 8,
            primary: 64,
            secondary: 0,
            intensity_packets: 0,
            subspace_visits: 0,
            primitive_tests: 0,
            trace_s: 0.0,
            image: String::new(),
        }
    }

    /// A simulated run of `clocks` against `t1` over `blocks` units.
    pub fn sim(clocks: u64, t1: u64, blocks: u64) -> SimRecord {
        let r = SimResult {
            clocks,
            ..SimResult::default()
        };
        SimRecord::new(&r, t1, blocks, 0.0)
    }

    #[test]
    fn the_step_keys_hash_is_fnv1a() {
        // FNV-1a's published test vectors: the hash cannot drift with the compiler.
        assert_eq!(stable_hash(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(stable_hash(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(stable_hash(b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn tori_are_as_even_as_possible_larger_axes_first() {
        assert_eq!(shape(1, 1), [1, 1, 1]);
        assert_eq!(shape(32, 1), [32, 1, 1]);
        assert_eq!(shape(32, 2), [8, 4, 1]);
        assert_eq!(shape(256, 2), [16, 16, 1]);
        assert_eq!(shape(128, 3), [8, 4, 4]);
        assert_eq!(powers(256), vec![1, 2, 4, 8, 16, 32, 64, 128, 256]);
        assert_eq!(powers(100).last(), Some(&64));
    }
}
