//! `bvh2`, `bvh4`, `bvh8`: bounding volume hierarchies of seed 001 (Kimura 2007), binary and
//! N-wide, with the children's boxes stored side by side and a SIMD ray–N-box test.
//!
//! Pipeline: primitive boxes ([`tree::BuildPrims`]) → a builder (object median, full-sweep
//! SAH, binned SAH, on triangle scenes with spatial splits: [`build_sah::spatial`];
//! [`config::Builder`]) → a binary tree collapsed to N-wide
//! ([`collapse`]), or 001's own N-ary construction ([`config::WideMethod::Direct`]) → flat
//! N-wide nodes ([`node`]) → traversal ([`traverse`]) with the scalar, SSE or AVX2 slab test
//! ([`box_test`], picked at run time by [`dispatch`]), or with `packet=8|16` packets of rays in
//! AVX2 lanes ([`packet`]). Leaves hold up to `leaf` primitives of
//! the shared [`Geometry`], copied in leaf order: triangles in packets of 4 tested with the
//! shared SIMD triangle kernel, other primitives tested with the shared scalar kernels
//! (`Prim::intersect`); see [`leaf`].
//!
//! Settings: see [`config`].

pub mod box_test;
pub mod build_median;
pub mod build_sah;
pub mod collapse;
pub mod config;
pub mod dispatch;
pub mod leaf;
pub mod node;
pub mod packet;
pub mod ray_setup;
pub mod stats;
pub mod traverse;
pub mod tree;

#[cfg(test)]
mod tests;

use crate::engine::{BuildInput, Counters, Engine, EngineError, EngineInfo, Settings};
use crate::geometry::{Geometry, Prim};
use crate::ray::{Hit, Ray};
use config::{Builder, Config, WideMethod};
use dispatch::Kernels;
use node::{flatten, WideNode, MAX_TRAVERSAL_PRIMS};
use std::collections::BTreeMap;
use std::time::Instant;
use traverse::Bvh;
use tree::{BuildPrims, BuildTree};

pub fn info2() -> EngineInfo {
    EngineInfo {
        name: "bvh2",
        description:
            "binary BVH (seed 001): object median, full-sweep or binned SAH; scalar traversal",
        available: || Ok(()),
        build: |input, settings| build_engine::<2>(input, settings, || None, || None),
    }
}

pub fn info4() -> EngineInfo {
    EngineInfo {
        name: "bvh4",
        description: "4-wide BVH (seed 001), children's boxes side by side, SSE ray-4-box test",
        available: || Ok(()),
        build: |input, settings| {
            build_engine::<4>(input, settings, dispatch::sse4, dispatch::sse4_avx512)
        },
    }
}

pub fn info8() -> EngineInfo {
    EngineInfo {
        name: "bvh8",
        description: "8-wide BVH, children's boxes side by side, AVX2 ray-8-box test",
        available: || Ok(()),
        build: |input, settings| {
            build_engine::<8>(input, settings, dispatch::avx8, dispatch::avx8_avx512)
        },
    }
}

/// A built N-wide BVH engine.
pub struct BvhEngine<const N: usize> {
    bvh: Bvh<N>,
    config: Config,
    kernels: Kernels<N>,
    stats: BTreeMap<String, f64>,
}

