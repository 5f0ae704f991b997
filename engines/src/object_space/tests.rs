//! Tests of the `object-space` engine: settings and bad input, the allocations' formulas and
//! adjacency, hits against the reference engine, the simulation's invariants and determinism,
//! the frame-buffer caches, and the queueing model against the digest's derived checks.

use super::config::{Costs, FrameBuffer, ObjectSpaceConfig};
use super::framebuffer::{self, Emission};
use super::machine::{Allocation, Machine};
use super::queueing::{self, Model};
use super::sim::simulate;
use super::trace::{Trace, TracedRay, NO_PIXEL};
use super::ObjectSpace;
use crate::engine::{BuildInput, Counters, Settings};
use crate::geometry::Geometry;
use crate::ray::{Hit, Ray};
use crate::test_support::spd;
use crate::{build_engine, EngineError};
use glam::Vec3;
use rtbench_scenes::spd::Program;
use std::sync::Arc;

fn config(kv: &[(&str, &str)]) -> Result<ObjectSpaceConfig, EngineError> {
    ObjectSpaceConfig::from_settings(Settings::new(
        "object-space",
        kv.iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
    ))
}

/// Deterministic rays from points around the scene towards points inside it.
fn rays(input: &BuildInput, n: usize) -> Vec<Ray> {
    let (lo, hi) = (input.geometry.bounds_min, input.geometry.bounds_max);
    let mut s = 0x1234_5678u64;
    let mut unit = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    (0..n)
        .map(|_| {
            let c = (lo + hi) * 0.5;
            let ext = hi - lo;
            let o = c + ext * Vec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * 2.5;
            let t = lo + ext * Vec3::new(unit(), unit(), unit());
            Ray::new(o, (t - o).normalize(), 0.0, f32::INFINITY)
        })
        .collect()
}

#[test]
fn bad_settings_are_errors() {
    let e = config(&[("pes", "12")]).unwrap_err().to_string();
    assert!(e.contains("does not divide the subspaces"), "{e}");
    let e = config(&[("pes", "0")]).unwrap_err().to_string();
    assert!(e.contains("zero processing elements"), "{e}");
    let e = config(&[("pes", "4x0x2")]).unwrap_err().to_string();
    assert!(e.contains("zero"), "{e}");
    for v in ["0", "-5", "x"] {
        let e = config(&[("cost.hop", v)]).unwrap_err().to_string();
        assert!(e.contains("cost.hop"), "{e}");
    }
    assert!(config(&[("allocation", "skewed"), ("pes", "4x4x4")]).is_err());
    assert!(config(&[("allocation", "diagonal")]).is_err());
    assert!(config(&[("rp_blocks", "0")]).is_err());
    assert!(config(&[("subspaces", "0")]).is_err());
    assert!(config(&[("frame_buffer", "cfbs:1")]).is_err());
    assert!(config(&[("nonsense", "1")]).is_err());
    let c = config(&[
        ("pes", "8x4"),
        ("subspaces", "16,8,4"),
        ("cost.sphere", "2000"),
    ])
    .unwrap();
    assert_eq!(c.machine.pes, [8, 4, 1]);
    assert_eq!(c.machine.dims, 2);
    assert_eq!(c.costs.sphere, 2000);
}

#[test]
fn allocation_formulas() {
    let s = [32, 32, 32];
    let m = |pes, dims, allocation| Machine {
        pes,
        dims,
        allocation,
        rp_blocks: 1,
    };
    // Eq. 7: blocks of ⌈32/4⌉ = 8.
    let b = m([4, 4, 1], 2, Allocation::Block);
    assert_eq!(b.owner_coords([9, 31, 5], s), [1, 3, 0]);
    // Eq. 8.
    let d = m([4, 4, 2], 3, Allocation::Distributed);
    assert_eq!(d.owner_coords([9, 31, 5], s), [1, 3, 1]);
    // Eqs. 9, 10.
    let k1 = m([8, 1, 1], 1, Allocation::Skewed);
    assert_eq!(k1.owner_coords([3, 4, 5], s), [4, 0, 0]);
    let k2 = m([4, 8, 1], 2, Allocation::Skewed);
    assert_eq!(k2.owner_coords([3, 9, 2], s), [1, 1, 0]);
    // Adjacent subspaces are on the same or neighbouring PEs, for every allocation.
    for mach in [b, d, k1, k2, m([32, 1, 1], 1, Allocation::Block)] {
        let own = mach.owner_map(s);
        for z in 0..31u32 {
            for y in 0..31u32 {
                for x in 0..31u32 {
                    let i = (x + 32 * (y + 32 * z)) as usize;
                    for j in [i + 1, i + 32, i + 1024] {
                        assert!(mach.route(own[i], own[j]).0 <= 1);
                    }
                }
            }
        }
    }
    // Torus routes take the short way round.
    let t = m([8, 1, 1], 1, Allocation::Distributed);
    assert_eq!(t.route(0, 7), (1, 1));
    assert_eq!(t.route(0, 3), (3, 0));
}

