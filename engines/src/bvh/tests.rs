//! bvh2/bvh4/bvh8 against the `reference` engine and against a brute-force loop over the same
//! f32 kernels, for every builder × width × construction × kernel, on small SPD scenes; and the
//! node-count identities of 001 §1.3.

use super::config::{Builder, Config, WideMethod};
use super::stats::TreeStats;
use super::*;
use crate::engine::{BuildInput, Settings};
use crate::geometry::kernels::f32::WatertightRay;
use crate::geometry::TriangleTest;
use glam::Vec3;
use rtbench_scenes::generate_scene;
use rtbench_scenes::spd::{Options, Program};
use std::sync::Arc;

fn input(program: Program, sf: u32, tessellate: Option<u32>) -> BuildInput {
    let scene = Arc::new(
        generate_scene(
            program,
            &Options {
                size_factor: sf,
                tessellate,
                ..Options::standard(program)
            },
        )
        .unwrap(),
    );
    BuildInput {
        geometry: Arc::new(Geometry::from_scene(&scene)),
        scene,
    }
}

/// A small deterministic generator (64-bit LCG, top bits).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
        lo + (hi - lo) * Vec3::new(self.next(), self.next(), self.next())
    }
}

/// Rays of three kinds over the scene's bounds: from outside towards a point inside (eye-like),
/// from a point inside in a random direction (secondary-like), and segments between two inside
/// points (shadow-like, finite tmax).
fn rays(g: &Geometry, n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Lcg(seed);
    let (lo, hi) = (g.bounds_min, g.bounds_max);
    let c = (lo + hi) * 0.5;
    let r = (hi - lo).length();
    (0..n)
        .map(|i| match i % 3 {
            0 => {
                let o = c + (rng.in_box(Vec3::splat(-1.0), Vec3::ONE).normalize_or_zero() * r);
                let d = (rng.in_box(lo, hi) - o).normalize();
                Ray::new(o, d, 0.0, f32::INFINITY)
            }
            1 => {
                let o = rng.in_box(lo, hi);
                let d = rng
                    .in_box(Vec3::splat(-1.0), Vec3::ONE)
                    .normalize_or(Vec3::Z);
                Ray::new(o, d, 0.0, f32::INFINITY)
            }
            _ => {
                let o = rng.in_box(lo, hi);
                let p = rng.in_box(lo, hi);
                let d = (p - o).normalize_or(Vec3::Z);
                Ray::new(o, d, 0.0, (p - o).length())
            }
        })
        .collect()
}

/// Nearest hit by testing every primitive with the same kernels the BVH uses.
fn brute_force(g: &Geometry, ray: &Ray) -> Hit {
    let wt = WatertightRay::new(ray.dir);
    let mut r = *ray;
    let mut best = Hit::MISS;
    for (p, &o) in g.prims.iter().zip(&g.prim_object) {
        if let Some((t, u, v)) = p.intersect(&r, TriangleTest::Watertight, &wt) {
            r.tmax = t;
            best = Hit { t, object: o, u, v };
        }
    }
    best
}

/// 001's agreement: both miss, same object, or same t within 1e-5 relative (a tie).
fn agree(a: &Hit, b: &Hit) -> bool {
    match (a.is_hit(), b.is_hit()) {
        (false, false) => true,
        (true, true) => a.object == b.object || (a.t - b.t).abs() <= 1e-5 * a.t.abs().max(1e-30),
        _ => false,
    }
}

fn engine(input: &BuildInput, width: usize, kv: &[(&str, &str)]) -> Box<dyn Engine> {
    let pairs = kv
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let info = match width {
        2 => info2(),
        4 => info4(),
        _ => info8(),
    };
    (info.build)(input, Settings::new(info.name, pairs)).unwrap()
}

fn closest(e: &dyn Engine, rays: &[Ray]) -> (Vec<Hit>, Counters) {
    let mut hits = vec![Hit::MISS; rays.len()];
    let mut c = Counters::default();
    e.intersect(rays, &mut hits, &mut c);
    (hits, c)
}

