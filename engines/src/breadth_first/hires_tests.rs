//! The high-resolution grid (seed 000 §4.3) changes where rays are registered, never the
//! answers: the capped single-level grid and the two-level grid (with lower grids, with a pool
//! too small so that rays go directly to the upper grid, with one-slice blocks and small
//! subspaces, with the hierarchy) answer exactly as the basic in-memory grid; each block is read
//! at most twice per traversal; a truncated or foreign on-disk grid is refused in one line, and a
//! build that fails leaves no file.

use super::hires::disk_grid::FILE_NAME;
use super::*;
use crate::geometry::Geometry;
use crate::store::tests::TempDir;
use crate::test_support::{answers, kv, rays_around, same_answers, spd};
use crate::{build_engine, Counters, Engine, Ray};
use rtbench_scenes::spd::Program;

fn rays(g: &Geometry, n: usize) -> (Vec<Ray>, Vec<Ray>) {
    rays_around(g, n, 987654321)
}

#[test]
fn every_grid_answers_as_the_basic_one() {
    let (mut lower, mut direct, mut culled) = (0, 0, 0.0);
    for (program, sf) in [
        (Program::Tetra, 5),
        (Program::Mount, 5),
        (Program::Rings, 3),
        (Program::Balls, 3),
    ] {
        let input = spd(program, sf);
        let r = rays(&input.geometry, 1500);
        let base = build_engine("breadth-first", &input, vec![]).unwrap();
        let want = answers(base.as_ref(), &r, &mut Counters::default());
        for settings in [
            vec![("grid", "single"), ("cap", "8")],
            vec![("grid", "two-level")],
            vec![("grid", "two-level"), ("upper", "4"), ("lower", "4")],
            // A pool of 2: most rays go directly to the upper grid.
            vec![
                ("grid", "two-level"),
                ("upper", "4"),
                ("lower", "2"),
                ("pool", "2"),
                ("block", "64"),
                ("subspace", "3"),
                ("memory", "2MiB"),
            ],
            vec![
                ("grid", "two-level"),
                ("upper", "8"),
                ("lower", "2"),
                ("hierarchy", "on"),
                ("subspace", "5"),
            ],
        ] {
            let (e, c) = same_answers("breadth-first", &input, &settings, &r, &want);
            if settings[0].1 == "two-level" {
                let s = e.build_stats();
                let x = s["res_x"] as u64;
                let slices = s["hr_block_slices"] as u64;
                // Each block read at most twice per traversal (once each way).
                let blocks = x.div_ceil(slices);
                assert!(c.extra["hr_blocks_read"] <= 2 * blocks * c.extra["hr_traversals"]);
                assert!(
                    c.extra["hr_voxels_read"]
                        <= 2 * (s["voxels"] as u64) * c.extra["hr_traversals"]
                );
                assert_eq!(
                    c.extra["hr_lower_registrations"] + c.extra["hr_direct_registrations"],
                    c.extra["bf_registrations"]
                );
                lower += c.extra["hr_lower_registrations"];
                direct += c.extra["hr_direct_registrations"];
                culled += s.get("hr_build_nodes_culled").copied().unwrap_or(0.0);
            }
        }
    }
    assert!(lower > 0 && direct > 0, "lower {lower}, direct {direct}");
    assert!(culled > 0.0, "no hierarchy node was culled from a subspace");
}

fn open_hr(dir: &std::path::Path, reuse: bool) -> Result<BreadthFirst, EngineError> {
    let s = Settings::new(
        "breadth-first",
        kv(&[
            ("grid", "two-level"),
            ("upper", "4"),
            ("hrgrid", if reuse { "reuse" } else { "build" }),
        ]),
    );
    BreadthFirst::open(dir, BreadthFirstConfig::from_settings(s).unwrap())
}

/// tetra SF 4 and its store in a new temporary folder.
fn tetra4_store(name: &str) -> (crate::engine::BuildInput, TempDir) {
    let input = spd(Program::Tetra, 4);
    let dir = TempDir::new(name);
    StoreWriter::create(&dir.0, "tetra4")
        .unwrap()
        .write_scene(&input.scene)
        .unwrap();
    (input, dir)
}