#[test]
fn hits_equal_the_reference_engine() {
    for program in [Program::Tetra, Program::Rings, Program::Balls] {
        let input = spd(program, 1);
        let os = build_engine(
            "object-space",
            &input,
            vec![("subspaces".into(), "8".into()), ("pes".into(), "4".into())],
        )
        .unwrap();
        let reference = build_engine("reference", &input, vec![]).unwrap();
        let rs = rays(&input, 400);
        let (mut a, mut b) = (vec![Hit::MISS; rs.len()], vec![Hit::MISS; rs.len()]);
        os.intersect(&rs, &mut a, &mut Counters::default());
        reference.intersect(&rs, &mut b, &mut Counters::default());
        let mut same = 0;
        for (x, y) in a.iter().zip(&b) {
            if x.object == y.object && (!x.is_hit() || (x.t - y.t).abs() <= 1e-3 * y.t.max(1.0)) {
                same += 1;
            }
        }
        assert!(
            same >= rs.len() - 2,
            "{program:?}: {same} of {} agree",
            rs.len()
        );
        let (mut oa, mut ob) = (vec![false; rs.len()], vec![false; rs.len()]);
        let short: Vec<Ray> = rs.iter().map(|r| Ray { tmax: 2.0, ..*r }).collect();
        os.occluded(&short, &mut oa, &mut Counters::default());
        reference.occluded(&short, &mut ob, &mut Counters::default());
        let agree = oa.iter().zip(&ob).filter(|(x, y)| x == y).count();
        assert!(agree >= rs.len() - 2, "{program:?}: occluded {agree}");
    }
}

/// A trace of every ray of `rs` as a root with an intensity packet to pixel i.
fn root_trace(os: &ObjectSpace, rs: &[Ray]) -> Trace {
    let mut t = Trace::default();
    for (i, r) in rs.iter().enumerate() {
        let start = t.segs.len() as u32;
        let h = os.execute(r, false, &mut t.segs, &mut Counters::default());
        t.rays.push(TracedRay {
            seg_start: start,
            seg_count: t.segs.len() as u32 - start,
            first_child: 0,
            children: 0,
            pixel: if h.is_hit() { i as u32 } else { NO_PIXEL },
            root: true,
            initial: true,
            hit: h.is_hit(),
        });
    }
    t
}

#[test]
fn simulation_invariants_and_determinism() {
    let input = spd(Program::Balls, 2);
    let os = ObjectSpace::build(&input, config(&[]).unwrap()).unwrap();
    let rs = rays(&input, 2000);
    let trace = root_trace(&os, &rs);
    let costs = Costs::default();
    let run = |pes: [u32; 3], dims, allocation, rp_blocks| {
        let m = Machine {
            pes,
            dims,
            allocation,
            rp_blocks,
        };
        simulate(
            &trace,
            &m,
            &m.owner_map([32; 3]),
            &costs,
            FrameBuffer::Direct,
            64,
        )
    };
    let one = run([1, 1, 1], 1, Allocation::Block, 1);
    // One PE, one RP block: never idle while work is queued behind the FRGU's first ray, and
    // no packet leaves the PE.
    assert_eq!(one.packets, 0);
    assert!(one.pe_clocks >= one.busy);
    let mut last = None;
    for (pes, dims, alloc) in [
        ([16, 1, 1], 1, Allocation::Skewed),
        ([4, 4, 1], 2, Allocation::Distributed),
        ([4, 4, 2], 3, Allocation::Block),
    ] {
        let r = run(pes, dims, alloc, 1);
        // The work is the machine's to spread, not to change.
        assert_eq!(r.busy, one.busy);
        assert_eq!(r.events, one.events);
        assert!(r.clocks < one.clocks);
        assert!(r.utilisation() <= 1.0 + 1e-12);
        assert!(r.packets > 0 && r.hops >= r.packets);
        // Same inputs, same clocks, bit for bit.
        assert_eq!(r, run(pes, dims, alloc, 1));
        last = Some(r);
    }
    // More RP blocks never make a PE slower here.
    let more = run([4, 4, 2], 3, Allocation::Block, 4);
    assert!(more.pe_clocks <= last.unwrap().pe_clocks);
}

