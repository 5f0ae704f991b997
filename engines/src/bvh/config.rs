//! The typed configuration of `bvh2`, `bvh4` and `bvh8`, parsed from `key=value` settings.
//!
//! | key | values | default |
//! |---|---|---|
//! | `builder` | `median` (001 object median), `sah-sweep` (001 full-sweep SAH), `sah-binned` | `sah-binned` |
//! | `wide` | `collapse` (binary tree collapsed to N-wide), `direct` (001's own N-ary builders) | `collapse` |
//! | `leaf` | most primitives per leaf, 1–16 (001 uses 1) | 1 for bvh2, 4 for bvh4/bvh8 |
//! | `simd` | `on`, `off` (bvh4: SSE, with FMA when the CPU has AVX2 + FMA; bvh8: AVX2 + FMA) | `on` (bvh2: `off`) |
//! | `isa` | `auto`: the widest instruction set the CPU has; `avx2`: AVX2 + FMA even where AVX-512 is there; `avx512`: the same traversal compiled with AVX-512 (F, VL, BW, DQ: 32 vector registers, comparisons into mask registers), where the CPU has it (else AVX2; `build_stats.avx512` says which ran). The same operations in the same order either way, so the same hits, counters and images | `auto` |
//! | `triangle` | `watertight`, `moller` | `watertight` |
//! | `bins` | bins per axis of the binned SAH, 2–256 | 32 |
//! | `packets` | `on`: leaves of triangles only store them in packets of 4 tested with one SIMD test (`leaf.rs`), and only triangles share leaves (spheres and cones get one leaf each, `collapse.rs`); `off`: every primitive tested on its own | `on` (bvh2: `off`) |
//! | `precompute` | `on`: the ray's reciprocal direction and origin terms are computed once per ray (001 §1.7, thesis Ch. 4.2.2); `off`: each box test divides by the direction and orders the slabs itself (scalar only, for 001's ablation) | `on` |
//! | `max_leaf` | largest leaf the binned or sweep SAH may choose, `leaf`–16 (with packets: scenes of triangles only; spheres and cones keep one leaf each and the tree below): a range of more than `leaf` primitives becomes a leaf when the SAH says testing it costs no more than splitting it (Embree's `BVHBuilderBinnedSAH` rule; `build_sah::binary_blocks`) | 16 for bvh4/bvh8 with packets and `simd=on` when `leaf` is not given, else `leaf` |
//! | `sah_block` | the SAH counts primitives in blocks of this many (Embree's `sahBlockSize`: a packet leaf of 1–4 triangles costs one test), 1, 2, 4, 8 or 16 | 4 for bvh4/bvh8 with packets and `simd=on`, else 1 |
//! | `packet` | `off`: one ray at a time; `8`, `16`: packets of 8 or 16 consecutive rays of a batch traverse together, their boxes tested in AVX2 lanes (`packet.rs`; needs `simd=on` and a CPU with AVX2 + FMA, else rays go one at a time and `build_stats.packet_rays` says 1) | `off` |
//! | `packet_cull` | `on`: packets test an 8-wide node's boxes against their interval ray first and only the children it passes lane by lane (`packet.rs`); `off`: every child lane by lane | `on` |
//! | `build_threads` | threads of the binned SAH build with Embree's leaf rule (the default tree of triangle scenes; `build_sah::binary_blocks_threads`, `build_sah::spatial_blocks`): the subtrees of the top splits are built on threads of their own, with or without spatial splits; the tree is the same whatever the count | 1 |
//! | `spatial` | extra references the spatial splits may make, as a fraction of the triangles (Stich, Friedrich and Dietrich 2009; Embree's spatial-split builder): a node may cut space instead of its list, referencing a triangle that crosses the cut on both sides, each reference bounded by its own part (`build_sah::spatial`). For the binned SAH tree with Embree's leaf rule, scenes of triangles only (with spheres or cones, or a `leaf` given, the tree is built without). `0`: none | `1` |
//! | `spatial_min` | the fewest references of a node whose spatial splits are searched, 2 or more | `128` |
//! | `split_leaves` | `on`: node slots left free split leaf-sized subtrees further (`collapse.rs`); `off`: leaves keep up to `leaf` primitives | `off` with packets, else `on` |
//!
//! `leaf` is an upper bound when `max_leaf` is `leaf` (bvh2, `packets=off`, or `leaf` given);
//! otherwise subtrees of at most `leaf` primitives are always leaves and the SAH may choose
//! leaves of up to `max_leaf` (the default bvh8 tree of gears4 went from 3,462 inner
//! nodes with 2.9 triangles per leaf to 1,566 with 7.7, as Embree's 1,610). bvh2 and `wide=direct` stop splitting at ≤ `leaf` primitives when
//! the SAH prefers a leaf (`median`: always). With `wide=collapse` a subtree of ≤ `leaf`
//! primitives becomes a leaf; with `split_leaves=on` node slots left free are spent splitting
//! such leaves further (`collapse.rs`), so wide leaves are often smaller. With triangle packets
//! a leaf of up to 4 triangles costs one test, so by default leaves are then kept whole. `simd=on` on a CPU without the
//! instructions runs the scalar test (`build_stats.simd_lanes` says which ran).

