//! Gives this package's binaries and tests an rpath to the Embree folder that rtbench-engines linked
//! against (engines/build.rs passes it as DEP_RTBENCH_EMBREE_LIB_DIR, only when its `embree` feature is on).
//! A `rustc-link-arg` from a dependency's build script does not reach our binaries, hence this file.
fn main() {
    println!("cargo:rerun-if-env-changed=DEP_RTBENCH_EMBREE_LIB_DIR");
    if let Ok(dir) = std::env::var("DEP_RTBENCH_EMBREE_LIB_DIR") {
        println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
