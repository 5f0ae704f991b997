//! Build script of rtbench-engines: locates Embree 4 for the `embree` feature.
//!
//! embree4-sys only emits `-l embree4` (its headers are bundled): the folder holding `libembree4.so` must come
//! from us. It is `RTBENCH_EMBREE_LIB_DIR`, which .cargo/config.toml sets to the workspace's `.embree/lib` (made
//! by scripts/setup.sh) as an absolute path computed by Cargo; without it we fall back to `../.embree/lib` from
//! this crate's manifest.
//!
//! - `rustc-link-search` propagates to every binary that links this crate, so `-l embree4` resolves everywhere.
//! - `rustc-link-arg` (the rpath) applies only to this package's own tests, examples and benches. Binaries of
//!   other packages get it from their own build script, which reads `DEP_RTBENCH_EMBREE_LIB_DIR` (the `lib_dir`
//!   metadata below; Cargo passes it to the build scripts of direct dependants because of `links`).

use std::env;
use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=RTBENCH_EMBREE_LIB_DIR");
    if env::var_os("CARGO_FEATURE_EMBREE").is_none() {
        return;
    }
    let dir = match env::var_os("RTBENCH_EMBREE_LIB_DIR") {
        Some(d) if !d.is_empty() => PathBuf::from(d),
        _ => {
            PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"))
                .join("..")
                .join(".embree")
                .join("lib")
        }
    };
    let lib = dir.join("libembree4.so");
    if !lib.exists() {
        eprintln!(
            "error: Embree 4 not found ({} is missing): run `bash scripts/setup.sh` at the repository root, \
             or build with `--no-default-features` to leave the embree engine out",
            lib.display()
        );
        std::process::exit(1);
    }
    let dir = dir.canonicalize().unwrap_or(dir);
    let dir = dir.to_str().unwrap_or_else(|| {
        eprintln!(
            "error: the Embree folder {} is not valid UTF-8",
            dir.display()
        );
        std::process::exit(1);
    });
    // A new Embree from setup.sh must relink.
    println!("cargo:rerun-if-changed={dir}/libembree4.so");
    println!("cargo:rustc-link-search=native={dir}");
    println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
    println!("cargo:lib_dir={dir}");
    // The file `embree::api` opens at run time (the engine calls Embree through pointers it
    // looks up there, so the binaries no longer need the library to start).
    println!("cargo:rustc-env=RTBENCH_EMBREE_LIB={dir}/libembree4.so");
}