use super::node::MAX_LEAF_PRIMS;
use super::packet::PacketSize;
use super::tree::MAX_WIDTH;
use crate::engine::{EngineError, Settings};
use crate::geometry::TriangleTest;
use std::str::FromStr;

/// Which instruction set the SIMD traversal is compiled for (`isa`; `simd=on` only).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// AVX-512 where the CPU has it, else AVX2 + FMA.
    Auto,
    /// AVX2 + FMA.
    Avx2,
    /// AVX-512 F, VL, BW and DQ where the CPU has them, else AVX2 + FMA.
    Avx512,
}

impl FromStr for Isa {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(Isa::Auto),
            "avx2" => Ok(Isa::Avx2),
            "avx512" => Ok(Isa::Avx512),
            _ => Err("expected auto, avx2 or avx512".into()),
        }
    }
}

/// How the binary tree (or, with `wide=direct`, the N-ary tree) is split.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Builder {
    /// 001 §1.4 (thesis Ch. 3.4, after Kay and Kajiya 1986): the axis cycles X→Y→Z with depth, primitives are
    /// ordered by the centre of their box and cut into equal counts.
    Median,
    /// 001 §1.5 (thesis Ch. 3.5, after Wald, Boulos and Shirley 2007): the exact SAH over every axis and every split
    /// position between primitives sorted by box centre.
    SahSweep,
    /// Wald 2007, "On fast construction of SAH-based bounding volume hierarchies": the SAH
    /// evaluated at the planes between `bins` equal bins of the centroid bounds.
    SahBinned,
}

impl FromStr for Builder {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "median" => Ok(Builder::Median),
            "sah-sweep" | "sweep" => Ok(Builder::SahSweep),
            "sah-binned" | "binned" | "sah" => Ok(Builder::SahBinned),
            _ => Err("expected median, sah-sweep or sah-binned".into()),
        }
    }
}

impl Builder {
    pub fn name(self) -> &'static str {
        match self {
            Builder::Median => "median",
            Builder::SahSweep => "sah-sweep",
            Builder::SahBinned => "sah-binned",
        }
    }
}

/// How a tree wider than two is made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WideMethod {
    /// Build a binary tree, then collapse it: each wide node opens the binary descendant of
    /// largest surface area until it has N children (Embree's BVHN builders; Dammertz et al.
    /// 2008's QBVH).
    Collapse,
    /// 001's own N-ary builders: object median straight into N equal-count groups (001 §1.4),
    /// or the binary SAH split re-applied to each half on the first split's axis (001 §1.5).
    Direct,
}

impl FromStr for WideMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "collapse" => Ok(WideMethod::Collapse),
            "direct" | "001" => Ok(WideMethod::Direct),
            _ => Err("expected collapse or direct".into()),
        }
    }
}

/// `on` / `off`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OnOff(pub bool);

impl FromStr for OnOff {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "on" | "true" | "1" | "yes" => Ok(OnOff(true)),
            "off" | "false" | "0" | "no" => Ok(OnOff(false)),
            _ => Err("expected on or off".into()),
        }
    }
}

