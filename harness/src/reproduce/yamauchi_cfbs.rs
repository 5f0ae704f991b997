//! `yamauchi-cfbs`: seed 003's cached frame buffer system (Yamauchi 1997, §3.4.3, §4.3): the
//! analytic queueing model (eqs. 11-21, Table 3) beside the random-arrival simulation, the caches
//! inside the execution-driven runs of 003's ray-tracing pass on SPD scenes, and faster processors
//! (Fig. 41: the processor-memory cycle ratio).

use super::object_space_pass::{self as osp, SimRecord, Traced};
use super::params::{Param, MAX_PES, SCENES, SIZE, THREADS};
use super::object_space_pass::ROOM;
use rtbench_engines::object_space::fbpath::FbPath;
use super::published::{self, Source};
use super::{environment, Claim, Ctx, Fidelity, Kind, Output, Row, Runtime, Table, Verdict};
use crate::error::Result;
use rayon::prelude::*;
use rtbench_engines::object_space::config::{Costs, FrameBuffer};
use rtbench_engines::object_space::machine::Allocation;
use rtbench_engines::object_space::queueing::{self, Model};
use rtbench_engines::object_space::sim::SimResult;
use rtbench_reports::plot::{Chart, LegendAt, Panel, XyPanel};
use rtbench_reports::{Document, Table as DocTable};
use serde::{Deserialize, Serialize};

const EXEC: &str = "003's ray-tracing pass on the room (rtbench_scenes::room), a stand-in for 003's unavailable scene; queue capacities are ours (003 gives none)";

pub const QUEUE: Param = Param {
    key: "queue",
    help: "entries in each frame-buffer queue (PE output, cache or buffer input, GFB), from 1 (default 4)",
};

const PARAMS: &[Param] = &[THREADS, SIZE, MAX_PES, SCENES, ROOM, QUEUE];