/// Builds the tree of `config` over `geometry`: a build tree with at most `config.width`
/// children per node.
pub fn build_tree(geometry: &Geometry, config: &Config) -> BuildTree {
    let mut phases = Phases::new();
    // The primitives' boxes and centres, made when a builder needs them: the binned build of a
    // wide tree of packets (the default) makes its own boxes from the geometry instead.
    let cell = std::cell::OnceCell::new();
    let prims = || cell.get_or_init(|| BuildPrims::new(geometry));
    let (width, leaf) = (config.width, config.leaf);
    if width > 2 && config.wide == WideMethod::Direct {
        return match config.builder {
            Builder::Median => build_median::nway(prims(), leaf, width),
            Builder::SahSweep => {
                build_sah::wide_same_axis(build_sah::Sweep::new(prims()), leaf, width)
            }
            Builder::SahBinned => {
                build_sah::wide_same_axis(build_sah::Binned::new(prims(), config.bins), leaf, width)
            }
        };
    }
    // bvh2 keeps the binary tree as built (leaves of up to `leaf` where the SAH prefers them);
    // wider trees collapse a binary tree built down to single primitives, merging subtrees of
    // at most `leaf` primitives into leaves (collapse.rs).
    let binary_leaf = if width == 2 { leaf } else { 1 };
    // Embree's leaf rule (`build_sah::binary_blocks`) for trees of packed triangles only. With
    // spheres or cones in the scene (tested one by one) the SAH's blocks would be wrong, and
    // on balls4 and rings7 that tree cost 1-3% more traversal instructions than the one below,
    // so those scenes keep it.
    let triangles = geometry
        .prims
        .iter()
        .all(|p| matches!(p, Prim::Triangle(_)));
    let packable = config.packets && triangles;
    let block_leaves = width > 2
        && config.builder != Builder::Median
        && config.max_leaf > leaf
        && (packable || !config.packets);
    let all = if block_leaves {
        vec![true; geometry.prims.len()]
    } else {
        Vec::new()
    };
    let block = config.sah_block;
    let rule = build_sah::BlockLeaves {
        min: leaf,
        max: config.max_leaf,
        block,
        packable: &all,
    };
    phases.mark("leaf rule");
    let binary = match config.builder {
        // Spatial splits clip triangles only.
        Builder::SahBinned if block_leaves && triangles && config.spatial > 0.0 => {
            build_sah::spatial_blocks(
                geometry,
                &rule,
                build_sah::SpatialSettings {
                    bins: config.bins,
                    budget: config.spatial,
                    min_refs: config.spatial_min,
                },
                config.build_threads,
            )
        }
        Builder::SahSweep if block_leaves => {
            build_sah::binary_blocks(build_sah::Sweep::new(prims()).with_block(block), &rule)
        }
        Builder::SahBinned if block_leaves => build_sah::binary_blocks_threads(
            build_sah::Binned::of_geometry(geometry, config.bins, config.build_threads)
                .with_block(block),
            &rule,
            config.build_threads,
        ),
        Builder::Median => build_median::binary(prims(), binary_leaf),
        Builder::SahSweep => build_sah::binary(build_sah::Sweep::new(prims()), binary_leaf),
        Builder::SahBinned => {
            build_sah::binary(build_sah::Binned::new(prims(), config.bins), binary_leaf)
        }
    };
    phases.mark("binary tree");
    if width == 2 {
        binary
    } else {
        // With packets, leaves of several primitives are for triangles only (collapse.rs).
        let scalar_before: Option<Vec<u32>> = config.packets.then(|| {
            let mut acc = 0u32;
            let mut v = Vec::with_capacity(binary.order.len() + 1);
            v.push(0);
            for &p in &binary.order {
                acc += !matches!(geometry.prims[p as usize], Prim::Triangle(_)) as u32;
                v.push(acc);
            }
            v
        });
        let leaves = collapse::Leaves {
            leaf,
            split_leaves: config.split_leaves,
            scalar_before: scalar_before.as_deref(),
        };
        let wide = collapse::collapse_threads(&binary, width, leaves, config.build_threads);
        phases.mark("collapse");
        wide
    }
}

/// Wall time per build phase on stderr when `RTBENCH_BUILD_PHASES` is set (a diagnostic:
/// which parts of a two-thread build run alone); nothing otherwise.
struct Phases(Option<(Instant, f64, i64)>);

impl Phases {
    fn new() -> Phases {
        Phases(std::env::var_os("RTBENCH_BUILD_PHASES").map(|_| Self::now()))
    }
    fn now() -> (Instant, f64, i64) {
        let (cpu, faults) = crate::usage::process();
        (Instant::now(), cpu, faults)
    }
    fn mark(&mut self, what: &str) {
        if let Some((t, cpu, faults)) = self.0 {
            let (t2, cpu2, faults2) = Self::now();
            eprintln!(
                "build phase {what}: {:.1} ms, CPU {:.1} ms, {} page faults",
                (t2 - t).as_secs_f64() * 1e3,
                (cpu2 - cpu) * 1e3,
                faults2 - faults
            );
            self.0 = Some(Self::now());
        }
    }
}