fn occluded(e: &dyn Engine, rays: &[Ray]) -> Vec<bool> {
    let mut out = vec![false; rays.len()];
    e.occluded(rays, &mut out, &mut Counters::default());
    out
}

/// Every builder × width × construction × kernel × leaf size agrees with the reference engine
/// (up to f32 vs f64 at edges) and exactly with the brute-force f32 loop.
#[test]
fn all_configurations_agree_with_reference() {
    let scenes = [
        (Program::Balls, 2, None),
        (Program::Gears, 1, None),
        (Program::Mount, 2, None),
        (Program::Rings, 1, None),
        (Program::Teapot, 2, None),
        (Program::Tetra, 2, None),
        (Program::Tree, 3, None),
        (Program::Balls, 1, Some(3)),
    ];
    for (si, &(program, sf, tess)) in scenes.iter().enumerate() {
        let inp = input(program, sf, tess);
        let rays = rays(&inp.geometry, 300, 17 + si as u64);
        let refe =
            (crate::reference::info().build)(&inp, Settings::new("reference", vec![])).unwrap();
        let (want, _) = closest(refe.as_ref(), &rays);
        let want_any = occluded(refe.as_ref(), &rays);
        let brute: Vec<Hit> = rays.iter().map(|r| brute_force(&inp.geometry, r)).collect();
        let n_hits = want.iter().filter(|h| h.is_hit()).count();
        assert!(n_hits > 30, "{program}{sf}: only {n_hits} of the rays hit");
        for width in [2, 4, 8] {
            for builder in ["median", "sah-sweep", "sah-binned"] {
                for wide in ["collapse", "direct"] {
                    if width == 2 && wide == "direct" {
                        continue;
                    }
                    for leaf in ["1", "3", "6"] {
                        for (simd, packets) in [("off", "off"), ("off", "on"), ("on", "on")] {
                            if width == 2 && simd == "on" {
                                continue;
                            }
                            let kv = [
                                ("builder", builder),
                                ("wide", wide),
                                ("leaf", leaf),
                                ("simd", simd),
                                ("packets", packets),
                            ];
                            let label = format!("bvh{width} {kv:?} on {program}{sf}");
                            let e = engine(&inp, width, &kv);
                            let (got, c) = closest(e.as_ref(), &rays);
                            let vs_ref = got.iter().zip(&want).filter(|(a, b)| agree(a, b)).count();
                            assert!(
                                vs_ref + 3 >= rays.len(),
                                "{label}: {vs_ref} of {} agree with reference",
                                rays.len()
                            );
                            for (i, (g, b)) in got.iter().zip(&brute).enumerate() {
                                assert!(
                                    agree(g, b),
                                    "{label}: ray {i}: {g:?} vs brute force {b:?}"
                                );
                            }
                            let any = occluded(e.as_ref(), &rays);
                            let any_ok = any.iter().zip(&want_any).filter(|(a, b)| a == b).count();
                            assert!(any_ok + 3 >= rays.len(), "{label}: any-hit {any_ok} agree");
                            // Any-hit agrees with closest-hit of the same engine exactly.
                            for (a, h) in any.iter().zip(&got) {
                                assert_eq!(*a, h.is_hit(), "{label}");
                            }
                            assert_eq!(c.rays, rays.len() as u64);
                            assert!(c.nodes_visited > 0 && c.box_tests >= c.nodes_visited);
                            assert!(
                                c.primitive_tests
                                    < rays.len() as u64 * inp.geometry.prims.len() as u64
                            );
                        }
                    }
                }
            }
        }
    }
}

fn stats_of(e: &dyn Engine) -> std::collections::BTreeMap<String, f64> {
    e.build_stats()
}

