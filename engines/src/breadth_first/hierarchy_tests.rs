//! The bounding-box hierarchy (seed 000 §4.2.2, "B") changes which boxes are read, never the
//! answers; it skips subtrees; a hierarchy that disagrees with its level below, a truncated level
//! file or one built for another header is refused in one line; a failed build leaves nothing.

use super::*;
use crate::geometry::Geometry;
use crate::store::hierarchy::{
    encode, level_file, Constants, Hierarchy, HIERARCHY_FILE, NODE_RECORD,
};
use crate::store::tests::TempDir;
use crate::store::FILE_HEADER;
use crate::test_support::{answers, kv, rays_around, same_answers, spd};
use crate::{build_engine, Counters, Ray};
use rtbench_scenes::spd::Program;

fn rays(g: &Geometry, n: usize) -> (Vec<Ray>, Vec<Ray>) {
    rays_around(g, n, 12345)
}

#[test]
fn the_hierarchy_skips_subtrees_and_changes_no_answer() {
    let mut skipped_somewhere = false;
    for (program, sf) in [
        (Program::Tetra, 4),
        (Program::Balls, 2),
        (Program::Mount, 4),
        (Program::Rings, 2),
        (Program::Tree, 6),
    ] {
        let input = spd(program, sf);
        let r = rays(&input.geometry, 1200);
        let base = build_engine("breadth-first", &input, vec![]).unwrap();
        let want = answers(base.as_ref(), &r, &mut Counters::default());
        for settings in [
            vec![("hierarchy", "on")],
            vec![
                ("hierarchy", "on"),
                ("bh_s", "1.5"),
                ("bh_m", "4"),
                ("bh_t", "0.5"),
            ],
            vec![
                ("hierarchy", "on"),
                ("bh_l", "1"),
                ("memory", "300KiB"),
                ("lazy", "off"),
            ],
        ] {
            let (e, c) = same_answers("breadth-first", &input, &settings, &r, &want);
            let s = e.build_stats();
            assert!(s["bh_levels"] >= 1.0);
            let objects = input.scene.objects.len() as u64;
            // Each object's box read at most once per pass; what is skipped is not read.
            let passes = c.extra["bf_passes"];
            assert!(c.extra["bh_level_0_read"] + c.extra["bh_objects_skipped"] <= objects * passes);
            skipped_somewhere |= c.extra["bh_objects_skipped"] > 0;
        }
    }
    assert!(skipped_somewhere, "no subtree was ever skipped");
}

#[test]
fn levels_follow_the_constants() {
    let input = spd(Program::Mount, 5);
    let dir = TempDir::new("bh-levels");
    StoreWriter::create(&dir.0, "mount5")
        .unwrap()
        .write_scene(&input.scene)
        .unwrap();
    let h = StoreHeader::read(&dir.0).unwrap();
    let c = Constants::thesis("mount5");
    assert_eq!((c.s, c.m, c.l, c.t), (3.0, 1000, 4, 1.0));
    assert_eq!(Constants::thesis("balls6").t, 0.5);
    let b = Hierarchy::build(&h, c, 4096).unwrap();
    // t = 1.0 merges everything on top: one group; below, fewer boxes at every level.
    assert_eq!(*b.levels.last().unwrap(), 1);
    assert!(b.levels.windows(2).all(|w| w[1] < w[0]) && b.levels[0] < h.objects);
    let info = Hierarchy::open(&h, Some(c)).unwrap().unwrap();
    info.verify(4096).unwrap();
    // Other constants: not this hierarchy.
    assert!(Hierarchy::open(&h, Some(Constants { s: 2.0, ..c }))
        .unwrap()
        .is_none());
    let deep = Hierarchy::build(
        &h,
        Constants {
            s: 1.0,
            m: 1,
            l: 3,
            t: 0.5,
        },
        4096,
    )
    .unwrap();
    assert_eq!(deep.levels.len(), 3);
}

fn open_bh(dir: &std::path::Path, verify: &str) -> Result<BreadthFirst, EngineError> {
    let s = Settings::new(
        "breadth-first",
        kv(&[("hierarchy", "on"), ("verify", verify), ("bh_s", "2")]),
    );
    BreadthFirst::open(dir, BreadthFirstConfig::from_settings(s).unwrap())
}

