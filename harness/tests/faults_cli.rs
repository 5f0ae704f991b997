//! Faults of the out-of-core method from the command line: a hierarchy
//! file that disagrees with its level below, and a full disk during preprocessing. Each must end
//! in exit status 2 with one line on stderr, and leave nothing half-written behind. (A truncated
//! on-disk grid is `hires_cli`'s `every_grid_renders_the_same_image_and_a_truncated_grid_exits_2`.)
//!
//! The full disk is simulated with a file-size limit (`RLIMIT_FSIZE`) on the child process, with
//! `SIGXFSZ` ignored: every write past the limit then fails with EFBIG, as a write on a full disk
//! fails with ENOSPC, without a tmpfs or a loop mount (which need root). The code under test sees
//! an I/O error from `write` in both cases; the same run on a 3,600 KiB tmpfs gives
//! ENOSPC instead.

mod common;

use common::{expect_input_error, json, store_scene, Dir};
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::Command;

/// Runs rtbench with every file it writes limited to `limit` bytes; returns (status, stderr).
fn rtbench_limited(args: &[&str], limit: u64) -> (Option<i32>, String) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_rtbench"));
    cmd.args(args);
    // SAFETY: between fork and exec only async-signal-safe calls (signal, setrlimit) on values
    // owned by this closure; no allocation, no lock.
    unsafe {
        cmd.pre_exec(move || {
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
            let r = libc::rlimit {
                rlim_cur: limit as libc::rlim_t,
                rlim_max: limit as libc::rlim_t,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &r) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let out = cmd.output().expect("rtbench runs");
    assert!(out.stdout.is_empty(), "{args:?}: wrote to stdout");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Exit 2, one line naming the failed write (besides a reproduction's progress lines, which
/// start with its id), no panic.
fn expect_write_failure(args: &[&str], limit: u64) {
    let (code, err) = rtbench_limited(args, limit);
    assert_eq!(code, Some(2), "{args:?}: {err}");
    let errors: Vec<&str> = err
        .trim_end()
        .lines()
        .filter(|l| !l.starts_with("nakamaru-4.1: "))
        .collect();
    assert_eq!(errors.len(), 1, "{args:?}: {err}");
    assert!(err.contains("File too large"), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_full_disk_while_writing_a_store_leaves_nothing() {
    let d = Dir::new("faults-cli", "store");
    let out = d.join("m6");
    // mount6 is 8,196 objects: its bbox.bin alone is 295 KB, past a 64 KiB limit.
    expect_write_failure(
        &[
            "scene",
            "store",
            "mount",
            "--sf",
            "6",
            "-o",
            &out,
            "--hierarchy",
        ],
        64 << 10,
    );
    assert!(names(&d.0).is_empty(), "left behind: {:?}", names(&d.0));
}

#[test]
fn a_full_disk_while_building_the_hierarchy_or_the_disk_grid_leaves_nothing() {
    let d = Dir::new("faults-cli", "pre");
    let store = d.join("m6");
    json(&[
        "scene", "store", "mount", "--sf", "6", "-o", &store, "--json",
    ]);
    let before = names(Path::new(&store));
    assert_eq!(
        before,
        ["bbox.bin", "geometry.bin", "header.json", "materials.bin"]
    );
    let render = |sets: &[&str], limit: u64| {
        let mut args = vec![
            "render",
            "--scene",
            &store,
            "--engine",
            "breadth-first",
            "--size",
            "16",
        ];
        for s in sets {
            args.extend(["--set", s]);
        }
        expect_write_failure(&args, limit);
        assert_eq!(names(Path::new(&store)), before, "{sets:?}");
    };
    // bh_s = 0.01 keeps level 1 near one box per object (8,196 × 44 bytes), past 64 KiB.
    render(&["hierarchy=on", "bh_s=0.01"], 64 << 10);
    // The on-disk grid of the high-resolution method: one byte per voxel, thousands of voxels
    // at mount6's resolution (capped at 32 per axis), past a 512-byte limit.
    render(&["grid=two-level", "upper=32", "lower=1", "cap=32"], 512);
    // With room, the same commands build and render (so the limit, not the settings, failed).
    for sets in [
        vec!["hierarchy=on", "bh_s=0.01"],
        vec!["grid=two-level", "upper=32", "lower=1", "cap=32"],
    ] {
        let v = common::render_breadth_first(&store, &sets);
        assert!(v["image"]["sha256"].is_string());
    }
}

#[test]
fn a_full_disk_in_a_reproduction_saves_no_row() {
    let d = Dir::new("faults-cli", "repro");
    let out = d.join("out");
    let spill = d.join("spill");
    std::fs::create_dir_all(&spill).unwrap();
    let set_spill = format!("spill={spill}");
    expect_write_failure(
        &[
            "reproduce",
            "nakamaru-4.1",
            "--out",
            &out,
            "--set",
            "rows=tetra6",
            "--set",
            "size=16",
            "--set",
            &set_spill,
        ],
        64 << 10,
    );
    let partial = Path::new(&out).join(".partial/nakamaru-4.1");
    assert!(
        !partial.exists() || names(&partial).is_empty(),
        "a step was saved: {:?}",
        names(&partial)
    );
    assert!(!Path::new(&out).join("nakamaru-4.1.json").exists());
    assert!(
        names(Path::new(&spill)).is_empty(),
        "{:?}",
        names(Path::new(&spill))
    );
}

/// CRC-32 (IEEE), as the store's records use.
fn crc32(parts: &[&[u8]]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    for p in parts {
        h.update(p);
    }
    h.finalize()
}

#[test]
fn a_hierarchy_that_disagrees_with_its_level_below_exits_2() {
    let d = Dir::new("faults-cli", "bh");
    let store = d.join("tetra4");
    store_scene("tetra", "4", &store, &["--hierarchy"]);
    // Level-1 node 0 (after the 16-byte file header; 44-byte records: 6 × f32 box, u64 end,
    // u32 children, u32 objects, u32 CRC of level, index and the first 40 bytes): its box shrunk
    // to its min corner, the checksum made right, so only the check against level 0 can tell.
    let l1 = Path::new(&store).join("bbox-1.bin");
    let mut b = std::fs::read(&l1).unwrap();
    let rec = &mut b[16..16 + 44];
    let lo = rec[..12].to_vec();
    rec[12..24].copy_from_slice(&lo);
    let crc = crc32(&[&1u32.to_le_bytes(), &0u64.to_le_bytes(), &rec[..40]]);
    rec[40..44].copy_from_slice(&crc.to_le_bytes());
    std::fs::write(&l1, &b).unwrap();
    expect_input_error(
        &[
            "render",
            "--scene",
            &store,
            "--engine",
            "breadth-first",
            "--size",
            "16",
            "--set",
            "hierarchy=on",
        ],
        "disagrees with the level below",
    );
    // Refused, not rebuilt: the store still holds the damaged file, for the user to look at.
    assert_eq!(std::fs::read(&l1).unwrap(), b);
}