/// Node counts against what each construction implies (001 §1.3): a binary tree with one
/// primitive per leaf has n leaves and n − 1 internal nodes and no empty node; every tree has
/// `leaves + (internal − 1) + empty = N · internal` slots; 001's memory model follows Eq. 3.3.
#[test]
fn node_counts_are_consistent() {
    let inp = input(Program::Tree, 3, None);
    let n = inp.geometry.prims.len() as f64;
    for width in [2usize, 4, 8] {
        for builder in ["median", "sah-sweep", "sah-binned"] {
            for wide in ["collapse", "direct"] {
                for leaf in ["1", "4"] {
                    let e = engine(
                        &inp,
                        width,
                        &[("builder", builder), ("wide", wide), ("leaf", leaf)],
                    );
                    let s = stats_of(e.as_ref());
                    let (inner, leaves, empty) =
                        (s["internal_nodes"], s["leaf_nodes"], s["empty_nodes"]);
                    let label = format!("bvh{width} {builder} {wide} leaf {leaf}: {s:?}");
                    assert_eq!(
                        leaves + inner - 1.0 + empty,
                        width as f64 * inner,
                        "{label}"
                    );
                    assert!(
                        (s["avg_leaf_prims"] * leaves - n).abs() < 1e-6 * n,
                        "{label}"
                    );
                    if leaf == "1" {
                        assert_eq!(leaves, n, "{label}");
                    }
                    if width == 2 {
                        assert_eq!((empty, inner), (0.0, leaves - 1.0), "{label}");
                    }
                    if builder == "median" && leaf == "4" && width == 2 {
                        // Equal-count halving stops at ≤ 4: leaves hold 2–4 primitives.
                        assert!(leaves >= n / 4.0 && leaves <= n / 2.0, "{label}");
                    }
                    let model =
                        inner * TreeStats::internal_node_model_bytes(width) as f64 + leaves * 32.0;
                    assert_eq!(s["model_bytes"], model, "{label}");
                    assert_eq!(s["model_bytes_with_empty"], model + empty * 32.0, "{label}");
                    assert!(s["avg_leaf_depth"] <= s["max_leaf_depth"], "{label}");
                    assert!(s["actual_bytes"] >= s["node_bytes"], "{label}");
                    assert!(s["max_leaf_depth"] <= tree::MAX_DEPTH as f64, "{label}");
                }
            }
        }
    }
    // Wider trees are shallower (001 §2.2: from B = 2 to 4 the average leaf depth about halves).
    let depth = |w: usize| {
        stats_of(engine(&inp, w, &[("builder", "median"), ("leaf", "1")]).as_ref())
            ["avg_leaf_depth"]
    };
    let (d2, d4, d8) = (depth(2), depth(4), depth(8));
    assert!(d4 < 0.6 * d2 && d8 < d4, "{d2} {d4} {d8}");
}

/// 001's wider branching factors through [`tree_statistics`] (N = 2…16, no engine): the slot
/// identity holds for every width, a 16-way median of 256 primitives is two full levels, a 6-way
/// median of 36 likewise, and 001's SAH at N = 16 builds.
#[test]
fn statistics_for_widths_up_to_16() {
    let inp = input(Program::Tetra, 4, None);
    let n = inp.geometry.prims.len();
    assert!(n >= 256, "{n}");
    let cfg = |w: usize, builder: &str| {
        Config::parse(
            w,
            Settings::new(
                "bvh",
                vec![
                    ("builder".into(), builder.into()),
                    ("wide".into(), "direct".into()),
                    ("leaf".into(), "1".into()),
                    ("simd".into(), "off".into()),
                    ("packets".into(), "off".into()),
                ],
            ),
        )
        .unwrap()
    };
    for w in [2usize, 4, 6, 8, 10, 12, 14, 16] {
        let (s, _) = tree_statistics(&inp.geometry, &cfg(w, "median"));
        assert_eq!(s.width, w);
        assert_eq!(s.leaf_nodes, n as u64, "N={w}");
        assert_eq!(
            s.leaf_nodes + s.internal_nodes - 1 + s.empty_nodes,
            w as u64 * s.internal_nodes,
            "N={w}: {s:?}"
        );
    }
    let (s16, _) = tree_statistics(&inp.geometry, &cfg(16, "sah-sweep"));
    assert_eq!(s16.leaf_nodes, n as u64);
    let (s8, _) = tree_statistics(&inp.geometry, &cfg(8, "sah-sweep"));
    assert!(s16.avg_leaf_depth < s8.avg_leaf_depth, "{s16:?} {s8:?}");
    for (w, m) in [(16usize, 256usize), (6, 36)] {
        let mut g = (*inp.geometry).clone();
        g.prims.truncate(m);
        g.prim_object.truncate(m);
        let (s, _) = tree_statistics(&g, &cfg(w, "median"));
        assert_eq!(
            (s.internal_nodes, s.empty_nodes, s.max_leaf_depth),
            (1 + w as u64, 0, 2),
            "N={w}"
        );
    }
}