#[test]
fn engine_counters_are_deterministic_across_calls() {
    let input = spd(Program::Tetra, 2);
    let e = build_engine("object-space", &input, vec![("pes".into(), "4x4".into())]).unwrap();
    let rs = rays(&input, 500);
    let mut h = vec![Hit::MISS; rs.len()];
    let (mut c1, mut c2) = (Counters::default(), Counters::default());
    e.intersect(&rs, &mut h, &mut c1);
    e.intersect(&rs, &mut h, &mut c2);
    assert_eq!(c1, c2);
    assert!(c1.extra["sim_clocks"] > 0);
    assert_eq!(c1.extra["sim_waves"], 1);
}

#[test]
fn frame_buffer_caches_accumulate() {
    let costs = Costs::default();
    // Two PEs write the same 4×4 block, then one pixel far away: the first-stage cache (2 PEs
    // share it with m = 2 over 4 PEs) misses once, hits once per repeat.
    let mut em: Vec<Emission> = (0..10u64)
        .map(|i| Emission {
            time: i * 100,
            pe: (i % 2) as u32,
            pixel: (i % 4) as u32,
        })
        .collect();
    let s = framebuffer::simulate(&mut em, 4, &costs, FrameBuffer::Cached { m: 2 }, 64);
    assert_eq!((s.hits, s.misses), (9, 1));
    assert_eq!(s.flushed_blocks, 1);
    // Direct: every packet pays the GFB's 14 clocks after its 8-clock link.
    let s = framebuffer::simulate(&mut em, 4, &costs, FrameBuffer::Direct, 64);
    assert_eq!((s.hits, s.misses), (0, 0));
    assert_eq!(s.latency_max, 8 + 14);
}

/// Finite frame-buffer queues (003 §4.3.2): with room enough nothing waits and the PEs' clocks
/// are the unbounded run's; with one-entry queues and a GFB made slow (so the path saturates)
/// RP blocks wait, the image takes longer, and the caches, which add packets up, beat write
/// buffers, which pass every packet on to the GFB. Repeats are bit-identical.
#[test]
fn frame_buffer_back_pressure_stalls_the_pes() {
    use super::fbpath::FbPath;
    use super::sim::simulate_path;
    let input = spd(Program::Balls, 2);
    let os = ObjectSpace::build(&input, config(&[]).unwrap()).unwrap();
    let rs = rays(&input, 4000);
    let trace = root_trace(&os, &rs);
    let m = Machine {
        pes: [8, 8, 1],
        dims: 2,
        allocation: Allocation::Skewed,
        rp_blocks: 8,
    };
    let owner = m.owner_map([32; 3]);
    let run = |costs: &Costs, kind, queue| {
        simulate_path(&trace, &m, &owner, costs, FbPath { kind, queue }, 64)
    };
    let costs = Costs::default();
    let free = simulate(&trace, &m, &owner, &costs, FrameBuffer::Direct, 64);
    let roomy = run(&costs, FrameBuffer::Direct, 1 << 20);
    assert_eq!(roomy.fb_stall, 0);
    assert_eq!(roomy.pe_clocks, free.pe_clocks);
    assert_eq!(roomy.frame_buffer.packets, free.frame_buffer.packets);
    let slow = Costs {
        gfb: 20_000,
        fb_hit: 2_000,
        ..costs
    };
    let direct = run(&slow, FrameBuffer::Direct, 1);
    assert!(direct.fb_stall > 0 && direct.pe_clocks > free.pe_clocks);
    assert_eq!(direct.frame_buffer.packets, free.frame_buffer.packets);
    let cfbs = run(&slow, FrameBuffer::Cached { m: 8 }, 1);
    let wb = run(&slow, FrameBuffer::WriteBuffer { m: 8 }, 1);
    assert!(cfbs.frame_buffer.hits > 0);
    assert!(
        cfbs.clocks < wb.clocks,
        "cfbs {} wb {}",
        cfbs.clocks,
        wb.clocks
    );
    assert_eq!(cfbs, run(&slow, FrameBuffer::Cached { m: 8 }, 1));
    assert_eq!(direct.busy, free.busy);
}