#[test]
fn a_truncated_or_foreign_grid_is_refused_and_a_failed_build_leaves_nothing() {
    let (input, dir) = tetra4_store("hr-bad");
    let r = rays(&input.geometry, 200);
    let e = open_hr(&dir.0, false).unwrap();
    let want = answers(&e, &r, &mut Counters::default());
    drop(e);
    let path = dir.0.join(FILE_NAME);
    let good = std::fs::read(&path).unwrap();
    // Reused whole: the same answers.
    let e = open_hr(&dir.0, true).unwrap();
    assert_eq!(answers(&e, &r, &mut Counters::default()).1, want.1);
    drop(e);
    // Truncated.
    std::fs::write(&path, &good[..good.len() - 5]).unwrap();
    let err = open_hr(&dir.0, true).err().unwrap().to_string();
    assert!(
        err.contains("truncated") && err.contains(FILE_NAME) && !err.contains('\n'),
        "{err}"
    );
    // Truncated while tracing: the engine reports a failure, it does not panic.
    std::fs::write(&path, &good).unwrap();
    let e = open_hr(&dir.0, true).unwrap();
    std::fs::write(&path, &good[..100]).unwrap();
    let _ = answers(&e, &r, &mut Counters::default());
    let f = e.failure().expect("a failure");
    assert!(f.contains("truncated") && !f.contains('\n'), "{f}");
    drop(e);
    // A grid of another resolution.
    std::fs::write(&path, &good).unwrap();
    let s = Settings::new(
        "breadth-first",
        kv(&[("grid", "two-level"), ("cap", "3"), ("hrgrid", "reuse")]),
    );
    let err = BreadthFirst::open(&dir.0, BreadthFirstConfig::from_settings(s).unwrap())
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("another"), "{err}");
    // A build that fails (the store's directory made read-only is not enough as root, so the
    // temporary's name is taken by a directory) leaves no grid and no temporary.
    std::fs::remove_file(&path).unwrap();
    let tmp = dir.0.join(format!("{FILE_NAME}.tmp"));
    std::fs::create_dir(&tmp).unwrap();
    let err = open_hr(&dir.0, false).err().unwrap().to_string();
    assert!(err.contains("on-disk grid") && !err.contains('\n'), "{err}");
    assert!(!path.exists());
    std::fs::remove_dir(&tmp).unwrap();
}

/// `hrgrid=resume`: a build killed after `k` subspaces goes on from subspace `k + 1` (the first
/// `k` are not swept or written again: their bytes, zeroed here, stay as they are), counts
/// the recorded seconds, and a finished build is taken whole; a record of another grid is not.
#[test]
fn a_resumed_grid_build_sweeps_only_the_subspaces_not_yet_on_disk() {
    use super::hires::disk_grid::PROGRESS_FILE;
    let (_, dir) = tetra4_store("hr-resume");
    let open = |mode: &str, side: &str| {
        let s = Settings::new(
            "breadth-first",
            kv(&[
                ("grid", "two-level"),
                ("upper", "4"),
                ("subspace", side),
                ("hrgrid", mode),
            ]),
        );
        BreadthFirst::open(&dir.0, BreadthFirstConfig::from_settings(s).unwrap()).unwrap()
    };
    let path = dir.0.join(FILE_NAME);
    let tmp = dir.0.join(format!("{FILE_NAME}.tmp"));
    let progress = dir.0.join(PROGRESS_FILE);
    // A plain build keeps no record; a resumable one keeps the finished build's.
    let e = open("build", "5");
    let plain = e.build_stats().clone();
    drop(e);
    let good = std::fs::read(&path).unwrap();
    assert!(!progress.exists());
    let e = open("resume", "5");
    let s = e.build_stats().clone();
    drop(e);
    assert_eq!(std::fs::read(&path).unwrap(), good);
    assert_eq!(s["hr_build_resumed_subspaces"], 0.0);
    assert_eq!(s["hr_build_boxes_read"], plain["hr_build_boxes_read"]);
    let total = s["hr_subspaces"];
    assert!(total >= 8.0, "{total} subspaces");
    let side = s["hr_subspace_side"] as usize;
    let res = [s["res_x"], s["res_y"], s["res_z"]].map(|r| r as usize);
    let count = res.map(|r| r.div_ceil(side));
    // Killed after 3 subspaces: the grid still a temporary, the record at 3, and (to see what
    // is written again) the flags of every voxel zeroed.
    let mut rec: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&progress).unwrap()).unwrap();
    rec["done"] = 3.into();
    rec["seconds"] = 1000.0.into();
    std::fs::write(&progress, serde_json::to_vec(&rec).unwrap()).unwrap();
    let mut zeroed = good.clone();
    zeroed[64..].fill(0);
    std::fs::write(&tmp, &zeroed).unwrap();
    std::fs::remove_file(&path).unwrap();
    let e = open("resume", "5");
    let s = e.build_stats().clone();
    drop(e);
    assert_eq!(s["hr_build_resumed_subspaces"], 3.0);
    assert!(s["hr_build_prior_s"] == 1000.0 && s["hr_build_s"] >= 1000.0);
    assert!(s["preprocess_s"] >= 1000.0);
    assert_eq!(s["hr_subspaces"], total);
    assert!(!tmp.exists());
    let resumed = std::fs::read(&path).unwrap();
    let mut kept = 0;
    for x in 0..res[0] {
        for y in 0..res[1] {
            for z in 0..res[2] {
                let sub = ((x / side) * count[1] + y / side) * count[2] + z / side;
                let at = 64 + (x * res[1] + y) * res[2] + z;
                if sub < 3 {
                    assert_eq!(resumed[at], 0, "subspace {sub} was written again");
                    kept += usize::from(good[at] != 0);
                } else {
                    assert_eq!(resumed[at], good[at], "subspace {sub} not rebuilt");
                }
            }
        }
    }
    assert!(
        kept > 0,
        "the first 3 subspaces held no flag: the test shows nothing"
    );
    // Finished: taken whole, nothing swept, the recorded seconds counted.
    std::fs::write(&path, &good).unwrap();
    let e = open("resume", "5");
    let s = e.build_stats().clone();
    drop(e);
    assert_eq!(s["hr_build_resumed_subspaces"], total);
    assert!(s["hr_build_prior_s"] >= 1000.0);
    assert_eq!(std::fs::read(&path).unwrap(), good);
    // Another subspace side: another build, the record replaced.
    let e = open("resume", "6");
    let s = e.build_stats().clone();
    drop(e);
    assert_eq!(s["hr_build_resumed_subspaces"], 0.0);
    assert!(s["hr_build_prior_s"] == 0.0 && s["hr_build_s"] < 1000.0);
    assert_eq!(std::fs::read(&path).unwrap(), good);
    // A plain build drops the record.
    drop(open("build", "5"));
    assert!(!progress.exists());
}