/// With triangle packets (the default), only triangles share leaves: curved primitives get one
/// leaf each, so balls (spheres and a floor of two triangles) has at least n − 1 leaves, while a
/// triangle-only scene keeps leaves of up to four.
#[test]
fn only_triangles_share_leaves() {
    let balls = input(Program::Balls, 2, None);
    let n = balls.geometry.prims.len() as f64;
    for width in [4usize, 8] {
        let s = stats_of(engine(&balls, width, &[]).as_ref());
        assert!(s["leaf_nodes"] >= n - 1.0, "bvh{width}: {s:?}");
        let s = stats_of(engine(&balls, width, &[("packets", "off")]).as_ref());
        assert!(s["leaf_nodes"] < n, "bvh{width} without packets: {s:?}");
    }
    let tetra = input(Program::Tetra, 4, None);
    let s = stats_of(engine(&tetra, 4, &[]).as_ref());
    assert!(s["avg_leaf_prims"] > 2.0, "{s:?}");
}

/// A 4-ary object median over 16 primitives (001 §1.3's example, cut from a tetra scene):
/// depth 2, 5 internal nodes, no empty node.
#[test]
fn nway_median_of_16_primitives() {
    let mut inp = input(Program::Tetra, 2, None);
    assert!(inp.geometry.prims.len() >= 16);
    let mut g = (*inp.geometry).clone();
    g.prims.truncate(16);
    g.prim_object.truncate(16);
    inp.geometry = Arc::new(g);
    let e = engine(
        &inp,
        4,
        &[("builder", "median"), ("wide", "direct"), ("leaf", "1")],
    );
    let s = stats_of(e.as_ref());
    assert_eq!(
        (s["internal_nodes"], s["leaf_nodes"], s["empty_nodes"]),
        (5.0, 16.0, 0.0)
    );
    assert_eq!((s["avg_leaf_depth"], s["max_leaf_depth"]), (2.0, 2.0));
}

#[test]
fn empty_and_single_primitive_scenes() {
    let mut inp = input(Program::Tetra, 1, None);
    let rays = rays(&inp.geometry, 60, 5);
    for keep in [0usize, 1] {
        let mut g = (*inp.geometry).clone();
        g.prims.truncate(keep);
        g.prim_object.truncate(keep);
        inp.geometry = Arc::new(g);
        for w in [2, 4, 8] {
            let e = engine(&inp, w, &[]);
            let (got, _) = closest(e.as_ref(), &rays);
            for (r, h) in rays.iter().zip(&got) {
                assert!(agree(h, &brute_force(&inp.geometry, r)));
            }
        }
    }
}