/// The SAH's cost constants (001 §1.5, Eq. 3.4, writes the binary split cost as
/// `2·T_AABB + Σ (A_i/A)·N_i·T_tri`; the thesis gives no values). One box test and one
/// primitive test cost the same here, as in Wald, Boulos and Shirley 2007.
pub const T_AABB: f32 = 1.0;
pub const T_TRI: f32 = 1.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    pub width: usize,
    pub builder: Builder,
    pub wide: WideMethod,
    pub leaf: usize,
    pub simd: bool,
    /// The instruction set of the SIMD traversal.
    pub isa: Isa,
    pub triangle: TriangleTest,
    pub bins: usize,
    pub packets: bool,
    pub split_leaves: bool,
    /// Per-ray precomputation of the slab test (`precompute=off` needs `simd=off`).
    pub precompute: bool,
    /// The largest leaf the SAH may choose (≥ `leaf`; wide trees only).
    pub max_leaf: usize,
    /// The SAH counts primitives in blocks of this many (Embree's `sahBlockSize`).
    pub sah_block: usize,
    /// Rays traced together (`packet.rs`).
    pub packet: PacketSize,
    /// Packets test a node's boxes against their interval ray first (`packet.rs`).
    pub packet_cull: bool,
    /// Threads of the build (`build_sah::binary_blocks_threads`).
    pub build_threads: usize,
    /// Extra references the spatial splits may make, as a fraction of the triangles (0: none).
    pub spatial: f32,
    /// The fewest references of a node whose spatial splits are searched.
    pub spatial_min: usize,
}