#[test]
fn a_disagreeing_truncated_or_foreign_hierarchy_is_refused() {
    let input = spd(Program::Tetra, 4);
    let dir = TempDir::new("bh-bad");
    StoreWriter::create(&dir.0, "tetra4")
        .unwrap()
        .write_scene(&input.scene)
        .unwrap();
    let e = open_bh(&dir.0, "full").unwrap();
    let r = rays(&input.geometry, 300);
    drop(e);
    let l1 = dir.0.join(level_file(1));
    let good = std::fs::read(&l1).unwrap();
    // Shrink the box of level-1 node 0 (checksum kept right): it no longer holds its children.
    let mut bad = good.clone();
    let at = FILE_HEADER as usize;
    let rec: [u8; NODE_RECORD] = bad[at..at + NODE_RECORD].try_into().unwrap();
    let f = |i: usize| f32::from_le_bytes(rec[i * 4..i * 4 + 4].try_into().unwrap());
    let node = crate::store::NodeRecord {
        lo: Vec3::new(f(0), f(1), f(2)),
        hi: Vec3::new(f(0), f(1), f(2)),
        end: u64::from_le_bytes(rec[24..32].try_into().unwrap()),
        children: u32::from_le_bytes(rec[32..36].try_into().unwrap()),
        objects: u32::from_le_bytes(rec[36..40].try_into().unwrap()),
    };
    bad[at..at + NODE_RECORD].copy_from_slice(&encode(1, 0, &node));
    std::fs::write(&l1, &bad).unwrap();
    let err = open_bh(&dir.0, "full").err().unwrap().to_string();
    assert!(
        err.contains("disagrees with the level below") && !err.contains('\n'),
        "{err}"
    );
    // Unverified (`verify=records`) a node whose box shrank is skipped when no ray needs it,
    // and its objects with it: only the full check (the default) reads what is skipped.
    let e = open_bh(&dir.0, "records").unwrap();
    let _ = answers(&e, &r, &mut Counters::default());
    drop(e);
    // A flipped byte: the record's checksum.
    let mut flipped = good.clone();
    flipped[at + 3] ^= 1;
    std::fs::write(&l1, &flipped).unwrap();
    let err = open_bh(&dir.0, "full").err().unwrap().to_string();
    assert!(
        err.contains("checksum") || err.contains("disagrees"),
        "{err}"
    );
    // Truncated.
    std::fs::write(&l1, &good[..good.len() - 7]).unwrap();
    let err = open_bh(&dir.0, "records").err().unwrap().to_string();
    assert!(err.contains("bytes") && !err.contains('\n'), "{err}");
    // Another header: the hierarchy belongs to the store it was built for.
    std::fs::write(&l1, &good).unwrap();
    assert!(open_bh(&dir.0, "full").is_ok());
    let hp = dir.0.join(crate::store::HEADER_FILE);
    let text = std::fs::read_to_string(&hp).unwrap();
    let other = dir.0.with_extension("other");
    let _ = std::fs::remove_dir_all(&other);
    StoreWriter::create(&other, "tetra4b")
        .unwrap()
        .write_scene(&input.scene)
        .unwrap();
    std::fs::copy(dir.0.join(HIERARCHY_FILE), other.join(HIERARCHY_FILE)).unwrap();
    let err = Hierarchy::open(&StoreHeader::read(&other).unwrap(), None)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("another header.json"), "{err}");
    let _ = std::fs::remove_dir_all(&other);
    assert!(!text.is_empty());
}

#[test]
fn a_failed_build_leaves_nothing_behind() {
    let input = spd(Program::Tetra, 4);
    let dir = TempDir::new("bh-fail");
    StoreWriter::create(&dir.0, "tetra4")
        .unwrap()
        .write_scene(&input.scene)
        .unwrap();
    let h = StoreHeader::read(&dir.0).unwrap();
    // Level 2's temporary file cannot be made (a directory is in its place): level 1, already
    // renamed into place, must go too, and no hierarchy.json is written.
    let blocker = dir
        .0
        .join(format!(".{}.tmp-{}", level_file(2), std::process::id()));
    std::fs::create_dir(&blocker).unwrap();
    let c = Constants {
        s: 1.0,
        m: 1,
        l: 4,
        t: 1.0,
    };
    assert!(Hierarchy::build(&h, c, 4096).is_err());
    std::fs::remove_dir(&blocker).unwrap();
    let left: Vec<_> = std::fs::read_dir(&dir.0)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("bbox-") || n.starts_with('.') || n == HIERARCHY_FILE)
        .collect();
    assert!(left.is_empty(), "{left:?}");
    assert!(Hierarchy::open(&h, None).unwrap().is_none());
    // hierarchy=on on a split layout only.
    let s = Settings::new(
        "breadth-first",
        kv(&[("layout", "basic"), ("hierarchy", "on")]),
    );
    assert!(BreadthFirstConfig::from_settings(s).is_err());
}