#[test]
fn simd_and_scalar_kernels_give_the_same_hits_and_counts() {
    let inp = input(Program::Balls, 2, Some(2));
    let rays = rays(&inp.geometry, 600, 99);
    for w in [4, 8] {
        let (a, ca) = closest(engine(&inp, w, &[("simd", "on")]).as_ref(), &rays);
        // The same tree: `simd=off` alone keeps leaves of at most 4 (config.rs).
        let scalar = [("simd", "off"), ("max_leaf", "16"), ("sah_block", "4")];
        let (b, cb) = closest(engine(&inp, w, &scalar).as_ref(), &rays);
        let same = a.iter().zip(&b).filter(|(x, y)| x == y).count();
        assert!(
            same + 2 >= rays.len(),
            "bvh{w}: {same} of {} identical",
            rays.len()
        );
        // The kernels only differ in rounding of box entry distances, not in what they visit
        // (up to those few grazing rays).
        let rel =
            (ca.nodes_visited as f64 - cb.nodes_visited as f64).abs() / cb.nodes_visited as f64;
        assert!(
            rel < 0.01,
            "bvh{w}: {} vs {} nodes",
            ca.nodes_visited,
            cb.nodes_visited
        );
    }
}

/// Triangle packets change how leaves are stored and tested, not what is found or counted: on
/// the same tree (`split_leaves` fixed), packets on and off give the same hits, the same nodes
/// and box tests, and the same primitive tests (padding is not counted), with either test.
#[test]
fn packets_change_no_answer_and_no_count() {
    let inp = input(Program::Balls, 1, Some(3));
    let rays = rays(&inp.geometry, 600, 23);
    for w in [4, 8] {
        for triangle in ["watertight", "moller"] {
            for simd in ["on", "off"] {
                let run = |packets| {
                    let kv = [
                        ("packets", packets),
                        ("split_leaves", "off"),
                        ("max_leaf", "16"),
                        ("sah_block", "4"),
                        ("triangle", triangle),
                        ("simd", simd),
                    ];
                    let e = engine(&inp, w, &kv);
                    let (hits, c) = closest(e.as_ref(), &rays);
                    (hits, c, occluded(e.as_ref(), &rays), e.build_stats())
                };
                let (on, off) = (run("on"), run("off"));
                let label = format!("bvh{w} {triangle} simd={simd}");
                assert!(on.3["triangle_packets"] > 0.0 && off.3["triangle_packets"] == 0.0);
                assert_eq!(on.0, off.0, "{label}");
                assert_eq!(on.2, off.2, "{label}");
                assert_eq!(
                    (on.1.nodes_visited, on.1.box_tests, on.1.primitive_tests),
                    (off.1.nodes_visited, off.1.box_tests, off.1.primitive_tests),
                    "{label}"
                );
                assert!(on.1.primitive_hits >= off.1.primitive_hits, "{label}");
            }
        }
    }
}

#[test]
fn moller_agrees_too() {
    let inp = input(Program::Teapot, 2, None);
    let rays = rays(&inp.geometry, 300, 3);
    let brute: Vec<Hit> = rays.iter().map(|r| brute_force(&inp.geometry, r)).collect();
    let (got, _) = closest(engine(&inp, 8, &[("triangle", "moller")]).as_ref(), &rays);
    let ok = got.iter().zip(&brute).filter(|(a, b)| agree(a, b)).count();
    assert!(ok + 3 >= rays.len());
}

#[test]
fn config_is_reported() {
    let inp = input(Program::Tetra, 1, None);
    let e = engine(&inp, 8, &[("builder", "sah-sweep")]);
    let s = e.build_stats();
    assert_eq!(s["width"], 8.0);
    assert!(s["build_s"] >= 0.0 && s["sah_cost"] > 0.0);
    assert_eq!(s["leaf_size"], 4.0);
    let c = Config::parse(8, Settings::new("bvh8", vec![])).unwrap();
    assert_eq!(
        (c.builder, c.wide),
        (Builder::SahBinned, WideMethod::Collapse)
    );
    assert!(e.structure_bytes() > 0);
}