impl Config {
    /// Reads this engine's keys from `settings` and rejects unknown ones.
    pub fn parse(width: usize, mut settings: Settings) -> Result<Config, EngineError> {
        let engine = format!("bvh{width}");
        let bad = |key: &str, value: String, reason: &str| EngineError::BadValue {
            engine: engine.clone(),
            key: key.into(),
            value,
            reason: reason.into(),
        };
        let builder = settings.get("builder", Builder::SahBinned)?;
        let wide = settings.get("wide", WideMethod::Collapse)?;
        // usize::MAX: not given.
        let leaf_given = settings.get("leaf", usize::MAX)?;
        let leaf = if leaf_given != usize::MAX {
            leaf_given
        } else if width == 2 {
            1
        } else {
            4
        };
        let simd = settings.get("simd", OnOff(width > 2))?.0;
        let isa = settings.get("isa", Isa::Auto)?;
        let triangle = settings.get("triangle", TriangleTest::default())?;
        let bins = settings.get("bins", 32usize)?;
        let packets = settings.get("packets", OnOff(width > 2))?.0;
        let split_leaves = settings.get("split_leaves", OnOff(!packets))?.0;
        let precompute = settings.get("precompute", OnOff(true))?.0;
        // Embree's leaf rule (`max_leaf`, `sah_block`) assumes a packet of 1-4 triangles costs
        // one SIMD test; tested lane by lane (`simd=off`) every triangle costs a test, and the
        // rule's larger leaves cost teapot1 39% more instructions, so the
        // scalar variant keeps 001's count and leaves of at most `leaf`.
        let wide_packets = width > 2 && packets && simd;
        // A `leaf` given is the largest leaf, as before `max_leaf` existed (001's leaf=1).
        let max_leaf = settings.get(
            "max_leaf",
            if wide_packets && leaf_given == usize::MAX {
                MAX_LEAF_PRIMS
            } else {
                leaf
            },
        )?;
        let sah_block = settings.get("sah_block", if wide_packets { 4usize } else { 1 })?;
        let packet = settings.get("packet", PacketSize::Off)?;
        let packet_cull = settings.get("packet_cull", OnOff(true))?.0;
        let build_threads = settings.get("build_threads", 1usize)?;
        let spatial = settings.get("spatial", 1.0f32)?;
        let spatial_min = settings.get("spatial_min", 128usize)?;
        settings.finish()?;
        if !(1..=64).contains(&build_threads) {
            return Err(bad(
                "build_threads",
                build_threads.to_string(),
                "must be from 1 to 64",
            ));
        }
        if !(0.0..=4.0).contains(&spatial) {
            return Err(bad(
                "spatial",
                spatial.to_string(),
                "must be from 0 (no spatial splits) to 4 (extra references per triangle)",
            ));
        }
        if spatial_min < 2 {
            return Err(bad(
                "spatial_min",
                spatial_min.to_string(),
                "must be at least 2",
            ));
        }
        if packet != PacketSize::Off && (!simd || width == 2) {
            return Err(bad(
                "packet",
                format!("{}", packet.rays()),
                "packets need simd=on and bvh4 or bvh8",
            ));
        }
        if (1..=MAX_LEAF_PRIMS).contains(&leaf) && !(leaf..=MAX_LEAF_PRIMS).contains(&max_leaf) {
            return Err(bad(
                "max_leaf",
                max_leaf.to_string(),
                &format!("must be from leaf ({leaf}) to {MAX_LEAF_PRIMS}"),
            ));
        }
        if !(1..=MAX_LEAF_PRIMS).contains(&sah_block) || !sah_block.is_power_of_two() {
            return Err(bad(
                "sah_block",
                sah_block.to_string(),
                &format!("must be a power of two from 1 to {MAX_LEAF_PRIMS}"),
            ));
        }
        if !precompute && simd {
            return Err(bad(
                "precompute",
                "off".into(),
                "the SIMD box tests always precompute; precompute=off needs simd=off",
            ));
        }
        if !(1..=MAX_LEAF_PRIMS).contains(&leaf) {
            return Err(bad(
                "leaf",
                leaf.to_string(),
                &format!("must be from 1 to {MAX_LEAF_PRIMS}"),
            ));
        }
        if !(2..=256).contains(&bins) {
            return Err(bad("bins", bins.to_string(), "must be from 2 to 256"));
        }
        check_width(width, builder, wide).map_err(|r| bad("width", width.to_string(), &r))?;
        if simd && width == 2 {
            return Err(bad(
                "simd",
                "on".into(),
                "bvh2 has no SIMD traversal (its nodes hold two boxes); use bvh4 or bvh8",
            ));
        }
        Ok(Config {
            width,
            builder,
            wide,
            leaf,
            simd,
            isa,
            triangle,
            bins,
            packets,
            split_leaves,
            precompute,
            max_leaf,
            sah_block,
            packet,
            packet_cull,
            build_threads,
            spatial,
            spatial_min,
        })
    }
}