#[test]
fn queueing_model_matches_the_digests_derived_checks() {
    // Derived by hand from eqs. 11-21 of Yamauchi 1997 §3.4.3 with its Table 3.
    let four = Model::table3(4, 5, 0.5);
    assert!((four.saturation() / 3.765e-4 - 1.0).abs() < 1e-3);
    let two = Model::table3(2, 10, 0.5);
    assert!((two.saturation() / 1.205e-2 - 1.0).abs() < 1e-3);
    let none = Model::table3(1024, 1, 0.5);
    assert!((none.saturation() / 2.353e-5 - 1.0).abs() < 1e-3);
    let (printed, normal) = four.latency(1e-6).unwrap();
    assert!((printed - 310.7).abs() < 0.5, "{printed}");
    assert!(normal > 0.0 && normal < printed);
    assert!(four.latency(4e-4).is_none());
    // The random simulation runs below the model's saturation, and lies near it when lightly
    // loaded (both are then mostly service times).
    let sim = queueing::simulate(&Model::table3(4, 3, 0.5), 1e-5, 20_000, 7);
    let (_, normal) = Model::table3(4, 3, 0.5).latency(1e-5).unwrap();
    assert!((sim / normal - 1.0).abs() < 0.2, "sim {sim} model {normal}");
}

fn room(ppm: u32) -> BuildInput {
    let mut c = rtbench_scenes::SceneCollector::default();
    rtbench_scenes::room::generate(ppm, &mut c).unwrap();
    let scene = c.scene;
    BuildInput {
        geometry: Arc::new(Geometry::from_scene(&scene)),
        scene: Arc::new(scene),
    }
}

/// 003's radiosity pass on the machine solves what the plain progressive refinement solves: at 1
/// PE the shooting order is nearly the reference's (global brightest first) and the radiosities
/// agree to 1%; on 16 and 256 PEs the PEs shoot side by side in their own order, and every
/// patch's radiosity is within the threshold of the reference's (both leave at most the threshold
/// unshot per patch). Repeats are bit-identical.
#[test]
fn radiosity_on_the_machine_equals_the_single_process_solution() {
    use super::radiosity::{self, Patches};
    let input = room(1);
    let os = ObjectSpace::build(&input, ObjectSpaceConfig::default()).unwrap();
    let em = rtbench_scenes::room::emission(&input.scene.materials);
    let patches = Patches::from_scene(&input.scene, &input.geometry.prim_object, &em).unwrap();
    let threshold = 0.1;
    let reference = radiosity::reference(&os, &patches, threshold);
    assert!(reference.shots > 10);
    let lit = reference
        .radiosity
        .iter()
        .filter(|b| b.max_element() > 0.0)
        .count();
    assert!(lit > reference.radiosity.len() / 2, "{lit} lit patches");
    for (pes, max_rel) in [("1", Some(0.01)), ("4x4", None), ("16x16", None)] {
        let cfg = config(&[("pes", pes)]).unwrap();
        let owner = cfg.machine.owner_map(cfg.subspaces);
        let run = radiosity::simulate(&os, &patches, &cfg.machine, &owner, &cfg.costs, threshold);
        let abs = run.solution.max_abs_difference(&reference);
        assert!(abs <= threshold as f64, "{pes}: max |dB| {abs}");
        if let Some(m) = max_rel {
            let d = run.solution.max_difference_above(&reference, threshold);
            assert!(d < m, "{pes}: max relative difference {d}");
        }
        for u in &run.solution.unshot {
            assert!(u.max_element() <= threshold);
        }
        if pes == "4x4" {
            let again =
                radiosity::simulate(&os, &patches, &cfg.machine, &owner, &cfg.costs, threshold);
            assert_eq!(again.clocks, run.clocks);
            assert_eq!(again.solution.radiosity, run.solution.radiosity);
        }
    }
}

#[test]
fn radiosity_bad_input_is_refused() {
    use super::radiosity::{check_threshold, Patches};
    for t in [0.0, -1.0, f32::NAN] {
        assert!(check_threshold(t).is_err());
    }
    assert!(check_threshold(0.05).is_ok());
    // A scene of spheres and cylinders has no patches to shoot from.
    let input = spd(Program::Jacks, 1);
    let em = vec![glam::DVec3::ONE; input.scene.materials.len()];
    assert!(Patches::from_scene(&input.scene, &input.geometry.prim_object, &em).is_err());
}
