//! `yamauchi-radiosity`: seed 003's two passes on the room (Yamauchi 1997, §2.4.1, §3.2.3,
//! Tables 4 and 6): the radiosity pass on the simulated (Mπ)² machine checked against a plain
//! single-process progressive refinement, then the ray-tracing pass reading the diffuse term from
//! the solution (the image), and how fast the simulation runs. The room is a stand-in for 003's
//! scene ([`rtbench_scenes::room`]).

use super::object_space_pass::{self as osp, threshold, Published, ROOM, THRESHOLD};
use super::params::{Param, SIZE, THREADS};
use super::published;
use super::{environment, Claim, Ctx, Fidelity, Image, Kind, Output, Row, Runtime, Table, Verdict};
use crate::error::{input, Result};
use crate::source::Source;
use super::models::pass_003;
use crate::workload;
use glam::Vec3;
use rtbench_engines::object_space::config::{FrameBuffer, ObjectSpaceConfig};
use rtbench_engines::object_space::machine::Allocation;
use rtbench_engines::object_space::radiosity::{self, Patches, Solution};
use rtbench_engines::object_space::sim;
use rtbench_engines::object_space::ObjectSpace;
use rtbench_reports::{Document, Table as DocTable};
use rayon::prelude::*;
use rtbench_engines::object_space::sim::SimResult;
use rtbench_engines::object_space::trace::Trace;
use serde::{Deserialize, Serialize};
use std::time::Instant;

pub const PES: Param = Param {
    key: "pes",
    help: "PE counts of the 2D skewed machines, powers of two 1-1024 (default 1,16,256,1024; 1,16,256 with --quick)",
};

const SCENE: &str = "the room stands in for 003's unavailable test scene (rtbench_scenes::room)";