/// 001's tree statistics for any of its branching factors (2 to 16, even; `config.width`, checked
/// by [`Config::parse`]), without building an engine: the engines traverse N = 2, 4 and 8 only,
/// 001 tabulates up to 16. Returns the statistics and the build seconds.
pub fn tree_statistics(geometry: &Geometry, config: &Config) -> (stats::TreeStats, f64) {
    fn of<const N: usize>(tree: &BuildTree) -> stats::TreeStats {
        let flat = flatten::<N>(tree);
        stats::tree_stats(&flat.nodes, flat.root, &flat.root_bounds)
    }
    let start = Instant::now();
    let tree = build_tree(geometry, config);
    let build_s = start.elapsed().as_secs_f64();
    let s = match config.width {
        2 => of::<2>(&tree),
        4 => of::<4>(&tree),
        6 => of::<6>(&tree),
        8 => of::<8>(&tree),
        10 => of::<10>(&tree),
        12 => of::<12>(&tree),
        14 => of::<14>(&tree),
        16 => of::<16>(&tree),
        w => unreachable!("width {w} passed Config::parse"),
    };
    (s, build_s)
}

/// Builds a [`Bvh`] and its statistics from geometry and a parsed configuration.
pub fn build_bvh<const N: usize>(
    geometry: &Geometry,
    config: &Config,
) -> Result<(Bvh<N>, stats::TreeStats), EngineError> {
    let n = geometry.prims.len();
    if n >= MAX_TRAVERSAL_PRIMS {
        return Err(EngineError::Build {
            engine: format!("bvh{N}"),
            reason: format!(
                "{n} primitives: at most {} fit a leaf reference",
                MAX_TRAVERSAL_PRIMS - 1
            ),
        });
    }
    if n == 0 {
        // One node with every slot empty: every ray misses.
        let flat = flatten::<N>(&BuildTree {
            nodes: vec![tree::BuildNode {
                bounds: crate::geometry::aabb::Aabb::EMPTY,
                kind: tree::BuildKind::Inner {
                    children: [0; tree::MAX_WIDTH],
                    len: 0,
                },
            }],
            order: Vec::new(),
        });
        let s = stats::tree_stats(&flat.nodes, flat.root, &flat.root_bounds);
        let bvh = Bvh {
            nodes: flat.nodes,
            root: flat.root,
            prims: Vec::new(),
            objects: Vec::new(),
            packets: Vec::new(),
            extent: 0.0,
        };
        return Ok((bvh, s));
    }
    let tree = build_tree(geometry, config);
    let mut phases = Phases::new();
    // A tree with spatial splits references some triangles more than once.
    debug_assert_eq!(
        if tree.order.len() > n {
            tree.validate_shared(&BuildPrims::new(geometry), N)
        } else {
            tree.validate(&BuildPrims::new(geometry), N)
        },
        Ok(()),
        "builder broke an invariant"
    );
    // On one thread: in a fresh process's two-thread build of balls4 tessellated, flattening
    // on two threads took 7.7–11 ms and on one 8.3–8.7 ms, both mostly faulting in
    // fresh pages, so the threaded copy was dropped.
    let mut flat = flatten::<N>(&tree);
    phases.mark("flatten");
    let extent = flat
        .root_bounds
        .lo
        .abs()
        .max(flat.root_bounds.hi.abs())
        .max_element();
    let (s, leaves) = if config.build_threads > 1 {
        // The statistics read the nodes as flattened, the leaf layout rewrites their leaf
        // references: the statistics get a copy and run beside it (the two were 42 M and 80 M
        // of the 403 M instructions the first thread ran alone on balls4 tessellated at two
        // threads; callgrind). The same figures and leaves either way.
        let copy = flat.nodes.clone();
        let (root, bounds) = (flat.root, flat.root_bounds);
        std::thread::scope(|scope| {
            let s = scope.spawn(move || stats::tree_stats(&copy, root, &bounds));
            let leaves = leaf::lay_out_threads(
                &mut flat.nodes,
                &mut flat.root,
                &tree.order,
                geometry,
                config.packets,
                config.build_threads,
            );
            (s.join().expect("the statistics thread panicked"), leaves)
        })
    } else {
        let s = stats::tree_stats(&flat.nodes, flat.root, &flat.root_bounds);
        let leaves = leaf::lay_out(
            &mut flat.nodes,
            &mut flat.root,
            &tree.order,
            geometry,
            config.packets,
        );
        (s, leaves)
    };
    phases.mark("statistics and leaf layout");
    Ok((
        Bvh {
            nodes: flat.nodes,
            root: flat.root,
            prims: leaves.prims,
            objects: leaves.objects,
            packets: leaves.packets,
            extent: if extent.is_finite() { extent } else { 0.0 },
        },
        s,
    ))
}