/// Packets of 8 and 16 rays (`packet.rs`) give every ray the single-ray traversal's answer: the
/// same occlusion, and the same hit (object and t bit for bit, apart from exact ties of t),
/// on triangles (gears, tessellated tree) and on spheres and cones (balls, rings), including a
/// short last packet and untraceable rays; eye-like coherent rays too.
#[test]
fn packets_answer_as_single_rays() {
    if !crate::geometry::lanes::Avx8::available() {
        return;
    }
    for (program, sf, tess) in [
        (Program::Gears, 2, None),
        (Program::Balls, 2, None),
        (Program::Rings, 1, None),
        (Program::Tree, 3, Some(2)),
    ] {
        let inp = input(program, sf, tess);
        let mut rs = rays(&inp.geometry, 1003, 11);
        rs[5] = Ray::new(Vec3::splat(f32::NAN), Vec3::X, 0.0, f32::INFINITY);
        // Coherent rays: a fan from one point towards the scene's centre.
        let (lo, hi) = (inp.geometry.bounds_min, inp.geometry.bounds_max);
        let o = hi + (hi - lo) * 0.7;
        for i in 0..24 {
            for j in 0..24 {
                let t = lo + (hi - lo) * Vec3::new(i as f32 / 23.0, j as f32 / 23.0, 0.5);
                rs.push(Ray::new(o, (t - o).normalize(), 0.0, f32::INFINITY));
            }
        }
        for width in [4, 8] {
            let single = engine(&inp, width, &[]);
            let (want, wc) = closest(single.as_ref(), &rs);
            let want_any = occluded(single.as_ref(), &rs);
            assert!(
                want.iter().filter(|h| h.is_hit()).count() > 200,
                "{program:?}"
            );
            for size in ["8", "16"] {
                let e = engine(&inp, width, &[("packet", size)]);
                assert_eq!(
                    stats_of(e.as_ref())["packet_rays"],
                    size.parse::<f64>().unwrap()
                );
                let (got, gc) = closest(e.as_ref(), &rs);
                let same = got
                    .iter()
                    .zip(&want)
                    .filter(|(a, b)| a.object == b.object && a.t.to_bits() == b.t.to_bits())
                    .count();
                let ties = got
                    .iter()
                    .zip(&want)
                    .filter(|(a, b)| a.object != b.object && a.t == b.t)
                    .count();
                assert_eq!(
                    same + ties,
                    rs.len(),
                    "{program:?} bvh{width} packet={size}"
                );
                assert_eq!(
                    occluded(e.as_ref(), &rs),
                    want_any,
                    "{program:?} bvh{width}"
                );
                assert_eq!(gc.rays, wc.rays);
                // A ray tests a leaf only where its own box test admits it: no more triangle
                // tests than alone, give or take the order in which leaves shrink tmax.
                assert!(gc.nodes_visited > 0 && gc.primitive_tests > 0);
            }
        }
    }
}

/// The two-thread build makes the one-thread build's tree, node for node.
#[test]
fn threads_build_the_same_tree() {
    // gears4: 36,610 triangles, so the top splits (ranges of ≥ 8,192) go to threads. balls2
    // tessellated: its top split cuts the floor's few triangles from the spheres', a side too
    // small to fork (built in place while the other side forks on). Both the binned SAH's
    // threaded build (`spatial=0`) and the spatial-split build (the default for triangles).
    for spatial in ["0", "1"] {
        for (program, sf, tessellate) in [(Program::Gears, 4, None), (Program::Balls, 2, Some(3))] {
            let inp = input(program, sf, tessellate);
            let base = build_tree(&inp.geometry, &threads_config("1", spatial));
            assert!(base.nodes.len() > 1000);
            for threads in ["2", "3"] {
                let t = build_tree(&inp.geometry, &threads_config(threads, spatial));
                let what = format!("{program:?} spatial={spatial} {threads} threads");
                assert_eq!(t.order, base.order, "{what}");
                assert_eq!(t.nodes, base.nodes, "{what}");
            }
        }
    }
}

