//! An rtbench engine plugin written in Rust: a `cdylib` that exports a Rust [`Engine`] through
//! the C ABI of `include/rtbench_engine.h` with [`rtbench_engines::export_plugin!`].
//!
//! What it exports is chosen by the setting `engine=NAME` (default `bvh8`): one of rtbench's
//! own engines, built from the arrays the plugin receives. Run beside the same engine built in
//! (`--engines bvh8,plugin:target/release/librtbench_rust_plugin.so`), it measures what the ABI
//! costs: same algorithm, same geometry, only the boundary differs. An engine of your own goes
//! where `build_engine` is called: any type implementing [`Engine`].
//!
//! Build: `cargo build --release -p rtbench-rust-plugin`.

use rtbench_engines::plugin::{PRIM_CONES, PRIM_SPHERES, PRIM_TRIANGLES};
use rtbench_engines::{BuildInput, Engine, EngineError, Settings};

fn build(input: &BuildInput, mut s: Settings) -> Result<Box<dyn Engine>, EngineError> {
    let name: String = s.get("engine", "bvh8".to_string())?;
    if name == "plugin" {
        return Err(EngineError::Build {
            engine: "rust-plugin".into(),
            reason: "engine=plugin: a plugin cannot load itself".into(),
        });
    }
    // The remaining settings are the inner engine's (it rejects keys it does not know).
    rtbench_engines::build_engine(&name, input, s.into_rest())
}

rtbench_engines::export_plugin!(
    c"rust-plugin",
    c"0.1",
    PRIM_TRIANGLES | PRIM_SPHERES | PRIM_CONES,
    build
);