fn build_engine<const N: usize>(
    input: &BuildInput,
    settings: Settings,
    simd_kernels: fn() -> Option<Kernels<N>>,
    avx512_kernels: fn() -> Option<Kernels<N>>,
) -> Result<Box<dyn Engine>, EngineError> {
    const { assert!(N <= traverse::MAX_TRAVERSAL_WIDTH) };
    let config = Config::parse(N, settings)?;
    let start = Instant::now();
    let (bvh, tree_stats) = build_bvh::<N>(&input.geometry, &config)?;
    let build_s = start.elapsed().as_secs_f64();
    // `simd=on` falls back to scalar on CPUs without the instructions (reported in stats).
    let kernels = if config.simd {
        let wide = match config.isa {
            config::Isa::Avx2 => None,
            config::Isa::Auto | config::Isa::Avx512 => avx512_kernels(),
        };
        let single = wide
            .or_else(simd_kernels)
            .unwrap_or_else(dispatch::scalar::<N>);
        packet::kernels::<N>(config.packet, config.packet_cull).unwrap_or(single)
    } else if !config.precompute {
        dispatch::scalar_per_box::<N>()
    } else {
        dispatch::scalar::<N>()
    };
    let mut stats = BTreeMap::new();
    tree_stats.insert_into(&mut stats);
    stats.insert("build_s".into(), build_s);
    stats.insert("leaf_size".into(), config.leaf as f64);
    stats.insert("simd_lanes".into(), kernels.lanes as f64);
    stats.insert(
        "avx512".into(),
        kernels.name.contains("avx512") as u8 as f64,
    );
    stats.insert(
        "packet_rays".into(),
        if kernels.name.contains("packets") {
            config.packet.rays() as f64
        } else {
            1.0
        },
    );
    stats.insert("triangle_packets".into(), bvh.packets.len() as f64);
    let mut engine = BvhEngine {
        bvh,
        config,
        kernels,
        stats,
    };
    let bytes = engine.structure_bytes() as f64;
    engine.stats.insert("actual_bytes".into(), bytes);
    Ok(Box::new(engine))
}

impl<const N: usize> BvhEngine<N> {
    pub fn config(&self) -> &Config {
        &self.config
    }

    pub fn kernel_name(&self) -> &'static str {
        self.kernels.name
    }
}

impl<const N: usize> Engine for BvhEngine<N> {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], counters: &mut Counters) {
        (self.kernels.closest)(&self.bvh, rays, hits, self.config.triangle, counters);
    }

    fn occluded(&self, rays: &[Ray], occluded: &mut [bool], counters: &mut Counters) {
        (self.kernels.any)(&self.bvh, rays, occluded, self.config.triangle, counters);
    }

    /// Nodes, plus the primitives and their object indices copied in leaf order (triangle
    /// packets, padding included, and scalar primitives).
    fn structure_bytes(&self) -> u64 {
        (std::mem::size_of::<WideNode<N>>() * self.bvh.nodes.len()
            + std::mem::size_of::<crate::geometry::Prim>() * self.bvh.prims.len()
            + 4 * self.bvh.objects.len()
            + std::mem::size_of::<leaf::LeafPacket>() * self.bvh.packets.len()) as u64
    }

    fn build_stats(&self) -> BTreeMap<String, f64> {
        self.stats.clone()
    }
}