/// `hrgrid_subspaces=K`: the build sweeps the first K subspaces only (each reading every box
/// of the store, as the whole build's do), the grid is opened at its whole length and then
/// removed from the store, so that no later run takes it; without `max_passes` (a run that
/// claims an image) or with `hrgrid=resume` the setting is refused.
#[test]
fn a_partial_grid_build_sweeps_k_subspaces_and_leaves_no_grid_behind() {
    let (_, dir) = tetra4_store("hr-partial");
    let config = |extra: &[(&str, &str)]| {
        let mut pairs = vec![("grid", "two-level"), ("upper", "4"), ("subspace", "5")];
        pairs.extend_from_slice(extra);
        BreadthFirstConfig::from_settings(Settings::new("breadth-first", kv(&pairs)))
    };
    let whole = BreadthFirst::open(&dir.0, config(&[]).unwrap()).unwrap();
    let w = whole.build_stats().clone();
    drop(whole);
    let path = dir.0.join(FILE_NAME);
    assert!(path.exists());
    let e = BreadthFirst::open(
        &dir.0,
        config(&[("hrgrid_subspaces", "3"), ("max_passes", "1")]).unwrap(),
    )
    .unwrap();
    let s = e.build_stats().clone();
    assert_eq!(s["hr_subspaces"], 3.0);
    assert_eq!(s["hr_subspaces_total"], w["hr_subspaces"]);
    assert!(w["hr_subspaces"] >= 8.0);
    assert_eq!((s["hr_build_partial"], w["hr_build_partial"]), (1.0, 0.0));
    assert_eq!(
        s["hr_build_boxes_read"] * w["hr_subspaces"],
        w["hr_build_boxes_read"] * 3.0
    );
    assert!(!path.exists(), "a partial grid was left in the store");
    // The run goes on with the grid it holds open: one pass, then the cap.
    let rays: Vec<Ray> = (0..64)
        .map(|i| {
            Ray::new(
                Vec3::new(-3.0, 0.01 * i as f32, 0.1),
                Vec3::X,
                0.0,
                f32::INFINITY,
            )
        })
        .collect();
    let mut c = Counters::default();
    let mut n = 0;
    e.trace_stream(
        &mut rays.iter().copied().enumerate().map(|(i, r)| (i as u32, r)),
        false,
        &mut |_, _| n += 1,
        &mut c,
    )
    .unwrap();
    assert_eq!(c.extra["bf_passes"], 1);
    for bad in [
        &[("hrgrid_subspaces", "3")][..],
        &[
            ("hrgrid_subspaces", "3"),
            ("max_passes", "1"),
            ("hrgrid", "resume"),
        ][..],
    ] {
        let Err(e) = config(bad) else {
            panic!("{bad:?} was taken")
        };
        let e = e.to_string();
        assert!(e.contains("hrgrid_subspaces") && !e.contains('\n'), "{e}");
    }
}
