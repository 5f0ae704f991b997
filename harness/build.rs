//! Build script of the rtbench binary.
//!
//! - An rpath to the Embree folder that rtbench-engines linked against (engines/build.rs passes it
//!   as DEP_RTBENCH_EMBREE_LIB_DIR when its `embree` feature is on): a `rustc-link-arg` from a
//!   dependency's build script does not reach our binaries.
//! - The git commit and the rustc version, for the environment recorded with every result.
use std::process::Command;

fn output(cmd: &str, args: &[&str]) -> Option<String> {
    let o = Command::new(cmd).args(args).output().ok()?;
    o.status
        .success()
        .then(|| String::from_utf8_lossy(&o.stdout).trim().to_string())
}

fn main() {
    // The target triple, for the tests that compile the example C plugin with the `cc` crate.
    if let Ok(t) = std::env::var("TARGET") {
        println!("cargo:rustc-env=RTBENCH_BUILD_TARGET={t}");
    }
    println!("cargo:rerun-if-env-changed=DEP_RTBENCH_EMBREE_LIB_DIR");
    if let Ok(dir) = std::env::var("DEP_RTBENCH_EMBREE_LIB_DIR") {
        println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
    }
    // Rebuild when HEAD moves or the index changes (a commit or a staged change): the checkout's own
    // HEAD and index, and the branch HEAD names, found through git so that a linked worktree (whose
    // `.git` is a file) and packed refs are followed too.
    let mut watch: Vec<std::path::PathBuf> = Vec::new();
    if let Some(git_dir) = output("git", &["rev-parse", "--absolute-git-dir"]) {
        let git_dir = std::path::PathBuf::from(git_dir);
        watch.extend([git_dir.join("HEAD"), git_dir.join("index")]);
    }
    if let Some(common) = output(
        "git",
        &["rev-parse", "--path-format=absolute", "--git-common-dir"],
    ) {
        let common = std::path::PathBuf::from(common);
        if let Some(branch) = output("git", &["symbolic-ref", "-q", "HEAD"]) {
            watch.push(common.join(branch));
        }
        watch.push(common.join("packed-refs"));
    }
    for f in watch.iter().filter(|f| f.exists()) {
        println!("cargo:rerun-if-changed={}", f.display());
    }
    let commit = output("git", &["rev-parse", "HEAD"]).unwrap_or_else(|| "unknown".into());
    let dirty = output("git", &["status", "--porcelain", "--untracked-files=no"])
        .map(|s| !s.is_empty())
        .unwrap_or(false);
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let rustc_version = output(&rustc, &["--version"]).unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=RTBENCH_GIT_COMMIT={commit}");
    println!("cargo:rustc-env=RTBENCH_GIT_DIRTY={dirty}");
    println!("cargo:rustc-env=RTBENCH_RUSTC={rustc_version}");
}