pub const TABLE: Table = Table {
    id: "yamauchi-radiosity",
    seed: "003",
    source: "§2.4.1, §3.2.3, Tables 4 and 6",
    about: "003 (Yamauchi 1997): the radiosity pass on the (Mπ)² machine vs a single-process solution, and both passes' image, on the room",
    runtime: Runtime {
        quick: "seconds",
        full: "about a quarter of an hour",
    },
    params: &[THREADS, SIZE, ROOM, THRESHOLD, PES],
    claims: &[
        Claim {
            key: "scene",
            fidelity: Fidelity::Substituted,
            why: SCENE,
        },
        Claim {
            key: "same-solution",
            fidelity: Fidelity::Substituted,
            why: SCENE,
        },
        Claim {
            key: "terminates",
            fidelity: Fidelity::Substituted,
            why: SCENE,
        },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/yamauchi-radiosity.json");

/// `pes`: powers of two from 1 to 1,024 (a 2D torus of them divides 32 × 32 subspaces).
pub fn pe_counts(ctx: &Ctx) -> Result<Vec<u32>> {
    let Some(list) = ctx.params.list(PES.key)? else {
        return Ok(if ctx.quick {
            vec![1, 16, 256]
        } else {
            vec![1, 16, 256, 1024]
        });
    };
    list.iter()
        .map(|s| match s.parse::<u32>() {
            Ok(p) if p.is_power_of_two() && p <= 1024 => Ok(p),
            _ => Err(input(format!(
                "{}: pes '{s}': a 2D torus of that many PEs does not divide the 32x32 subspaces of its axes (powers of two from 1 to 1024)",
                ctx.id
            ))),
        })
        .collect()
}

/// The room, its engine and patches, and the single-process solution.
pub struct Room {
    pub label: String,
    pub os: ObjectSpace,
    pub scene: std::sync::Arc<rtbench_scenes::Scene>,
    pub patches: Patches,
    pub threshold: f32,
    pub reference: Solution,
    pub reference_s: f64,
}

impl Room {
    pub fn new(ctx: &Ctx, default_ppm: u32) -> Result<Room> {
        let ppm = ctx
            .params
            .number::<u32>(ROOM.key, 0)?
            .unwrap_or(default_ppm);
        let threshold = threshold(ctx)?;
        let src = Source::resolve(&format!("room{ppm}"), None, None, None)?;
        let prepared = workload::prepare(&src)?;
        let label = prepared.input.scene.name.clone();
        let os = ObjectSpace::build(&prepared.input, ObjectSpaceConfig::default())
            .map_err(|e| input(e.to_string()))?;
        let scene = prepared.input.scene.clone();
        let em = rtbench_scenes::room::emission(&scene.materials);
        let patches = Patches::from_scene(&scene, &prepared.input.geometry.prim_object, &em)
            .map_err(|e| input(format!("{label}: {e}")))?;
        eprintln!("{label}: single-process progressive radiosity, threshold {threshold} …");
        let t = Instant::now();
        let reference = radiosity::reference(&os, &patches, threshold);
        Ok(Room {
            label,
            os,
            scene,
            patches,
            threshold,
            reference,
            reference_s: t.elapsed().as_secs_f64(),
        })
    }

    /// The diffuse term the ray-tracing pass reads: the reference radiosity, exposed so that the
    /// mean lit, non-emitting patch shows at 0.4.
    pub fn diffuse(&self) -> Vec<Vec3> {
        let (mut s, mut n) = (0.0f64, 0u64);
        for (i, b) in self.reference.radiosity.iter().enumerate() {
            if self.patches.is_patch(i) && self.patches.emission[i] == Vec3::ZERO {
                s += b.max_element() as f64;
                n += 1;
            }
        }
        let exposure = 0.4 / (s / n.max(1) as f64).max(1e-9) as f32;
        self.reference
            .radiosity
            .iter()
            .map(|b| *b * exposure)
            .collect()
    }

    /// Patches per subspace (by the subspace holding each patch's centre): the mean over all
    /// subspaces and the share of subspaces holding at most one.
    fn occupancy(&self) -> (u64, f64, f64) {
        let cfg = self.os.config();
        let n = (cfg.subspaces[0] * cfg.subspaces[1] * cfg.subspaces[2]) as usize;
        let (lo, hi) = (self.os.lattice().lo, self.os.lattice().hi);
        let mut count = vec![0u32; n];
        let mut patches = 0u64;
        for i in 0..self.patches.area.len() {
            if self.patches.is_patch(i) {
                let c = self.patches.centre[i].clamp(lo, hi);
                let l = self.os.lattice();
                count[l.index(l.cell_of(c))] += 1;
                patches += 1;
            }
        }
        let at_most_one = count.iter().filter(|&&c| c <= 1).count();
        (
            patches,
            patches as f64 / n as f64,
            at_most_one as f64 / n as f64,
        )
    }
}

/// One PE count's machine, both passes, as measured (saved as a step of the checkpoint).
#[derive(Serialize, Deserialize)]
struct PeStep {
    pes: u32,
    radiosity: SimResult,
    radiosity_wall_s: f64,
    shots: u64,
    delta_rays: u64,
    max_abs_difference: f64,
    max_relative_difference: f64,
    mean_relative_difference: f64,
    max_unshot_left: f32,
    ray_tracing: SimResult,
    ray_tracing_wall_s: f64,
    repeat_identical: Option<bool>,
}

/// Both passes on `n` PEs (2D skewed, 1 RP block), the radiosity against the reference; at 16
/// PEs the radiosity pass again (determinism).
fn pe_step(room: &Room, trace: &Trace, n: u32, size: u32) -> PeStep {
    let m = osp::machine(n, 2, Allocation::Skewed, 1);
    let owner = m.owner_map(room.os.config().subspaces);
    let costs = &room.os.config().costs;
    eprintln!("{}: radiosity pass on {} PEs …", room.label, n);
    let t = Instant::now();
    let r = radiosity::simulate(&room.os, &room.patches, &m, &owner, costs, room.threshold);
    let wall = t.elapsed().as_secs_f64();
    eprintln!(
        "{}: {} PEs: radiosity pass {} clocks, {} packet events in {wall:.1} s",
        room.label, n, r.clocks, r.events
    );
    let t = Instant::now();
    let rt = sim::simulate(trace, &m, &owner, costs, FrameBuffer::Direct, size);
    let rt_wall = t.elapsed().as_secs_f64();
    let repeat_identical = (n == 16).then(|| {
        let again = radiosity::simulate(&room.os, &room.patches, &m, &owner, costs, room.threshold);
        again.clocks == r.clocks && again.solution.radiosity == r.solution.radiosity
    });
    let s = &r.solution;
    PeStep {
        pes: n,
        radiosity: osp::as_sim(&r),
        radiosity_wall_s: wall,
        shots: s.shots,
        delta_rays: s.rays,
        max_abs_difference: s.max_abs_difference(&room.reference),
        max_relative_difference: s.max_difference_above(&room.reference, room.threshold),
        mean_relative_difference: s.mean_relative_difference(&room.reference),
        max_unshot_left: s.unshot.iter().map(|u| u.max_element()).fold(0.0, f32::max),
        ray_tracing: rt,
        ray_tracing_wall_s: rt_wall,
        repeat_identical,
    }
}

#[derive(Serialize)]
struct PeRun {
    pes: u32,
    shape: String,
    radiosity: osp::SimRecord,
    shots: u64,
    delta_rays: u64,
    max_abs_difference: f64,
    max_relative_difference: f64,
    mean_relative_difference: f64,
    max_unshot_left: f32,
    ray_tracing: osp::SimRecord,
    repeat_identical: Option<bool>,
}

#[derive(Serialize)]
struct Measured {
    scene: String,
    patches: u64,
    subspaces: u32,
    patches_per_subspace: f64,
    subspaces_with_at_most_one: f64,
    threshold: f32,
    reference_shots: u64,
    reference_rays: u64,
    reference_s: f64,
    size: u32,
    ray_tracing_rays: u64,
    ray_tracing_trace_s: f64,
    runs: Vec<PeRun>,
    image: String,
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    published: serde_json::Value,
    quick: bool,
    measured: Measured,
    environment: serde_json::Value,
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let size = osp::size(ctx)?;
    let pes = pe_counts(ctx)?;
    let pool = crate::measure::threads::pool(ctx.params.threads()?)?;
    let room = Room::new(ctx, if ctx.quick { 2 } else { 8 })?;
    let diffuse = room.diffuse();
    eprintln!("{}: tracing 003's ray-tracing pass at {size}x{size} …", room.label);
    let t = Instant::now();
    let pass = pool.install(|| pass_003::trace_pass(&room.os, &room.scene, size, Some(&diffuse)));
    let trace_s = t.elapsed().as_secs_f64();
    let (patches, per_subspace, at_most_one) = room.occupancy();
    // The PE counts are independent machines: run side by side on the pool's threads, each
    // saved when finished (`--resume` loads it: the full room's 1- and 16-PE machines are each
    // about 5 × 10⁸ packet events).
    let steps: Vec<Result<PeStep>> = pool.install(|| {
        pes.par_iter()
            .map(|&n| {
                let key = format!(
                    "{}-t{}-s{size}-{n}pes",
                    room.label, room.threshold
                );
                if let Some(step) = ctx.checkpoint.load::<PeStep>(&key)? {
                    eprintln!("{}: {n} PEs loaded from its saved step", room.label);
                    return Ok(step);
                }
                let step = pe_step(&room, &pass.trace, n, size);
                ctx.checkpoint.save(&key, &step)?;
                Ok(step)
            })
            .collect()
    });
    let steps: Vec<PeStep> = steps.into_iter().collect::<Result<_>>()?;
    let (t1_rad, t1_rt) = steps
        .iter()
        .find(|s| s.pes == 1)
        .map(|s| (s.radiosity.clocks, s.ray_tracing.clocks))
        .unwrap_or((0, 0));
    let runs: Vec<PeRun> = steps
        .into_iter()
        .map(|s| {
            let m = osp::machine(s.pes, 2, Allocation::Skewed, 1);
            PeRun {
                pes: s.pes,
                shape: m.pes_label(),
                radiosity: osp::SimRecord::new(
                    &s.radiosity,
                    t1_rad.max(1),
                    s.pes as u64,
                    s.radiosity_wall_s,
                ),
                shots: s.shots,
                delta_rays: s.delta_rays,
                max_abs_difference: s.max_abs_difference,
                max_relative_difference: s.max_relative_difference,
                mean_relative_difference: s.mean_relative_difference,
                max_unshot_left: s.max_unshot_left,
                ray_tracing: osp::SimRecord::new(
                    &s.ray_tracing,
                    t1_rt.max(1),
                    s.pes as u64,
                    s.ray_tracing_wall_s,
                ),
                repeat_identical: s.repeat_identical,
            }
        })
        .collect();
    let image = format!("images/{}-radiosity.png", room.label);
    let measured = Measured {
        scene: room.label.clone(),
        patches,
        subspaces: room.os.owner().len() as u32,
        patches_per_subspace: per_subspace,
        subspaces_with_at_most_one: at_most_one,
        threshold: room.threshold,
        reference_shots: room.reference.shots,
        reference_rays: room.reference.rays,
        reference_s: room.reference_s,
        size,
        ray_tracing_rays: pass.primary + pass.secondary,
        ray_tracing_trace_s: trace_s,
        runs,
        image: image.clone(),
    };
    let rows = rows(&p, &measured);
    let doc = document(ctx, &p, &measured);
    let result = Result_ {
        id: ctx.id,
        published: raw,
        quick: ctx.quick,
        measured,
        environment: environment(pool.current_num_threads()),
    };
    let mut out = Output::new(result, rows, doc);
    out.images.push(Image {
        path: image,
        pixels: pass.pixels(),
        size,
    });
    Ok(out)
}

fn rows(p: &Published, m: &Measured) -> Vec<Row> {
    let s = &m.scene;
    let patches_003 = p.value("scene");
    let agree = m
        .runs
        .iter()
        .all(|r| r.max_abs_difference <= m.threshold as f64);
    let diffs = m
        .runs
        .iter()
        .map(|r| {
            format!(
                "{} PEs: max |ΔB| {:.3}τ, max rel {:.2}%, mean rel {:.3}%",
                r.pes,
                r.max_abs_difference / m.threshold as f64,
                r.max_relative_difference * 100.0,
                r.mean_relative_difference * 100.0
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    vec![
        Row::new(
            "scene",
            s,
            format!("{patches_003:.0} patches in 32,768 subspaces, under 1 patch per subspace"),
            format!(
                "{} patches in {} subspaces, {:.2} per subspace, {:.1}% of subspaces hold at most 1",
                m.patches,
                m.subspaces,
                m.patches_per_subspace,
                m.subspaces_with_at_most_one * 100.0
            ),
            Kind::Ratio,
            Verdict::of(
                (m.patches as f64 / patches_003 - 1.0).abs() < 0.01 && m.patches_per_subspace < 1.0,
            ),
        ),
        Row::new(
            "same-solution",
            s,
            "the machine computes the progressive-refinement radiosity: equal to a single-process solution, within the threshold τ per patch",
            format!("τ = {}; {diffs}", m.threshold),
            Kind::Ratio,
            Verdict::of(agree),
        ),
        Row::new(
            "terminates",
            s,
            "the pass ends when no delta-radiosity ray remains, with no patch above the threshold",
            m.runs
                .iter()
                .map(|r| {
                    format!(
                        "{} PEs: {} shots, largest unshot left {:.4}",
                        r.pes, r.shots, r.max_unshot_left
                    )
                })
                .collect::<Vec<_>>()
                .join("; "),
            Kind::Ordering,
            Verdict::of(m.runs.iter().all(|r| r.max_unshot_left <= m.threshold)),
        ),
    ]
}

fn document(ctx: &Ctx, p: &Published, m: &Measured) -> Document {
    let mut doc = Document::new("yamauchi-radiosity: 003's radiosity pass and both passes on the room");
    doc.paragraph(osp::source_line(&p.source));
    doc.paragraph(format!(
        "Measured: `rtbench reproduce {}{}` — {} ({} patches; {:.2} patches per subspace, {:.1}% of the {} subspaces hold at most one), threshold τ = {} on unshot radiosity (lights emit 12), 1,200-pixel hemicubes, ≤ 3 mirror reflections; 2D tori with skewed allocation and 1 RP block per PE, Table 4 costs. The single-process reference shot {} times ({} delta rays) in {:.1} s. The ray-tracing pass ({}×{}, {} rays, traced in {:.1} s) reads the diffuse term from the reference solution.",
        ctx.id,
        if ctx.quick { " --quick" } else { "" },
        m.scene,
        m.patches,
        m.patches_per_subspace,
        m.subspaces_with_at_most_one * 100.0,
        m.subspaces,
        m.threshold,
        m.reference_shots,
        m.reference_rays,
        m.reference_s,
        m.size,
        m.size,
        m.ray_tracing_rays,
        m.ray_tracing_trace_s
    ));
    let mut t = DocTable::new(
        "",
        &[
            "PEs",
            "shots",
            "max |ΔB| / τ",
            "max rel. diff.",
            "mean rel. diff.",
            "radiosity clocks",
            "efficiency",
            "events/s",
            "wall s",
            "ray-tracing clocks",
            "efficiency",
            "events/s",
            "wall s",
        ],
    );
    for r in &m.runs {
        t.push(vec![
            format!("{} ({})", r.pes, r.shape),
            r.shots.to_string(),
            format!("{:.3}", r.max_abs_difference / m.threshold as f64),
            format!("{:.2}%", r.max_relative_difference * 100.0),
            format!("{:.3}%", r.mean_relative_difference * 100.0),
            r.radiosity.clocks.to_string(),
            format!("{:.1}%", r.radiosity.efficiency * 100.0),
            format!("{:.2e}", r.radiosity.events_per_s),
            format!("{:.1}", r.radiosity.wall_s),
            r.ray_tracing.clocks.to_string(),
            format!("{:.1}%", r.ray_tracing.efficiency * 100.0),
            format!("{:.2e}", r.ray_tracing.events_per_s),
            format!("{:.1}", r.ray_tracing.wall_s),
        ]);
    }
    doc.table(t);
    doc.list(vec![
        "Relative differences are |B − B_ref| / max(B, B_ref, τ) per patch and channel: a radiosity is known only to within the unshot radiosity left, at most τ, in either solution. At 1 PE the machine shoots almost in the reference's order (globally brightest first); on more PEs each PE shoots its own brightest side by side, so the order, the number of shots and the result differ within τ.".into(),
        format!(
            "Repeat on 16 PEs bit-identical (clocks and every radiosity): {}.",
            m.runs
                .iter()
                .find_map(|r| r.repeat_identical)
                .map_or("not run".into(), |b| b.to_string())
        ),
    ]);
    doc.figure(
        m.image.clone(),
        format!("{}: the ray-tracing pass with the radiosity pass's diffuse term", m.scene),
    );
    doc
}