pub const TABLE: Table = Table {
    id: "yamauchi-cfbs",
    seed: "003",
    source: "§3.4.3, §4.3",
    about: "003 (Yamauchi 1997) §3.4, §4.3: cached frame buffer, queueing model vs simulation",
    runtime: Runtime {
        quick: "seconds",
        full: "minutes",
    },
    params: PARAMS,
    claims: &[
        Claim {
            key: "several-hundred-times",
            fidelity: Fidelity::Faithful,
            why: "",
        },
        Claim {
            key: "derived-saturation",
            fidelity: Fidelity::Faithful,
            why: "",
        },
        Claim {
            key: "sim-vs-theory",
            fidelity: Fidelity::Faithful,
            why: "",
        },
        Claim {
            key: "hit-rate-60",
            fidelity: Fidelity::Substituted,
            why: EXEC,
        },
        Claim {
            key: "lambda-1024",
            fidelity: Fidelity::Substituted,
            why: EXEC,
        },
        Claim {
            key: "bursty",
            fidelity: Fidelity::Substituted,
            why: EXEC,
        },
        Claim {
            key: "cfbs-at-1024",
            fidelity: Fidelity::Substituted,
            why: EXEC,
        },
        Claim {
            key: "cfbs-beats-wb",
            fidelity: Fidelity::Substituted,
            why: EXEC,
        },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/yamauchi-cfbs.json");

#[derive(Deserialize)]
struct Published {
    source: Source,
    claims: Vec<PublishedClaim>,
}

/// The fields of 003's CFBS claims this table reads.
#[derive(Deserialize)]
struct PublishedClaim {
    id: String,
    #[serde(default)]
    claim: String,
    value: Option<f64>,
    value_1rpb: Option<f64>,
    value_32rpb: Option<f64>,
    range: Option<[f64; 2]>,
    #[serde(default)]
    rows: Vec<Derived>,
}

/// A saturation point the digest derived from eqs. 11-21.
#[derive(Deserialize)]
struct Derived {
    m: u32,
    saturation: f64,
}

impl Published {
    fn claim(&self, id: &str) -> &PublishedClaim {
        self.claims
            .iter()
            .find(|c| c.id == id)
            .unwrap_or_else(|| panic!("yamauchi-cfbs.json: no claim '{id}'"))
    }
}

#[derive(Serialize)]
struct ModelRow {
    m: u32,
    stages: u32,
    miss: f64,
    saturation: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    derived: Option<f64>,
}

#[derive(Serialize)]
struct CurvePoint {
    lambda: f64,
    model_printed: Option<f64>,
    model_normalised: Option<f64>,
    simulated: f64,
}

#[derive(Serialize)]
struct ExecRun {
    scene: String,
    #[serde(flatten)]
    sim: SimRecord,
    pes: u32,
    rp_blocks: u32,
    /// "direct", "cfbs" or "wb" (write buffers).
    fb: &'static str,
    cfbs: bool,
    /// The tree's arity (none without caches or buffers).
    m: Option<u32>,
    /// RP-block clocks spent waiting for the frame buffer, over all RP-block clocks.
    stall_share: f64,
    lambda_pe: f64,
    interval_var_over_mean: f64,
    interval_var_over_mean_squared: f64,
    /// The frame buffer's share of the image time after the last RP block.
    fb_share: f64,
    hit_rate: f64,
}

#[derive(Serialize)]
struct PmcrRow {
    pmcr: u32,
    pes: u32,
    rp_blocks: u32,
    m: u32,
    direct: SimRecord,
    cfbs: SimRecord,
    lambda_pe: f64,
    direct_fb_share: f64,
    cfbs_fb_share: f64,
    cfbs_hit_rate: f64,
}

/// Where the model's normalised latency and the simulation's first exceed twice their light-load
/// value, on the grid of λ.
#[derive(Serialize)]
struct Knees {
    model_saturation: f64,
    model: Option<f64>,
    simulated: Option<f64>,
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    published: serde_json::Value,
    quick: bool,
    size: u32,
    model: Vec<ModelRow>,
    /// saturation(2-ary 10-stage) / saturation(1024-ary 1-stage), P_M = 0.5.
    load_ratio: f64,
    packets_per_point: usize,
    model_vs_simulation: Vec<CurvePoint>,
    knees: Knees,
    execution_driven: Vec<ExecRun>,
    pmcr: Vec<PmcrRow>,
    environment: serde_json::Value,
}

/// 003 §4.3.1's random simulation: a 1000×1000 image, 1 000 000 intensity packets.
const PACKETS_003: usize = 1_000_000;

/// The experiment's settings: from the options and `--quick`.
struct Setup {
    size: u32,
    scenes: Vec<String>,
    packets: usize,
    blocks: Vec<u32>,
    /// (PEs, cache arity): 256 with 16-ary, 1024 with 32-ary 2-stage caches.
    configs: Vec<(u32, u32)>,
    pmcrs: Vec<u32>,
    r_pmcr: u32,
    queue: u32,
}

fn setup(ctx: &Ctx) -> Result<Setup> {
    let q = ctx.quick;
    let max_pes = osp::max_pes(ctx, 1024)?;
    let ppm = ctx.params.number::<u32>(ROOM.key, 0)?.unwrap_or(if q { 2 } else { 8 });
    let queue = ctx.params.number::<u32>(QUEUE.key, 1)?.unwrap_or(4);
    let room = format!("room{ppm}");
    Ok(Setup {
        size: osp::size(ctx)?,
        scenes: osp::scenes(ctx, &[room.as_str()])?,
        queue,
        packets: if q { 50_000 } else { PACKETS_003 },
        blocks: if q {
            vec![1, 4, 16]
        } else {
            vec![1, 2, 4, 8, 16, 32, 64]
        },
        configs: [(256u32, 16u32), (1024, 32)]
            .into_iter()
            .filter(|&(p, _)| p <= max_pes)
            .collect(),
        pmcrs: if q {
            vec![1, 64]
        } else {
            vec![1, 4, 16, 64, 256]
        },
        r_pmcr: if q { 4 } else { 16 },
    })
}

/// Saturation by configuration (P_M = 0.5, beside the digest's values) and by miss rate.
fn model_rows(p: &Published) -> Vec<ModelRow> {
    let derived = &p.claim("derived-saturation").rows;
    let mut rows: Vec<ModelRow> = [(2u32, 10u32), (4, 5), (32, 2), (1024, 1)]
        .into_iter()
        .map(|(m, n)| ModelRow {
            m,
            stages: n,
            miss: 0.5,
            saturation: Model::table3(m, n, 0.5).saturation(),
            derived: derived.iter().find(|d| d.m == m).map(|d| d.saturation),
        })
        .collect();
    rows.extend([0.1, 0.3, 0.7, 0.9, 1.0].into_iter().map(|pm| ModelRow {
        m: 4,
        stages: 5,
        miss: pm,
        saturation: Model::table3(4, 5, pm).saturation(),
        derived: None,
    }));
    rows
}

/// 4-ary 5-stage, P_M = 0.5: the model's latency and the random-arrival simulation's, vs λ.
fn curve(packets: usize) -> (Vec<CurvePoint>, Knees) {
    let model = Model::table3(4, 5, 0.5);
    let sat = model.saturation();
    let lambdas: Vec<f64> = (0..=16)
        .map(|k| 1e-7 * 10f64.powf(k as f64 * 0.25))
        .filter(|&l| l < sat * 20.0)
        .collect();
    let sims: Vec<f64> = lambdas
        .par_iter()
        .map(|&l| queueing::simulate(&model, l, packets, 1997))
        .collect();
    let points: Vec<CurvePoint> = lambdas
        .iter()
        .zip(&sims)
        .map(|(&l, &s)| {
            let m = model.latency(l);
            CurvePoint {
                lambda: l,
                model_printed: m.map(|v| v.0),
                model_normalised: m.map(|v| v.1),
                simulated: s,
            }
        })
        .collect();
    let light_model = points[0].model_normalised.unwrap_or(f64::INFINITY);
    let knees = Knees {
        model_saturation: sat,
        model: points
            .iter()
            .find(|c| c.model_normalised.is_none_or(|v| v > 2.0 * light_model))
            .map(|c| c.lambda),
        simulated: points
            .iter()
            .find(|c| c.simulated > 2.0 * points[0].simulated)
            .map(|c| c.lambda),
    };
    (points, knees)
}

fn fb_share(r: &SimResult) -> f64 {
    r.clocks.saturating_sub(r.pe_clocks) as f64 / r.clocks as f64
}

fn fb_name(fb: FrameBuffer) -> &'static str {
    match fb {
        FrameBuffer::Direct => "direct",
        FrameBuffer::Cached { .. } => "cfbs",
        FrameBuffer::WriteBuffer { .. } => "wb",
    }
}

/// Direct, cached and write-buffered frame buffers with finite queues (the PEs wait when theirs
/// is full) on the 2D skewed torus, each R, each (PEs, arity).
fn execution_driven(t: &Traced, s: &Setup) -> Vec<ExecRun> {
    let mut keys = Vec::new();
    for &(p, m) in &s.configs {
        for &r in &s.blocks {
            for fb in [
                FrameBuffer::Direct,
                FrameBuffer::Cached { m },
                FrameBuffer::WriteBuffer { m },
            ] {
                keys.push((p, r, fb));
            }
        }
    }
    let machines: Vec<_> = keys
        .iter()
        .map(|&(p, r, kind)| {
            (
                osp::machine(p, 2, Allocation::Skewed, r),
                FbPath {
                    kind,
                    queue: s.queue,
                },
            )
        })
        .collect();
    eprintln!("{}: simulating {} machines …", t.label, machines.len());
    let results = osp::run_all_path(t, &machines);
    keys.iter()
        .zip(&results)
        .map(|(k, (r, wall))| {
            let base = keys
                .iter()
                .position(|b| *b == (k.0, 1, k.2))
                .map(|i| results[i].0.clocks)
                .unwrap_or(r.clocks);
            let f = &r.frame_buffer;
            let vm = f.interval_var / f.interval_mean.max(1e-9);
            let m = match k.2 {
                FrameBuffer::Cached { m } | FrameBuffer::WriteBuffer { m } => Some(m),
                FrameBuffer::Direct => None,
            };
            ExecRun {
                scene: t.label.clone(),
                sim: SimRecord::new(r, base, 1, *wall),
                pes: k.0,
                rp_blocks: k.1,
                fb: fb_name(k.2),
                cfbs: matches!(k.2, FrameBuffer::Cached { .. }),
                m,
                stall_share: r.fb_stall as f64
                    / (r.clocks.max(1) as f64 * (k.0 as u64 * k.1 as u64) as f64),
                lambda_pe: f.packets as f64 / (k.0 as f64 * r.pe_clocks.max(1) as f64),
                interval_var_over_mean: vm,
                interval_var_over_mean_squared: vm / f.interval_mean.max(1e-9),
                fb_share: f.finish.saturating_sub(r.pe_clocks) as f64 / r.clocks as f64,
                hit_rate: f.hit_rate(),
            }
        })
        .collect()
}

/// Table 4's costs with every PE unit `pmcr` times faster (at least 1 clock); the link's hop and
/// the frame buffer's costs stay.
fn faster(pmcr: u32) -> Costs {
    let c = Costs::default();
    let f = |v: u32| (v / pmcr).max(1);
    Costs {
        primary: f(c.primary),
        triangle: f(c.triangle),
        sphere: f(c.sphere),
        cone: f(c.cone),
        intensity: f(c.intensity),
        dda_init: f(c.dda_init),
        dda: f(c.dda),
        secondary: f(c.secondary),
        packet: f(c.packet),
        ..c
    }
}

/// 003 Fig. 41: the first scene traced with faster PE units, direct vs cached frame buffer on
/// the largest configuration.
fn pmcr_rows(s: &Setup) -> Result<Vec<PmcrRow>> {
    let (pp, pm) = *s.configs.last().unwrap_or(&(256, 16));
    let mut rows = Vec::new();
    for &pmcr in &s.pmcrs {
        let traced = osp::trace_scenes(&s.scenes[..1.min(s.scenes.len())], s.size, faster(pmcr), None)?;
        let Some(t) = traced.first() else { break };
        let m = osp::machine(pp, 2, Allocation::Skewed, s.r_pmcr);
        let path = |kind| FbPath {
            kind,
            queue: s.queue,
        };
        let res = osp::run_all_path(
            t,
            &[
                (m, path(FrameBuffer::Direct)),
                (m, path(FrameBuffer::Cached { m: pm })),
            ],
        );
        let (d, c) = (&res[0].0, &res[1].0);
        rows.push(PmcrRow {
            pmcr,
            pes: pp,
            rp_blocks: s.r_pmcr,
            m: pm,
            direct: SimRecord::new(d, d.clocks, 1, res[0].1),
            cfbs: SimRecord::new(c, d.clocks, 1, res[1].1),
            lambda_pe: d.frame_buffer.packets as f64 / (pp as f64 * d.pe_clocks.max(1) as f64),
            direct_fb_share: fb_share(d),
            cfbs_fb_share: fb_share(c),
            cfbs_hit_rate: c.frame_buffer.hit_rate(),
        });
    }
    Ok(rows)
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let s = setup(ctx)?;
    let pool = crate::measure::threads::pool(ctx.params.threads()?)?;
    let model = model_rows(&p);
    let (points, knees) = pool.install(|| curve(s.packets));
    let traced = osp::trace_scenes(&s.scenes, s.size, Costs::default(), None)?;
    let exec: Vec<ExecRun> = traced
        .iter()
        .flat_map(|t| pool.install(|| execution_driven(t, &s)))
        .collect();
    let pmcr = pool.install(|| pmcr_rows(&s))?;
    let result = Result_ {
        id: ctx.id,
        published: raw,
        quick: ctx.quick,
        size: s.size,
        load_ratio: Model::table3(2, 10, 0.5).saturation()
            / Model::table3(1024, 1, 0.5).saturation(),
        model,
        packets_per_point: s.packets,
        model_vs_simulation: points,
        knees,
        execution_driven: exec,
        pmcr,
        environment: environment(pool.current_num_threads()),
    };
    let rows = rows(&p, &result);
    let doc = document(ctx, &p, &result, &s);
    let mut out = Output::new(&result, rows, doc);
    out.charts = vec![chart(ctx.id, &result.model_vs_simulation)];
    out.images = traced.iter().filter_map(Traced::image).collect();
    Ok(out)
}

/// "lo–hi" of a measure over some runs.
fn span(v: impl Iterator<Item = f64>, show: impl Fn(f64) -> String) -> Option<String> {
    let v: Vec<f64> = v.collect();
    let lo = v.iter().copied().reduce(f64::min)?;
    let hi = v.iter().copied().reduce(f64::max)?;
    Some(format!("{} to {}", show(lo), show(hi)))
}

/// The comparison rows (pure).
fn rows(p: &Published, r: &Result_) -> Vec<Row> {
    let mut rows = model_claim_rows(p, r);
    let mut scenes: Vec<&str> = r
        .execution_driven
        .iter()
        .map(|e| e.scene.as_str())
        .collect();
    scenes.dedup();
    for scene in scenes {
        rows.extend(exec_rows(p, scene, &r.execution_driven));
    }
    rows
}

fn model_claim_rows(p: &Published, r: &Result_) -> Vec<Row> {
    let digits = |v: f64| format!("{v:.3e}");
    let derived: Vec<&ModelRow> = r.model.iter().filter(|m| m.derived.is_some()).collect();
    let agree = derived
        .iter()
        .all(|m| m.derived.map(digits) == Some(digits(m.saturation)));
    let k = &r.knees;
    vec![
        Row::new(
            "several-hundred-times",
            "2-ary 10-stage vs 1024-ary 1-stage, P_M = 0.5",
            "several hundred times the load (judged: 100 to 1000)",
            format!("{:.0}×", r.load_ratio),
            Kind::Range,
            Verdict::of((100.0..1000.0).contains(&r.load_ratio)),
        ),
        Row::new(
            "derived-saturation",
            "eqs. 11-21, Table 3, P_M = 0.5",
            derived
                .iter()
                .map(|m| format!("{}-ary: {}", m.m, m.derived.map_or("-".into(), digits)))
                .collect::<Vec<_>>()
                .join(", "),
            derived
                .iter()
                .map(|m| format!("{}-ary: {}", m.m, digits(m.saturation)))
                .collect::<Vec<_>>()
                .join(", "),
            Kind::Count,
            Verdict::of(agree),
        )
        .with_note("checks our code against 003's own equations (11)-(21) with Table 3's values: the saturation points are derived from them (003 prints none), equal to 4 significant digits"),
        at_003s_length(Row::new(
            "sim-vs-theory",
            "4-ary 5-stage, P_M = 0.5",
            p.claim("sim-vs-theory").claim.clone(),
            format!(
                "latency doubles at λ ≈ {} (model) and {} (simulation){}; model saturation {:.3e}",
                k.model.map_or("-".into(), |v| format!("{v:.2e}")),
                k.simulated
                    .map_or("beyond the grid".into(), |v| format!("{v:.2e}")),
                match (k.model, k.simulated) {
                    (Some(m), Some(s)) => format!(": simulation / model = {:.2}", s / m),
                    _ => String::new(),
                },
                k.model_saturation
            ),
            Kind::Ratio,
            order_later(k.model, k.simulated),
        )
        .with_note("holds when the simulation's knee (latency twice the light-load latency) is 10^0.5 to 10^1.5 times the model's, on a grid of λ in steps of 10^0.25; a simulation with Table 3's service times saturates where a unit's utilisation reaches 1, the load at which the model saturates too, so an order of magnitude between them needs other times than Table 3's (003 does not say which its simulator used)"), r.packets_per_point),
    ]
}

/// 003 §4.3.1: the random simulation saturates "about one order of magnitude" later than the
/// model. Judged on the knees' ratio, simulation / model, within half an order of 10; shown when
/// either knee lies beyond the grid.
fn order_later(model: Option<f64>, simulated: Option<f64>) -> Verdict {
    match (model, simulated) {
        (Some(m), Some(s)) => Verdict::of((10f64.powf(0.5)..=10f64.powf(1.5)).contains(&(s / m))),
        _ => Verdict::Shown,
    }
}

/// The random simulation's row is 003's own method (§4.3.1: Poisson emissions, Table 3's times)
/// only at 003's length; shorter runs (`--quick`) are a named stand-in.
fn at_003s_length(row: Row, packets: usize) -> Row {
    if packets >= PACKETS_003 {
        return row;
    }
    row.with_fidelity(
        Fidelity::Substituted,
        format!("{packets} packets per point (--quick), not 003's 1 000 000"),
    )
}

/// 003 (4.3.2): "the variance of the emission intervals is 100 to 1000 times the mean", offered as
/// evidence that emission is not Poisson. Judged on variance / mean², the squared coefficient of
/// variation, which is 1 for a Poisson stream whatever the clock; variance / mean has the unit of a
/// clock and is shown beside it.
fn bursty(var_over_mean_squared: f64, range: [f64; 2]) -> bool {
    (range[0]..=range[1]).contains(&var_over_mean_squared)
}

/// The execution-driven claims on one scene: shown, and the burstiness judged on its range.
fn exec_rows(p: &Published, scene: &str, exec: &[ExecRun]) -> Vec<Row> {
    let runs = || exec.iter().filter(move |e| e.scene == scene);
    let cached = || runs().filter(|e| e.cfbs);
    let pct = |v: f64| format!("{:.1}%", v * 100.0);
    let lam = p.claim("lambda-1024");
    let lambda_at = |r: u32| {
        runs()
            .find(|e| e.pes == 1024 && e.rp_blocks == r && e.fb == "direct")
            .map_or("not run".into(), |e| format!("{:.2e}", e.lambda_pe))
    };
    let range = p.claim("bursty").range.unwrap_or([100.0, 1000.0]);
    // 003 measured the intervals at 1024 PEs (4.3.2); judged there, on the dimensionless index.
    let at_1024 = || runs().filter(|e| e.pes == 1024);
    let judged = || if at_1024().next().is_some() { at_1024().collect::<Vec<_>>() } else { runs().collect() };
    let is_bursty = judged().iter().all(|e| bursty(e.interval_var_over_mean_squared, range));
    // T(other) / T(CFBS) at each R for one PE count.
    let ratios = |pes: u32, other: &str| -> Vec<(u32, f64)> {
        runs()
            .filter(|e| e.pes == pes && e.cfbs)
            .filter_map(|c| {
                let o = runs().find(|e| e.pes == pes && e.rp_blocks == c.rp_blocks && e.fb == other)?;
                Some((c.rp_blocks, o.sim.clocks as f64 / c.sim.clocks as f64))
            })
            .collect()
    };
    let show = |v: &[(u32, f64)]| {
        v.iter()
            .map(|(r, x)| format!("R={r}: {x:.3}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    // "Helps": the image at least 5% sooner with the caches.
    const HELPS: f64 = 1.05;
    let d256 = ratios(256, "direct");
    let d1024 = ratios(1024, "direct");
    let onset = d1024.iter().find(|(_, x)| *x >= HELPS).map(|(r, _)| *r);
    let cfbs_verdict = if d256.is_empty() || d1024.is_empty() {
        Verdict::NotMeasured
    } else {
        let none_at_256 = d256.iter().all(|(_, x)| (x - 1.0).abs() < HELPS - 1.0);
        Verdict::of(none_at_256 && onset.is_some_and(|r| (8..=32).contains(&r)))
    };
    let wb: Vec<(u32, f64)> = [256u32, 1024]
        .into_iter()
        .flat_map(|p| ratios(p, "wb").into_iter().map(move |(r, x)| (p * 1000 + r, x)))
        .collect();
    let wb_verdict = if wb.is_empty() {
        Verdict::NotMeasured
    } else {
        Verdict::of(wb.iter().all(|(_, x)| *x >= 1.0) && wb.iter().any(|(_, x)| *x >= HELPS))
    };
    let wb_show = |pes: u32| show(&ratios(pes, "wb"));
    vec![
        Row::new(
            "hit-rate-60",
            scene,
            format!("about {}", pct(p.claim("hit-rate-60").value.unwrap_or(0.6))),
            span(cached().map(|e| e.hit_rate), pct).unwrap_or("not run".into()),
            Kind::Ratio,
            Verdict::Shown,
        ),
        Row::new(
            "lambda-1024",
            scene,
            format!(
                "1024 PEs: about {:.1e} (R = 1), {:.1e} (R = 32)",
                lam.value_1rpb.unwrap_or(f64::NAN),
                lam.value_32rpb.unwrap_or(f64::NAN)
            ),
            format!("{} (R = 1), {} (R = 32)", lambda_at(1), lambda_at(32)),
            Kind::Ratio,
            Verdict::Shown,
        ),
        Row::new(
            "bursty",
            format!("{scene}, 1024 PEs"),
            format!(
                "interval variance {} to {} times the mean; judged as variance / mean² (Poisson: 1)",
                range[0], range[1]
            ),
            format!(
                "variance / mean² {}; variance / mean {} clocks",
                span(judged().into_iter().map(|e| e.interval_var_over_mean_squared), |v| format!("{v:.1}"))
                    .unwrap_or("not run".into()),
                span(judged().into_iter().map(|e| e.interval_var_over_mean), |v| format!("{v:.0}"))
                    .unwrap_or("not run".into())
            ),
            Kind::Range,
            if runs().next().is_some() {
                Verdict::of(is_bursty)
            } else {
                Verdict::NotMeasured
            },
        )
        .with_note("003's words (variance 100-1000 times the mean) do not fit its own numbers read in clocks: at its λ (5.9e-6 per PE per clock, 1024 PEs) a Poisson stream's intervals have variance / mean = mean ≈ 165 clocks, inside the band, so the band cannot mean 'not Poisson' in clocks; the dimensionless variance / mean² (1 for Poisson) is the reading that does"),
        Row::new(
            "cfbs-at-1024",
            scene,
            "256 PEs: almost no effect; 1024 PEs: helps from about 16 RP blocks per PE",
            format!(
                "T direct / T CFBS — 256 PEs: {}; 1024 PEs: {} (helps, ≥ {HELPS}: from R = {})",
                show(&d256),
                show(&d1024),
                onset.map_or("never".into(), |r| r.to_string())
            ),
            Kind::Shape,
            cfbs_verdict,
        ),
        Row::new(
            "cfbs-beats-wb",
            scene,
            "the CFBS beats a write buffer in its place (the caches add up packets)",
            format!(
                "T write buffer / T CFBS — 256 PEs: {}; 1024 PEs: {}",
                wb_show(256),
                wb_show(1024)
            ),
            Kind::Shape,
            wb_verdict,
        ),
    ]
}

fn document(ctx: &Ctx, p: &Published, r: &Result_, s: &Setup) -> Document {
    let mut doc = Document::new("yamauchi-cfbs: the cached frame buffer system");
    doc.paragraph(osp::source_line(&p.source));
    doc.paragraph(format!(
        "Measured: `rtbench reproduce {}{}`.",
        ctx.id,
        if ctx.quick { " --quick" } else { "" }
    ));
    model_section(&mut doc, r);
    exec_section(&mut doc, r, s);
    pmcr_section(&mut doc, r, s);
    let (hit, lam) = (p.claim("hit-rate-60"), p.claim("lambda-1024"));
    let range = p.claim("bursty").range.unwrap_or([f64::NAN; 2]);
    doc.paragraph(format!("003 (4.3.2): FBC hit rate about {:.0}%; λ about {:.1e} (1024 PEs × 1 RP block) and {:.1e} (× 32); interval variance {}-{} times the mean; the caches help only at 1024 PEs with about 16 RP blocks or more. 'FB share' is how much of the image time the frame buffer adds after the last RP block finishes.", hit.value.unwrap_or(f64::NAN) * 100.0, lam.value_1rpb.unwrap_or(f64::NAN), lam.value_32rpb.unwrap_or(f64::NAN), range[0], range[1]));
    doc
}

fn model_section(doc: &mut Document, r: &Result_) {
    doc.heading("Queueing model (eqs. 11-21, Table 3)");
    let mut t = DocTable::new(
        "",
        &[
            "m-ary n-stage",
            "P_M",
            "saturation λ_PE (per PE per clock)",
            "derived from eqs. 11-21",
        ],
    );
    for m in &r.model {
        t.push(vec![
            format!("{}-ary {}-stage", m.m, m.stages),
            m.miss.to_string(),
            format!("{:.4e}", m.saturation),
            m.derived.map_or(String::new(), |d| format!("{d:.4e}")),
        ]);
    }
    doc.table(t);
    doc.paragraph(format!(
        "2-ary 10-stage tolerates {:.0}× the load of no CFBS (003: several hundred times).",
        r.load_ratio
    ));
    doc.heading(format!(
        "4-ary 5-stage, P_M = 0.5: model vs random-arrival simulation ({} packets per point)",
        r.packets_per_point
    ));
    let mut t = DocTable::new(
        "",
        &[
            "λ_PE",
            "model L_mean as printed",
            "model L_mean normalised",
            "simulated L_mean",
        ],
    );
    let show = |v: Option<f64>| v.map_or("saturated".into(), |v| format!("{v:.1}"));
    for c in &r.model_vs_simulation {
        t.push(vec![
            format!("{:.3e}", c.lambda),
            show(c.model_printed),
            show(c.model_normalised),
            format!("{:.1}", c.simulated),
        ]);
    }
    doc.table(t);
    let k = &r.knees;
    doc.paragraph(format!("Latency doubles at λ ≈ {} (model, normalised) and {} (simulation), on this grid of λ; model saturation {:.3e}. 003: the simulation saturates about an order of magnitude later.", k.model.map_or("–".into(), |v| format!("{v:.2e}")), k.simulated.map_or("beyond the grid".into(), |v| format!("{v:.2e}")), k.model_saturation));
    doc.figure(
        "plots/yamauchi-cfbs-model-vs-simulation.svg",
        "model vs simulation",
    );
}

fn exec_section(doc: &mut Document, r: &Result_, s: &Setup) {
    let mut scenes: Vec<&str> = r
        .execution_driven
        .iter()
        .map(|e| e.scene.as_str())
        .collect();
    scenes.dedup();
    for scene in scenes {
        doc.heading(format!(
            "{scene}: execution-driven, 2D skewed, {0}×{0}",
            s.size
        ));
        let mut t = DocTable::new(
            "",
            &[
                "PEs",
                "frame buffer",
                "R",
                "speed-up vs R = 1",
                "image clocks",
                "RP stall share",
                "FB share of image time",
                "hit rate",
                "λ_PE",
                "interval var/mean",
                "var/mean²",
                "mean latency",
            ],
        );
        for e in r.execution_driven.iter().filter(|e| e.scene == scene) {
            t.push(vec![
                e.pes.to_string(),
                match (e.fb, e.m) {
                    ("cfbs", Some(m)) => format!("CFBS {m}-ary 2-stage"),
                    ("wb", Some(m)) => format!("write buffers {m}-ary"),
                    _ => "direct GFB".into(),
                },
                e.rp_blocks.to_string(),
                format!("{:.2}", e.sim.speedup),
                e.sim.clocks.to_string(),
                format!("{:.3}", e.stall_share),
                format!("{:.3}", e.fb_share),
                if e.cfbs {
                    format!("{:.1}%", e.hit_rate * 100.0)
                } else {
                    "–".into()
                },
                format!("{:.2e}", e.lambda_pe),
                format!("{:.0}", e.interval_var_over_mean),
                format!("{:.1}", e.interval_var_over_mean_squared),
                format!("{:.1}", e.sim.frame_buffer.latency_mean),
            ]);
        }
        doc.table(t);
    }
}

fn pmcr_section(doc: &mut Document, r: &Result_, s: &Setup) {
    let (pp, pm) = *s.configs.last().unwrap_or(&(256, 16));
    doc.heading(format!(
        "Processor-memory cycle ratio (003 Fig. 41): {pp} PEs × {} RP blocks, 2D skewed, {}",
        s.r_pmcr,
        s.scenes.first().map_or("", |s| s.as_str())
    ));
    doc.paragraph("Every PE unit cost (Table 4 but the link's hop) divided by the PMCR; links and frame buffer unchanged.");
    let cfbs_col = format!("T direct / T with {pm}-ary CFBS");
    let mut t = DocTable::new(
        "",
        &[
            "PMCR",
            &cfbs_col,
            "FB share of image time (direct)",
            "FB share (CFBS)",
            "hit rate",
            "λ_PE",
            "mean latency direct",
            "mean latency CFBS",
        ],
    );
    for x in &r.pmcr {
        t.push(vec![
            x.pmcr.to_string(),
            format!("{:.3}", x.direct.clocks as f64 / x.cfbs.clocks as f64),
            format!("{:.3}", x.direct_fb_share),
            format!("{:.3}", x.cfbs_fb_share),
            format!("{:.1}%", x.cfbs_hit_rate * 100.0),
            format!("{:.2e}", x.lambda_pe),
            format!("{:.1}", x.direct.frame_buffer.latency_mean),
            format!("{:.1}", x.cfbs.frame_buffer.latency_mean),
        ]);
    }
    doc.table(t);
}

fn chart(id: &str, curve: &[CurvePoint]) -> Chart {
    let mpts: Vec<(f64, f64)> = curve
        .iter()
        .filter_map(|c| c.model_normalised.map(|v| (c.lambda, v)))
        .collect();
    let spts: Vec<(f64, f64)> = curve.iter().map(|c| (c.lambda, c.simulated)).collect();
    Chart {
        stem: format!("{id}-model-vs-simulation"),
        title: "4-ary 5-stage CFBS, P_M = 0.5: mean latency vs λ_PE".into(),
        panels: vec![Panel::Xy(XyPanel {
            title: "mean latency".into(),
            x_label: "λ_PE (packets per PE per clock)".into(),
            y_label: "clocks".into(),
            x_log: true,
            y_log: true,
            x_ticks: Vec::new(),
            lines: true,
            legend: LegendAt::UpperLeft,
            series: vec![
                osp::series("model (normalised)", 1, &mpts),
                osp::series("random simulation", 2, &spts),
            ],
        })],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_model_matches_the_digests_saturation_points() {
        let (p, _): (Published, _) = published::load("yamauchi-cfbs", PUBLISHED);
        let rows = model_rows(&p);
        assert_eq!(rows.iter().filter(|r| r.derived.is_some()).count(), 4);
        for r in rows.iter().filter(|r| r.derived.is_some()) {
            let d = r.derived.unwrap();
            assert!((r.saturation / d - 1.0).abs() < 1e-3, "{}-ary", r.m);
        }
        assert!(p.claim("lambda-1024").value_32rpb.is_some());
        assert_eq!(p.claim("bursty").range, Some([100.0, 1000.0]));
    }

    /// The burstiness check on 003's own numbers: at its λ a Poisson stream falls inside the band
    /// read in clocks (so that reading cannot tell bursty from Poisson), and outside it read
    /// dimensionless, as a stream 100-1000 times burstier than Poisson falls inside.
    #[test]
    fn burstiness_is_judged_dimensionless_on_003s_numbers() {
        let (p, _): (Published, _) = published::load("yamauchi-cfbs", PUBLISHED);
        let range = p.claim("bursty").range.unwrap();
        let lambda = p.claim("lambda-1024").value_1rpb.unwrap();
        // Intervals at the frame buffer: 1024 PEs emitting at λ each.
        let mean = 1.0 / (1024.0 * lambda);
        let poisson_var = mean * mean;
        let in_clocks = poisson_var / mean;
        assert!((in_clocks - 165.5).abs() < 1.0, "{in_clocks}");
        assert!((range[0]..=range[1]).contains(&in_clocks));
        assert!(!bursty(poisson_var / (mean * mean), range));
        for factor in [range[0], 300.0, range[1]] {
            assert!(bursty(factor * poisson_var / (mean * mean), range));
        }
    }

    /// The random simulation is 003's own only at 003's length: a shorter run names itself.
    #[test]
    fn the_random_simulation_is_faithful_only_at_003s_length() {
        let row = || Row::new("sim-vs-theory", "-", "-", "-", Kind::Shape, Verdict::Shown);
        assert_eq!(at_003s_length(row(), PACKETS_003).fidelity, None);
        let quick = at_003s_length(row(), 50_000);
        assert_eq!(quick.fidelity, Some(Fidelity::Substituted));
        assert!(quick.note.contains("50000 packets"), "{}", quick.note);
        let claim = TABLE.claims.iter().find(|c| c.key == "sim-vs-theory").unwrap();
        assert_eq!(claim.fidelity, Fidelity::Faithful);
    }

    /// "About one order of magnitude later", fed through its check: ten times holds, the same knee
    /// or a hundred times does not, a knee beyond the grid is only shown.
    #[test]
    fn the_simulation_saturating_an_order_later_is_judged_on_the_knees_ratio() {
        assert_eq!(order_later(Some(1e-4), Some(1e-3)), Verdict::Holds);
        assert_eq!(order_later(Some(1e-4), Some(5.62e-4)), Verdict::Holds);
        assert_eq!(order_later(Some(5.62e-4), Some(5.62e-4)), Verdict::Fails);
        assert_eq!(order_later(Some(1e-4), Some(1e-2)), Verdict::Fails);
        assert_eq!(order_later(Some(1e-4), None), Verdict::Shown);
    }

    #[test]
    fn faster_units_keep_the_links_cost() {
        let (c, f) = (Costs::default(), faster(64));
        assert_eq!(f.triangle, (c.triangle / 64).max(1));
        assert_eq!(f.hop, c.hop);
    }
}