/// bvh8's settings with `build_threads` and `spatial` set.
fn threads_config(threads: &str, spatial: &str) -> Config {
    let set = |k: &str, v: &str| (k.to_string(), v.to_string());
    Config::parse(
        8,
        Settings::new(
            "bvh8",
            vec![set("build_threads", threads), set("spatial", spatial)],
        ),
    )
    .unwrap()
}

/// The two-thread engine build (primitive boxes, the top split's binning, statistics beside the
/// leaf layout on threads) makes the one-thread build's engine: the same wide nodes, leaf
/// packets, scalar primitives and statistics.
#[test]
fn threads_build_the_same_engine() {
    // gears4: 36,610 triangles, above every threshold of the threaded parts (8,192); with and
    // without spatial splits.
    let inp = input(Program::Gears, 4, None);
    for spatial in ["0", "1"] {
        let (base, base_stats) =
            build_bvh::<8>(&inp.geometry, &threads_config("1", spatial)).unwrap();
        assert!(base.packets.len() > 1000);
        for threads in ["2", "3"] {
            let (b, s) = build_bvh::<8>(&inp.geometry, &threads_config(threads, spatial)).unwrap();
            let what = format!("spatial={spatial} {threads} threads");
            assert_eq!(b.root, base.root, "{what}");
            assert_eq!(b.nodes, base.nodes, "{what}");
            assert_eq!(b.prims, base.prims, "{what}");
            assert_eq!(b.objects, base.objects, "{what}");
            assert_eq!(b.extent.to_bits(), base.extent.to_bits());
            // Debug prints every float of a packet exactly (shortest round trip, signs of zero).
            assert_eq!(
                format!("{:?}", b.packets),
                format!("{:?}", base.packets),
                "{what}"
            );
            assert_eq!(s, base_stats, "{what}");
        }
    }
}

/// Spatial splits (the default tree of triangle scenes) reference some triangles in several
/// leaves, each bounded by its part: the tree keeps the shared invariants, and the engines
/// find the brute-force loop's hits and blockers exactly, as without them.
#[test]
fn spatial_splits_answer_as_without() {
    let scenes = [
        (Program::Gears, 2, None),
        (Program::Teapot, 2, None),
        (Program::Balls, 1, Some(3)),
    ];
    for (si, &(program, sf, tess)) in scenes.iter().enumerate() {
        let inp = input(program, sf, tess);
        let n = inp.geometry.prims.len();
        let rays = rays(&inp.geometry, 400, 91 + si as u64);
        let brute: Vec<Hit> = rays.iter().map(|r| brute_force(&inp.geometry, r)).collect();
        for width in [4, 8] {
            for (budget, min) in [("1", "128"), ("4", "2")] {
                let kv = [("spatial", budget), ("spatial_min", min)];
                let label = format!("bvh{width} {kv:?} on {program}{sf}");
                let settings = kv
                    .iter()
                    .map(|(k, v)| (k.to_string(), v.to_string()))
                    .collect();
                let config = Config::parse(width, Settings::new("bvh", settings)).unwrap();
                let tree = build_tree(&inp.geometry, &config);
                tree.validate_shared(&BuildPrims::new(&inp.geometry), width)
                    .unwrap_or_else(|e| panic!("{label}: {e}"));
                if program == Program::Gears && min == "2" {
                    assert!(tree.order.len() > n, "{label}: no triangle was split");
                }
                let e = engine(&inp, width, &kv);
                let (got, _) = closest(e.as_ref(), &rays);
                for (i, (g, b)) in got.iter().zip(&brute).enumerate() {
                    assert!(agree(g, b), "{label}: ray {i}: {g:?} vs brute force {b:?}");
                }
                let any = occluded(e.as_ref(), &rays);
                for (a, h) in any.iter().zip(&got) {
                    assert_eq!(*a, h.is_hit(), "{label}");
                }
            }
        }
    }
}