/// 001's branching factors (§1.4–§1.5): 2 to [`MAX_WIDTH`] in steps of two; 001's N-ary SAH
/// (`wide=direct` with a SAH builder) splits in halves, so it needs a power of two.
pub fn check_width(width: usize, builder: Builder, wide: WideMethod) -> Result<(), String> {
    if !(2..=MAX_WIDTH).contains(&width) || width & 1 == 1 {
        return Err(format!("must be even, from 2 to {MAX_WIDTH}"));
    }
    if wide == WideMethod::Direct && builder != Builder::Median && !width.is_power_of_two() {
        return Err(format!(
            "wide=direct with builder={} needs a power of two (001's SAH splits in halves)",
            builder.name()
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(width: usize, kv: &[(&str, &str)]) -> Result<Config, EngineError> {
        let pairs = kv
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        Config::parse(width, Settings::new("bvh", pairs))
    }

    #[test]
    fn defaults_and_keys() {
        let c = parse(4, &[]).unwrap();
        assert_eq!(c.builder, Builder::SahBinned);
        assert!(c.simd);
        assert_eq!(c.leaf, 4);
        let c = parse(2, &[]).unwrap();
        assert!(!c.simd);
        assert_eq!(c.leaf, 1);
        let c = parse(8, &[("builder", "median"), ("leaf", "1"), ("simd", "off")]).unwrap();
        assert_eq!((c.builder, c.leaf, c.simd), (Builder::Median, 1, false));
        assert!(parse(8, &[("leaf", "0")]).is_err());
        assert!(parse(8, &[("leaf", "17")]).is_err());
        assert!(parse(8, &[("builder", "kd")]).is_err());
        assert!(parse(2, &[("simd", "on")]).is_err());
        assert_eq!(parse(8, &[]).unwrap().isa, Isa::Auto);
        for (v, isa) in [
            ("auto", Isa::Auto),
            ("avx2", Isa::Avx2),
            ("avx512", Isa::Avx512),
        ] {
            assert_eq!(parse(4, &[("isa", v)]).unwrap().isa, isa);
        }
        assert!(parse(8, &[("isa", "sse9")]).is_err());
        assert_eq!((c.packets, c.split_leaves), (true, false));
        let c = parse(4, &[("packets", "off")]).unwrap();
        assert_eq!((c.packets, c.split_leaves), (false, true));
        assert!(!parse(2, &[]).unwrap().packets);
        assert!(parse(4, &[]).unwrap().precompute);
        assert!(parse(4, &[("precompute", "off")]).is_err());
        assert!(
            !parse(4, &[("precompute", "off"), ("simd", "off")])
                .unwrap()
                .precompute
        );
        assert!(matches!(
            parse(4, &[("colour", "red")]),
            Err(EngineError::UnknownKey { .. })
        ));
    }

    #[test]
    fn sah_leaves_default_with_packets_only() {
        let c = parse(8, &[]).unwrap();
        assert_eq!((c.leaf, c.max_leaf, c.sah_block), (4, 16, 4));
        // A leaf given is the largest (001's leaf=1 keeps one primitive per leaf).
        let c = parse(4, &[("leaf", "1")]).unwrap();
        assert_eq!((c.leaf, c.max_leaf), (1, 1));
        let c = parse(4, &[("packets", "off")]).unwrap();
        assert_eq!((c.max_leaf, c.sah_block), (4, 1));
        // Lane by lane every triangle is a test: 001's count, leaves of at most `leaf`.
        let c = parse(4, &[("simd", "off")]).unwrap();
        assert_eq!((c.leaf, c.max_leaf, c.sah_block), (4, 4, 1));
        assert_eq!(parse(2, &[]).unwrap().max_leaf, 1);
        assert!(parse(8, &[("leaf", "8"), ("max_leaf", "4")]).is_err());
        assert!(parse(8, &[("max_leaf", "17")]).is_err());
        assert!(parse(8, &[("sah_block", "0")]).is_err());
        assert!(parse(8, &[("sah_block", "3")]).is_err());
    }

    #[test]
    fn packets_and_build_threads() {
        let c = parse(8, &[]).unwrap();
        assert_eq!((c.packet, c.build_threads), (PacketSize::Off, 1));
        assert_eq!(parse(8, &[("packet", "16")]).unwrap().packet.rays(), 16);
        assert_eq!(parse(4, &[("packet", "8")]).unwrap().packet.rays(), 8);
        // Packets test boxes in AVX2 lanes: not for the scalar kernels, nor for bvh2.
        assert!(parse(4, &[("packet", "8"), ("simd", "off")]).is_err());
        assert!(parse(2, &[("packet", "8")]).is_err());
        assert!(parse(8, &[("packet", "4")]).is_err());
        assert_eq!(
            parse(8, &[("build_threads", "2")]).unwrap().build_threads,
            2
        );
        assert!(parse(8, &[("build_threads", "0")]).is_err());
    }

    #[test]
    fn widths_are_001s() {
        for w in [2, 4, 6, 8, 10, 12, 14, 16] {
            assert!(parse(w, &[("builder", "median"), ("wide", "direct")]).is_ok());
            assert!(parse(w, &[("simd", "off")]).is_ok(), "collapse to {w}");
        }
        for w in [0, 1, 3, 7, 18, 32] {
            let e = parse(w, &[("simd", "off")]).unwrap_err();
            assert!(e.to_string().contains("'width'"), "{e}");
        }
        for w in [6, 10, 12, 14] {
            assert!(parse(w, &[("builder", "sah-sweep"), ("wide", "direct")]).is_err());
        }
        assert!(parse(16, &[("builder", "sah-sweep"), ("wide", "direct")]).is_ok());
    }
}
