//! `tinybvh`: J. Bikker's tinybvh (a single C++ header) as a peer of our own BVHs, like `obvhs`:
//! its builder and its own traversal kernels, hits and any-hit queries included.
//!
//! | key | values | default |
//! |---|---|---|
//! | `layout` | `bvh8_cpu` (8-wide, AVX2; Fuetterling et al. 2017), `bvh4_cpu` (4-wide, SSE), `cwbvh` (Ylitie, Karras and Laine 2017; CPU traversal, no any-hit query of its own), `bvh` (binary) | `bvh8_cpu` |
//! | `quality` | `default` (tinybvh's binned SAH), `hq` (its spatial-split builder) | `default` |
//! | `tess`, `tessellate` | as for `plugin`: tinybvh takes triangles only, spheres and cones are tessellated | 8, `auto` |
//!
//! Why a plugin and not the `tinybvh-rs` crate in this process: the crate binds the BVH8_CPU
//! traversal only under `cfg(target_feature = "avx2")`, and cargo (stable) has no per-crate
//! target features: enabling AVX2 for the crate means enabling it for every crate of the binary,
//! which changes every other engine's code generation. The crate also binds no any-hit query
//! (`IsOccluded`) and no BVH4_CPU. So examples/tinybvh/build.sh compiles a small C ABI wrapper
//! (include/rtbench_engine.h) against the header that `tinybvh-rs` ships, with AVX2 and FMA for
//! that library alone, and this engine loads it through [`crate::plugin`], which checks every
//! answer.
//!
//! tinybvh counts nothing in its release traversal: the counters give rays only.

use crate::engine::{BuildInput, EngineError, EngineInfo, Settings};
use crate::plugin;
use std::path::PathBuf;

/// The library's file name, in `$RTBENCH_PLUGIN_DIR` (or `./plugins`) or where build.sh puts it.
const LIB: &str = "librtbench_tinybvh.so";

pub const LAYOUTS: [&str; 4] = ["bvh8_cpu", "bvh4_cpu", "cwbvh", "bvh"];

pub fn info() -> EngineInfo {
    EngineInfo {
        name: "tinybvh",
        description: "tinybvh (C++ header of the tinybvh-rs crate, AVX2 plugin): \
                      layout=bvh8_cpu|bvh4_cpu|cwbvh|bvh",
        available: || library().map(|_| ()),
        build,
    }
}

/// Where examples/tinybvh/build.sh writes the library by default: `target/tinybvh/` of the
/// workspace this rtbench was built in (RTBENCH_TINYBVH_LIB, set by .cargo/config.toml).
fn built_library() -> Option<PathBuf> {
    option_env!("RTBENCH_TINYBVH_LIB").map(PathBuf::from)
}

/// The plugin library: in the plugin folder first, else where build.sh put it.
pub fn library() -> Result<PathBuf, String> {
    let in_dir = plugin::plugin_dir().join(LIB);
    if in_dir.is_file() {
        return Ok(in_dir);
    }
    match built_library() {
        Some(p) if p.is_file() => Ok(p),
        _ => Err(format!(
            "{LIB} not built (bash examples/tinybvh/build.sh; needs a C++ compiler and an \
             x86-64 CPU with AVX2 and FMA)"
        )),
    }
}

fn build(
    input: &BuildInput,
    mut settings: Settings,
) -> Result<Box<dyn crate::engine::Engine>, EngineError> {
    let layout: String = settings.get("layout", "bvh8_cpu".to_string())?;
    if !LAYOUTS.contains(&layout.as_str()) {
        return Err(EngineError::BadValue {
            engine: "tinybvh".into(),
            key: "layout".into(),
            value: layout,
            reason: format!("expected one of {}", LAYOUTS.join(", ")),
        });
    }
    let quality: String = settings.get("quality", "default".to_string())?;
    if quality != "default" && quality != "hq" {
        return Err(EngineError::BadValue {
            engine: "tinybvh".into(),
            key: "quality".into(),
            value: quality,
            reason: "expected default or hq".into(),
        });
    }
    let tess: String = settings.get("tess", "8".to_string())?;
    let tessellate: String = settings.get("tessellate", "auto".to_string())?;
    settings.finish()?;
    let path = library().map_err(|reason| EngineError::Unavailable {
        engine: "tinybvh".into(),
        reason,
    })?;
    let pairs = vec![
        ("path".to_string(), path.display().to_string()),
        ("tess".to_string(), tess),
        ("tessellate".to_string(), tessellate),
        ("layout".to_string(), layout),
        ("quality".to_string(), quality),
    ];
    (plugin::info().build)(input, Settings::new("plugin", pairs)).map_err(|e| match e {
        EngineError::Build { reason, .. } => EngineError::Build {
            engine: "tinybvh".into(),
            reason,
        },
        EngineError::BadValue {
            key, value, reason, ..
        } => EngineError::BadValue {
            engine: "tinybvh".into(),
            key,
            value,
            reason,
        },
        other => other,
    })
}

#[cfg(test)]
mod tests;
