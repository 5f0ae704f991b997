//! Gives the tests an rpath to the Embree folder rtbench-engines linked against (see
//! engines/build.rs: DEP_RTBENCH_EMBREE_LIB_DIR, set when its `embree` feature is on).
fn main() {
    println!("cargo:rerun-if-env-changed=DEP_RTBENCH_EMBREE_LIB_DIR");
    if let Ok(dir) = std::env::var("DEP_RTBENCH_EMBREE_LIB_DIR") {
        println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
